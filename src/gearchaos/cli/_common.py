"""What every command shares: the Typer app and :func:`command`, consoles, error handling,
``--set`` parsing, loading the target of the :class:`~gearchaos.cli._options.Target` options and
the solver settings of the :class:`~gearchaos.cli._options.Protocol` and
:class:`~gearchaos.cli._options.Solver` options (the option groups themselves are declared in
:mod:`._options` and re-exported here: ``c.Target``).

Exit codes: 0 success; 2 invalid input (unknown or invalid parameter, conflicting options,
missing gear-set file, a sweep store made with other settings or damaged) — the message names
the parameter, the rule and the value and suggests the closest valid name; 1 the integration
failed or a file could not be written; 130 a sweep interrupted with Ctrl-C (its store keeps
every finished chunk); 141, without a word, when the reader of the output went away
(``gearchaos --help | head``: what a Unix tool ended by SIGPIPE returns). Errors are reported
on stderr as one line, never as a traceback.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import select
import unicodedata
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, NoReturn, TypeVar, overload

import numpy as np
import typer
import typer.core
from rich.console import Console
from rich.text import Text

from .._text import escape_path, escape_text
from .._version import __version__
from ..errors import IntegrationError, ParameterError, StoreError
from ..gearset.parsing import parse_text
from ..model.target import DEFAULT_OMEGA, OMEGA, check_omega
from ._options import (  # the shared options, re-exported: c.Target, c.Direction …
    DEFAULT_PRESET as DEFAULT_PRESET,
    RECORDED_MODEL as RECORDED_MODEL,
    Assess as Assess,
    Confirm as Confirm,
    Direction as Direction,
    Execution as Execution,
    ExportFormat as ExportFormat,
    InitialConditions as InitialConditions,
    Output as Output,
    Protocol as Protocol,
    Quantity as Quantity,
    Settle as Settle,
    Solver as Solver,
    Target as Target,
    Verdict as Verdict,
    choice_value as choice_value,
    named_options as named_options,
    spread_groups,
)
from ._speeds import one_point, point_omega, without_speeds

if TYPE_CHECKING:
    from ..gearset import GearSet
    from ..integrate.settings import SolverSettings


EXIT_FAILURE = 1
EXIT_INVALID = 2
EXIT_INTERRUPTED = 130
#: The reader of the output went away (``| head``): 128 + SIGPIPE, as a Unix tool ended by it.
EXIT_BROKEN_PIPE = 141

INTERRUPTED_MESSAGE = (
    "interrupted: the store keeps every finished chunk; run the same command again to resume"
)


class _Commands(typer.core.TyperGroup):
    """The command group: refuses a single-valued option given twice (Click would keep the
    last silently: ``response --vary omega=1:2:3 --vary xi=0.03,0.05`` swept ξ only)."""

    def main(self, *args: Any, **kwargs: Any) -> Any:
        # Output that meets a closed pipe ends with exit code 1 where Rich or Click catch it
        # (Rich points stdout at /dev/null, Click silences it): exit as a Unix tool ended by
        # SIGPIPE instead; a command's own BrokenPipeError ends in end_quietly()
        before = _stream_identity()
        try:
            return super().main(*args, **kwargs)
        except SystemExit as exc:
            if exc.code == EXIT_FAILURE and (reader_gone() or _stream_identity() != before):
                raise SystemExit(EXIT_BROKEN_PIPE) from None
            raise

    def invoke(self, ctx: Any) -> Any:
        # every command's errors, also those outside its own reported_errors() block (an
        # over-long or unreadable path met while checking its arguments), are one line, and
        # so is each distinct warning (an interrupted store read by plot or export)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("default")
            try:
                with reported_errors():
                    return super().invoke(ctx)
            finally:
                for message in dict.fromkeys(str(w.message) for w in caught):
                    warn(message)

    def resolve_command(self, ctx: Any, args: list[str]) -> Any:
        name, cmd, rest = super().resolve_command(ctx, args)
        if cmd is not None:
            # a flag takes no value: no "<bool>" beside it in --help
            for param in [*cmd.params, cmd.get_help_option(ctx)]:
                if param is not None and getattr(param, "is_flag", False) and not param.metavar:
                    param.metavar = ""
            problem = repeated_option(cmd, rest)
            if problem:
                ctx.fail(problem)
        return name, cmd, rest


def repeated_option(cmd: Any, args: list[str]) -> str | None:
    """What is wrong when an option that takes one value appears more than once in ``args``
    (the command's arguments), or None."""
    tokens = args[: args.index("--")] if "--" in args else args
    for param in cmd.params:
        if getattr(param, "param_type_name", "") != "option" or param.multiple or param.count:
            continue
        names = [*param.opts, *param.secondary_opts]
        longs = [n for n in names if n.startswith("--")]
        hits = [t for t in tokens if t in names or any(t.startswith(n + "=") for n in longs)]
        if len(hits) > 1:
            return (
                f"{names[0]} was given {len(hits)} times ({', '.join(hits)}); "
                f"'{cmd.name}' takes it once"
            )
    return None


app = typer.Typer(
    name="gearchaos",
    cls=_Commands,
    help=(
        "Nonlinear dynamics of planetary gear trains with backlash and bearing clearance: "
        "simulate a gear set at a mesh frequency, sweep any parameter into bifurcation "
        "diagrams and maps, reproduce the seed paper's figures, inspect linear properties, "
        "manage gear-set files. Parameters are addressed by dotted names "
        "(backlash.sun_planet, teeth.sun, xi, ...), the same as in Python and in result files."
    ),
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode="markdown",
    context_settings={"help_option_names": ["-h", "--help"]},
)


F = TypeVar("F", bound=Callable[..., Any])


def command(name: str | None = None) -> Callable[[F], F]:
    """Register a command of :data:`app` whose option groups (parameters typed
    :class:`~gearchaos.cli._options.Target`, :class:`~gearchaos.cli._options.Protocol`, …)
    are spread into their options (:func:`~gearchaos.cli._options.spread_groups`)."""

    def register(fn: F) -> F:
        run = spread_groups(fn)
        app.command(name)(run)
        return run

    return register


# --------------------------------------------------------------------------- consoles, errors
def stdout() -> Console:
    return Console(highlight=False)


def stderr() -> Console:
    return Console(stderr=True, highlight=False)


def fail(message: str, code: int) -> NoReturn:
    """``error: MESSAGE`` on stderr, one line (control characters of paths and names in it,
    a newline included, shown as escapes: :func:`~gearchaos._text.escape_text`), then exit
    with ``code``."""
    text = escape_text(message)
    stderr().print(Text("error: ", style="bold red") + Text(text), soft_wrap=True)
    raise typer.Exit(code)


def warn(message: str) -> None:
    text = escape_text(message)
    stderr().print(Text("warning: ", style="bold yellow") + Text(text), soft_wrap=True)


def wrote(path: Path | str) -> None:
    """``wrote PATH`` on stdout, never wrapped (paths must stay copyable; control characters
    shown as escapes)."""
    stdout().print(Text.assemble(("wrote ", "dim"), (escape_path(path), "bold")), soft_wrap=True)


def _stream_identity() -> tuple[int, int] | None:
    """What stdout's descriptor refers to (it changes only when a broken pipe was silenced)."""
    try:
        st = os.fstat(1)
    except OSError:
        return None
    return st.st_dev, st.st_ino


def _reader_gone(fd: int) -> bool:
    """Whether ``fd`` is a pipe (or socket) whose reading end is closed."""
    try:
        poller = select.poll()
        poller.register(fd, select.POLLOUT)
        return any(event & select.POLLERR for _, event in poller.poll(0))
    except (OSError, ValueError, AttributeError):  # closed, or no poll on this platform
        return False


def reader_gone() -> bool:
    """Whether stdout or stderr is a pipe (or socket) whose reading end is closed."""
    return _reader_gone(1) or _reader_gone(2)


def end_quietly() -> NoReturn:
    """End without a word when the reader of the output went away (``gearchaos … | head``):
    the closed streams are pointed at /dev/null, so that nothing fails when Python flushes them
    at exit, and the exit code is :data:`EXIT_BROKEN_PIPE`."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    for fd in (1, 2):
        if _reader_gone(fd):
            os.dup2(devnull, fd)
    os.close(devnull)
    raise typer.Exit(EXIT_BROKEN_PIPE)


@contextlib.contextmanager
def reported_errors() -> Iterator[None]:
    """Turn the package's exceptions into one line on stderr and an exit code; say so on
    stderr before the first compilation of the numerical kernels in this process."""
    from .._numba import on_first_compile

    on_first_compile(
        lambda: stderr().print(
            "compiling numerical kernels for this model (once per model, planet count and "
            "analysis: from a few seconds to a minute or two on a small machine; later runs "
            "load them from the cache)…"
        )
    )
    try:
        yield
    except (ParameterError, StoreError) as exc:
        fail(str(exc), EXIT_INVALID)
    except FileNotFoundError as exc:
        fail(str(exc), EXIT_INVALID)
    except IntegrationError as exc:
        fail(str(exc), EXIT_FAILURE)
    except OSError as exc:
        if isinstance(exc, BrokenPipeError) and reader_gone():
            end_quietly()  # `gearchaos … | head`: not an error
        where = f": '{exc.filename}'" if getattr(exc, "filename", None) else ""
        fail(f"{exc.strerror or exc}{where}", EXIT_FAILURE)


@contextlib.contextmanager
def interruptible() -> Iterator[None]:
    """Ctrl-C (and SIGTERM, which the sweep engine turns into it) → one line and exit 130."""
    try:
        yield
    except KeyboardInterrupt:
        fail(INTERRUPTED_MESSAGE, EXIT_INTERRUPTED)


@contextlib.contextmanager
def warnings_to_stderr() -> Iterator[None]:
    """Collect the warnings of a computation and print each as one line on stderr."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield
    for w in caught:
        warn(str(w.message))


def jsonable(obj: Any) -> Any:
    """A JSON-ready copy: numpy scalars and arrays to Python, non-finite floats to null."""
    if isinstance(obj, Mapping):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, list | tuple):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.generic):
        return jsonable(obj.item())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, Path):
        return str(obj)
    return obj


def print_json(obj: Any) -> None:
    typer.echo(json.dumps(jsonable(obj), indent=2, ensure_ascii=False, allow_nan=False))


# --------------------------------------------------------------------------- --set parsing
def parse_sets(items: Sequence[str]) -> tuple[float | None, dict[str, object]]:
    """Split ``--set NAME=VALUE`` options into Ω and gear-set changes.

    Parameters
    ----------
    items : sequence of str
        The option values, e.g. ``["omega=1.5", "xi=0.05", "backlash.sun_planet=3"]``. A
        speed (``sun_rpm=7500``, ``mesh_hz=3000``) stays among the changes: it sets Ω through
        the gear set the changes build (:func:`point_omega`, :func:`sweep_fixed`).
        Values are parsed by the kind of the field: integers for tooth and planet numbers,
        numbers for physical values, comma-separated numbers (optionally in brackets) for the
        stiffness harmonics, text for ``torque.mode``, ``*.units``, ``mesh_phasing.model``,
        ``name`` and ``description``. A name given twice keeps its last value.

    Returns
    -------
    omega : float or None
        The value of ``omega`` if given.
    changes : dict
        The other names and their parsed values, for :meth:`GearSet.evolve`, which rejects
        unknown names with a suggestion.

    Raises
    ------
    ParameterError
        For an item without ``=``, a value that does not parse as its field's kind, ``omega``
        not finite, > 0 and plausible, or Ω set twice (``omega`` and a speed, or two speeds).
    """
    omega: float | None = None
    changes: dict[str, object] = {}
    for item in items:
        key, sep, raw = item.partition("=")
        key, raw = key.strip(), raw.strip()
        if not sep or not key:
            raise ParameterError(f"--set expects NAME=VALUE (e.g. omega=1.5): got {item!r}")
        if key == OMEGA:
            omega = check_omega(parse_text(OMEGA, raw))
        else:
            changes[key] = parse_text(key, raw)
    one_point(set(), changes, omega, "set")
    return omega, changes


def load_gearset(target: Target, changes: Mapping[str, object] | None = None) -> GearSet:
    """The gear set of ``--preset`` / ``--gearset`` (default preset), with ``changes``."""
    from ..gearset import GearSet, preset as load_preset

    preset, gearset_file = target.preset, target.gearset_file
    if preset is not None and gearset_file is not None:
        raise ParameterError(
            f"--preset and --gearset are mutually exclusive: got --preset {preset} and "
            f"--gearset {gearset_file}; give one (default: --preset {DEFAULT_PRESET})"
        )
    if gearset_file is not None:
        gs = GearSet.from_toml(gearset_file)
    else:
        gs = load_preset(preset if preset is not None else DEFAULT_PRESET)
    changes = without_speeds(changes or {})  # a speed is the operating point (point_omega)
    if changes:
        # a changed gear set is no longer the named one: its name says so (and which
        # parameters), so titles and result files never call it plain "sheng2016"
        names = [k for k in changes if k not in ("name", "description")]
        label = ", ".join(names) if len(names) <= 3 else f"{len(names)} parameters"
        renamed = {"name": f"{gs.name} (modified: {label})"} if names else {}
        gs = gs.evolve({**dict(changes), **renamed})
    for field, keep in (("name", ""), ("description", "\t\n")):
        text = getattr(gs, field)
        bad = next((ch for ch in text if unicodedata.category(ch) == "Cc" and ch not in keep), None)
        if bad is not None:  # an ESC would start an escape sequence in the user's terminal
            raise ParameterError(
                f"the gear set's {field} contains the control character {ord(bad):#04x}, "
                "which would reach the terminal and every title as it is; remove it "
                f"(got {text!r})"
            )
    return gs


def load_target(target: Target, changes: Mapping[str, object] | None = None) -> Any:
    """The gear set of ``--preset``/``--gearset`` with ``changes`` (:func:`load_gearset`), or,
    with ``--model``, a :class:`~gearchaos.model.System` of that model class with ``changes``
    as its parameters (at Ω = DEFAULT_OMEGA until a command sets Ω; a model refuses a speed)."""
    model = target.model
    if model is None:
        return load_gearset(target, changes)
    if target.names_gear_set:
        raise ParameterError("--model excludes --preset and --gearset: give one of them")
    from ..model import System
    from ..model.loading import build_model, load_model_class

    own = without_speeds(changes or {})
    system = System(build_model(load_model_class(model), own), DEFAULT_OMEGA)
    point_omega(system, None, changes or {})  # a speed: refused, naming it (no gear set)
    return system


@overload
def point_target(target: Target) -> tuple[Any, float | None]: ...
@overload
def point_target(target: Target, quiet: bool) -> tuple[Any, float]: ...
def point_target(target: Target, quiet: bool | None = None) -> tuple[Any, float | None]:
    """(target, Ω) of a command at one operating point: the target of ``--preset``,
    ``--gearset`` or ``--model`` changed by ``--set``, and Ω from ``--set omega`` or a speed
    (``--set sun_rpm``, converted through it); ``None`` when neither is set, or, unless
    ``quiet`` is None, the default Ω with a note unless ``quiet``."""
    omega, changes = parse_sets(target.sets or [])
    built = load_target(target, changes)
    omega = point_omega(built, omega, changes)  # --set sun_rpm / mesh_hz: through it
    if omega is None and quiet is not None:
        omega = DEFAULT_OMEGA
        default_omega_note(quiet, "set")
    return built, omega


def sweep_target(
    target: Target, swept: set[str], quiet: bool, verb: str = "swept"
) -> tuple[Any, dict[str, Any]]:
    """(target, fixed values) of a command over the parameters ``swept`` (a sweep, a gallery,
    a continuation: ``verb``, for the messages): a ``--model``'s parameters are set on the
    model itself (its fields), a gear set's changes are fixed values (:func:`sweep_fixed`)."""
    omega, changes = parse_sets(target.sets or [])
    if target.model is not None:
        return load_target(target, changes), sweep_fixed(swept, omega, {}, quiet, verb)
    return load_gearset(target), sweep_fixed(swept, omega, changes, quiet, verb)


def default_omega_note(quiet: bool, what: str = "swept") -> None:
    """Tell the user which Ω a command uses when it is neither swept nor set."""
    if not quiet:
        stderr().print(
            Text(
                f"Ω = {DEFAULT_OMEGA:g} (not {what}; change it with --set omega=...)",
                style="dim",
            )
        )


def sweep_fixed(
    swept: set[str],
    omega: float | None,
    changes: Mapping[str, Any],
    quiet: bool,
    verb: str = "swept",
    note: str | None = None,
) -> dict[str, Any]:
    """The fixed values of a command over the parameters ``swept`` from ``--set``: refuse a
    name both swept and set, and fix Ω (the default, with a note, when it is neither swept nor
    set; a speed, swept or set, gives Ω and stays among the values for the library). ``verb``
    names what the command does to them in the messages, ``note`` in the default-Ω note."""
    fixed: dict[str, Any] = dict(changes)
    for name in sorted(swept & set(fixed)):
        raise ParameterError(f"{name} is both {verb} and set with --set; choose one")
    if not one_point(swept, fixed, omega, verb):
        if omega is None:
            omega = DEFAULT_OMEGA
            default_omega_note(quiet, verb if note is None else note)
        fixed[OMEGA] = omega
    return fixed


def settings(protocol: Protocol, solver: Solver) -> SolverSettings:
    """The :class:`~gearchaos.integrate.settings.SolverSettings` of a command's protocol and
    solver options (:func:`solver_settings`)."""
    return solver_settings(
        protocol.transient,
        protocol.periods,
        solver.rtol,
        solver.atol,
        protocol.samples_per_period,
        str(protocol.settle.value),
        protocol.perturbation,
    )


def solver_settings(
    transient: float,
    periods: int,
    rtol: float,
    atol: float,
    samples_per_period: int = 1,
    settle: str = "off",
    perturbation: float | None = None,
) -> SolverSettings:
    """The :class:`~gearchaos.integrate.settings.SolverSettings` of the solver options;
    invalid values exit 2 naming the setting."""
    from ..integrate.settings import SolverSettings

    try:
        settings = SolverSettings(
            transient_periods=transient,
            periods=periods,
            samples_per_period=samples_per_period,
            rtol=rtol,
            atol=atol,
            settle=settle,
        )
        if perturbation is not None:
            settings = settings.replace(perturbation=perturbation)
        settings.check_span()
        return settings
    except ParameterError as exc:
        option = setting_option(exc.name)
        raise ParameterError(f"{option}: {exc}" if option else str(exc), name=exc.name) from None


def setting_option(name: str | None) -> str | None:
    """The command-line option of a solver setting (by its field name: ``--rtol``,
    ``--samples-per-period``; ``--transient`` for ``transient_periods``), else None."""
    from ..integrate.settings import SolverSettings

    if name not in SolverSettings.field_names():
        return None
    return _SHORTENED.get(name, "--" + name.replace("_", "-"))


#: Solver settings whose option is not their field name spelled with hyphens.
_SHORTENED = {"transient_periods": "--transient"}


@app.callback(invoke_without_command=True)
def main(
    ctx: typer.Context,
    version: Annotated[
        bool, typer.Option("--version", "-V", help="Print the version and exit.")
    ] = False,
) -> None:
    """gearchaos: nonlinear dynamics of planetary gear trains with clearances."""
    if version:
        if ctx.invoked_subcommand is not None:
            fail(
                f"--version takes no command: got {ctx.invoked_subcommand!r}; run "
                f"'gearchaos --version' or 'gearchaos {ctx.invoked_subcommand} ...'",
                EXIT_INVALID,
            )
        typer.echo(f"gearchaos {__version__}")
        raise typer.Exit()
    if ctx.invoked_subcommand is None:
        typer.echo(ctx.get_help())
        raise typer.Exit(EXIT_INVALID)


def run_sweep(
    fn: Any,
    *args: Any,
    settings: Any,
    output: Output,
    execution: Execution,
    **options: Any,
) -> tuple[Any, float]:
    """``fn(*args, **options)`` (a sweep function of :mod:`gearchaos.sweep`) with the options
    every sweep command shares — solver settings, store and overwrite, the execution options
    the command offers, a progress bar unless ``--quiet`` — timed; returns its
    :class:`~gearchaos.sweep.SweepResult` and seconds."""
    import time

    from ..sweep import SweepResult

    t0 = time.perf_counter()
    ds = fn(
        *args,
        settings=settings,
        store=output.required_path(),
        overwrite=output.overwrite,
        progress=not output.quiet,
        **execution.offered_values(),
        **options,
    )
    return SweepResult.of(ds), time.perf_counter() - t0


def sweep_report(title: str, res: Any, result: Mapping[str, Any], output: Output) -> Any:
    """What a sweep command prints of ``result`` (its summary): the JSON with ``--json``,
    nothing with ``--quiet`` (both return None), else the summary table to be completed."""
    from ._render import sweep_table

    if output.json:
        print_json(result)
        return None
    if output.quiet:
        return None
    return sweep_table(title, res, result)
