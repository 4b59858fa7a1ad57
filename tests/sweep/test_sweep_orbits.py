"""``orbits=True`` (``--orbits``): every nT label of a sweep is checked by a period-n orbit.

Checked against theory and independent computations, not against the code's own output:

* a point labelled 1T or 2T is an attractor found by simulation, so the orbit shot from its
  final state converges (residual below the Newton tolerance), has minimal period n, passes
  through the sweep's own section points, and is stable: max |μ| < 1; its decay rate
  ln(max |μ|)/(nT) is the largest Lyapunov exponent the sweep integrated independently
  (variational equations over the recorded window);
* chaotic points (λ₁ > 0) get no orbit: NaN residual and multiplier, status ``not_periodic``;
* a label that overstates the period (a 1T point claimed 2T) is flagged ``shorter_period``;
* the orbit variables are written with their task: a sweep interrupted after its first task
  and resumed equals an uninterrupted one.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.errors import ParameterError
from gearchaos.integrate.settings import SolverSettings
from gearchaos.sweep import SweepSpec
from gearchaos.sweep.orbits import orbit_checks
from gearchaos.sweep.store import SweepStore, foreign_files_ignored
from gearchaos.sweep.variables import ORBIT_STATUS

KW = {"transient_periods": 600, "periods": 64}


def backlash() -> gc.System:
    return gc.backlash_oscillator(1.0, zeta=0.05, f_alt=0.1, f_mean=0.1)


@pytest.fixture(scope="module")
def swept():
    """Down the period-doubling cascade of the backlash oscillator into chaos (Ω 2.1 → 1.7)."""
    return gc.bifurcation(
        backlash(), "omega=1.70:2.10:9", initial_conditions="continuation", direction="down",
        lyapunov=True, orbits=True, progress=False, **KW,
    )  # fmt: skip


def test_periodic_labels_are_confirmed_by_stable_orbits(swept) -> None:
    motion = swept.motion.values
    status = swept.orbit_status.values
    periodic = [k for k, m in enumerate(motion) if m in ("1T", "2T")]
    assert {motion[k] for k in periodic} == {"1T", "2T"}
    tol = 0.1 * SolverSettings(**KW).rtol  # the Newton tolerance of the sweep's settings
    for k in periodic:
        n = int(motion[k][:-1])
        assert status[k] == ORBIT_STATUS["confirmed"], (k, motion[k])
        assert int(swept.orbit_period.values[k]) == n
        assert swept.orbit_residual.values[k] < tol
        mu = float(swept.orbit_max_multiplier.values[k])
        assert mu < 1.0
        # the orbit's decay rate is the Lyapunov exponent integrated by the sweep
        omega = float(swept.omega.values[k])
        rate = math.log(mu) / (n * 2 * math.pi / omega)
        assert rate == pytest.approx(float(swept.lle.values[k]), abs=0.012)
    # the shot orbit passes through the sweep's own section points (they have converged)
    k = periodic[-1]
    orbit = gc.periodic_orbit(
        backlash(), guess=swept.final_state.values[k], omega=float(swept.omega.values[k]), **KW
    )
    assert orbit.converged and orbit.minimal_period == 1
    assert orbit.section("x")[0] == pytest.approx(float(swept.x.values[k, -1]), abs=1e-6)


def test_chaotic_points_get_no_orbit(swept) -> None:
    chaotic = np.flatnonzero(swept.motion.values == "chaos")
    assert chaotic.size >= 2
    assert np.all(swept.lle.values[chaotic] > 0.02)
    assert np.all(swept.orbit_status.values[chaotic] == ORBIT_STATUS["not_periodic"])
    assert np.all(np.isnan(swept.orbit_residual.values[chaotic]))
    assert np.all(np.isnan(swept.orbit_max_multiplier.values[chaotic]))
    assert np.all(swept.orbit_period.values[chaotic] == 0)
    meanings = swept.orbit_status.attrs["flag_meanings"].split()
    assert dict(zip(meanings, swept.orbit_status.attrs["flag_values"], strict=True)) == ORBIT_STATUS


def test_a_label_that_overstates_the_period_is_flagged() -> None:
    """The linear oscillator's steady state is 1T; claimed 2T, the period-2 shooting converges
    to that fixed point of P, whose two section points coincide."""
    system = gc.linear_oscillator(1.3, zeta=0.1, force=1.0)
    settings = SolverSettings(transient_periods=0, periods=1)
    y = np.array([[0.3, -0.2], [0.3, -0.2], [0.3, -0.2], [np.nan, 0.0]])
    found = orbit_checks(system, [{"omega": 1.3}] * 4, [1, 2, 0, 1], y, settings)
    assert found["orbit_status"].tolist() == [
        ORBIT_STATUS["confirmed"],
        ORBIT_STATUS["shorter_period"],
        ORBIT_STATUS["not_periodic"],
        ORBIT_STATUS["failed"],
    ]
    # the multipliers of a linear oscillator: |μ| = exp(−ζ n T), n = 1 and 2
    t = 2 * math.pi / 1.3
    assert found["orbit_max_multiplier"][0] == pytest.approx(math.exp(-0.1 * t), rel=1e-7)
    assert found["orbit_max_multiplier"][1] == pytest.approx(math.exp(-0.2 * t), rel=1e-7)
    assert found["orbit_period"].tolist() == [1, 2, 0, 0]
    too_long = orbit_checks(system, [{"omega": 1.3}], [9], y[:1], settings)
    assert too_long["orbit_status"].tolist() == [ORBIT_STATUS["period_too_long"]]


def test_orbit_variables_resume_with_their_task(tmp_path, monkeypatch) -> None:
    """Stopped after the first of three tasks: the resumed store equals an uninterrupted run,
    and the first task's orbit variables were already in the store."""
    args = (backlash(), "omega=1.9:2.1:9")
    kw = {"orbits": True, "progress": False, "transient_periods": 300, "periods": 16}
    whole = gc.bifurcation(*args, **kw)
    path = tmp_path / "run.zarr"
    original = SweepStore.write_tasks
    calls = []

    def write_then_stop(self, tasks):
        # the first task of the first write (writes are batched since issue 36), then stop
        original(self, tasks[:1])
        calls.append(tasks[0][0])
        raise KeyboardInterrupt

    monkeypatch.setattr(SweepStore, "write_tasks", write_then_stop)
    with pytest.raises(KeyboardInterrupt):
        gc.bifurcation(*args, store=path, **kw)
    monkeypatch.undo()
    import xarray as xr

    with foreign_files_ignored():
        part = xr.open_zarr(path, consolidated=False)
    written = np.flatnonzero(part.status.values != 4)
    assert written.size >= 1 and len(calls) == 1
    assert np.all(part.orbit_status.values[written] >= 0)
    assert np.all(part.orbit_status.values[part.status.values == 4] == -1)
    resumed = gc.bifurcation(*args, store=path, **kw)
    for name in ("orbit_status", "orbit_period", "orbit_residual", "orbit_max_multiplier"):
        np.testing.assert_array_equal(resumed[name].values, whole[name].values)
    assert "orbits = true" in resumed.attrs["sweep_toml"]


def test_orbits_option_is_validated_and_spelled_in_the_spec() -> None:
    with pytest.raises(ParameterError, match="orbits"):
        SweepSpec.build("omega=1:2:3", orbits="yes")
    spec = SweepSpec.build("omega=1:2:3", orbits=True)
    assert SweepSpec.from_toml(spec.to_toml()) == spec
    assert "orbits" not in SweepSpec.build("omega=1:2:3").to_toml()


def test_cli_bifurcation_orbits_counts_the_outcomes(tmp_path) -> None:
    import json

    from typer.testing import CliRunner

    from gearchaos.cli import app

    out = tmp_path / "run.zarr"
    args = ["bifurcation", "--preset", "hindawi2021", "--vary", "omega=0.5,0.6"]
    args += ["--set", "xi=0.1", "--transient", "200", "--periods", "16", "--orbits"]
    args += ["-o", str(out)]
    result = CliRunner().invoke(app, [*args, "--json", "--quiet"])
    assert result.exit_code == 0, result.output
    counts = json.loads(result.stdout)["orbits"]
    ds = gc.open_sweep(out)
    assert sum(counts.values()) == 2
    names = {v: k for k, v in ORBIT_STATUS.items()}
    for code in ds.orbit_status.values:
        assert names[int(code)] in counts
    # a 1T point of a well-damped train at low Ω: confirmed by a stable orbit
    assert list(ds.motion.values) == ["1T", "1T"]
    assert counts == {"confirmed": 2}
    assert np.all(ds.orbit_max_multiplier.values < 1.0)
