"""detect_period: exact periods of synthetic section sequences, and None where there is none.

Expected values come from the construction of each sequence: a sequence built to cycle
through n points with noise far below the tolerance has period n; an irrational rotation has
none, because its closest return within 64 steps is a known distance away.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearchaos.analysis.periodicity import detect_period, period_label, periods_of
from gearchaos.errors import ParameterError

GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def cycle(n: int, m: int, d: int = 2, noise: float = 0.0, seed: int = 0) -> np.ndarray:
    """m points cycling through n points of the unit circle (d = 2) or of cos (d = 1)."""
    rng = np.random.default_rng(seed)
    angle = 2 * math.pi * (np.arange(m) % n) / n + 0.1
    pts = np.column_stack([np.cos(angle), np.sin(angle)])[:, :d]
    pts = pts + noise * rng.uniform(-1.0, 1.0, pts.shape)
    return pts[:, 0] if d == 1 else pts


def rotation(m: int, alpha: float = GOLDEN) -> np.ndarray:
    k = np.arange(m)
    return np.column_stack([np.cos(2 * math.pi * k * alpha), np.sin(2 * math.pi * k * alpha)])


@pytest.mark.parametrize("n", [1, 2, 3, 5, 7])
@pytest.mark.parametrize("d", [1, 2])
def test_known_period_with_noise_below_tolerance(n: int, d: int) -> None:
    # noise ≤ 1e-5 per coordinate moves |x_{k+n} − x_k| by ≤ 2√2·1e-5, far below
    # rtol × size ≈ 1e-3 × 2; distinct points of the cycle are ≥ 2 sin(π/7) ≈ 0.87 apart
    # (on the circle) and the cos values of the offset angles are distinct (d = 1)
    pts = cycle(n, 300, d, noise=1e-5)
    assert detect_period(pts) == n


def test_period_65_is_beyond_max_period() -> None:
    # the 65 points are 2 sin(π n/65) ≥ 0.097 apart for every lag n ≤ 64 (tolerance ≈ 2e-3)
    pts = cycle(65, 400)
    assert detect_period(pts) is None
    assert detect_period(pts, max_period=65) == 65


def test_irrational_rotation_has_no_period() -> None:
    # |x_{k+n} − x_k| = 2|sin(π n α)| for every k; for n ≤ 64 its minimum is at the
    # Fibonacci number n = 55: 2 sin(π‖55α‖) ≈ 0.051 ≫ 1e-3 × 2
    assert detect_period(rotation(500)) is None


def test_noise_above_tolerance_hides_the_period() -> None:
    # noise 0.05 gives differences up to 0.14 ≫ 1e-3 × size
    assert detect_period(cycle(2, 300, noise=0.05)) is None
    # ... unless an absolute tolerance covers it (centres stay 2 apart, so not period 1)
    assert detect_period(cycle(2, 300, noise=0.05), atol=0.2) == 2


def test_tolerance_is_relative_to_attractor_size() -> None:
    pts = cycle(3, 300, noise=1e-5)
    for scale in (1e-9, 1.0, 1e9):
        assert detect_period(scale * pts) == 3
    # a noise of 1 % of the attractor is resolved by rtol = 0.05, not by the default
    noisy = cycle(3, 300, noise=0.01)
    assert detect_period(noisy) is None
    assert detect_period(noisy, rtol=0.05) == 3


def test_needs_2n_plus_1_points() -> None:
    pts = cycle(3, 7)
    assert detect_period(pts[:6]) is None  # 6 < 2·3 + 1: period 3 undecidable
    assert detect_period(pts) == 3


def test_transient_is_checked_over_the_whole_sequence() -> None:
    pts = cycle(2, 300)
    k = np.arange(300)[:, None]
    drifting = pts + 0.5 * np.exp(-k / 10.0)  # transient decays to 1e-13 by the end
    assert detect_period(drifting) is None
    assert detect_period(drifting[200:]) == 2  # e^{-20}·0.5 ≈ 1e-9 ≪ tolerance


def test_coincident_points_are_period_1() -> None:
    assert detect_period(np.full((50, 2), 3.0)) == 1
    assert detect_period(np.zeros(50)) == 1
    # a fixed point still drifting by 1e-6 of its value of 5: one point (count_distinct's rule)
    x = 5.0 + 1e-6 * np.linspace(0.0, 1.0, 100)
    assert detect_period(x) == 1


def test_nan_row_gives_none() -> None:
    pts = cycle(2, 100)
    pts[50, 1] = np.nan
    assert detect_period(pts) is None
    assert detect_period(np.empty((0, 2))) is None


def test_periods_of_matches_detect_period_over_a_batch() -> None:
    seqs = np.stack([cycle(1, 200), cycle(2, 200), cycle(5, 200), rotation(200)])
    batch = np.stack([seqs, seqs[::-1]])  # shape (2, 4, 200, 2)
    got = periods_of(batch)
    assert got.shape == (2, 4)
    np.testing.assert_array_equal(got, [[1, 2, 5, 0], [0, 5, 2, 1]])
    for i in range(4):
        expect = detect_period(seqs[i])
        assert got[0, i] == (0 if expect is None else expect)


def test_periods_of_takes_one_absolute_tolerance_per_sequence() -> None:
    # noise of 0.01 hides a 2-cycle at atol 0 and shows it at atol 0.05: one call with both
    # tolerances gives what two calls give
    seqs = np.stack([cycle(2, 200, noise=0.01), cycle(2, 200, noise=0.01)])
    got = periods_of(seqs, rtol=1e-6, atol=np.array([0.0, 0.05]))
    assert (
        got.tolist()
        == [
            int(periods_of(seqs[0], rtol=1e-6, atol=0.0)),
            int(periods_of(seqs[1], rtol=1e-6, atol=0.05)),
        ]
        == [0, 2]
    )
    with pytest.raises(ParameterError, match="atol"):
        periods_of(seqs, atol=np.array([0.0, -1.0]))
    with pytest.raises(ParameterError, match="one per sequence"):
        periods_of(seqs, atol=np.zeros(3))


def test_period_label() -> None:
    assert period_label(1) == "1T"
    assert period_label(np.int64(12)) == "12T"  # type: ignore[arg-type]
    for bad in (0, -2, 1.0, True):
        with pytest.raises(ParameterError, match="n"):
            period_label(bad)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"max_period": 0}, "max_period"),
        ({"rtol": -1e-3}, "rtol"),
        ({"atol": math.nan}, "atol"),
        ({"rtol": 0.0, "atol": 0.0}, "both"),
    ],
)
def test_invalid_arguments(kw: dict[str, float], match: str) -> None:
    with pytest.raises(ParameterError, match=match):
        detect_period(cycle(2, 20), **kw)  # type: ignore[arg-type]


def test_invalid_shape() -> None:
    with pytest.raises(ParameterError, match="shape"):
        detect_period(np.zeros((4, 5, 2)))
