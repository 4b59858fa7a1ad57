"""Issue 25: a model written in the user's own file runs through the command line (--model
FILE.py:CLASS) and everything downstream: stores that record how to build it again, starts from
them (--from), the explorer's recomputed point. The model is the forced Duffing oscillator
written as a UserModel without a tangent; gearchaos's built-in Duffing kernel is an independent
implementation of the same equations, so the two must agree number for number."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app

MODEL = """
import math
from dataclasses import dataclass

import numba
import numpy as np

from gearchaos.model.contract import UserModel


@numba.njit(cache=True)
def rhs(t, y, p, dydt, obs, level):
    x, v = y[0], y[1]
    dydt[0] = v
    dydt[1] = p[4] * math.cos(p[0] * t) - p[1] * v - p[2] * x - p[3] * x * x * x
    obs[0] = x
    obs[1] = v


@dataclass(frozen=True)
class TwinWell(UserModel):
    delta: float = 0.3
    alpha: float = -1.0
    beta: float = 1.0
    gamma: float = 0.5
    name = "twin_well"
    state_names = ("x", "x_dot")
    obs_names = ("x", "x_dot")
    n_track = 1
    rhs = rhs

    def pack(self, omega):
        return np.array([omega, self.delta, self.alpha, self.beta, self.gamma])
"""


@pytest.fixture(scope="module")
def model_file(tmp_path_factory: pytest.TempPathFactory) -> str:
    path = tmp_path_factory.mktemp("own_model") / "twin_well_cli.py"
    path.write_text(MODEL, encoding="utf-8")
    return f"{path}:TwinWell"


@pytest.fixture(scope="module")
def runner() -> CliRunner:
    return CliRunner()


def _json(runner: CliRunner, args: list[str]) -> object:
    result = runner.invoke(app, [*args, "--json"])
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def _builtin(omega: float, gamma: float = 0.5) -> gc.System:
    return gc.duffing(omega, delta=0.3, alpha=-1.0, beta=1.0, gamma=gamma)


def test_simulate_own_model_equals_the_builtin_kernel(runner: CliRunner, model_file: str) -> None:
    out = _json(runner, ["simulate", "--model", model_file, "--set", "omega=0.9",
                         "--set", "gamma=0.2", "--no-verdict"])  # fmt: skip
    assert out["section_variable"] == "x"
    ref = gc.simulate(_builtin(0.9, 0.2))
    x = ref.section("x")
    assert out["section_min"] == float(np.min(x))
    assert out["section_max"] == float(np.max(x))
    assert out["steps_accepted"] == ref.steps_accepted
    assert out["gearset"] is None and "load_factor_sp_max" not in out


def test_orbit_of_own_model_has_the_builtin_multipliers(runner: CliRunner, model_file: str) -> None:
    """The finite-difference tangent of the user model gives the multipliers the built-in
    analytic tangent gives."""
    out = _json(runner, ["orbit", "--model", model_file, "--set", "omega=1.2"])
    ref = gc.periodic_orbit(_builtin(1.2), period=1)
    assert out["converged"] and ref.converged
    np.testing.assert_allclose(
        sorted(m["abs"] for m in out["multipliers"]), sorted(np.abs(ref.multipliers)), rtol=1e-6
    )


def test_sweep_store_rebuilds_the_model_for_starts_and_the_explorer(
    runner: CliRunner, model_file: str, tmp_path: Path
) -> None:
    store = tmp_path / "tw.zarr"
    result = runner.invoke(
        app, ["bifurcation", "--model", model_file, "--vary", "omega=1.1:1.3:3",
              "--set", "gamma=0.3", "-o", str(store), "--quiet"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    ds = gc.open_sweep(store)
    assert ds.attrs["model_class"].endswith("twin_well_cli.py:TwinWell")
    assert json.loads(ds.attrs["model_fields"])["gamma"] == 0.3
    # a start from the store's point (the model named: a file alone never runs code): the
    # orbit of the built-in system at that point
    out = _json(runner, ["orbit", "--from", str(store), "--at", "omega=1.2", "--model", model_file])
    ref = gc.periodic_orbit(_builtin(1.2, 0.3), period=out["period"])
    assert out["converged"] and ref.converged
    np.testing.assert_allclose(out["section"], ref.section("x"), atol=1e-8)
    # the explorer recomputes the point from the model the store names
    from gearchaos.explore.compute import compute_point

    point = compute_point(str(store), {"omega": 1.2})
    from gearchaos.dynamics.verdict.point import analyse_point
    from gearchaos.sweep.result import SweepResult

    settings = SweepResult.open(store).spec.solver.replace(samples_per_period=64)
    ref_point = analyse_point(_builtin(1.0, 0.3), {"omega": 1.2}, settings, lyapunov=True)
    for key in ("motion", "section_min", "section_max", "steps_accepted"):
        assert point["summary"][key] == ref_point.summary[key], key
    assert point["png"][:8] == b"\x89PNG\r\n\x1a\n"
    # the explorer's finer sweep of the store: the model the store names, its protocol
    from gearchaos.explore.compute import run_zoom

    finer = gc.open_sweep(run_zoom(str(store), {"omega": (1.15, 1.25, 3)}))
    ref = gc.bifurcation(
        _builtin(1.0, 0.3), "omega=1.15:1.25:3", settings=settings.replace(samples_per_period=1),
        progress=False,
    )  # fmt: skip
    np.testing.assert_array_equal(finer["x"].values, ref["x"].values)
    assert list(finer["motion"].values) == list(ref["motion"].values)


def test_continue_and_attractors_take_the_model(
    runner: CliRunner, model_file: str, tmp_path: Path
) -> None:
    branch = tmp_path / "tw.nc"
    out = _json(runner, ["continue", "--model", model_file, "--vary", "omega=1.15:1.25",
                         "-o", str(branch)])  # fmt: skip
    assert out["points"] > 2
    ds = gc.open_branch(branch)
    assert ds.attrs["model_class"].endswith(":TwinWell")
    found = _json(runner, ["attractors", "--model", model_file, "--set", "omega=1.2",
                           "--starts", "2", "--transient", "20", "--periods", "20"])  # fmt: skip
    assert isinstance(found, list) and found


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--model", "nope.py:X"], "no such file"),
        (["--model", "{file}", "--preset", "sheng2016-v1"], "--model excludes"),
        (["--model", "{file}", "--set", "gama=0.2"], "did you mean 'gamma'"),
        (["--model", "{stem}:Missing"], "defines no 'Missing'"),
        (["--model", "no_such_model_entry"], "no model of that name"),
    ],
)
def test_bad_models_are_refused_naming_the_option(
    runner: CliRunner, model_file: str, args: list[str], needle: str
) -> None:
    path = model_file.rpartition(":")[0]
    filled = [a.format(file=model_file, stem=path) for a in args]
    result = runner.invoke(app, ["simulate", *filled, "--no-plot"])
    assert result.exit_code == 2, result.output
    assert needle in result.output


def test_plot_of_a_simulation_file_says_what_the_file_is(runner: CliRunner, tmp_path: Path) -> None:
    out = tmp_path / "sim"
    args = ["--set", "omega=0.5", "--transient", "5", "--periods", "5", "--no-verdict"]
    result = runner.invoke(app, ["simulate", *args, "-o", str(out), "--no-plot"])
    assert result.exit_code == 0, result.output
    result = runner.invoke(app, ["plot", str(out / "simulation.nc"), "-o", str(tmp_path / "x.png")])
    assert result.exit_code != 0
    assert "is a simulation file" in result.output and "simulate -o" in result.output


def test_a_simulation_file_says_where_its_record_starts(runner: CliRunner, tmp_path: Path) -> None:
    """Where the motion verdict had to continue a record (Ω = 1.5: a slow approach to the 1T
    orbit, |μ| ≈ 0.997, so the distance falls by e only every ~330 periods) the saved record is
    the trajectory's own continuation, integrated again from where it reached, and the file says
    so instead of 'given', with the periods the verdict added to the protocol's transient
    beside it (extra_periods; transient_periods stays the protocol's 100, issue 35); a record
    the verdict took as it is (Ω = 0.5) started from rest after the protocol's 100 periods."""
    for omega, words in (("1.5", "continuation of the run reached from rest"),
                         ("0.5", "rest, perturbed")):  # fmt: skip
        out = tmp_path / f"sim{omega}"
        result = runner.invoke(app, ["simulate", "--preset", "sheng2016-v1", "--set",
                                     f"omega={omega}", "-o", str(out), "--no-plot"])  # fmt: skip
        assert result.exit_code == 0, result.output
        ds = gc.open_simulation(out / "simulation.nc")
        assert words in ds.attrs["initial_state"]
        # a 1T record: every section lies on the orbit, within the verdict's reach (10⁻³)
        spread = np.ptp(ds["delta_sp"].values, axis=0)
        assert np.all(spread < 1e-3)
        assert ds.attrs["transient_periods"] == 100
        if omega == "1.5":  # ~10 e-folds (0.1 → 10⁻⁵) of ~330 periods each: thousands
            assert ds.attrs["extra_periods"] > 1000
        else:
            assert ds.attrs["extra_periods"] == 0


def test_an_installed_model_is_found_by_its_entry_point_name(
    runner: CliRunner, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A package that declares ``[project.entry-points."gearchaos.models"] twin_well = ...``
    offers its model by name (--model twin_well): here a distribution's metadata on sys.path."""
    site = tmp_path / "site"
    dist = site / "twin_well_models-0.1.dist-info"
    dist.mkdir(parents=True)
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: twin-well-models\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text(
        "[gearchaos.models]\ntwin_well = twin_well_ep:TwinWell\n"
    )
    (site / "twin_well_ep.py").write_text(MODEL, encoding="utf-8")
    monkeypatch.syspath_prepend(str(site))
    out = _json(runner, ["simulate", "--model", "twin_well", "--set", "omega=0.9",
                         "--set", "gamma=0.2", "--no-verdict"])  # fmt: skip
    assert out["section_min"] == float(np.min(gc.simulate(_builtin(0.9, 0.2)).section("x")))
