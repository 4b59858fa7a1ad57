"""``settle="auto"``: the transient ends early once the Poincaré sections repeat (issue 13).

Facts used, none taken from this code's output:

* The weakly forced, damped linear oscillator x'' + δx' + x = γ cos Ωτ (the Duffing system with
  β = 0) has one periodic attractor, the 1T response of amplitude γ/√((1 − Ω²)² + δ²Ω²), and
  transients decay as e^(−δτ/2): with δ = 0.5 they are below 1e-9 after 90 τ, so its sections
  repeat long before a 200-period transient ends.
* The Ueda oscillator x'' + 0.05x' + x³ = 7.5 cos τ (Ueda 1979; Duffing with α = 0) is chaotic:
  its sections never repeat, so it must never settle early.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.integrate.settings import SolverSettings


def _runs(system: gc.System, transient: int, periods: int) -> tuple[object, object]:
    kw = {"transient_periods": transient, "periods": periods, "y0": [0.3, 0.0]}
    return gc.simulate(system, settle="off", **kw), gc.simulate(system, settle="auto", **kw)


def test_a_periodic_motion_settles_early_with_the_same_sections() -> None:
    omega, delta, gamma = 1.3, 0.5, 0.2
    system = gc.duffing(omega, delta=delta, alpha=1.0, beta=0.0, gamma=gamma)
    full, auto = _runs(system, 200, 20)
    T = 2.0 * math.pi / omega
    t_full, t_auto = float(full.tau[0]), float(auto.tau[0])
    assert t_full == pytest.approx(200 * T, rel=1e-12)
    skipped = (t_full - t_auto) / T
    # settled: whole periods earlier (the forcing phase of the section is kept), long before 200
    assert skipped > 100
    assert skipped == pytest.approx(round(skipped), abs=1e-6)
    x_full = np.asarray(full.section("x"))
    x_auto = np.asarray(auto.section("x"))
    amp = gamma / math.sqrt((1.0 - omega**2) ** 2 + (delta * omega) ** 2)
    # the same 1T section point, within the settling tolerance, and on the analytic orbit
    np.testing.assert_allclose(x_auto, x_full, atol=1e-6)
    assert np.all(np.abs(x_auto) <= amp * (1 + 1e-6))
    assert np.ptp(x_auto) < 1e-6


def test_a_chaotic_motion_never_settles_early() -> None:
    system = gc.duffing(1.0, delta=0.05, alpha=0.0, beta=1.0, gamma=7.5)
    full, auto = _runs(system, 100, 20)
    assert float(auto.tau[0]) == float(full.tau[0])
    # and it is chaotic: its sections do not repeat with any period ≤ 10
    x = np.asarray(auto.section("x"))
    for n in range(1, 11):
        assert np.max(np.abs(x[n:] - x[:-n])) > 1e-3


def test_a_sweep_store_says_which_points_settled(tmp_path) -> None:
    lin = gc.duffing(1.3, delta=0.5, alpha=1.0, beta=0.0, gamma=0.2)
    ds = gc.bifurcation(
        lin,
        {"omega": np.array([0.8, 1.3])},
        store=str(tmp_path / "s.zarr"),
        transient_periods=150,
        periods=10,
        settle="auto",
        observe=["x"],
        progress=False,
    )
    skipped = np.asarray(ds["transient_skipped"].values)
    assert skipped.shape == (2,)
    assert np.all(skipped > 50)
    assert 'settle = "auto"' in ds.attrs["sweep_toml"]
    plain = gc.bifurcation(
        lin,
        {"omega": np.array([0.8, 1.3])},
        store=str(tmp_path / "p.zarr"),
        transient_periods=150,
        periods=10,
        observe=["x"],
        progress=False,
    )
    assert "transient_skipped" not in plain
    np.testing.assert_allclose(ds["x"].values, plain["x"].values, atol=1e-6)


def test_settle_must_be_off_or_auto() -> None:
    with pytest.raises(gc.ParameterError, match="settle must be one of 'off', 'auto'"):
        SolverSettings(settle="yes")
    with pytest.raises(gc.ParameterError, match="settle"):
        gc.simulate(gc.duffing(1.0), settle=True)  # type: ignore[arg-type]


def test_the_command_line_refuses_a_bad_settle(tmp_path) -> None:
    from typer.testing import CliRunner

    from gearchaos.cli import app

    runner = CliRunner()
    for args in (
        ["simulate", "--json"],
        ["bifurcation", "--vary", "omega=1,2", "-o", str(tmp_path / "b.zarr")],
    ):
        result = runner.invoke(app, [*args, "--settle", "maybe"], env={"COLUMNS": "200"})
        assert result.exit_code == 2, result.output
        # refused by the command line, naming the option and the library's SETTLE_CHOICES
        assert "'--settle'" in result.stderr
        assert "'maybe' is not one of 'off', 'auto'" in result.stderr
    assert list(tmp_path.iterdir()) == []
