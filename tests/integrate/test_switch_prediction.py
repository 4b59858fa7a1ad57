"""Switch prediction (issue 13): the extrapolated crossing time of a dead-zone level.

``predict_switch`` extrapolates the Hermite interpolant through the last accepted points (value
and derivative at each) and finds where it first reaches ±b within the proposed step. A
polynomial of the interpolant's degree is reproduced exactly by it, so the predicted time must
be the polynomial's own first crossing, computed here independently by ``numpy.roots``.
"""

from __future__ import annotations

import numpy as np
import pytest

from gearchaos.integrate._switch import predict_switch


def _first_crossing(coeffs: np.ndarray, b: float, h: float) -> float:
    """Smallest u in (0, h] where the polynomial (highest power first) equals +b or −b."""
    best = np.inf
    for level in (b, -b):
        c = coeffs.copy()
        c[-1] -= level
        for r in np.roots(c):
            if abs(r.imag) < 1e-9 and 0.0 < r.real <= h:
                best = min(best, r.real)
    return float(best)


def _history(coeffs: np.ndarray, times: list[float]) -> np.ndarray:
    """Rows (v, v') of one observable at ``times`` (newest first)."""
    d = np.polyder(coeffs)
    return np.array([[np.polyval(coeffs, t), np.polyval(d, t)] for t in times])


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("n_pts", [2, 3])
def test_predicted_switch_is_the_polynomials_crossing(seed: int, n_pts: int) -> None:
    rng = np.random.default_rng(seed)
    degree = 5 if n_pts == 3 else 3  # what 3 (2) points with derivatives determine exactly
    b = 1.0
    h = 0.4
    # a polynomial inside the clearance now (|v(0)| < b) that leaves it within the step
    while True:
        coeffs = rng.normal(size=degree + 1)
        coeffs[-1] = rng.uniform(-0.9, 0.9)  # v(0)
        u_star = _first_crossing(coeffs, b, h)
        # one crossing: the step ends outside (a crossing out and back within one step is
        # invisible by design, at the step's end as in the check after it)
        if np.isfinite(u_star) and u_star > 0.02 and abs(np.polyval(coeffs, h)) > b:
            break
    times = [0.0, -0.07, -0.16][:n_pts] + [-0.3] * (3 - n_pts)
    hist = _history(coeffs, times)
    got = predict_switch(hist, n_pts, np.array(times), 1, np.array([b]), h)
    assert got == pytest.approx(u_star, abs=1e-9 * h)


def test_no_switch_predicted_when_the_extrapolant_stays_inside() -> None:
    coeffs = np.array([0.0, 0.0, 0.5, -0.1, 0.2, 0.3])  # stays within ±1 on [0, 0.4]
    times = [0.0, -0.07, -0.16]
    got = predict_switch(_history(coeffs, times), 3, np.array(times), 1, np.array([1.0]), 0.4)
    assert got == -1.0


def test_observables_without_a_switch_are_ignored() -> None:
    coeffs = np.array([0.0, 0.0, 0.0, 0.0, 5.0, 0.5])  # crosses 1 at u = 0.1
    times = [0.0, -0.07, -0.16]
    hist = _history(coeffs, times)
    assert predict_switch(hist, 3, np.array(times), 1, np.array([np.inf]), 0.4) == -1.0
    assert predict_switch(hist, 3, np.array(times), 1, np.array([1.0]), 0.4) == pytest.approx(
        0.1, abs=1e-12
    )


def test_no_switch_predicted_ahead_of_an_observable_sitting_on_its_level() -> None:
    """An observable exactly on ±b (to rounding) leaving the clearance crosses at the start of
    the step: no shortened step is aimed at it (a step of 1e-13 would not move it off the
    level in floating point, and the next step would be aimed at it again)."""
    b = 1.0
    for v0, d0 in ((b, 1e-5), (-b, -1e-5), (np.nextafter(b, 0.0), 1e-5)):
        times = [0.0, -1e-9, -2e-9]
        hist = np.array([[v0 + d0 * t, d0] for t in times])
        got = predict_switch(hist, 3, np.array(times), 1, np.array([b]), 1e-8)
        assert got == -1.0, (v0, got)
    # (one off its level is predicted as before: test_predicted_switch_is_the_polynomials_crossing)


def test_an_orbit_grazing_its_clearance_is_integrated_with_its_tangents() -> None:
    """A period-1 orbit of the backlash oscillator that grazes the clearance (it dips 1e-9
    into the dead zone: a point of the grazing curve of tests/dynamics/curves/test_curves.py),
    integrated over one period with its variational equations at rtol 1e-10, once stalled at
    the exit of the dead zone (x landed exactly on b̄, each step then aimed at a crossing 1e-13
    ahead) until the step budget ran out. It must finish, and its end state must be the plain
    run's (the tangents change the step sizes, not the solution beyond the tolerance)."""
    import gearchaos as gc
    from gearchaos.dynamics.orbits.shooting import shoot
    from gearchaos.integrate.settings import SolverSettings

    y = np.array([1.1989473899282392, 0.01025968298815881])
    system = gc.backlash_oscillator(
        0.7089749308498624, zeta=0.05129841325237217, f_alt=0.1, f_mean=0.1
    )
    cfg = SolverSettings(rtol=1e-10, atol=1e-12)
    plain = shoot([system], y[None], 1, cfg, tangents=False)
    full = shoot([system], y[None], 1, cfg, tangents=True)
    assert plain.ok(0) and full.ok(0), (plain.status, full.status)
    assert abs(plain.obs_min[0, 0] - 1.0) < 1e-8  # it does graze b̄ = 1
    np.testing.assert_allclose(full.end[0], plain.end[0], rtol=0, atol=1e-9)
