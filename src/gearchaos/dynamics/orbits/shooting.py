"""Shooting on the stroboscopic map: map evaluations and the Newton corrector.

The stroboscopic map of a T-periodically forced system y' = f(τ, y), T = 2π/Ω, is
P(y) = φ(τ_s + T; τ_s, y), from the section τ ≡ τ_s (mod T) to itself. :func:`shoot` evaluates
Pⁿ for C states (and C parameter sets) in one compiled
:func:`~gearchaos.integrate._chains.run_chains` call: each chain has n points of one forcing
period, each continuing from its predecessor. With tangents, the kernel starts the n_state
tangent vectors as the identity at every section and does not re-orthonormalise them (one
sample per point), so the final tangents of point k hold the one-period fundamental solution
Φ_k column by column and the monodromy matrix is M = DPⁿ(y) = Φ_{n−1} ⋯ Φ_0.

:func:`correct` solves the bordered system

    G(y, λ) = Pⁿ_λ(y) − y = 0,    ⟨a, z⟩ = c,    z = (y, λ),

by a quasi-Newton iteration with the Jacobian [[M − I, G_λ], [aᵀ]]. M comes from the
variational equations where a Jacobian is needed (at the start, or when the convergence slows
below a tenfold reduction per step) and is updated by Broyden's rank-one formula after every
step; a continuation passes in the M of the previous point extrapolated along the branch.
G itself is always evaluated without tangents, about 20 times cheaper for the planetary model
and the map that simulations and sweeps integrate (with the tangents in the error control the
steps differ, and so does Pⁿ, by about rtol). A step that does not lower ‖G‖_∞ is refused: a
stale Jacobian is refreshed, a fresh one backtracks (½ … 1/16 of the step, evaluated together);
a step never moves the state by more than ten times its size (trust region). A fixed-parameter
Newton solve is the case a = e_λ, c = λ. The last evaluation with tangents is always at the
solution, so the returned multipliers belong to the returned state.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError, Status
from ...integrate._chains import ChainRun, run_chains
from ...integrate.interface import Info
from ...integrate.settings import SampleTimes, SolverSettings
from ...model.system import System

__all__ = [
    "Shot",
    "Solution",
    "correct",
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
        sl = slice(c, c + 1)
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


# ------------------------------------------------------------------------------ corrector
@dataclass(eq=False)
class Solution:
    """A solution of the bordered shooting system: the state y, the parameter λ, the shot
    (with the monodromy) at (y, λ), G_λ, the residual, the work done (map evaluations, of
    which ``jacobians`` with tangents), the sorted multipliers and the number of Newton
    ``corrections``; a continuation adds the
    unit ``tangent``, the arclength ``s`` and whether the point was ``landed`` on a grid value."""

    y: np.ndarray
    lam: float
    shot: Shot
    g_lam: np.ndarray
    residual: float
    evals: int
    jacobians: int
    mu: np.ndarray
    corrections: int = 0
    tangent: np.ndarray | None = None
    s: float = 0.0
    landed: bool = False

    @property
    def monodromy(self) -> np.ndarray:
        assert self.shot.monodromy is not None
        return self.shot.monodromy[0]

    @property
    def z(self) -> np.ndarray:
        return np.append(self.y, self.lam)


@dataclass(frozen=True)
class Problem:
    """What the corrector needs: systems by parameter value, the period, the settings, the
    residual tolerance, the evaluation budget and the finite-difference step of G_λ
    (0: G_λ is not needed)."""

    system: Callable[[float], System]
    period: int
    settings: SolverSettings
    tol: float
    max_evals: int
    fd_step: float = 0.0


#: The largest Newton step, relative to max(1, ‖y‖_∞).
TRUST_RADIUS = 10.0


def _bordered(mono: np.ndarray, g_lam: np.ndarray, normal: np.ndarray) -> np.ndarray:
    m = mono.shape[0]
    jac = np.zeros((m + 1, m + 1))
    jac[:-1, :-1] = mono - np.eye(m)
    jac[:-1, -1] = g_lam
    jac[-1] = normal
    return jac


class _Corrector:
    """State of one :func:`correct` solve (see there)."""

    def __init__(self, prob: Problem, g_lam: np.ndarray | None, m: int):
        self.prob = prob
        self.evals = 0
        self.jacs = 0
        self.g_l = np.zeros(m) if g_lam is None else np.asarray(g_lam, dtype=float)
        self.why = ""

    def systems(self, lam: float, fd: bool) -> tuple[list[System], float] | None:
        h = self.prob.fd_step
        try:
            out = [self.prob.system(lam)]
            if fd:
                try:
                    out.append(self.prob.system(lam + h))
                except ParameterError:
                    h = -h
                    out.append(self.prob.system(lam + h))
        except ParameterError as exc:
            self.why = f"invalid parameter value {lam:.8g}: {exc}"
            return None
        return out, h

    def evaluate(self, z: np.ndarray, tangents: bool, fd: bool = False) -> Shot | None:
        """Pⁿ at z (with M when ``tangents``; G_λ refreshed when ``fd``)."""
        fd = fd and self.prob.fd_step != 0.0
        got = self.systems(float(z[-1]), fd)
        if got is None:
            return None
        systems, h = got
        shot = shoot(
            systems,
            np.repeat(z[None, :-1], len(systems), axis=0),
            self.prob.period,
            self.prob.settings,
            tangents=tangents,
        )
        self.evals += 1
        self.jacs += int(tangents)
        if not all(shot.ok(c) for c in range(len(systems))):
            bad = Status(int(np.max(shot.status)))
            self.why = f"integration failed ({bad.name.lower()}: {bad.message})"
            return None
        if fd:
            self.g_l = (shot.end[1] - shot.end[0]) / h
        return shot.chain(0)


def correct(
    prob: Problem,
    z0: np.ndarray,
    normal: np.ndarray,
    offset: float,
    *,
    monodromy: np.ndarray | None = None,
    g_lam: np.ndarray | None = None,
) -> tuple[Solution | None, str]:
    """Solve G(y, λ) = 0, ⟨normal, z⟩ = offset from z0 (see the module docstring).

    ``monodromy`` and ``g_lam`` of a nearby solution start the iteration without a Jacobian
    evaluation. G is always evaluated without tangents (the map that simulations and sweeps
    integrate: with the tangents in the error control the steps differ, and so does Pⁿ, by
    about rtol); evaluations with tangents only supply M. The iteration stops when the
    residual is below ``prob.tol`` and the Newton correction is too (relative to
    max(1, ‖y‖_∞) and max(1, |λ|)), or the correction no longer lowers ‖G‖ (the noise floor
    of the map, which an ill-conditioned Jacobian amplifies into the correction). At the
    solution M comes from an evaluation with tangents there and, when ``prob.fd_step`` is not
    0, G_λ from a forward difference (two chains in one call). Returns (None, reason) on
    failure.
    """
    cor = _Corrector(prob, g_lam, z0.size - 1)
    tol = prob.tol
    z = np.array(z0, dtype=np.float64)
    corrections = 0
    mono_at: np.ndarray | None = None  # the z where the monodromy was evaluated
    tshot: Shot | None = None
    if monodromy is None:
        tshot = cor.evaluate(z, tangents=True)
        if tshot is None:
            return None, cor.why
        assert tshot.monodromy is not None
        monodromy, mono_at = tshot.monodromy[0], z.copy()
    fd_at: np.ndarray | None = z.copy() if g_lam is None else None
    shot = cor.evaluate(z, tangents=False, fd=g_lam is None)
    if shot is None:
        return None, cor.why
    mono = monodromy
    g = shot.end[0] - z[:-1]
    r = residual_of(g, z[:-1])

    def small(dz: np.ndarray) -> bool:
        ys = max(1.0, float(np.max(np.abs(z[:-1]))))
        lam_s = max(1.0, abs(float(z[-1])))
        return bool(np.max(np.abs(dz[:-1])) <= tol * ys and abs(dz[-1]) <= tol * lam_s)

    jac = _bordered(mono, cor.g_l, normal)
    while True:
        fresh = mono_at is not None and np.array_equal(mono_at, z)
        dz = newton_step(jac, -np.append(g, normal @ z - offset))
        if r <= tol and small(dz):
            break
        if cor.evals >= prob.max_evals:
            if r <= tol:
                break
            return None, f"no convergence in {prob.max_evals} map evaluations (residual {r:.3g})"
        # trust region: a nearly singular Jacobian must not throw the state far away
        reach = float(np.max(np.abs(dz[:-1])))
        cap = TRUST_RADIUS * max(1.0, float(np.max(np.abs(z[:-1]))))
        if reach > cap:
            dz = dz * (cap / reach)
        trial = z + dz
        corrections += 1
        ts = cor.evaluate(trial, tangents=False)
        rt = math.inf
        # decrease is judged on ‖G‖ itself (the relative residual would also fall if y ran off)
        a, at = float(np.max(np.abs(g))), math.inf
        if ts is not None:
            gt = ts.end[0] - trial[:-1]
            rt = residual_of(gt, trial[:-1])
            at = float(np.max(np.abs(gt)))
        if r <= tol and not at < 0.5 * a:
            break  # within tolerance, and the correction no longer helps: the noise floor
        if ts is not None and (at < (1.0 - 1e-4) * a or rt <= tol):
            slow = at > 0.1 * a and not fresh
            # Broyden's (good) rank-one update of the Jacobian along the step taken
            change = np.append(gt - g, normal @ dz) - jac @ dz
            jac += np.outer(change, dz) / float(dz @ dz)
            z, g, r, shot = trial, gt, rt, ts
            if not slow:
                continue
        elif fresh:
            # a fresh Jacobian and still no decrease: shorter steps, together in one call
            step = _backtrack(prob, z, dz, g)
            cor.evals += 1
            if step is None:
                return None, f"the damped Newton step no longer lowers the residual ({r:.3g})"
            z, g, r, shot = step
            continue
        # the Jacobian is stale (slow or no decrease): M, G_λ (and G) at z
        tshot = cor.evaluate(z, tangents=True)
        new = tshot and cor.evaluate(z, tangents=False, fd=True)
        if tshot is None or not new:
            return None, cor.why
        assert tshot.monodromy is not None
        mono, mono_at, fd_at, shot = tshot.monodromy[0], z.copy(), z.copy(), new
        jac = _bordered(mono, cor.g_l, normal)
        g = shot.end[0] - z[:-1]
        r = residual_of(g, z[:-1])

    # the multipliers of the solution (and G_λ there)
    if mono_at is None or not np.array_equal(mono_at, z):
        tshot = cor.evaluate(z, tangents=True)
    if tshot is None or tshot.monodromy is None:
        return None, cor.why
    if prob.fd_step != 0.0 and (fd_at is None or not np.array_equal(fd_at, z)):
        if not cor.evaluate(z, tangents=False, fd=True):
            return None, cor.why
    mu = multipliers_of(tshot.monodromy[0])
    # sections and extrema of the map without tangents, the monodromy from the tangents
    shot = dataclasses.replace(shot, monodromy=tshot.monodromy)
    sol = Solution(
        z[:-1].copy(), float(z[-1]), shot, cor.g_l, r, cor.evals, cor.jacs, mu, corrections
    )
    return sol, "converged"


def _plain(prob: Problem, zs: np.ndarray) -> Shot | None:
    """Map evaluations without tangents at several points z (one compiled call)."""
    try:
        systems = [prob.system(float(z[-1])) for z in zs]
    except ParameterError:
        return None
    return shoot(systems, zs[:, :-1], prob.period, prob.settings, tangents=False)


def _backtrack(
    prob: Problem, z: np.ndarray, dz: np.ndarray, g0: np.ndarray
) -> tuple[np.ndarray, np.ndarray, float, Shot] | None:
    """The longest of the steps λ dz, λ = ½ … 1/16, that lowers ‖G‖ (Armijo)."""
    lams = (0.5, 0.25, 0.125, 0.0625)
    zs = np.array([z + lam * dz for lam in lams])
    shots = _plain(prob, zs)
    a = float(np.max(np.abs(g0)))
    if shots is None:
        return None
    for c, lam in enumerate(lams):
        if not shots.ok(c):
            continue
        g = shots.end[c] - zs[c, :-1]
        if float(np.max(np.abs(g))) < (1.0 - 1e-4 * lam) * a:
            return zs[c], g, residual_of(g, zs[c, :-1]), shots.chain(c)
    return None
