"""Period of a Poincaré section sequence: the smallest n with x_{k+n} = x_k within a tolerance.

An nT-periodic orbit of a system forced with period T returns to the same section point after
n forcing periods, so its section sequence x_0, x_1, … (one point per period, MODEL.md §8)
repeats with period n. :func:`detect_period` finds the smallest such n ≤ ``max_period`` by
checking the recurrence over the whole recorded sequence, with a tolerance relative to the
size of the attractor (the same scale convention as
:func:`~gearchaos.analysis.poincare.count_distinct`). :func:`period_label` names the result
(``1T``, ``2T``, …) as the seed does.

Unlike counting distinct points, the recurrence test uses the order of the points: a
quasi-periodic or chaotic sequence that happens to visit only a few clusters is not periodic,
and an n-periodic orbit two of whose points nearly coincide is still reported as nT.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import ParameterError
from .motion import Motion

__all__ = ["detect_period", "period_label", "periods_of"]


def _check_tolerances(max_period: Any, rtol: Any, atol: Any) -> None:
    if not (
        isinstance(max_period, int | np.integer)
        and not isinstance(max_period, bool)
        and max_period >= 1
    ):
        raise ParameterError(f"max_period must be an integer >= 1: got {max_period!r}")
    if not (isinstance(rtol, int | float | np.floating) and math.isfinite(rtol) and rtol >= 0):
        raise ParameterError(f"rtol must be a finite number >= 0: got {rtol!r}")
    if not (isinstance(atol, int | float | np.floating) and math.isfinite(atol) and atol >= 0):
        raise ParameterError(f"atol must be a finite number >= 0: got {atol!r}")
    if rtol == 0 and atol == 0:
        raise ParameterError("rtol and atol must not both be 0: got rtol=0, atol=0")


def periods_of(
    points: Any,
    *,
    max_period: int = 64,
    rtol: float = 1e-3,
    atol: Any = 0.0,
    floor: Any = None,
) -> np.ndarray:
    """Vectorised :func:`detect_period` over the leading axes of a batch of section sequences.

    Parameters
    ----------
    points
        Array of shape (..., m, d): one sequence of m section points in d coordinates per
        leading index (e.g. a sweep's (Ω, section, 2) array of (X̄_sp1, X̄'_sp1)).
    max_period, rtol, atol
        As in :func:`detect_period`; ``atol`` may also be one value per sequence.
    floor
        The noise floor ε of the section points (a scalar, or one per sequence), in their
        units: a sequence whose spread S is at most ε is one point (period 1), whatever its
        magnitude. The motion verdict passes ε = 10³ (atol + rtol·max|x|) of the integration
        (:mod:`gearchaos.dynamics.verdict.decide`). None keeps :func:`detect_period`'s rule
        S ≤ rtol·max|x|.

    Returns
    -------
    numpy.ndarray
        Integer array of the leading shape: the period n, or 0 where no period
        n ≤ ``max_period`` is found (or the sequence holds a non-finite value).
    """
    p = np.asarray(points, dtype=np.float64)
    if p.ndim < 2:
        raise ParameterError(f"points must have shape (..., m, d): got shape {p.shape}")
    lead = p.shape[:-2]
    if np.ndim(atol) > 0:  # one absolute tolerance per sequence
        try:
            atols = np.broadcast_to(np.asarray(atol, dtype=np.float64), lead).reshape(-1)
        except (TypeError, ValueError):
            raise ParameterError(
                f"atol must be a number or one per sequence ({lead}): got shape {np.shape(atol)}"
            ) from None
        if not np.all(np.isfinite(atols) & (atols >= 0)):
            raise ParameterError("atol must be finite numbers >= 0: got a negative or NaN value")
        _check_tolerances(max_period, rtol, float(np.max(atols)) if atols.size else 1.0)
    else:
        _check_tolerances(max_period, rtol, atol)
        atols = np.full(math.prod(lead), float(atol))
    m, d = p.shape[-2:]
    out = np.zeros(math.prod(lead), dtype=np.int64)
    if m == 0 or d == 0:
        return out.reshape(lead)
    p = p.reshape(-1, m, d)
    finite = np.all(np.isfinite(p), axis=(1, 2))
    idx = np.flatnonzero(finite)
    q = p[idx]
    size = np.max(np.ptp(q, axis=1), axis=1)  # attractor size: largest coordinate range
    if floor is None:
        # points that agree to the relative precision rtol are one point (count_distinct's)
        mag = np.max(np.abs(q), axis=(1, 2))
        single = size <= rtol * mag
    else:
        eps = np.broadcast_to(np.asarray(floor, dtype=np.float64), lead).reshape(-1)[idx]
        single = size <= eps
    out[idx[single]] = 1
    keep = ~single
    idx, q, size = idx[keep], q[keep], size[keep]
    tol2 = (rtol * size + atols[idx]) ** 2
    for n in range(1, max_period + 1):
        if idx.size == 0 or m < 2 * n + 1:
            break
        diff = q[:, n:, :] - q[:, :-n, :]
        err2 = np.max(np.sum(diff * diff, axis=2), axis=1)
        hit = err2 <= tol2
        if np.any(hit):
            out[idx[hit]] = n
            idx, q, tol2 = idx[~hit], q[~hit], tol2[~hit]
    return out.reshape(lead)


def detect_period(
    points: Any, *, max_period: int = 64, rtol: float = 1e-3, atol: float = 0.0
) -> int | None:
    """Smallest period n ≤ ``max_period`` of a Poincaré section sequence, or None.

    Parameters
    ----------
    points
        Section points in recording order, shape (m,) or (m, d) — e.g. columns X̄_sp1 and
        X̄'_sp1 at τ_k = 2πk/Ω, k = 0 … m−1.
    max_period
        Largest period tried (the issue's 64).
    rtol
        Tolerance relative to the attractor's size S, the largest range (max − min) over the d
        coordinates of the points. Being relative, the test is scale-free: it gives the same
        answer for X̄_sp1 in units of b_c or for δ_sp in metres. The default 1e-3 (0.1 % of
        the attractor) lies well above the section error of an integration at rtol ≤ 1e-6
        after 100+ transient periods (a decayed transient and the integration error leave
        ≲ 1e-5 S) and well below the spacing of the points of any resolved periodic orbit.
        Raise it for loose integrations or short transients, lower it to separate nearly
        coincident points.
    atol
        Absolute tolerance added to ``rtol × S`` (same units as the points).

    Returns
    -------
    int or None
        The smallest n such that ‖x_{k+n} − x_k‖ ≤ rtol·S + atol for every k = 0 … m−1−n
        (Euclidean norm over the d coordinates); None when no n ≤ ``max_period`` qualifies,
        or when any point is NaN/inf (an integration that stopped early).

    Notes
    -----
    The recurrence is checked over the whole recorded sequence, so a transient that has not
    died out (to within the tolerance) prevents a period from being found. A period n is
    only decidable with m ≥ 2n + 1 points — every one of the n phases is then compared at
    least once and one of them twice; periods beyond (m − 1)/2 are not tried, so a short
    record returns None rather than guess.

    As in :func:`~gearchaos.analysis.poincare.count_distinct`, points whose spread is at most
    ``rtol`` times their largest magnitude (S ≤ rtol·max|x|) are one point: period 1. Without
    this rule a 1T orbit whose section point still drifts by 10⁻⁹ of its value would be
    measured against its own drift.

    An n-periodic sequence is also kn-periodic; the smallest n is returned, so a
    period-doubled orbit whose two branches are closer than the tolerance reads as 1T.
    """
    p = np.asarray(points, dtype=np.float64)
    if p.ndim == 1:
        p = p[:, None]
    elif p.ndim != 2:
        raise ParameterError(f"points must have shape (m,) or (m, d): got shape {p.shape}")
    n = int(periods_of(p, max_period=max_period, rtol=rtol, atol=atol))
    return n if n > 0 else None


def period_label(n: int) -> str:
    """Seed's name of an n-periodic motion: ``1T``, ``2T``, …, ``nT`` (n ≥ 1)."""
    if not (isinstance(n, int | np.integer) and not isinstance(n, bool) and n >= 1):
        raise ParameterError(f"n (period) must be an integer >= 1: got {n!r}")
    return Motion.periodic(int(n)).format()
