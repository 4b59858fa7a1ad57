"""Poincaré sections: the section points of a result and how many distinct points they hold.

The seed samples the response once per mesh period, at τ_k = 2πk/Ω (MODEL.md §8), and names the
motion by the number of distinct section points: n distinct points mean an nT-periodic orbit,
many points a quasi-periodic or chaotic one. :func:`count_distinct` counts them with a tolerance
relative to the size of the attractor; :func:`section_points` returns the (X̄_sp1, X̄'_sp1) pairs
the seed plots.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import ParameterError

__all__ = ["count_distinct", "section_points", "section_variables"]


def count_distinct(
    points: Any,
    *,
    tol: float = 1e-3,
    max_count: int = 64,
    scale: float | None = None,
) -> int:
    """Number of distinct points in a sequence of Poincaré section points.

    Parameters
    ----------
    points
        Section points, shape (m,) or (m, d) (e.g. columns X̄_sp1 and X̄'_sp1). Rows holding a
        NaN are ignored (an integration that stopped early leaves NaN samples).
    tol
        Relative clustering tolerance. Two points belong to the same cluster when their
        Euclidean distance is at most ``tol × size``, where ``size`` is the attractor size:
        the largest range (max − min) over the d coordinates of the points. With the default
        1e-3 a period-n orbit is resolved when its n points are more than 0.1 % of the
        attractor size apart, and integration noise or a slowly decaying transient below
        that level does not split a point.
    max_count
        Counting stops beyond this many clusters; the function then returns ``max_count + 1``,
        meaning "many" (quasi-periodic or chaotic motion, or a transient that has not died out).
    scale
        Override of ``size`` (same units as the points), e.g. the extent of the whole orbit.

    Returns
    -------
    int
        The number of clusters: 0 when there is no finite point, 1 when the points coincide
        (see below), ``max_count + 1`` for "many".

    Notes
    -----
    When ``scale`` is not given, the points are taken as one point when ``size`` is at most
    ``tol`` times the largest magnitude of any coordinate (``size ≤ tol · max|x|``): all points
    then agree to the relative precision ``tol`` and the range carries no structure (a 1T
    orbit whose transient still drifts by 10⁻⁴ would otherwise split into many clusters).

    Clustering is greedy in sequence order: each point joins the first cluster whose first
    point lies within ``tol × size``, otherwise it opens a new cluster. For the well separated
    points of a periodic orbit this is exact; for a continuum (a torus or a strange attractor)
    the count grows until it passes ``max_count``.
    """
    if not (math.isfinite(tol) and tol > 0):
        raise ParameterError(f"tol must be a finite number > 0: got {tol!r}")
    if not (isinstance(max_count, int | np.integer) and max_count >= 1):
        raise ParameterError(f"max_count must be an integer >= 1: got {max_count!r}")
    p = np.asarray(points, dtype=np.float64)
    if p.ndim == 1:
        p = p[:, None]
    elif p.ndim != 2:
        raise ParameterError(f"points must have shape (m,) or (m, d): got shape {p.shape}")
    p = p[np.all(np.isfinite(p), axis=1)]
    if p.shape[0] == 0:
        return 0
    size = float(np.max(np.ptp(p, axis=0)))
    if scale is None:
        if size <= tol * float(np.max(np.abs(p))):
            return 1
    else:
        if not (math.isfinite(scale) and scale >= 0):
            raise ParameterError(f"scale must be a finite number >= 0: got {scale!r}")
        size = float(scale)
    if size == 0.0:
        return 1
    radius2 = (tol * size) ** 2
    centres = np.empty((max_count + 1, p.shape[1]))
    n = 0
    for row in p:
        if n and np.min(np.sum((centres[:n] - row) ** 2, axis=1)) <= radius2:
            continue
        if n == max_count:
            return max_count + 1
        centres[n] = row
        n += 1
    return n


def section_variables(result: Any, var: str | None = None, planet: int = 1) -> tuple[str, str]:
    """Names of a variable and of its τ-derivative in ``result`` (state or observable names).

    ``var`` names a state or observable that has a ``<var>_dot`` partner, or a per-member
    group (the planetary model's ``delta_sp``, ``delta_rp``, ``p``: ``planet`` selects the
    member); the default is the model's :attr:`~gearchaos.model.System.default_observables`
    (the seed's ``delta_sp`` for the planetary model), else the first state (``x`` of the
    backlash oscillator).
    """
    system = result.system
    names = tuple(system.state_names) + tuple(system.obs_names)
    if var is None:  # the model's default pair (planetary: X̄_sp of ``planet``)
        if system.group_size and not 1 <= planet <= system.group_size:
            raise ParameterError(
                f"planet must be an integer in 1..{system.group_size}: got {planet!r}"
            )
        return system.section_pair(planet)
    var = system.member(var, planet) or var
    if var not in names:
        raise ParameterError(
            f"var must name a variable of {system.name} ({', '.join(names)}): got {var!r}"
        )
    if var.startswith("delta_") and "_dot" not in var:
        head, _, i = var.rpartition("_")
        dot = f"{head}_dot_{i}"
    else:
        dot = f"{var}_dot"
    if dot not in names:
        raise ParameterError(
            f"var {var!r} has no derivative {dot!r} among the variables of {system.name}"
        )
    return var, dot


def section_points(
    result: Any, planet: int = 1, var: str | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Poincaré section points (x, x') of a result, one pair per recorded period.

    For the planetary model the default is the seed's (X̄_sp1, X̄'_sp1) — the sun–planet mesh
    deflection δ_sp/b_c of ``planet`` and its derivative d/dτ — at τ_k = (2πk + φ)/Ω. For other
    systems the default is the first state and its derivative (see :func:`section_variables`).
    """
    name, dot = section_variables(result, var, planet)
    return np.asarray(result.section(name)), np.asarray(result.section(dot))
