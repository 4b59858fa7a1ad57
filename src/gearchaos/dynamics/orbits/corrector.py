"""The one Newton corrector of the shooting problems, over K points at once.

Every point z = (y, λ) solves the bordered system

    G(y, λ) = Pⁿ_λ(y) − y = 0,    ⟨a, z⟩ = c,

with the Jacobian [[M − I, G_λ], [aᵀ]], M = DPⁿ from the variational equations and G_λ by a
forward difference (a second chain at λ + h). A fixed-parameter orbit is the case a = e_λ,
c = λ: dλ = 0, and a step solves (M − I) dy = −G alone. Continuation and event location pass
a = W t, the tangent of the branch.

Each point is iterated on its own, by the same code whatever K (:class:`_Point`, a generator
that yields the map evaluations it needs next as :class:`Ask` s); :func:`correct_points`
gathers the evaluations of all points still iterating into one compiled
:func:`~.shooting.shoot` call per kind (with tangents, without) per round. Chains are
independent, so a point's result does not depend, to the bit, on the points that share its
rounds. :func:`correct` is the case K = 1.

A round of a point evaluates G at its trial state without tangents (the map simulations and
sweeps integrate: with the tangents in the error control Pⁿ differs by about rtol), and M (and
G_λ) there too when a fresh Jacobian is due. A trial that lowers max|G| is accepted (judged on
‖G‖ itself: the relative residual would also fall if y ran off), and the Newton step from it
taken, at most :data:`TRUST_RADIUS` × max(1, ‖y‖_∞) long. A point has converged when the
residual ‖G‖_∞ / max(1, ‖y‖_∞) and the step (relative to max(1, ‖y‖_∞), max(1, |λ|)) are
below ``tol``, or when the residual is and a step no longer lowers max|G| (the noise floor of
the map, which an ill-conditioned Jacobian amplifies into the step). A refused trial (no
decrease, or a failed integration) is answered from the accepted state: with M evaluated there
and the step taken again when the step's M was not evaluated there, else with ½ … 1/16 of the
step (the longest that lowers max|G|; the point fails when none does). The multipliers
returned are those of an evaluation with tangents within ``tol`` of the returned state.

The records a correction is given and returns, and its options, are in :mod:`.problem`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Generator, Sequence
from dataclasses import dataclass, field

import numpy as np

from ...errors import ParameterError, Status
from ...model.system import System
from .problem import (
    MIN_FRACTION,
    TRUST_RADIUS,
    Ask,
    Iteration,
    Problem,
    Solution,
    Start,
)
from .shooting import Shot, multipliers_of, newton_step, residual_of, shoot

__all__ = ["Ask", "Iteration", "Problem", "Solution", "Start", "correct", "correct_points"]


@dataclass(eq=False)
class _Point:
    """The state of one point's iteration (see the module docstring); :meth:`iterate` is the
    iteration itself."""

    prob: Problem
    start: Start
    z: np.ndarray  # the state evaluated next
    fixed: bool  # the border is e_λ at the start's λ: dλ = 0
    best_z: np.ndarray = field(default_factory=lambda: np.empty(0))  # the accepted state …
    best: Shot | None = None  # … its map …
    best_g: np.ndarray = field(default_factory=lambda: np.empty(0))  # … G there …
    best_a: float = math.inf  # … max|G| …
    best_r: float = math.inf  # … and the residual
    mono: np.ndarray | None = None  # the last evaluated M …
    mono_at: np.ndarray | None = None  # … where
    g_lam: np.ndarray | None = None  # the last evaluated G_λ …
    lam_at: np.ndarray | None = None  # … where
    jac_m: np.ndarray | None = None  # the M of the steps (Broyden-updated)
    jac_l: np.ndarray = field(default_factory=lambda: np.empty(0))  # the G_λ of the steps
    refresh: bool = False  # evaluate M at the next trial
    redo: bool = False  # evaluate M at the accepted state and step again
    exact: bool = False  # the last step's M was evaluated at its start
    step: np.ndarray = field(default_factory=lambda: np.empty(0))  # the last Newton step
    frac: float = 1.0  # the fraction of it tried next
    evals: int = 0
    jacobians: int = 0
    corrections: int = 0
    history: list[float] = field(default_factory=list)  # best max|G| after each round
    message: str = ""
    status: Status = Status.OK

    @classmethod
    def begin(cls, prob: Problem, start: Start) -> _Point:
        z = np.array(start.z, dtype=np.float64)
        normal = np.asarray(start.normal, dtype=np.float64)
        fixed = not np.any(normal[:-1]) and normal[-1] == 1.0 and float(start.offset) == z[-1]
        m = z.size - 1
        p = cls(prob, start, z, bool(fixed), best_z=z.copy(), step=np.zeros(m + 1))
        p.jac_l = np.zeros(m) if start.g_lam is None else np.asarray(start.g_lam, dtype=float)
        if start.g_lam is not None:
            p.g_lam = p.jac_l
        p.refresh = start.monodromy is None
        if start.monodromy is not None:
            p.jac_m = np.asarray(start.monodromy, dtype=float)
        p.message = f"no convergence in {prob.max_iterations} iterations"
        return p

    def _near(self, at: np.ndarray | None, z: np.ndarray) -> bool:
        """Whether ``at`` lies within ``tol`` of z (relative to max(1, ‖y‖_∞), max(1, |λ|))."""
        return at is not None and self._small(at - z, z)

    def _evaluated_at(self, z: np.ndarray) -> bool:
        """Whether the last M was evaluated at z."""
        return self.mono_at is not None and bool(np.array_equal(self.mono_at, z))

    def _small(self, dz: np.ndarray, z: np.ndarray) -> bool:
        tol = self.prob.tol
        ys = max(1.0, float(np.max(np.abs(z[:-1]))))
        lam_s = max(1.0, abs(float(z[-1])))
        return bool(np.max(np.abs(dz[:-1])) <= tol * ys and abs(dz[-1]) <= tol * lam_s)

    def _systems(self, lam: float, fd: bool) -> tuple[list[System], float] | str:
        """The system at λ (and at λ + h, or λ − h where λ + h is invalid, with ``fd``), or
        why there is none."""
        h = self.prob.fd_step
        try:
            out = [self.start.system(lam)]
            if fd:
                try:
                    out.append(self.start.system(lam + h))
                except ParameterError:
                    h = -h
                    out.append(self.start.system(lam + h))
        except ParameterError as exc:
            return f"invalid parameter value {lam:.8g}: {exc}"
        return out, h

    def _fail(self, shot: Shot, c: int = 0) -> bool:
        """End the iteration: the evaluation of chain c failed."""
        self.status = Status(int(shot.status[c]))
        self.message = f"integration failed ({self.status.name.lower()}: {self.status.message})"
        return True

    def _matrix(self, shot: Shot, z: np.ndarray) -> None:
        assert shot.monodromy is not None
        self.mono, self.mono_at = shot.monodromy[0], z.copy()
        self.jac_m, self.refresh = self.mono, False
        self.evals += 1
        self.jacobians += 1

    def _difference(self, g_end: np.ndarray, h_end: np.ndarray, h: float, z: np.ndarray) -> None:
        self.g_lam = (h_end - g_end) / h
        self.jac_l, self.lam_at = self.g_lam, z.copy()

    def iterate(self) -> Iteration:
        """Rounds until convergence, failure or ``max_iterations``; returns (solution or
        None, why)."""
        p = self.prob
        for _ in range(p.max_iterations):
            if self.redo:
                done = yield from self._redo()
            elif self.frac < 1.0 and p.fractions > 1:
                done = yield from self._damped()
            else:
                done = yield from self._trial()
            if done:
                break
            self.history.append(self.best_a)
            h = self.history
            if p.contraction is not None and len(h) > 3 and h[-1] > p.contraction * h[-4]:
                self.message = (
                    f"no convergence: max|G| shrank by less than {p.contraction:g} over three "
                    "iterations"
                )
                break
        else:
            self.message = f"{self.message} (residual {self.best_r:.3g})"
        return (yield from self._finish())

    def _trial(self) -> Generator[tuple[Ask, ...], tuple[Shot, ...], bool]:
        """G at the trial state (and M, G_λ there when asked for)."""
        p, z = self.prob, self.z
        want_m = self.refresh or p.jacobian == "newton"
        want_fd = p.fd_step != 0.0 and (want_m or self.g_lam is None)
        got = self._systems(float(z[-1]), want_fd)
        if isinstance(got, str):
            if self.best is None:
                self.message = got
                return True
            return self._refused()
        systems, h = got
        asks = [Ask(systems[:1], z[None, :-1], True)] if want_m else []
        asks.append(Ask(systems, np.repeat(z[None, :-1], len(systems), axis=0), False))
        shots = yield tuple(asks)
        if want_m:
            if not shots[0].ok(0):
                return self._fail(shots[0])
            self._matrix(shots[0], z)
        plain = shots[-1]
        self.evals += 1
        if want_fd and plain.ok(0) and plain.ok(1):
            self._difference(plain.end[0], plain.end[1], h, z)
        bad = [c for c in range(len(systems)) if not plain.ok(c)]
        if self.best is None and bad:
            return self._fail(plain, bad[0])
        g = plain.end[0] - z[:-1]
        a = float(np.max(np.abs(g)))
        if self.best is None and not math.isfinite(a):
            self.message = "the map is not finite at the start"
            return True
        damped = self.frac < 1.0
        if not plain.ok(0) or not self._lowers(z, g, a, self.frac):
            return self._refused()
        return self._accept(z, g, a, plain.take(slice(0, 1)), damped=damped)

    def _redo(self) -> Generator[tuple[Ask, ...], tuple[Shot, ...], bool]:
        """M (and G_λ) afresh at the accepted state, and the step from there again."""
        z = self.best_z
        fd = self.prob.fd_step != 0.0
        got = self._systems(float(z[-1]), fd)
        if isinstance(got, str):
            self.message = got
            return True
        systems, h = got
        asks = [Ask(systems[:1], z[None, :-1], True)]
        if fd:  # G at z is known: the chain at λ + h alone
            asks.append(Ask(systems[1:], z[None, :-1], False))
        shots = yield tuple(asks)
        if not shots[0].ok(0):
            return self._fail(shots[0])
        self._matrix(shots[0], z)
        if fd:
            self.evals += 1
            if not shots[1].ok(0):
                return self._fail(shots[1])
            assert self.best is not None
            self._difference(self.best.end[0], shots[1].end[0], h, z)
        self.redo = False
        return self._newton()

    def _damped(self) -> Generator[tuple[Ask, ...], tuple[Shot, ...], bool]:
        """Up to ``fractions`` damped steps from the accepted state, evaluated together."""
        fracs: list[float] = []
        f = self.frac
        while len(fracs) < self.prob.fractions and f >= MIN_FRACTION:
            fracs.append(f)
            f *= 0.5
        zs, systems = [], []
        for f in fracs:
            z = self.best_z + f * self.step
            got = self._systems(float(z[-1]), False)
            if not isinstance(got, str):  # a parameter value out of range is not tried
                zs.append(z)
                systems.append(got[0][0])
        self.frac = fracs[-1]
        if not systems:
            return self._refused()
        (shot,) = yield (Ask(systems, np.array([z[:-1] for z in zs]), False),)
        self.evals += 1
        for c, z in enumerate(zs):
            if not shot.ok(c):
                continue
            g = shot.end[c] - z[:-1]
            a = float(np.max(np.abs(g)))
            if self._lowers(z, g, a, fracs[c]):
                return self._accept(z, g, a, shot.take(slice(c, c + 1)), damped=True)
        return self._refused()

    def _refused(self) -> bool:
        """The trial did not lower max|G|: the noise floor, a fresh Jacobian, or a shorter
        step."""
        if self.best_r <= self.prob.tol:
            return True  # within tolerance, and a step no longer helps: the noise floor
        self.z = self.best_z
        if not self.exact:
            self.redo = True
            return False
        self.frac *= 0.5
        if self.frac < MIN_FRACTION:
            self.message = (
                f"the damped Newton step no longer lowers the residual ({self.best_r:.3g})"
            )
            return True
        if self.prob.fractions == 1:
            self.z = self.best_z + self.frac * self.step
        return False

    def _lowers(self, z: np.ndarray, g: np.ndarray, a: float, frac: float) -> bool:
        """Whether the trial z (G there g, max|G| a), a fraction ``frac`` of the step, lowers
        max|G|: by any amount, or, for ``broyden``, sufficiently (Armijo: below
        (1 − 10⁻⁴ frac) of the accepted max|G|; a full step also when its residual is within
        tolerance)."""
        if self.prob.jacobian != "broyden":
            return a < self.best_a
        if a < (1.0 - 1e-4 * frac) * self.best_a:
            return True
        return frac == 1.0 and residual_of(g, z[:-1]) <= self.prob.tol

    def _accept(
        self, z: np.ndarray, g: np.ndarray, a: float, shot: Shot, *, damped: bool = False
    ) -> bool:
        """z lowered max|G|: it becomes the accepted state, and the next step is taken.

        ``broyden`` updates [M − I, G_λ] along a full step alone, and evaluates M afresh after
        a slow one only where that step's M was not evaluated at its start: a step from a fresh
        M (damped or not) keeps the matrix, updated, for the next step, which is what brings a
        poor guess (a state off the orbit by the orbit's size) into Newton's basin more often
        than a fresh M at every slow step does."""
        p = self.prob
        broyden = p.jacobian == "broyden"
        if broyden and self.best is not None and not damped and not self._evaluated_at(z):
            # Broyden's (good) rank-one update of [M − I, G_λ] along the step taken
            assert self.jac_m is not None
            dz = z - self.best_z
            change = (g - self.best_g) - (self.jac_m - np.eye(g.size)) @ dz[:-1]
            change -= self.jac_l * dz[-1]
            scale = float(dz @ dz)
            self.jac_m = self.jac_m + np.outer(change, dz[:-1]) / scale
            self.jac_l = self.jac_l + change * (dz[-1] / scale)
        # a kept matrix stays only while max|G| shrinks tenfold a step: afresh at the next
        # trial (chord), or at once at the accepted state (broyden)
        slow = not a <= 0.1 * self.best_a
        self.refresh = slow and p.jacobian == "chord"
        self.best_z, self.best_g, self.best_a, self.best = z, g, a, shot
        self.best_r = residual_of(g, z[:-1])
        self.frac = 1.0
        fresh = p.jacobian == "newton" or (slow and broyden and not self.exact)
        if fresh and not self._evaluated_at(z):
            self.redo = True  # M at the accepted state before the step
            return False
        return self._newton()

    def _newton(self) -> bool:
        """The Newton (or chord) step from the accepted state, or convergence."""
        z, g = self.best_z, self.best_g
        assert self.jac_m is not None
        self.exact = self._evaluated_at(z)
        if self.fixed:  # dλ = 0: the border needs no row
            dz = np.append(newton_step(self.jac_m - np.eye(g.size), -g), 0.0)
        else:
            m = g.size
            jac = np.zeros((m + 1, m + 1))
            jac[:-1, :-1] = self.jac_m - np.eye(m)
            jac[:-1, -1] = self.jac_l
            jac[-1] = self.start.normal
            dz = newton_step(jac, -np.append(g, self.start.normal @ z - self.start.offset))
        if self.best_r <= self.prob.tol and self._small(dz, z):
            return True
        # trust region: a nearly singular Jacobian must not throw the state far away
        reach = float(np.max(np.abs(dz[:-1])))
        cap = TRUST_RADIUS * max(1.0, float(np.max(np.abs(z[:-1]))))
        if reach > cap:
            dz = dz * (cap / reach)
        self.step = dz
        self.z = z + dz
        self.corrections += 1
        return False

    def _finish(self) -> Iteration:
        """The solution: the accepted state's map, with M (and G_λ) evaluated within
        ``tol`` of it."""
        p = self.prob
        converged = self.best is not None and self.best_r <= p.tol
        if not converged and not p.keep_failed:
            return None, self.message
        if self.best is None:  # no successful evaluation: report the start
            return (yield from self._report_start())
        z = self.best_z
        want_m = not self._near(self.mono_at, z)
        want_fd = p.fd_step != 0.0 and not self._near(self.lam_at, z)
        if want_m or want_fd:
            got = self._systems(float(z[-1]), want_fd)
            if isinstance(got, str):
                return None, got
            systems, h = got
            asks = [Ask(systems[:1], z[None, :-1], True)] if want_m else []
            if want_fd:
                asks.append(Ask(systems[1:], z[None, :-1], False))
            shots = yield tuple(asks)
            self.evals += len(shots)
            self.jacobians += int(want_m)
            bad = [s for s in shots if not s.ok(0)]
            if bad:
                self._fail(bad[0])
                if not p.keep_failed:
                    return None, self.message
                return (yield from self._report_start())
            if want_m:
                self.mono = shots[0].monodromy[0]  # type: ignore[index]
            if want_fd:
                self.g_lam = (shots[-1].end[0] - self.best.end[0]) / h
        assert self.mono is not None
        shot = dataclasses.replace(self.best, monodromy=self.mono[None])
        return self._solution(z, shot, self.best_r, converged)

    def _report_start(self) -> Iteration:
        """The start with its map and M (the iteration reached no state of its own)."""
        z = np.asarray(self.start.z, dtype=np.float64)
        got = self._systems(float(z[-1]), False)
        if isinstance(got, str):
            return None, got
        (shot,) = yield (Ask(got[0], z[None, :-1], True),)
        if self.status == Status.OK:
            self.status = Status(int(shot.status[0]))
        r = residual_of(shot.end[0] - z[:-1], z[:-1]) if shot.ok(0) else math.inf
        self.g_lam = None
        return self._solution(z, shot, r, False)

    def _solution(
        self, z: np.ndarray, shot: Shot, residual: float, converged: bool
    ) -> tuple[Solution, str]:
        assert shot.monodromy is not None
        sol = Solution(
            z[:-1].copy(),
            float(z[-1]),
            shot,
            np.zeros(z.size - 1) if self.g_lam is None else self.g_lam,
            residual,
            self.evals,
            self.jacobians,
            multipliers_of(shot.monodromy[0]),
            self.corrections,
            converged=converged,
            message="converged" if converged else self.message,
            status=Status.OK if converged else self.status,
        )
        return sol, sol.message


def correct_points(prob: Problem, starts: Sequence[Start]) -> list[tuple[Solution | None, str]]:
    """Solve the bordered systems of the module docstring for K points together.

    Every point is iterated by :class:`_Point`; each round, the map evaluations all points
    ask for go to one :func:`~.shooting.shoot` call per kind (with tangents, without). All
    points share ``prob`` (period, settings, tolerance and options); their systems must share
    one model kind and layout. Returns (solution, why) per point, in order: the solution is
    None when the point did not converge, unless ``prob.keep_failed`` (then its best state,
    ``converged`` False).
    """
    iterations = [_Point.begin(prob, s).iterate() for s in starts]
    out: list[tuple[Solution | None, str]] = [(None, "")] * len(iterations)
    asks: dict[int, tuple[Ask, ...]] = {}

    def advance(k: int, answer: tuple[Shot, ...] | None) -> None:
        try:
            asks[k] = iterations[k].send(answer)  # type: ignore[arg-type]
        except StopIteration as stop:
            out[k] = stop.value
            asks.pop(k, None)

    for k in range(len(iterations)):
        advance(k, None)
    while asks:
        answers = _evaluate(prob, asks)
        for k in list(asks):
            advance(k, answers[k])
    return out


def _evaluate(prob: Problem, asks: dict[int, tuple[Ask, ...]]) -> dict[int, tuple[Shot, ...]]:
    """One round: every point's asks, one :func:`shoot` call per kind."""
    got: dict[tuple[int, int], Shot] = {}
    for tangents in (True, False):
        these = [
            (k, i, a) for k, q in asks.items() for i, a in enumerate(q) if a.tangents is tangents
        ]
        if not these:
            continue
        systems = [s for _, _, a in these for s in a.systems]
        states = np.concatenate([a.states for _, _, a in these])
        shot = shoot(
            systems,
            states,
            prob.period,
            prob.settings,
            tangents=tangents,
            tangent_tol=prob.tangent_tol if tangents else 1.0,
        )
        at = 0
        for k, i, a in these:
            got[k, i] = shot.take(slice(at, at + len(a.systems)))
            at += len(a.systems)
    return {k: tuple(got[k, i] for i in range(len(q))) for k, q in asks.items()}


def correct(prob: Problem, start: Start) -> tuple[Solution | None, str]:
    """One point (K = 1 of :func:`correct_points`): (solution, "converged"), or (None, why)
    (the point's best state instead of None with ``prob.keep_failed``)."""
    ((sol, why),) = correct_points(prob, [start])
    return sol, why
