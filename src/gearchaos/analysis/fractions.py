"""Confidence intervals of a fraction estimated from counts: :func:`wilson_interval`.

A basin fraction is estimated by the share k/n of n independent uniform random starts that
end on an attractor. Its Wilson score interval (Wilson 1927; Brown, Cai & DasGupta 2001,
*Statistical Science* 16:101) at confidence 1 − α, with z the 1 − α/2 normal quantile and
p̂ = k/n,

    centre = (p̂ + z²/(2n)) / (1 + z²/n),
    half   = z √(p̂(1 − p̂)/n + z²/(4n²)) / (1 + z²/n),

covers the true fraction with close to the nominal probability even for small n and for
fractions near 0 or 1, where the textbook p̂ ± z√(p̂(1−p̂)/n) collapses to a point (k = 0 or
k = n gives the width 0). For k = n the interval is [n/(n + z²), 1].
"""

from __future__ import annotations

from statistics import NormalDist
from typing import Any

import numpy as np

from .._checks import check_real
from ..errors import ParameterError

__all__ = ["wilson_interval"]


def wilson_interval(k: Any, n: Any, confidence: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
    """The Wilson score interval (low, high) of the fraction k/n (arrays broadcast; n = 0
    gives NaN)."""
    conf = check_real("confidence", confidence, lo=0.0, hi=1.0, lo_open=True, hi_open=True)
    k = np.asarray(k, dtype=np.float64)
    n = np.asarray(n, dtype=np.float64)
    if np.any(k < 0) or np.any(k > n):
        raise ParameterError("counts k must satisfy 0 <= k <= n")
    z = NormalDist().inv_cdf(0.5 + 0.5 * conf)
    with np.errstate(invalid="ignore", divide="ignore"):
        p = k / n
        den = 1.0 + z * z / n
        centre = (p + z * z / (2.0 * n)) / den
        half = z * np.sqrt(p * (1.0 - p) / n + z * z / (4.0 * n * n)) / den
        low = np.clip(centre - half, 0.0, 1.0)
        high = np.clip(centre + half, 0.0, 1.0)
    low = np.where(k == 0, 0.0, low)
    high = np.where(k == n, 1.0, high)
    bad = n <= 0
    return np.where(bad, np.nan, low), np.where(bad, np.nan, high)
