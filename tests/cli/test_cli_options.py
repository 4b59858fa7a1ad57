"""The options many commands share are declared once (issue 36, item 6): the target, protocol,
solver, execution and output options live in one place each (:mod:`gearchaos.cli._options`)
and every command that takes them gets them from there; the verdict switch has one spelling
(``--verdict/--no-verdict``; ``--verdicts/--no-verdicts`` still works, hidden); choices come
from the library's own tuples, and what the library refuses reaches the user under the
option's name."""

from __future__ import annotations

import ast
import re
from pathlib import Path
from typing import Any

import pytest
import typer.main
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import EXIT_INVALID, _options as o, app
from gearchaos.dynamics.curves.boundary import ASSESS
from gearchaos.integrate.settings import SETTLE_CHOICES
from gearchaos.plot.amplitude import QUANTITIES
from gearchaos.sweep.exports import FORMATS
from gearchaos.sweep.spec import DIRECTIONS, INITIAL_CONDITIONS

CLI = Path(o.__file__).parent
GROUPS = (o.Target, o.Protocol, o.Solver, o.Execution, o.Output, o.Verdict)


def _names(declaration: Any) -> list[str]:
    """The option names of an ``Annotated[T, typer.Option(...)]`` declaration."""
    info = declaration.__metadata__[0]
    decls = [info.default, *(info.param_decls or ())]
    return [n for d in decls if isinstance(d, str) for n in d.split("/") if n.startswith("-")]


def _shared() -> dict[str, str]:
    """Long option name → its group, for every visible option of every group."""
    return {
        name: group.__name__
        for group in GROUPS
        for declaration in group.declarations().values()
        if not declaration.__metadata__[0].hidden
        for name in _names(declaration)
        if name.startswith("--")
    }


def _declarations_in_source() -> list[tuple[str, str, bool]]:
    """(file, long option name, hidden) of every ``typer.Option(...)`` call in the CLI's
    source, read from its syntax tree."""
    found = []
    for path in sorted(CLI.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not (
                isinstance(node, ast.Call)
                and isinstance(node.func, ast.Attribute)
                and node.func.attr == "Option"
                and isinstance(node.func.value, ast.Name)
                and node.func.value.id == "typer"
            ):
                continue
            hidden = any(
                k.arg == "hidden" and isinstance(k.value, ast.Constant) and k.value.value is True
                for k in node.keywords
            )
            for arg in node.args:
                if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                    for name in arg.value.split("/"):
                        if name.startswith("--"):
                            found.append((path.name, name, hidden))
    return found


def _commands() -> dict[str, Any]:
    return dict(typer.main.get_command(app).commands)  # type: ignore[attr-defined]


def test_every_shared_option_is_declared_once_in_the_source() -> None:
    shared = _shared()
    # the groups hold what the issue names: target, protocol, solver, output, the verdict
    for name in ("--preset", "--gearset", "--model", "--set", "--transient", "--periods"):
        assert name in shared
    for name in ("--samples-per-period", "--settle", "--perturbation", "--rtol", "--atol"):
        assert name in shared
    for name in ("--output", "--json", "--quiet", "--overwrite", "--workers", "--verdict"):
        assert name in shared
    visible = [(f, n) for f, n, hidden in _declarations_in_source() if not hidden]
    for name in shared:
        places = [f for f, n in visible if n == name]
        assert places == ["_options.py"], f"{name} is declared in {places}"
    # hidden: the old spelling of the verdict switch, declared once beside it, and deprecated
    # spellings of two commands' own options (classify --rtol is its --period-rtol)
    hidden = sorted((f, n) for f, n, h in _declarations_in_source() if h)
    assert hidden == [
        ("_options.py", "--no-verdicts"),
        ("_options.py", "--verdicts"),
        ("sweep.py", "--ic"),
        ("sweep.py", "--rtol"),
    ]


def test_every_command_takes_the_shared_options_from_their_group() -> None:
    """A command's shared options are exactly those its groups offer: none is redeclared by a
    command (it would be an option outside every group), each comes with the group's help
    unless the command gives its own."""
    shared = _shared()
    takers: dict[str, list[str]] = {}
    for name, cmd in _commands().items():
        groups = getattr(cmd.callback, "option_groups", {})
        offered = {
            n
            for record, fields in groups.values()
            for field in fields
            for n in _names(type(record).declarations()[field])
            if n in shared
        }
        on_command = {
            n
            for p in cmd.params
            if not p.hidden
            for n in [*p.opts, *p.secondary_opts]
            if n in shared
        }
        assert on_command == offered, name
        params = {p.name: p for p in cmd.params}
        for record, fields in groups.values():
            takers.setdefault(type(record).__name__, []).append(name)
            own = dict(record.offered.help)
            for field in fields:
                declared = type(record).declarations()[field].__metadata__[0].help
                assert params[field].help == own.get(field, declared), (name, field)
    # the target options: on every command that simulates or reads a recorded model, and on
    # init-gearset, whose --preset names the gear set whose values it writes
    assert sorted(takers["Target"]) == sorted(
        ["simulate", "info", "bifurcation", "response", "poincare", "orbit", "continue",
         "attractors", "basins", "basin-fractions", "reproduce", "plot", "explore", "boundary",
         "init-gearset"]
    )  # fmt: skip
    assert sorted(takers["Solver"]) == sorted(
        ["simulate", "bifurcation", "response", "poincare", "orbit", "continue", "attractors",
         "basins", "basin-fractions"]
    )  # fmt: skip
    assert sorted(takers["Verdict"]) == ["bifurcation", "simulate"]


def test_the_verdict_switch_has_one_spelling() -> None:
    spellings = set()
    for cmd in _commands().values():
        for p in cmd.params:
            names = [*p.opts, *p.secondary_opts]
            if any("verdict" in n for n in names):
                spellings.add((tuple(names), p.hidden))
    assert spellings == {
        (("--verdict", "--no-verdict"), False),
        (("--verdicts", "--no-verdicts"), True),
    }
    runner = CliRunner()
    for command in ("simulate", "bifurcation"):
        text = runner.invoke(app, [command, "--help"], env={"COLUMNS": "200"}).output
        assert "--no-verdict " in text and "--verdicts" not in text


@pytest.mark.parametrize(
    ("flags", "decided"),
    [
        ([], True),
        (["--verdict"], True),
        (["--no-verdict"], False),
        (["--verdicts"], True),  # the old spelling of bifurcation, on every command
        (["--no-verdicts"], False),
    ],
)
@pytest.mark.parametrize("command", ["simulate", "bifurcation"])
def test_both_spellings_of_the_verdict_switch_reach_the_library(
    command: str, flags: list[str], decided: bool, monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """What reaches the library's keyword (``verdict=`` of a point, ``verdicts=`` of a sweep)
    is the switch as given, in either spelling."""
    import gearchaos.dynamics.verdict.point
    import gearchaos.sweep

    seen: dict[str, Any] = {}

    class Reached(Exception):
        pass

    def catch(*args: Any, **kwargs: Any) -> None:
        seen.update(kwargs)
        raise Reached

    monkeypatch.setattr(gearchaos.dynamics.verdict.point, "analyse_point", catch)
    monkeypatch.setattr(gearchaos.sweep, "bifurcation", catch)
    args = {
        "simulate": ["simulate", "--set", "omega=1.5"],
        "bifurcation": ["bifurcation", "--vary", "omega=1,2", "-o", str(tmp_path / "x.zarr")],
    }[command]
    result = CliRunner().invoke(app, [*args, *flags])
    assert isinstance(result.exception, Reached), result.output
    assert seen["verdict" if command == "simulate" else "verdicts"] is decided


@pytest.mark.parametrize("command", ["simulate", "bifurcation"])
def test_both_spellings_at_once_are_refused(command: str, tmp_path: Path) -> None:
    args = ["--vary", "omega=1,2"] if command == "bifurcation" else []
    result = CliRunner().invoke(
        app, [command, *args, "--verdict", "--no-verdicts", "-o", str(tmp_path / "x.zarr")]
    )
    assert result.exit_code == EXIT_INVALID, result.output
    assert "--verdict" in result.stderr and "old spelling" in result.stderr
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize(
    ("choice", "library"),
    [
        (o.Direction, DIRECTIONS),
        (o.InitialConditions, INITIAL_CONDITIONS),
        (o.Settle, SETTLE_CHOICES),
        (o.Assess, ASSESS),
        (o.ExportFormat, FORMATS),
        (o.Quantity, QUANTITIES),
    ],
)
def test_choices_are_the_library_tuples(choice: Any, library: tuple[str, ...]) -> None:
    assert tuple(m.value for m in choice) == library


@pytest.mark.parametrize(
    ("args", "option", "library"),
    [
        (["response", "--vary", "omega=1,2", "-o", "r.zarr", "--direction", "sideways"],
         "--direction", DIRECTIONS),
        (["bifurcation", "--vary", "omega=1,2", "-o", "b.zarr", "--initial-conditions", "warm"],
         "--initial-conditions", INITIAL_CONDITIONS),
        (["simulate", "--settle", "sometimes"], "--settle", SETTLE_CHOICES),
        (["export", "x.zarr", "-o", "x.csv", "--to", "xlsx"], "--to", FORMATS),
        (["boundary", "--from", "b.nc", "--vary", "xi=0:1", "-o", "c.nc", "--assess", "some"],
         "--assess", ASSESS),
    ],
)  # fmt: skip
def test_a_value_outside_a_choice_is_refused_naming_the_option_and_the_library_choices(
    args: list[str], option: str, library: tuple[str, ...], tmp_path: Path, monkeypatch: Any
) -> None:
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(app, args, env={"COLUMNS": "200"})
    assert result.exit_code == EXIT_INVALID, result.output
    assert "Traceback" not in result.output
    text = re.sub(r"[\s│╭╮╰╯─]+", " ", result.stderr)
    assert option in text and all(repr(v) in text for v in library), text
    assert not list(tmp_path.iterdir())


def test_refusals_of_the_library_reach_the_user_under_the_option(tmp_path: Path) -> None:
    """The command line no longer checks what the library checks: the library's rule and the
    value arrive as one line, its keyword spelt as the option that was given."""
    runner = CliRunner()
    base = ["bifurcation", "--vary", "omega=1,2", "--transient", "1", "--periods", "2"]
    store = str(tmp_path / "x.zarr")
    for extra, line in [
        (["--planets", "0"], "error: --planets must be an integer >= 1: got 0"),
        (
            ["--ic", "warm"],
            "error: --ic must be one of 'fresh', 'continuation': got 'warm' (str)",
        ),
        (
            ["--direction", "down"],
            "error: --direction down needs --initial-conditions continuation",
        ),
    ]:
        result = runner.invoke(app, [*base, *extra, "-o", store])
        assert result.exit_code == EXIT_INVALID, result.output
        errors = [ln for ln in result.stderr.splitlines() if ln.startswith("error:")]
        assert len(errors) == 1 and errors[0].startswith(line), result.stderr
        assert not (tmp_path / "x.zarr").exists()


def test_classify_refusals_come_from_the_library(tmp_path: Path) -> None:
    system = gc.backlash_oscillator(1.0, zeta=0.05, f_alt=0.1, f_mean=0.1)
    store = tmp_path / "run.zarr"
    gc.bifurcation(
        system, "omega=1.8,1.9", transient_periods=2, periods=4, verdicts=False, store=store,
        progress=False,
    )  # fmt: skip
    runner = CliRunner()
    for extra, line in [
        (["--period-rtol", "2"], "error: --period-rtol must be a finite number < 1: got 2.0"),
        (["--rtol", "0"], "error: --rtol must be a finite number > 0: got 0.0"),
        (["--max-period", "0"], "error: --max-period must be an integer >= 1: got 0"),
    ]:
        result = runner.invoke(app, ["classify", str(store), *extra])
        assert result.exit_code == EXIT_INVALID, result.output
        errors = [ln for ln in result.stderr.splitlines() if ln.startswith("error:")]
        assert errors == [line], result.stderr
