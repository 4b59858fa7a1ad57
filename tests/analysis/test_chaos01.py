"""The 0–1 test for chaos: K ≈ 1 for chaotic maps, K ≈ 0 for periodic and quasi-periodic ones.

The expected limits are the theorems of Gottwald & Melbourne (2004, 2009): the translation
variables of a regular sequence stay bounded (K → 0), those of a chaotic one diffuse (K → 1).
The FFT evaluation of the mean-square displacement is checked against its definition.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from reference_maps import henon, logistic, rotation

from gearchaos.analysis.chaos01 import chaos01, chaos01_components
from gearchaos.errors import ParameterError


def test_logistic_map_is_chaotic() -> None:
    assert chaos01(logistic(1000)) > 0.9


def test_henon_map_as_a_2d_section_is_chaotic() -> None:
    assert chaos01(henon(1000)) > 0.8


@pytest.mark.parametrize("n", [1, 2, 3, 5])
def test_periodic_sequence_is_regular(n: int) -> None:
    # a mean of 0.5 exercises the V_osc correction; n = 1 is a constant (a fixed point)
    k = np.arange(1000)
    x = 0.5 + np.cos(2 * math.pi * k / n + 0.3) if n > 1 else np.full(1000, 0.7)
    assert abs(chaos01(x)) < 0.1


def test_periodic_2d_section_with_small_noise_is_regular() -> None:
    rng = np.random.default_rng(1)
    k = np.arange(1000)
    pts = np.column_stack([np.cos(2 * math.pi * k / 3), np.sin(2 * math.pi * k / 3)])
    pts += 1e-6 * rng.uniform(-1.0, 1.0, pts.shape)
    assert abs(chaos01(pts)) < 0.1


def test_irrational_rotation_is_regular() -> None:
    assert abs(chaos01(rotation(1000))) < 0.2


def test_deterministic_for_a_seed_and_scale_invariant() -> None:
    x = logistic(300)
    assert chaos01(x, seed=3) == chaos01(x, seed=3)
    # p_c, q_c scale with φ, M_c and V_osc with φ², and the correlation is scale-free
    assert chaos01(1e3 * x, seed=3) == pytest.approx(chaos01(x, seed=3), rel=1e-9)


def direct_k(phi: np.ndarray, c: float, ncut: int) -> float:
    """K_c straight from the definitions (Gottwald & Melbourne 2009, eqs. 2.1–2.5)."""
    N = phi.size
    j = np.arange(1, N + 1)
    p = np.cumsum(phi * np.cos(j * c))
    q = np.cumsum(phi * np.sin(j * c))
    n = np.arange(1, ncut + 1)
    M = np.array([np.mean((p[m:] - p[:-m]) ** 2 + (q[m:] - q[:-m]) ** 2) for m in n])
    V = phi.mean() ** 2 * (1.0 - np.cos(n * c)) / (1.0 - math.cos(c))
    return float(np.corrcoef(n, M - V)[0, 1])


def test_components_match_the_definition() -> None:
    rng = np.random.default_rng(7)
    # a regular signal plus a random walk increment, with a mean: D_c is neither trivial nor linear
    k = np.arange(400)
    phi = 0.8 + np.cos(0.9 * k) + 0.3 * rng.normal(size=400)
    c, K = chaos01_components(phi, n_c=5, seed=11, ncut=40)
    assert K.shape == (5, 1)
    for ci, ki in zip(c, K[:, 0], strict=True):
        assert math.pi / 5 < ci < 4 * math.pi / 5
        assert ki == pytest.approx(direct_k(phi, ci, 40), abs=1e-10)


def test_validation() -> None:
    with pytest.raises(ParameterError, match="at least 100"):
        chaos01(np.arange(99.0))
    x = logistic(200)
    x[5] = np.nan
    with pytest.raises(ParameterError, match="finite"):
        chaos01(x)
    with pytest.raises(ParameterError, match="ncut"):
        chaos01(logistic(200), ncut=1)
    with pytest.raises(ParameterError, match="n_c"):
        chaos01(logistic(200), n_c=0)
    with pytest.raises(ParameterError, match="shape"):
        chaos01(np.zeros((100, 2, 2)))


@pytest.mark.parametrize("series", ["logistic", "periodic", "henon"])
def test_direct_sums_and_fft_autocorrelation_agree(series: str) -> None:
    """The two evaluations of M_c (compiled direct sums for short series, FFT autocorrelation
    for long ones) are different algorithms for the same numbers."""
    from gearchaos.analysis.chaos01 import _k_values_direct, _k_values_fft

    k = np.arange(600)
    phi = {
        "logistic": logistic(600)[:, None],
        "periodic": (0.4 + np.cos(2 * math.pi * k / 3))[:, None],
        "henon": henon(600),
    }[series]
    c = np.random.default_rng(2).uniform(math.pi / 5, 4 * math.pi / 5, 30)
    for ncut in (10, 60):
        np.testing.assert_allclose(
            _k_values_direct(phi, c, ncut), _k_values_fft(phi, c, ncut), rtol=0, atol=1e-9
        )
