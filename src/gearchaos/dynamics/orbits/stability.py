"""One stability criterion for periodic orbits, used by :func:`~gearchaos.periodic_orbit`,
``gearchaos orbit`` and the motion verdict alike.

An orbit is *stable* when every Floquet multiplier that is not structural lies inside the
circle |μ| < 1 − ``margin`` (:data:`STABILITY_MARGIN` = 10⁻⁴, stated with every verdict and
orbit summary). A multiplier is *structural* when it equals 1 for a reason of the model, not of
the orbit: a free direction v of the state space along which the vector field does not change,
f(τ, y + εv) = f(τ, y) at every point of the orbit (a sun free inside its bearing clearance and
perpendicular to every line of action, as with two planets at 180°: the orbit shifted along v is
an orbit too, so Pⁿ has the eigenvalue 1 exactly). Such a direction is found from the
multiplier's eigenvector and checked on the orbit itself (:func:`structural_multipliers`):
its component along the velocities must vanish and the right-hand side must not change when
the orbit's samples are shifted along it (relative change ≤ 10⁻⁶ per unit shift, against
|∂f/∂y·v| of order one for any direction the dynamics act on).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = [
    "STABILITY_MARGIN",
    "STRUCTURAL_TOL",
    "stability_of",
    "structural_multipliers",
]

#: Stable means every non-structural |μ| < 1 − STABILITY_MARGIN.
STABILITY_MARGIN = 1e-4
#: Multipliers within this distance of 1 are examined for a structural reason.
STRUCTURAL_TOL = 1e-5
#: Largest change of f per unit shift (relative to max(1, max|f|)) along a free direction.
FREE_TOL = 1e-6
#: Samples per forcing period along the orbit for the free-direction test.
FREE_SAMPLES = 32


def stability_of(
    multipliers: np.ndarray, structural: np.ndarray | None = None, margin: float = STABILITY_MARGIN
) -> tuple[bool, float]:
    """(stable, max |μ| over the non-structural multipliers): stable when that maximum is
    below 1 − ``margin``. NaN multipliers are never stable."""
    mu = np.abs(np.asarray(multipliers))
    if mu.size == 0 or not np.all(np.isfinite(mu)):
        return False, math.nan
    keep = np.ones(mu.size, dtype=bool) if structural is None else ~np.asarray(structural)
    top = float(np.max(mu[keep])) if np.any(keep) else 0.0
    return bool(top < 1.0 - margin), top


def structural_multipliers(
    system: Any,
    state: np.ndarray,
    period: int,
    monodromy: np.ndarray,
    settings: Any,
) -> np.ndarray:
    """(n_state,) mask of the multipliers (in
    :func:`~gearchaos.dynamics.orbits.shooting.multipliers_of`
    order) that equal 1 structurally: within :data:`STRUCTURAL_TOL` of 1, with a real
    eigenvector v that has no velocity component and along which the right-hand side does
    not change at :data:`FREE_SAMPLES` points a period of the orbit from ``state`` (see the
    module docstring). Cheap when no multiplier is near 1 (no integration)."""
    from .shooting import multipliers_of

    M = np.asarray(monodromy, dtype=np.float64)
    mus = multipliers_of(M)
    mask = np.zeros(mus.size, dtype=bool)
    near = np.flatnonzero(np.abs(mus - 1.0) <= STRUCTURAL_TOL)
    if near.size == 0 or not np.all(np.isfinite(M)):
        return mask
    w, vecs = np.linalg.eig(M)
    taus, ys = _orbit_samples(system, state, period, settings)
    _, f0 = system.evaluate(taus, ys)
    fscale = max(1.0, float(np.max(np.abs(f0))))
    yscale = max(1.0, float(np.max(np.abs(ys))))
    for j in np.flatnonzero(np.abs(w - 1.0) <= STRUCTURAL_TOL).tolist():
        v = vecs[:, j]
        if np.max(np.abs(v.imag)) > 1e-8 * np.max(np.abs(v)):
            continue
        v = np.real(v) / float(np.max(np.abs(v)))
        if _free(system, v, taus, ys, f0, fscale, yscale):
            # the same multiplier in the sorted order (the closest one not yet marked)
            gap = np.where(mask, np.inf, np.abs(mus - w[j]))
            mask[int(np.argmin(gap))] = True
    return mask


def _free(
    system: Any,
    v: np.ndarray,
    taus: np.ndarray,
    ys: np.ndarray,
    f0: np.ndarray,
    fscale: float,
    yscale: float,
) -> bool:
    """Whether f does not change along v at the orbit's samples (and v moves no velocity)."""
    eps = 1e-6 * yscale
    _, f1 = system.evaluate(taus, ys + eps * v[None, :])
    change = float(np.max(np.abs(f1 - f0))) / (eps * fscale)
    return change <= FREE_TOL


def _orbit_samples(
    system: Any, state: np.ndarray, period: int, settings: Any
) -> tuple[np.ndarray, np.ndarray]:
    """Times and states at FREE_SAMPLES points a period along the orbit from ``state``."""
    from ...integrate.simulate import run_simulation
    from .shooting import section_fraction

    window = settings.replace(
        transient_periods=0.0,
        periods=int(period),
        samples_per_period=FREE_SAMPLES,
        section_phase=0.0,
        perturbation=0.0,
    )
    tau_s = section_fraction(settings) * system.period
    res = run_simulation(system, window, y0=np.asarray(state), t0=tau_s)
    return np.asarray(res.tau), np.asarray(res.states)
