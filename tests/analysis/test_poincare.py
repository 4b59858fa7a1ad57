"""count_distinct and section_points: exact counts of synthetic period-n sequences."""

from __future__ import annotations

import math

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.analysis.poincare import count_distinct, section_points, section_variables
from gearchaos.errors import ParameterError


def periodic_sequence(n: int, m: int, d: int, noise: float, seed: int = 0) -> np.ndarray:
    """m points cycling through n well separated centres (on a circle), plus uniform noise."""
    rng = np.random.default_rng(seed)
    angles = 2 * math.pi * np.arange(n) / n
    centres = np.column_stack([np.cos(angles), np.sin(angles)] + [np.zeros(n)] * (d - 2))
    pts = centres[np.arange(m) % n] + noise * rng.uniform(-1, 1, (m, d))
    return pts[:, 0] if d == 1 else pts


@pytest.mark.parametrize("n", [1, 2, 3, 7])
@pytest.mark.parametrize("d", [1, 2])
def test_period_n_sequences_with_noise_below_tol(n: int, d: int) -> None:
    if d == 1 and n > 2:
        # on a line: distinct x = cos(2πk/n) values (cos is symmetric, so n=3 and 7 pair up)
        pts = np.cos(2 * math.pi * (np.arange(200) % n) / n + 0.1)
    else:
        pts = periodic_sequence(n, 200, d, noise=1e-5)
    # noise 1e-5 is far below tol × size = 1e-3 × 2
    assert count_distinct(pts, tol=1e-3) == n


def test_noise_above_tol_splits_points() -> None:
    pts = periodic_sequence(2, 200, 2, noise=0.05)
    assert count_distinct(pts, tol=1e-3) > 2


def test_irrational_rotation_is_many() -> None:
    alpha = (math.sqrt(5) - 1) / 2
    k = np.arange(500)
    pts = np.column_stack([np.cos(2 * math.pi * alpha * k), np.sin(2 * math.pi * alpha * k)])
    assert count_distinct(pts) == 65
    assert count_distinct(pts, max_count=10) == 11


def test_max_count_boundary() -> None:
    pts = periodic_sequence(10, 100, 2, noise=0.0)
    assert count_distinct(pts, max_count=10) == 10
    assert count_distinct(pts, max_count=9) == 10  # 9 + 1 means "more than 9"


def test_degenerate_inputs() -> None:
    assert count_distinct(np.full(50, 3.25)) == 1
    assert count_distinct(np.zeros((10, 2))) == 1
    assert count_distinct(np.full(5, np.nan)) == 0
    assert count_distinct(np.empty((0, 2))) == 0
    # NaN rows are ignored
    pts = periodic_sequence(3, 30, 2, noise=0.0)
    pts[::4] = np.nan
    assert count_distinct(pts) == 3
    # a slowly drifting fixed point (relative spread 1e-4 < tol) is one point
    assert count_distinct(3.5 + 1e-4 * np.linspace(0, 1, 40)) == 1


def test_scale_override() -> None:
    pts = np.array([0.0, 1e-3, 0.0, 1e-3])
    assert count_distinct(pts) == 2  # relative to their own range
    assert count_distinct(pts, scale=10.0) == 1  # 1e-3 < 1e-3 × 10


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [({"tol": 0.0}, "tol"), ({"tol": math.nan}, "tol"), ({"max_count": 0}, "max_count")],
)
def test_bad_arguments(kwargs: dict[str, float], match: str) -> None:
    with pytest.raises(ParameterError, match=match):
        count_distinct(np.arange(3.0), **kwargs)  # type: ignore[arg-type]


def test_bad_shape() -> None:
    with pytest.raises(ParameterError, match="shape"):
        count_distinct(np.zeros((2, 2, 2)))


def test_section_points_of_the_planetary_model() -> None:
    r = gc.simulate(gc.preset("hindawi2021"), omega=0.5, transient_periods=20, periods=20)
    x, xd = section_points(r)
    np.testing.assert_array_equal(x, r.to_dataset().delta_sp.sel(planet=1).values)
    np.testing.assert_array_equal(xd, r.to_dataset().delta_sp_dot.sel(planet=1).values)
    assert section_variables(r, None, 3) == ("delta_sp_3", "delta_sp_dot_3")
    assert count_distinct(np.column_stack([x, xd])) == 1  # below the first resonance: 1T
    with pytest.raises(ParameterError, match="planet"):
        section_points(r, planet=6)


def test_section_points_of_a_reference_system() -> None:
    r = gc.simulate(
        gc.backlash_oscillator(1.0, zeta=0.1, b=1.0, f_mean=2.0, f_alt=0.3, omega_power=0),
        transient_periods=20,
        periods=10,
    )
    x, xd = section_points(r)
    np.testing.assert_array_equal(x, r.section("x"))
    np.testing.assert_array_equal(xd, r.section("x_dot"))
