"""Many periodic orbits at once: :func:`periodic_orbits`, K points in one compiled call per round.

For K parameter points (e.g. the points of a sweep labelled nT, with the sweep's final states
as guesses) the Newton corrector of :mod:`.corrector` solves Pⁿ(y) − y = 0 for all points
together: each round, the map evaluations of every unconverged point (with tangents for M,
without for G, the map simulations and sweeps integrate) go to one
:func:`~gearchaos.dynamics.orbits.shooting.shoot` call per kind, whose chains run in parallel
over the cores. Each point's iteration is the one :func:`~.orbit.periodic_orbit` runs alone,
with the options of a batch (M afresh every round or kept as a chord; damped steps one per
round; an optional early give-up).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..._checks import check_int, check_real
from ...errors import ParameterError
from ...integrate._chains import ChainRun, run_chains
from ...integrate.settings import SolverSettings
from ...model.target import Target, resolve
from .corrector import Problem, Start, correct_points
from .orbit import ORBIT_SETTINGS, PeriodicOrbit, default_tol, orbit_from

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
        Rounds of the Newton iteration per point (each at most one evaluation with and one
        without tangents per point).
    tangent_tol
        Factor on the error tolerances of the monodromy's columns (1: the state's). The
        residual comes from the map without tangents, so the orbit is as accurate either way;
        the multipliers move by roughly f·rtol or less (the motion verdict uses 1000: it
        compares max |μ| with 1 − 10⁻⁴).
    contraction
        Give a point up early when three rounds have not shrunk its best residual
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
        One per point, in order; never raises when Newton fails (check ``converged``): a
        point that did not converge is reported at its best state (the start when no
        evaluation succeeded).
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
    prob = Problem(
        n,
        cfg,
        eps,
        iters,
        jacobian="chord" if chord else "newton",
        fractions=1,
        contraction=contraction,
        tangent_tol=tangent_tol,
        keep_failed=True,
    )
    solved = correct_points(prob, [Start.fixed(s, y[k]) for k, s in enumerate(systems)])
    out = []
    for k, (sol, _) in enumerate(solved):
        assert sol is not None  # keep_failed
        out.append(orbit_from(systems[k], sol, period=n, settings=cfg, tol=eps, values=values[k]))
    return out
