"""Periodic orbits behind the labels of a sweep (``orbits=True``, ``--orbits``).

A sweep point that the section sequence labels nT (n ≤ :data:`MAX_ORBIT_PERIOD`) is confirmed
by shooting: Newton on Pⁿ(y) − y = 0 (:func:`gearchaos.dynamics.periodic_orbits`, all the
task's points of one period together) from the point's final state, which lies on the sweep's
section. Per point the store then holds

* ``orbit_residual`` — ‖Pⁿ(y*) − y*‖_∞ / max(1, ‖y*‖_∞) of the orbit found (NaN where none was
  sought or the integration failed);
* ``orbit_max_multiplier`` — max |μ| of its Floquet multipliers (NaN likewise);
* ``orbit_period`` — the n that was shot (0: none);
* ``orbit_status`` — why, as a flag (:data:`ORBIT_STATUS`): ``confirmed`` (converged, minimal
  period n, every |μ| < 1, as an attractor found by simulation must be), ``unstable``
  (converged but max |μ| ≥ 1), ``shorter_period`` (converged to an orbit of minimal period
  d < n: the label overstates the period), ``not_converged``, ``failed`` (the map could not be
  integrated), ``not_periodic`` (the label is QP, chaos, unresolved or failed: nothing to shoot)
  and ``period_too_long`` (n > :data:`MAX_ORBIT_PERIOD`).

The label is the one :func:`~gearchaos.sweep.classify.classify_store` writes (the same
function, inputs and default tolerances, evaluated on the task's points), and the variables are
written with the task's other variables, so an interrupted sweep resumes with them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..errors import Status
from ..integrate.settings import SolverSettings
from ..model.target import Target
from .classify import label_periods
from .variables import ORBIT_STATUS, ORBIT_VARIABLES

__all__ = ["MAX_ORBIT_PERIOD", "ORBIT_STATUS", "ORBIT_VARIABLES", "orbit_checks"]

#: The longest period confirmed by shooting.
MAX_ORBIT_PERIOD = 8


def empty(shape: tuple[int, ...]) -> dict[str, np.ndarray]:
    """Arrays of the orbit variables for ``shape`` points, at their fill values."""
    return {
        nm: np.full(shape, fill, dtype=dtype) for nm, (_, dtype, fill) in ORBIT_VARIABLES.items()
    }


def orbit_checks(
    target: Target,
    points: Sequence[Mapping[str, Any]],
    periods: Sequence[int] | np.ndarray,
    final_states: np.ndarray,
    settings: SolverSettings,
    *,
    max_period: int = MAX_ORBIT_PERIOD,
) -> dict[str, np.ndarray]:
    """Confirm the period labels of K points by shooting from their final states.

    Parameters
    ----------
    target
        The sweep's gear set or system.
    points
        Parameter values by dotted name of each point.
    periods
        The label's period n of each point (0: not periodic — QP, chaos, failed …).
    final_states
        (K, n_state) states at the sweep's section (the end of the recorded window).
    settings
        The sweep's solver settings: their section (``transient_periods`` fraction and
        ``section_phase``) is the one the final states lie on, their tolerances are used.
    max_period
        Longest period shot.

    Returns
    -------
    dict of numpy.ndarray
        ``orbit_residual``, ``orbit_max_multiplier``, ``orbit_period``, ``orbit_status`` (K,).
    """
    from ..dynamics.orbits.batch import periodic_orbits

    K = len(points)
    out = empty((K,))
    per = np.asarray(periods, dtype=int).reshape(K)
    y = np.asarray(final_states, dtype=float).reshape(K, -1)
    out["orbit_status"][:] = ORBIT_STATUS["not_periodic"]
    out["orbit_status"][per > max_period] = ORBIT_STATUS["period_too_long"]
    for n in sorted({int(p) for p in per if 1 <= p <= max_period}):
        idx = np.flatnonzero(per == n)
        good = [int(k) for k in idx if np.all(np.isfinite(y[k]))]
        for k in sorted(set(idx.tolist()) - set(good)):
            out["orbit_status"][k] = ORBIT_STATUS["failed"]
        if not good:
            continue
        orbits = periodic_orbits(
            target, [points[k] for k in good], period=n, guesses=y[good], settings=settings
        )
        for k, orb in zip(good, orbits, strict=True):
            out["orbit_period"][k] = n
            if orb.status != Status.OK or not np.isfinite(orb.residual):
                out["orbit_status"][k] = ORBIT_STATUS["failed"]
                continue
            out["orbit_residual"][k] = orb.residual
            out["orbit_max_multiplier"][k] = orb.max_multiplier
            if not orb.converged:
                flag = "not_converged"
            elif orb.minimal_period < n:
                flag = "shorter_period"
            elif not orb.max_multiplier < 1.0:
                flag = "unstable"
            else:
                flag = "confirmed"
            out["orbit_status"][k] = ORBIT_STATUS[flag]
    return out


def task_orbits(
    grid: Any, observed: Sequence[Any], task: Any, run: Any, data: dict[str, np.ndarray]
) -> dict[str, np.ndarray]:
    """The orbit variables of a sweep task's points, from the task's block arrays ``data``
    (written with them). ``observed`` are the sweep's observables (the first two give the
    section pairs of the label, first observed planet, as :func:`classify_store` reads them)."""
    spec = grid.spec
    where = task.points()
    pos = [p for *_, p in where]
    pairs = []
    for ob in observed[:2]:
        v = np.stack([data[ob.name][p] for p in pos])
        pairs.append(v[..., 0] if ob.per_planet else v)
    lle = np.array([data["lle"][p] for p in pos]) if spec.lyapunov else None
    periods = label_periods(
        np.stack(pairs, axis=-1),
        np.array([data["status"][p] for p in pos]),
        lle=lle,
        run_periods=int(spec.solver.periods),
        forcing_period=np.array([run.dt[c, j] for c, j, *_ in where]),
    )
    found = orbit_checks(
        grid.target,
        [grid.values_at(idx) for _, _, idx, _ in where],
        periods,
        np.stack([data["final_state"][p] for p in pos]),
        spec.solver,
    )
    out = empty(task.shape)
    for k, p in enumerate(pos):
        for nm in out:
            out[nm][p] = found[nm][k]
    return out
