"""Many periodic orbits at once: :func:`periodic_orbits`, one compiled call per Newton iteration.

For K parameter points (e.g. the points of a sweep labelled nT, with the sweep's final states
as guesses) Newton's method on Pⁿ(y) − y = 0 runs for all points together: every iteration
evaluates the map of every unconverged point with tangents (for M) and without (for G, the map
simulations and sweeps integrate) in two :func:`~gearchaos.analysis.shooting.shoot` calls of
K chains each, which run in parallel over the cores. A point whose ‖G‖ does not fall takes
half its previous step instead; a point converges when the residual and the Newton
correction are below ``tol`` (or the correction no longer lowers ‖G‖ below the tolerance: the
noise floor of the map).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .._checks import check_int, check_real
from ..errors import ParameterError
from ..integrate._chains import ChainRun, run_chains
from ..integrate.settings import SolverSettings
from ..model.target import resolve
from .orbits import ORBIT_SETTINGS, PeriodicOrbit, default_tol, orbit_from
from .shooting import (
    TRUST_RADIUS,
    Shot,
    Solution,
    multipliers_of,
    newton_step,
    residual_of,
    shoot,
)

__all__ = ["periodic_orbits"]


def _guesses(systems: list[Any], n: int, cfg: SolverSettings) -> np.ndarray:
    """Section points that best repeat after n periods, from simulations from rest (one
    compiled call, ``transient_periods`` then 2n periods)."""
    run = ChainRun.from_systems([[s] for s in systems], cfg.replace(periods=2 * n))
    out = run_chains(run)
    m = systems[0].n_state
    secs = out.states[:, 0, :, :m]
    guesses = np.empty((len(systems), m))
    for c in range(len(systems)):
        gaps = [np.max(np.abs(secs[c, j + n] - secs[c, j])) for j in range(n)]
        guesses[c] = secs[c, int(np.argmin(gaps)) + n]
    return guesses


def periodic_orbits(
    target: Any,
    points: Sequence[Mapping[str, Any]],
    *,
    period: int = 1,
    guesses: Any = None,
    settings: SolverSettings | None = None,
    tol: float | None = None,
    max_iterations: int = 12,
    tangent_tol: float = 1.0,
) -> list[PeriodicOrbit]:
    """Period-n orbits of ``target`` at many parameter points, by a batched Newton iteration.

    Parameters
    ----------
    target
        A :class:`~gearchaos.gearset.GearSet` or a :class:`~gearchaos.model.System`.
    points
        Parameter values by name for each orbit, e.g. ``[{"omega": w} for w in omegas]``
        (one model kind and number of planets for all).
    period
        n, in forcing periods.
    guesses
        (K, n_state) Newton starts (a sweep's ``final_state`` at the same section: the same
        ``transient_periods`` fraction and ``section_phase``), or None: simulations from rest
        of ``transient_periods`` (default 50) as :func:`~gearchaos.analysis.orbits.periodic_orbit`.
    settings
        Solver settings (tolerances, section phase, guess transient).
    tol
        Residual and correction tolerance (default rtol/10, at least 1e-12).
    max_iterations
        Newton iterations (each one evaluation with and one without tangents per point).
    tangent_tol
        Factor on the error tolerances of the monodromy's columns (1: the state's). The
        residual comes from the map without tangents, so the orbit is as accurate either way;
        the multipliers move by roughly f·rtol or less (the motion verdict uses 1000: it
        compares max |μ| with 1 − 10⁻⁴).

    Returns
    -------
    list of PeriodicOrbit
        One per point, in order; never raises when Newton fails (check ``converged``).
    """
    n = check_int("period", period, lo=1, hi=10_000)
    cfg = settings or ORBIT_SETTINGS
    if not isinstance(cfg, SolverSettings):
        raise ParameterError(f"settings must be a SolverSettings: got {type(cfg).__name__}")
    eps = default_tol(cfg) if tol is None else check_real("tol", tol, lo=0.0, lo_open=True)
    iters = check_int("max_iterations", max_iterations, lo=1)
    values = [dict(p) for p in points]
    if not values:
        return []
    systems = [resolve(target, v) for v in values]
    K, m = len(systems), systems[0].n_state
    if guesses is None:
        y = _guesses(systems, n, cfg)
    else:
        y = np.array(guesses, dtype=np.float64)
        if y.shape != (K, m) or not np.all(np.isfinite(y)):
            raise ParameterError(
                f"guesses must be {K} × {m} finite numbers (one state per point): "
                f"got shape {y.shape}"
            )
    best_y = y.copy()
    best_a = np.full(K, np.inf)
    best_r = np.full(K, np.inf)
    best: list[tuple[Shot, np.ndarray] | None] = [None] * K  # map and monodromy at best_y
    last_step = np.zeros((K, m))
    done = np.zeros(K, dtype=bool)
    evals = np.zeros(K, dtype=int)
    messages = [f"no convergence in {iters} iterations"] * K
    for _ in range(iters):
        active = np.flatnonzero(~done)
        if active.size == 0:
            break
        subs = [systems[k] for k in active]
        plain = shoot(subs, y[active], n, cfg, tangents=False)
        tang = shoot(subs, y[active], n, cfg, tangents=True, tangent_tol=tangent_tol)
        assert tang.monodromy is not None
        for i, k in enumerate(active.tolist()):
            evals[k] += 2
            if not (plain.ok(i) and tang.ok(i)):
                done[k] = True
                messages[k] = "integration failed"
                continue
            g = plain.end[i] - y[k]
            a = float(np.max(np.abs(g)))
            if a >= best_a[k]:
                if best_r[k] <= eps:  # the noise floor: keep the best state
                    done[k] = True
                    continue
                last_step[k] *= 0.5  # no decrease: half the previous step from the best
                y[k] = best_y[k] + last_step[k]
                continue
            r = residual_of(g, y[k])
            best_y[k], best_a[k], best_r[k] = y[k], a, r
            best[k] = (plain.chain(i), tang.monodromy[i])
            d = newton_step(tang.monodromy[i] - np.eye(m), -g)
            scale = max(1.0, float(np.max(np.abs(y[k]))))
            if r <= eps and float(np.max(np.abs(d))) <= eps * scale:
                done[k] = True
                continue
            reach = float(np.max(np.abs(d)))
            if reach > TRUST_RADIUS * scale:
                d *= TRUST_RADIUS * scale / reach
            last_step[k] = d
            y[k] = y[k] + d
    out = []
    for k in range(K):
        ok = best_r[k] <= eps and best[k] is not None
        kept = best[k]
        if kept is None:  # no successful evaluation: report the start
            t = shoot([systems[k]], y[k][None], n, cfg, tangents=True, tangent_tol=tangent_tol)
            assert t.monodromy is not None
            kept = (t, t.monodromy[0])
        chain, mono = kept
        shot = dataclasses.replace(chain, monodromy=mono[None])
        state = best_y[k] if best[k] is not None else y[k]
        sol = Solution(
            state.copy(),
            0.0,
            shot,
            np.zeros(m),
            float(best_r[k]),
            int(evals[k]),
            0,
            multipliers_of(mono),
        )
        out.append(
            orbit_from(
                systems[k],
                sol,
                converged=ok,
                message="converged" if ok else messages[k],
                period=n,
                settings=cfg,
                tol=eps,
                values=values[k],
            )
        )
    return out
