"""An option that takes one value, given twice, is refused (issue 23, item 8): Click kept the
last one silently, so `response --vary omega=1:2:3 --vary xi=0.03,0.05` swept ξ only."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from gearchaos.cli import EXIT_INVALID, app


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (["response", "--vary", "omega=1:2:3", "--vary", "xi=0.03,0.05"], "--vary"),
        (["poincare", "--vary", "omega=1,2", "--vary=xi=0.03,0.05"], "--vary"),
        (["continue", "--vary", "omega=1.5:1.6", "-v", "omega=1.5:1.7"], "--vary"),
        (
            ["bifurcation", "-v", "omega=1:2:3", "--family", "xi=0.03", "--family", "xi=1"],
            "--family",
        ),
        (
            ["simulate", "--set", "omega=1.5", "--transient", "10", "--transient", "20"],
            "--transient",
        ),
    ],
)
def test_a_single_valued_option_given_twice_is_refused(
    args: list[str], option: str, tmp_path: Path
) -> None:
    r = CliRunner().invoke(app, [*args, "-o", str(tmp_path / "out.zarr")])
    assert r.exit_code == EXIT_INVALID, r.output
    assert f"{option} was given 2 times" in r.output
    assert not list(tmp_path.iterdir())  # refused before anything ran


def test_options_that_may_repeat_still_do(tmp_path: Path) -> None:
    # --set and a 2-D map's two --vary are lists (teeth.sun = 33 is sheng2016-v1's own, so the
    # gear set stays consistent: z_r = z_s + 2 z_p)
    out = tmp_path / "m.zarr"
    r = CliRunner().invoke(
        app,
        [
            "bifurcation", "--preset", "sheng2016-v1", "-v", "omega=1:1.2:2", "-v", "xi=0.03,0.05",
            "--set", "teeth.sun=33",
            "--set", "backlash.sun_planet=3", "--transient", "2", "--periods", "2", "-o", str(out),
        ],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    assert out.exists()


def test_control_characters_of_a_gear_set_never_reach_the_terminal(tmp_path: Path) -> None:
    # issue 23: `info` printed the ANSI escape sequences of a gear-set name as they were
    from gearchaos.gearset import preset

    f = tmp_path / "g.toml"
    f.write_text(preset("sheng2016-v1").evolve({"name": "gear\x1b[2J\x1b[31mset"}).to_toml())
    r = CliRunner().invoke(app, ["info", "--gearset", str(f)])
    assert r.exit_code == EXIT_INVALID
    assert "name contains the control character 0x1b" in r.output
    assert "\x1b[2J" not in r.output


def test_plot_options_that_a_figure_does_not_use_are_refused(tmp_path: Path) -> None:
    # issue 23: `plot resp.zarr --var nope` and `--planet 9` on a response store and on a 2-D
    # store exited 0, ignoring the option
    runner = CliRunner()
    resp, grid = tmp_path / "resp.zarr", tmp_path / "map.zarr"
    quick = ["--transient", "2", "--periods", "2"]
    assert (
        runner.invoke(app, ["response", "-v", "omega=1:2:3", *quick, "-o", str(resp)]).exit_code
        == 0
    )
    r = runner.invoke(
        app, ["bifurcation", "-v", "omega=1:2:2", "-v", "xi=0.03,0.05", *quick, "-o", str(grid)]
    )
    assert r.exit_code == 0, r.output
    for args, words in (
        ([str(resp), "--var", "nope"], "--var does not apply to the frequency-response figure"),
        ([str(resp), "--planet", "9"], "--planet does not apply"),
        ([str(grid), "--planet", "9"], "planet must be one of the observed planets [1]: got 9"),
    ):
        r = runner.invoke(app, ["plot", *args, "-o", str(tmp_path / "f.png")])
        assert r.exit_code == EXIT_INVALID and words in r.output, r.output
    assert not (tmp_path / "f.png").exists()


@pytest.mark.parametrize("command", ["simulate", "bifurcation", "plot", "continue", "explore"])
def test_flags_show_no_value_placeholder_in_help(command: str) -> None:
    # issue 24: every flag showed a `<bool>` placeholder in --help, as if it took a value
    r = CliRunner().invoke(app, [command, "--help"], env={"COLUMNS": "120"})
    assert r.exit_code == 0
    assert "<bool>" not in r.output and "--help" in r.output
