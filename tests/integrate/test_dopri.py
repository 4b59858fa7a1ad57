"""What the compiled Dormand–Prince 5(4) integrator promises.

* 5th-order global convergence against the exact matrix-exponential solution of a linear system,
  measured from a log-log fit of the error against the number of accepted steps (adaptive over a
  range of rtol, and with a fixed step imposed through ``max_step``);
* samples at τ_k bit-for-bit equal to restarting one period at a time (``t0``, ``first_step``,
  ``final_state``, ``next_step``), on the planetary model with clearances active;
* failures reported as status values (never silent NaN), NaN for unreached samples, and
  ``simulate(check=...)`` raising or warning;
* running extrema refined inside steps (exact for cos τ, and equal to a dense evaluation for the
  backlash oscillator with impacts).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import scipy.linalg

import gearchaos as gc
from gearchaos.errors import IntegrationError, Status
from gearchaos.integrate import integrate

# 4x4 damped two-mass oscillator chain: x'' + C x' + K x = 0
_K = np.array([[2.0, -1.0], [-1.0, 2.0]])
_C = 0.05 * _K
A_CHAIN = np.block([[np.zeros((2, 2)), np.eye(2)], [-_K, -_C]])
Y0_CHAIN = np.array([1.0, 0.0, 0.0, 0.5])


def _chain_errors(settings: list[dict]) -> tuple[np.ndarray, np.ndarray]:
    system = gc.linear_system(A_CHAIN, 1.0)
    periods = 3
    exact_end = scipy.linalg.expm(A_CHAIN * periods * system.period) @ Y0_CHAIN
    steps, errors = [], []
    for kw in settings:
        tr = integrate(system, y0=Y0_CHAIN, transient_periods=0, periods=periods, **kw)
        assert tr.ok
        # every section sample too, against expm(A τ_k) y0
        for tau, y in zip(tr.tau, tr.states, strict=True):
            exact = scipy.linalg.expm(A_CHAIN * tau) @ Y0_CHAIN
            assert np.abs(y - exact).max() < 100 * kw["rtol"] + 1e-12
        steps.append(tr.steps_accepted)
        errors.append(np.abs(tr.final_state - exact_end).max())
    return np.array(steps, float), np.array(errors)


def test_convergence_order_adaptive() -> None:
    rtols = 10.0 ** -np.arange(5.0, 10.5, 0.5)
    steps, errors = _chain_errors([{"rtol": r, "atol": 1e-16} for r in rtols])
    slope = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert slope == pytest.approx(-5.0, abs=0.3)
    # the error is controlled in units of the tolerance
    assert np.all(errors < 100 * rtols)


def test_convergence_order_fixed_step() -> None:
    T = 2 * math.pi
    m = [20, 30, 40, 60, 80, 120]
    # loose tolerances never reject, so h = max_step throughout
    steps, errors = _chain_errors([{"rtol": 0.1, "atol": 1.0, "max_step": T / k} for k in m])
    nominal = 3 * np.array(m)
    # round-off may add one sliver step per sample time, never more
    assert np.all((steps >= nominal) & (steps <= nominal + 3))
    slope = np.polyfit(np.log(nominal), np.log(errors), 1)[0]
    assert slope == pytest.approx(-5.0, abs=0.3)


def test_forced_linear_system_matches_variation_of_constants() -> None:
    """y' = A y + f cos Ωτ + g sin Ωτ: exact solution via an augmented matrix exponential."""
    om = 0.7
    f = np.array([0.0, 0.0, 0.3, 0.0])
    g = np.array([0.0, 0.0, 0.0, -0.2])
    system = gc.linear_system(A_CHAIN, om, cos_forcing=f, sin_forcing=g)
    # augmented linear system z = (y, cos Ωτ, sin Ωτ)
    big = np.zeros((6, 6))
    big[:4, :4] = A_CHAIN
    big[:4, 4] = f
    big[:4, 5] = g
    big[4, 5] = -om
    big[5, 4] = om
    tr = integrate(system, y0=Y0_CHAIN, transient_periods=0.5, periods=4, rtol=1e-11, atol=1e-14)
    assert tr.ok
    z0 = np.concatenate([Y0_CHAIN, [1.0, 0.0]])
    for tau, y in zip(tr.tau, tr.states, strict=True):
        exact = (scipy.linalg.expm(big * tau) @ z0)[:4]
        np.testing.assert_allclose(y, exact, rtol=0, atol=1e-9)
    # sections land exactly on τ = (transient + k) T
    np.testing.assert_allclose(tr.tau, (0.5 + np.arange(4)) * system.period, rtol=1e-15)


@pytest.mark.parametrize("rtol", [1e-8, 1e-11])
def test_restart_one_period_at_a_time_is_identical(rtol: float) -> None:
    gs = gc.preset("hindawi2021")
    system = gc.planetary_system(gs, 1.5)
    K = 6
    # exactly at rest, as the restarted pieces (the first from y = 0)
    full = integrate(system, transient_periods=0, periods=K, rtol=rtol, atol=1e-12, perturbation=0)
    assert full.ok
    # clearances are active: the sun–planet mesh leaves the drive flank
    b_sp = gs.backlash.sun_planet
    assert full.obs_min[: gs.n_planets].min() < b_sp
    y = np.zeros(system.n_state)
    t0 = 0.0
    h = None
    for k in range(K):
        part = integrate(
            system, y0=y, t0=t0, transient_periods=0, periods=1, first_step=h, rtol=rtol, atol=1e-12
        )
        assert part.ok
        assert part.tau[0] == pytest.approx(full.tau[k], rel=1e-14, abs=1e-14)
        scale = max(np.abs(full.states[k]).max(), 1.0)
        # the PI controller's memory err_{n-1} and the switch predictor's points are not carried
        # over a restart (only the next step is), so the runs agree to the tolerance
        assert np.abs(part.states[0] - full.states[k]).max() <= max(1e-10, 3 * rtol) * scale
        y, h, t0 = part.final_state, part.next_step, t0 + system.period
    scale = np.abs(full.final_state).max()
    assert np.abs(y - full.final_state).max() <= max(1e-10, 3 * rtol) * scale


def test_blow_up_is_reported_not_silent() -> None:
    system = gc.linear_system([[50.0]], 1.0)  # y = exp(50 τ) overflows near τ = 14.2
    tr = integrate(system, y0=[1.0], transient_periods=0, periods=10)
    assert tr.status is Status.NON_FINITE
    assert not tr.ok
    reached = np.isfinite(tr.tau)
    # samples before the overflow are right (relative error grows ∝ steps at rtol = 1e-8),
    # the rest are NaN (never zeros that look like data)
    assert reached.sum() == 3  # τ = 0, 2π, 4π < 14.2 < 6π
    np.testing.assert_allclose(tr.states[reached, 0], np.exp(50.0 * tr.tau[reached]), rtol=1e-5)
    assert np.all(np.isnan(tr.states[~reached]))
    assert np.all(np.isnan(tr.observables[~reached]))
    assert np.all(np.isfinite(tr.final_state))


def test_max_steps() -> None:
    system = gc.linear_oscillator(1.0, zeta=0.1)
    tr = integrate(system, y0=[1.0, 0.0], transient_periods=0, periods=10, max_steps=10)
    assert tr.status is Status.MAX_STEPS
    assert tr.steps_accepted + tr.steps_rejected + tr.steps_switch == 10
    assert np.all(np.isnan(tr.tau[1:]))
    assert np.all(np.isnan(tr.states[1:]))
    assert tr.status.message  # informative text


def test_simulate_check_raises_or_warns() -> None:
    system = gc.linear_system([[50.0]], 1.0)
    with pytest.raises(IntegrationError, match="NON_FINITE") as info:
        gc.simulate(system, transient_periods=0, periods=10, y0=[1.0])
    assert info.value.result.status is Status.NON_FINITE
    with pytest.warns(RuntimeWarning, match="NON_FINITE"):
        res = gc.simulate(system, transient_periods=0, periods=10, y0=[1.0], check=False)
    assert res.status is Status.NON_FINITE
    assert np.isnan(res.tau[-1])
    # a successful run does not warn
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ok = gc.simulate(gc.linear_oscillator(1.0), transient_periods=0, periods=2, y0=[1, 0])
    assert ok.ok


@pytest.mark.parametrize("rtol", [1e-10, 1e-12])
def test_extrema_of_cosine_with_sparse_samples(rtol: float) -> None:
    # x'' + x = 0, x = cos τ, x' = −sin τ; Ω = 0.37 puts no sample near an interior extremum
    system = gc.linear_oscillator(0.37, zeta=0.0)
    tr = integrate(system, y0=[1.0, 0.0], transient_periods=0.3, periods=3, rtol=rtol, atol=1e-14)
    assert tr.ok
    # samples alone are far from the extrema
    assert np.abs(np.abs(tr.states) - 1.0).min() > 1e-3
    np.testing.assert_allclose(tr.obs_min, [-1.0, -1.0], atol=1e-8)
    np.testing.assert_allclose(tr.obs_max, [1.0, 1.0], atol=1e-8)


def _refined_extremum(x: np.ndarray, sign: float) -> float:
    """Extremum of densely sampled data, refined by the parabola through the 3 best samples."""
    v = sign * x
    i = int(np.argmax(v[1:-1])) + 1
    a, b, c = v[i - 1], v[i], v[i + 1]
    return sign * (b - (a - c) ** 2 / (8.0 * (a - 2.0 * b + c)))


@pytest.mark.parametrize(("omega", "f_alt"), [(0.8, 0.5), (1.2, 0.8), (2.0, 1.0)])
def test_extrema_match_dense_evaluation_backlash(omega: float, f_alt: float) -> None:
    system = gc.backlash_oscillator(omega, zeta=0.05, b=1.0, f_mean=0.1, f_alt=f_alt, omega_power=0)
    kw = {"transient_periods": 2, "periods": 5, "rtol": 1e-12, "atol": 1e-14}
    sparse = integrate(system, **kw)
    m = 2000
    dense = integrate(system, samples_per_period=m, **kw)
    assert sparse.ok and dense.ok
    x = dense.series("x")
    # impacts happen: the response enters the clearance |x| < b
    assert np.any(np.abs(x) < 1.0)
    assert sparse.obs_min[0] == pytest.approx(_refined_extremum(x, -1.0), abs=1e-8)
    assert sparse.obs_max[0] == pytest.approx(_refined_extremum(x, 1.0), abs=1e-8)
