"""Shooting on the stroboscopic map: map evaluations.

The stroboscopic map of a T-periodically forced system y' = f(τ, y), T = 2π/Ω, is
P(y) = φ(τ_s + T; τ_s, y), from the section τ ≡ τ_s (mod T) to itself. :func:`shoot` evaluates
Pⁿ for C states (and C parameter sets) in one compiled
:func:`~gearchaos.integrate._chains.run_chains` call: each chain has n points of one forcing
period, each continuing from its predecessor. With tangents, the kernel starts the n_state
tangent vectors as the identity at every section and does not re-orthonormalise them (one
sample per point), so the final tangents of point k hold the one-period fundamental solution
Φ_k column by column and the monodromy matrix is M = DPⁿ(y) = Φ_{n−1} ⋯ Φ_0.

The Newton corrector that solves Pⁿ(y) − y = 0 with these evaluations, for one point or K
points at once, is :mod:`.corrector`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError, Status
from ...integrate._chains import ChainRun, run_chains
from ...integrate.interface import Info
from ...integrate.settings import SampleTimes, SolverSettings
from ...model.system import System

__all__ = [
    "Shot",
    "multipliers_of",
    "newton_step",
    "residual_of",
    "section_time",
    "shoot",
    "sort_multipliers",
]


def section_fraction(settings: SolverSettings) -> float:
    """τ_s/T ∈ [0, 1) of the section that :func:`gearchaos.simulate` samples with
    ``settings``: frac(transient_periods + φ/2π)."""
    frac = float(settings.transient_periods) % 1.0
    phase = float(settings.section_phase) / (2.0 * math.pi)
    return (frac + phase) % 1.0


def section_time(settings: SolverSettings, system: System) -> float:
    """τ_s ∈ [0, T) of the section that :func:`gearchaos.simulate` samples with ``settings``."""
    return section_fraction(settings) * system.period


@dataclass(frozen=True, eq=False)
class Shot:
    """C shootings over n forcing periods (chain first).

    ``end`` (C, n_state) Pⁿ(y); ``monodromy`` (C, n_state, n_state) DPⁿ(y) or None;
    ``sections`` (C, n, n_state) the states at the n section times (the first is y);
    ``section_obs`` (C, n, n_obs) their observables; ``obs_min``/``obs_max`` (C, n_track)
    extrema of the tracked observables over the n periods; ``status`` (C,) the first failure
    of each chain; ``steps`` (C,) accepted steps.
    """

    end: np.ndarray
    monodromy: np.ndarray | None
    sections: np.ndarray
    section_obs: np.ndarray
    obs_min: np.ndarray
    obs_max: np.ndarray
    status: np.ndarray
    steps: np.ndarray

    def ok(self, c: int) -> bool:
        return int(self.status[c]) == int(Status.OK)

    def chain(self, c: int) -> Shot:
        """The shot of chain c alone (chain axis kept)."""
        return self.take(slice(c, c + 1))

    def take(self, sl: slice) -> Shot:
        """The shot of the chains ``sl`` (views)."""
        return Shot(
            end=self.end[sl],
            monodromy=None if self.monodromy is None else self.monodromy[sl],
            sections=self.sections[sl],
            section_obs=self.section_obs[sl],
            obs_min=self.obs_min[sl],
            obs_max=self.obs_max[sl],
            status=self.status[sl],
            steps=self.steps[sl],
        )


def shoot(
    systems: Sequence[System],
    states: np.ndarray,
    period: int,
    settings: SolverSettings,
    *,
    tangents: bool = True,
    tangent_tol: float = 1.0,
) -> Shot:
    """Integrate C states of C systems (one kind and layout) over ``period`` forcing periods
    from their section time (:func:`section_time`) in one :func:`run_chains` call (on one
    thread for one or two chains: waking the thread pool costs more than they take).
    ``tangent_tol`` scales the tolerances of the monodromy's columns (1: the state's)."""

    C = len(systems)
    ref = systems[0]
    n = ref.n_state
    y = np.asarray(states, dtype=np.float64).reshape(C, n)
    k = n if tangents else 0
    for s in systems:
        if s.kind != ref.kind or s.params.size != ref.params.size:
            raise ParameterError("all systems of a shooting must share kind and layout")
    T = np.array([s.period for s in systems])
    ts = section_fraction(settings) * T
    t0 = ts[:, None] + np.arange(period)[None, :] * T[:, None]
    # the layout of ChainRun.from_systems without packing point by point (the hot path of
    # Newton iterations): each chain link one period, sampled at its start, no transient
    times = SampleTimes.over_periods(
        t0, T[:, None], first=0, periods=1, end=1, max_steps=settings.budget_for(1)
    )
    run = ChainRun.from_arrays(
        ref,
        np.repeat(np.array([s.params for s in systems])[:, None, :], period, axis=1),
        np.repeat(np.array([s.switch_widths for s in systems])[:, None, :], period, axis=1),
        t0,
        times,
        settings,
        y0=y,
        n_tangent=k,
        continuation=True,
        tangent_tol=tangent_tol,
    )
    # waking a thread pool costs more than one or two short chains take
    out = run_chains(run, threads=1 if C <= 2 else None)
    status = np.zeros(C, dtype=np.int64)
    for c in range(C):
        bad = out.status[c][out.status[c] != 0]
        status[c] = int(bad[0]) if bad.size else 0
    mono = None
    if tangents:
        mono = np.empty((C, n, n))
        for c in range(C):
            m = np.eye(n)
            for j in range(period):
                m = out.final_state[c, j, n:].reshape(n, n).T @ m
            mono[c] = m
    return Shot(
        end=out.final_state[:, -1, :n].copy(),
        monodromy=mono,
        sections=out.states[:, :, 0, :n].copy(),
        section_obs=out.observables[:, :, 0, :].copy(),
        obs_min=out.obs_min.min(axis=1),
        obs_max=out.obs_max.max(axis=1),
        status=status,
        steps=out.info[:, :, Info.ACCEPTED].sum(axis=1).astype(np.int64),
    )


def sort_multipliers(mu: np.ndarray) -> np.ndarray:
    """Multipliers sorted by modulus, descending (ties: by argument, ascending)."""
    mu = np.asarray(mu, dtype=complex)
    order = np.lexsort((np.angle(mu), -np.round(np.abs(mu), 12)))
    return mu[order]


def multipliers_of(monodromy: np.ndarray) -> np.ndarray:
    """Sorted eigenvalues of a monodromy matrix (NaN when it is not finite)."""
    if not np.all(np.isfinite(monodromy)):
        return np.full(monodromy.shape[0], np.nan + 0j)
    return sort_multipliers(np.linalg.eigvals(monodromy))


def residual_of(g: np.ndarray, y: np.ndarray) -> float:
    """The residual ‖Pⁿ(y) − y‖_∞ / max(1, ‖y‖_∞)."""
    return float(np.max(np.abs(g)) / max(1.0, float(np.max(np.abs(y)))))


def newton_step(jac: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve jac·d = rhs; least squares (minimum norm) when jac is singular."""
    try:
        d = np.linalg.solve(jac, rhs)
        if np.all(np.isfinite(d)):
            return d
    except np.linalg.LinAlgError:
        pass
    return np.asarray(np.linalg.lstsq(jac, rhs, rcond=None)[0])
