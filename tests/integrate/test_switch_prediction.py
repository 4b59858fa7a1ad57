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
