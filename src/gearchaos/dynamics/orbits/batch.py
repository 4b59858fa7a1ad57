"""Many periodic orbits at once: :func:`periodic_orbits`, one compiled call per Newton iteration.

For K parameter points (e.g. the points of a sweep labelled nT, with the sweep's final states
as guesses) Newton's method on Pⁿ(y) − y = 0 runs for all points together: every iteration
evaluates the map of every unconverged point with tangents (for M) and without (for G, the map
simulations and sweeps integrate) in two :func:`~gearchaos.dynamics.orbits.shooting.shoot` calls of
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

from ..._checks import check_int, check_real
from ...errors import ParameterError
from ...integrate._chains import ChainRun, run_chains
from ...integrate.settings import SolverSettings
from ...model.target import Target, resolve
from .orbit import ORBIT_SETTINGS, PeriodicOrbit, default_tol, orbit_from
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
    target: Target,
    points: Sequence[Mapping[str, Any]],
    *,
    period: int = 1,
    guesses: Any = None,
    settings: SolverSettings | None = None,
    tol: float | None = None,
    max_iterations: int = 12,
    tangent_tol: float = 1.0,
    systems: Sequence[Any] | None = None,
    contraction: float | None = None,
    chord: bool = False,
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
        of ``transient_periods`` (default 50) as
        :func:`~gearchaos.dynamics.orbits.orbit.periodic_orbit`.
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
    contraction
        Give a point up early when three evaluations have not shrunk its best residual
        max|G| by this factor (0.25: a Newton iteration inside its basin of convergence
        shrinks it far faster, one outside it wanders): None runs every point up to
        ``max_iterations``.
    chord
        Reuse a point's monodromy matrix while the iteration contracts fast (each step
        shrinking max|G| tenfold; a chord step is one evaluation without tangents), and compute
        it afresh otherwise, after a step that did not decrease max|G|, and at the converged
        state when that lies farther than ``tol`` from where it was computed — so the
        multipliers returned are those of the orbit's own state, as with plain Newton.
    systems
        The points' resolved :class:`~gearchaos.model.System` objects when the caller already
        has them (``target`` at each of ``points``; saves resolving them again), or None.

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
    if contraction is not None:
        contraction = check_real("contraction", contraction, lo=0.0, hi=1.0, lo_open=True)
    values = [dict(p) for p in points]
    if not values:
        return []
    if systems is None:
        systems = [resolve(target, v) for v in values]
    elif len(systems) != len(values):
        raise ParameterError(
            f"systems must hold one system per point ({len(values)}): got {len(systems)}"
        )
    systems = list(systems)
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
    best: list[Shot | None] = [None] * K  # the map at best_y …
    best_g = np.zeros((K, m))  # … and its G
    mono: list[np.ndarray | None] = [None] * K  # the latest monodromy …
    mono_at = y.copy()  # … and the state it was computed at
    refresh = np.ones(K, dtype=bool)  # compute the monodromy afresh at the next evaluation
    redo = np.zeros(K, dtype=bool)  # a Newton step from best_y with a fresh monodromy only
    exact = np.zeros(K, dtype=bool)  # the last step used the monodromy of its start
    last_step = np.zeros((K, m))
    done = np.zeros(K, dtype=bool)
    evals = np.zeros(K, dtype=int)
    messages = [f"no convergence in {iters} iterations"] * K
    history: list[np.ndarray] = []  # best max|G| of every point after each evaluation

    def monodromies(idx: np.ndarray, states: np.ndarray) -> tuple[Shot, np.ndarray]:
        """The map with tangents of the points ``idx`` at ``states``, and its monodromy
        matrices."""
        shot = shoot(
            [systems[k] for k in idx], states[idx], n, cfg, tangents=True, tangent_tol=tangent_tol
        )
        assert shot.monodromy is not None
        return shot, shot.monodromy

    def step(k: int, g: np.ndarray, r: float) -> None:
        """The Newton (or chord) step from y[k] = best_y[k], or convergence."""
        M = mono[k]
        assert M is not None
        d = newton_step(M - np.eye(m), -g)
        exact[k] = bool(np.array_equal(mono_at[k], y[k]))
        scale = max(1.0, float(np.max(np.abs(y[k]))))
        reach = float(np.max(np.abs(d)))
        if r <= eps and reach <= eps * scale:
            done[k] = True
            return
        if reach > TRUST_RADIUS * scale:
            d *= TRUST_RADIUS * scale / reach
        last_step[k] = d
        y[k] = y[k] + d

    for _ in range(iters):
        active = np.flatnonzero(~done)
        if active.size == 0:
            break
        fresh = active[refresh[active]] if chord else active
        mapped = active[~redo[active]]
        if fresh.size:
            tang, tang_m = monodromies(fresh, y)
            for j, k in enumerate(fresh.tolist()):
                evals[k] += 1
                ok_j = tang.ok(j)
                mono[k] = tang_m[j] if ok_j else None
                mono_at[k], refresh[k] = y[k], False
        plain = (
            shoot([systems[k] for k in mapped], y[mapped], n, cfg, tangents=False)
            if mapped.size
            else None
        )
        row = {k: i for i, k in enumerate(mapped.tolist())}
        for k in active.tolist():
            if mono[k] is None or (plain is not None and k in row and not plain.ok(row[k])):
                done[k] = True
                messages[k] = "integration failed"
                continue
            if redo[k]:  # y[k] is best_y[k], whose G is known
                redo[k] = False
                step(k, best_g[k], float(best_r[k]))
                continue
            i = row[k]
            assert plain is not None
            evals[k] += 1
            g = plain.end[i] - y[k]
            a = float(np.max(np.abs(g)))
            if a >= best_a[k]:
                if best_r[k] <= eps:  # the noise floor: keep the best state
                    done[k] = True
                    continue
                y[k] = best_y[k]
                if chord and not exact[k]:  # a stale matrix: a Newton step from the best
                    redo[k] = refresh[k] = True
                    continue
                last_step[k] *= 0.5  # no decrease: half the previous step from the best
                y[k] = best_y[k] + last_step[k]
                continue
            # a chord step keeps its matrix only while max|G| shrinks tenfold a step
            refresh[k] = not a <= 0.1 * best_a[k]
            best_y[k], best_a[k], best_g[k] = y[k], a, g
            best_r[k] = residual_of(g, y[k])
            best[k] = plain.chain(i)
            step(k, g, float(best_r[k]))
        history.append(best_a.copy())
        if contraction is not None and len(history) > 3:
            slow = ~done & (history[-1] > contraction * history[-4])
            for k in np.flatnonzero(slow).tolist():
                done[k] = True
                messages[k] = (
                    f"no convergence: max|G| shrank by less than {contraction:g} over three "
                    "iterations"
                )
    # the multipliers of the orbit's own state (a chord iteration's matrix may be older)
    stale = [
        k
        for k in range(K)
        if best[k] is not None
        and (
            mono[k] is None
            or float(np.max(np.abs(mono_at[k] - best_y[k])))
            > eps * max(1.0, float(np.max(np.abs(best_y[k]))))
        )
    ]
    if stale:
        t, t_m = monodromies(np.array(stale), best_y)
        for j, k in enumerate(stale):
            evals[k] += 1
            mono[k] = t_m[j] if t.ok(j) else None
    out = []
    for k in range(K):
        ok = best_r[k] <= eps and best[k] is not None and mono[k] is not None
        chain, M = best[k], mono[k]
        if chain is None or M is None:  # no successful evaluation: report the start
            t = shoot([systems[k]], y[k][None], n, cfg, tangents=True, tangent_tol=tangent_tol)
            assert t.monodromy is not None
            chain, M = t, t.monodromy[0]
        shot = dataclasses.replace(chain, monodromy=M[None])
        state = best_y[k] if best[k] is not None else y[k]
        sol = Solution(
            state.copy(),
            0.0,
            shot,
            np.zeros(m),
            float(best_r[k]),
            int(evals[k]),
            0,
            multipliers_of(M),
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
