"""``gearchaos bifurcation | plot | reproduce``: JSON contract, stores, figures, clean errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import INTERRUPTED_MESSAGE, PAPER_FIGURES, app
from gearchaos.sweep import SweepSpec

SHORT = ["--transient", "10", "--periods", "10"]


@pytest.fixture(scope="module")
def runner() -> CliRunner:
    return CliRunner()


@pytest.fixture(scope="module")
def omega_store(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    """A 6-point Ω sweep of sheng2016 written by the CLI, and its --json output."""
    store = tmp_path_factory.mktemp("sweep") / "run.zarr"
    result = CliRunner().invoke(
        app,
        ["bifurcation", "--vary", "omega=0.3:1.8:6", *SHORT, "-o", str(store), "--quiet", "--json"],
    )
    assert result.exit_code == 0, result.output
    return store, json.loads(result.stdout)


def test_bifurcation_json_and_store(omega_store: tuple[Path, dict]) -> None:
    store, data = omega_store
    assert list(data) == ["store", "points", "failed", "seconds"]
    assert data["store"] == str(store)
    assert data["points"] == 6
    assert data["failed"] == int(np.sum(xr.open_zarr(store).status.values != 0))
    assert data["seconds"] > 0

    ds = xr.open_zarr(store)
    assert ds.delta_sp.dims == ("omega", "section", "planet")
    assert ds.sizes["section"] == 10
    np.testing.assert_allclose(ds.omega.values, np.linspace(0.3, 1.8, 6))
    assert ds.planet.values.tolist() == [1]
    for key in ("gearset_toml", "sweep_toml", "rtol", "atol", "transient_periods", "periods"):
        assert key in ds.attrs
    assert gc.GearSet.from_toml_string(ds.attrs["gearset_toml"]) == gc.preset(
        "sheng2016"
    )  # the default


def test_rerun_is_a_resume_and_other_settings_are_refused(
    runner: CliRunner, omega_store: tuple[Path, dict]
) -> None:
    store, _ = omega_store
    again = runner.invoke(
        app, ["bifurcation", "--vary", "omega=0.3:1.8:6", *SHORT, "-o", str(store), "--json"]
    )
    assert again.exit_code == 0, again.output
    assert json.loads(again.stdout)["points"] == 6

    other = runner.invoke(
        app,
        [
            *("bifurcation", "--vary", "omega=0.3:1.8:6", "--transient", "10"),
            *("--periods", "12", "-o", str(store), "--quiet"),
        ],
    )
    assert other.exit_code == 2
    assert "error:" in other.stderr and "--overwrite" in other.stderr
    assert "Traceback" not in other.output


def test_non_omega_sweep_fixes_default_omega(runner: CliRunner, tmp_path: Path) -> None:
    store = tmp_path / "b.zarr"
    result = runner.invoke(
        app,
        [
            *("bifurcation", "--vary", "backlash.sun_planet=2,4", "--set", "xi=0.05"),
            *(*SHORT, "-o", str(store), "--quiet"),
        ],
    )
    assert result.exit_code == 0, result.output
    ds = gc.open_sweep(store)
    spec = SweepSpec.from_toml(ds.attrs["sweep_toml"])
    assert dict(spec.fixed) == {"omega": 1.5, "xi": 0.05}
    assert ds.delta_sp.dims == ("backlash.sun_planet", "section", "planet")
    help_text = runner.invoke(app, ["bifurcation", "--help"]).stdout
    assert "1.5" in help_text


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ([], "--vary is required"),
        (["--vary", "omega=1,2", "--vary", "xi=0.03", "--vary", "torque.input=1"], "once or twice"),
        (["--vary", "omgea=1:2:3"], "omega"),
        (["--vary", "omega=1:2"], "start:stop:count"),
        (["--vary", "omega=1,2", "--direction", "both"], "--initial-conditions continuation"),
        (["--vary", "omega=1,2", "--initial-conditions", "warm"], "--initial-conditions"),
        (["--vary", "omega=1,2", "--ic", "warm"], "--ic must be"),
        (
            ["--vary", "omega=1,2", "--ic", "fresh", "--initial-conditions", "fresh"],
            "--ic is its deprecated spelling",
        ),
        (["--vary", "omega=1,2", "--set", "omega=1.5"], "both swept and set"),
        (["--vary", "omega=1,2", "--planets", "0"], "--planets"),
    ],
)
def test_bifurcation_invalid_input_exits_2(
    runner: CliRunner, tmp_path: Path, args: list[str], message: str
) -> None:
    result = runner.invoke(app, ["bifurcation", *args, *SHORT, "-o", str(tmp_path / "x.zarr")])
    assert result.exit_code == 2, result.output
    assert message in result.stderr
    assert "Traceback" not in result.output
    assert not (tmp_path / "x.zarr").exists() or message == "omega"


def test_initial_conditions_is_spelt_as_in_python_and_ic_is_deprecated(
    runner: CliRunner, tmp_path: Path
) -> None:
    """Issue 35: ``--ic`` on the command line was ``initial_conditions=`` in Python (and in the
    store); the option is now ``--initial-conditions``, ``--ic`` warns for one release."""
    args = ["bifurcation", "--vary", "omega=1,1.2", "--direction", "both", *SHORT, "--quiet"]
    new = runner.invoke(
        app, [*args, "--initial-conditions", "continuation", "-o", str(tmp_path / "a.zarr")]
    )
    assert new.exit_code == 0, new.output
    assert "deprecated" not in new.stderr
    old = runner.invoke(app, [*args, "--ic", "continuation", "-o", str(tmp_path / "b.zarr")])
    assert old.exit_code == 0, old.output
    assert "--ic is deprecated" in old.stderr and "--initial-conditions" in old.stderr
    for name in ("a.zarr", "b.zarr"):
        assert gc.open_sweep(tmp_path / name).attrs["initial_conditions"] == "continuation"
    help_text = runner.invoke(app, ["bifurcation", "--help"], env={"COLUMNS": "200"}).output
    assert "--initial-conditions" in help_text and "--ic " not in help_text


def test_interrupt_exits_130_with_resume_hint(
    runner: CliRunner, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import gearchaos.sweep

    def interrupted(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(gearchaos.sweep, "bifurcation", interrupted)
    result = runner.invoke(
        app, ["bifurcation", "--vary", "omega=1,2", *SHORT, "-o", str(tmp_path / "i.zarr")]
    )
    assert result.exit_code == 130
    assert INTERRUPTED_MESSAGE in result.stderr
    assert "Traceback" not in result.output


def test_plot_writes_a_png(
    runner: CliRunner, omega_store: tuple[Path, dict], tmp_path: Path
) -> None:
    store, _ = omega_store
    png = tmp_path / "fig.png"
    result = runner.invoke(
        app, ["plot", str(store), "-o", str(png), "--clearance-lines", "--resonances"]
    )
    assert result.exit_code == 0, result.output
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert png.stat().st_size > 10_000
    svg = tmp_path / "fig.svg"
    assert runner.invoke(app, ["plot", str(store), "-o", str(svg)]).exit_code == 0
    assert svg.read_text(encoding="utf-8").lstrip().startswith("<?xml")


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["missing.zarr", "-o", "f.png"], "store not found"),
        (["STORE", "-o", "f.gif"], ".png"),
        (["STORE", "-o", "f.png", "--var", "nonsense"], "var"),
        (["STORE", "-o", "f.png", "--planet", "3"], "planet"),
    ],
)
def test_plot_invalid_input_exits_2(
    runner: CliRunner,
    omega_store: tuple[Path, dict],
    tmp_path: Path,
    args: list[str],
    message: str,
) -> None:
    store, _ = omega_store
    args = [str(store) if a == "STORE" else str(tmp_path / a) if "." in a else a for a in args]
    result = runner.invoke(app, ["plot", *args])
    assert result.exit_code == 2, result.output
    assert message in result.stderr
    assert "Traceback" not in result.output


def test_plot_refuses_a_directory_that_is_no_store(runner: CliRunner, tmp_path: Path) -> None:
    result = runner.invoke(app, ["plot", str(tmp_path), "-o", str(tmp_path / "f.png")])
    assert result.exit_code == 2
    assert "not a readable sweep store" in result.stderr


def test_reproduce_unknown_figure(runner: CliRunner, tmp_path: Path) -> None:
    result = runner.invoke(app, ["reproduce", "fig3", "-o", str(tmp_path)])
    assert result.exit_code == 2
    assert "error:" in result.stderr
    for name in PAPER_FIGURES:
        assert name in result.stderr
    assert "Traceback" not in result.output
    assert list(tmp_path.iterdir()) == []


def test_reproduce_calls_the_recipe_and_prints_json(
    runner: CliRunner, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    recipes = pytest.importorskip("gearchaos.paper.recipes")
    calls: list[tuple] = []
    gearsets: list[object] = []
    protocols: list[bool] = []

    def fake(
        name: str,
        outdir: object,
        *,
        quick: bool,
        progress: bool,
        workers: int | None = None,
        overwrite: bool = False,
        gearset: object = None,
        paper_protocol: bool = False,
    ) -> dict:
        calls.append((name, Path(str(outdir)), quick, progress, workers, overwrite))
        gearsets.append(gearset)
        protocols.append(paper_protocol)
        return {
            "figure": str(tmp_path / f"{name}.png"),
            "store": str(tmp_path / f"{name}.zarr"),
            "points": 12,
            "failed": 0,
            "seconds": 1.5,
        }

    monkeypatch.setattr(recipes, "reproduce", fake)
    result = runner.invoke(app, ["reproduce", "FIG9", "-o", str(tmp_path), "--quick", "--json"])
    assert result.exit_code == 0, result.output
    assert calls == [("fig9", tmp_path, True, True, None, False)]
    assert json.loads(result.stdout)["points"] == 12

    result = runner.invoke(
        app, ["reproduce", "fig4", "-o", str(tmp_path), "--quiet", "-w", "2", "--overwrite"]
    )
    assert result.exit_code == 0
    assert calls[-1] == ("fig4", tmp_path, False, False, 2, True)
    assert result.stdout == ""
    assert gearsets == [None, None]  # the recipe's default preset
    # one figure runs the seed's own protocol only when asked (--paper-protocol)
    assert protocols == [False, False]
    result = runner.invoke(
        app, ["reproduce", "fig4", "-o", str(tmp_path), "-q", "--paper-protocol"]
    )
    assert result.exit_code == 0, result.output
    assert protocols[-1] is True

    # --preset and --gearset reach the recipe as a GearSet; both at once is refused
    import gearchaos

    result = runner.invoke(
        app, ["reproduce", "fig4", "-o", str(tmp_path), "-q", "-p", "hindawi2021"]
    )
    assert result.exit_code == 0, result.output
    assert gearsets[-1] == gearchaos.preset("hindawi2021")
    custom = gearchaos.preset("hindawi2021").evolve({"torque.input": 500.0, "name": "mine"})
    file = tmp_path / "mine.toml"
    file.write_text(custom.to_toml())
    result = runner.invoke(app, ["reproduce", "fig4", "-o", str(tmp_path), "-q", "-g", str(file)])
    assert result.exit_code == 0, result.output
    assert gearsets[-1] == custom
    n = len(calls)
    result = runner.invoke(
        app, ["reproduce", "fig4", "-o", str(tmp_path), "-p", "sheng2016", "-g", str(file)]
    )
    assert result.exit_code != 0 and "mutually exclusive" in result.stderr
    assert len(calls) == n

    def interrupted(*args: object, **kwargs: object) -> dict:
        raise KeyboardInterrupt

    monkeypatch.setattr(recipes, "reproduce", interrupted)
    result = runner.invoke(app, ["reproduce", "fig4", "-o", str(tmp_path)])
    assert result.exit_code == 130
    assert INTERRUPTED_MESSAGE in result.stderr


def test_a_dask_local_sweep_says_nothing_but_its_result(tmp_path: Path) -> None:
    """Issue 35: a --dask-local sweep ended with Dask's log lines ("Worker process still alive
    after 4.0 seconds, killing", heartbeat tracebacks) and, when port 8787 was taken, with
    "Port 8787 is already in use" (the scheduler's HTTP server on every interface)."""
    import socket
    import subprocess
    import sys

    pytest.importorskip("dask.distributed")
    held = socket.socket()
    try:
        held.bind(("0.0.0.0", 8787))  # taken, as by another cluster or notebook
        held.listen()
    except OSError:
        pass  # taken already
    try:
        proc = subprocess.run(
            [sys.executable, "-m", "gearchaos", "bifurcation", "--vary", "omega=1,1.5", *SHORT,
             "--dask-local", "2", "-q", "-o", str(tmp_path / "d.zarr")],
            capture_output=True, text=True, timeout=600,
        )  # fmt: skip
    finally:
        held.close()
    assert proc.returncode == 0, proc.stderr
    notice = ("compiling numerical kernels", "analysis:", "load them from the cache")
    said = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert not [ln for ln in said if not ln.startswith(notice)], proc.stderr
    assert gc.open_sweep(tmp_path / "d.zarr").attrs["complete"] is True
