"""Recurrence of a recorded section sequence: its noise floor, whether it converges onto a
periodic orbit or lingers near one, and its distance from an orbit's section points.

Pure functions of recorded arrays, used by the motion verdict
(:mod:`gearchaos.dynamics.verdict.decide`) to pick the period to shoot.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["approaches", "converging_period", "distance_to_orbit", "near_period", "noise_floor"]


def noise_floor(sections: np.ndarray, settings: Any, factor: float) -> np.ndarray:
    """ε per point: factor · (atol + rtol · max|x|) of its section sequence."""
    with np.errstate(invalid="ignore"):
        mag = np.nanmax(np.abs(sections), axis=(1, 2))
    mag = np.where(np.isfinite(mag), mag, 0.0)
    return factor * (float(settings.atol) + float(settings.rtol) * mag)


def converging_period(x: np.ndarray, max_n: int) -> int:
    """The n ≤ max_n whose recurrence gaps g_k = ‖x_{k+n} − x_k‖ decay geometrically over
    the second half of the record (a least-squares line through ln g_k falling by more than
    four times its residual scatter and by at least 20 % overall), fastest first; 0: none."""
    m = x.shape[0]
    best, best_slope = 0, 0.0
    for n in range(1, max_n + 1):
        if m - n < 16:
            break
        g = np.sqrt(np.sum((x[n:] - x[:-n]) ** 2, axis=1))
        h = g[(m - n) // 2 :]
        if h.size < 8 or not np.all(h > 0) or not np.all(np.isfinite(h)):
            continue
        # the least-squares line y ≈ slope·k + icpt, in closed form
        k = np.arange(h.size, dtype=float) - 0.5 * (h.size - 1)
        y = np.log(h)
        slope = float(k @ (y - y.mean()) / (k @ k))
        scatter = float(np.std(y - y.mean() - slope * k))
        drop = -slope * (h.size - 1)
        if slope < 0 and drop > max(4.0 * scatter, math.log(1.25)) and slope < best_slope:
            best, best_slope = n, slope
    return best


def near_period(x: np.ndarray, max_n: int, reach: float) -> int:
    """The n ≤ max_n with the smallest median recurrence gap over the last quarter of the
    record, when that gap is at most ``reach`` · max(1, max|x|) (the record lingers near a
    period-n orbit, as a slowly spiralling transient does); 0: none."""
    m = x.shape[0]
    scale = max(1.0, float(np.max(np.abs(x))))
    gaps = []
    for n in range(1, max_n + 1):
        if m - n < 8:
            break
        g = np.max(np.abs(x[n:] - x[:-n]), axis=1)
        gaps.append(float(np.median(g[3 * (m - n) // 4 :])))
    if not gaps or min(gaps) > reach * scale:
        return 0
    # the shortest period within twice the best gap (a multiple of the period repeats too)
    return next(n for n, g in enumerate(gaps, start=1) if g <= 2.0 * min(gaps))


def distance_to_orbit(y: np.ndarray, sections: np.ndarray) -> np.ndarray:
    """∞-norm distance of the state(s) y (…, n) from the nearest section point of an orbit."""
    y = np.asarray(y)
    d = np.max(np.abs(y[..., None, :] - sections), axis=-1)
    return np.min(d, axis=-1)


def approaches(record: np.ndarray, sections: np.ndarray) -> bool:
    """Whether a full-state record comes closer to an orbit: the median distance over its
    second half is below that over its first half."""
    d = distance_to_orbit(record, sections)
    h = d.size // 2
    return bool(h >= 4 and np.median(d[h:]) < np.median(d[:h]))
