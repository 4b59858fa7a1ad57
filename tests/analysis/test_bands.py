"""Band and torus tests of a section sequence on sequences whose nature is known by
construction: a rotation on an ellipse (an invariant circle, irrational rotation number), the
same curve deformed into a figure eight in its plane (not star-shaped), two curves visited in
turn, and chaos (the logistic map at r = 4 and the Hénon map)."""

from __future__ import annotations

import math

import numpy as np

from gearchaos.analysis.bands import band_count, circle_order, uniform_return

GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def _ellipse(m: int, rho: float = GOLDEN, phase: float = 0.3) -> np.ndarray:
    t = 2 * math.pi * (phase + rho * np.arange(m))
    return np.column_stack([2.0 * np.cos(t), np.sin(t), 0.1 * np.cos(2 * t)])


def _henon(m: int) -> np.ndarray:
    x, y = 0.1, 0.1
    out = np.empty((m + 1000, 2))
    for k in range(m + 1000):
        x, y = 1.0 - 1.4 * x * x + y, 0.3 * x
        out[k] = x, y
    return out[1000:]


def _logistic(m: int) -> np.ndarray:
    x = 0.2
    out = np.empty((m + 100, 2))
    for k in range(m + 100):
        x = 4.0 * x * (1.0 - x)
        out[k] = x, x * x
    return out[100:]


def test_a_rotation_keeps_its_cyclic_order() -> None:
    assert circle_order(_ellipse(400)) >= 0.99
    assert circle_order(_henon(400)) < 0.5
    assert circle_order(_logistic(400)) < 0.5


def test_uniform_return_falls_on_a_circle_and_not_on_chaos() -> None:
    # on a rotation the best return over m points is at most ~ 2π |h'| / q_best with q_best a
    # continued-fraction denominator of ρ near m/3: it falls as the record grows
    r_short, _ = uniform_return(_ellipse(200))
    r_long, q = uniform_return(_ellipse(1600))
    assert r_long < r_short and r_long < 0.02
    assert min(abs(q * GOLDEN - round(q * GOLDEN)), 1.0) < 0.01  # a near return of the rotation
    # a figure eight (self-intersecting in its plane) is no obstacle to the return test
    fig8 = _ellipse(1600)
    fig8[:, 1] = np.sin(2 * np.arctan2(fig8[:, 1], fig8[:, 0] / 2))
    assert uniform_return(fig8)[0] < 0.05
    # chaos: no shift returns every point at once
    assert uniform_return(_henon(1600))[0] > 0.3
    assert uniform_return(_logistic(1600))[0] > 0.3


def test_two_curves_visited_in_turn_are_two_bands() -> None:
    a = _ellipse(800)
    b = _ellipse(800, phase=0.1) + np.array([10.0, 0.0, 0.0])
    two = np.empty((1600, 3))
    two[0::2], two[1::2] = a, b
    assert band_count(two) == 2
    assert band_count(_ellipse(1600)) in (1, 2, 3, 5, 8)  # bands of a rotation: near returns
    assert band_count(_henon(800)) == 1
