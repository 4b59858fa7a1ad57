"""Two-parameter continuation of bifurcation and grazing boundaries (stability charts).

A fold, period doubling, Neimark–Sacker or grazing event of a one-parameter branch
(:func:`gearchaos.continuation`) is a point of a curve in the plane of two parameters (λ₁, λ₂):
(Ω, ξ), (Ω, b̄_sp), (Ω, input torque) or any two dotted names. The curve is followed as the
solution set of the **minimally augmented system** in the unknowns z = (y, λ₁, λ₂),

    G(z) = Pⁿ_λ(y) − y = 0,    g(z) = 0,

Pⁿ the n-fold stroboscopic map and g the scalar test function of the event
(:mod:`gearchaos.dynamics.curves.defining`: a bordered determinant of M ∓ I for folds and period
doublings, |μ_c|² − 1 for Neimark–Sacker, the contact gap over the orbit for grazing). These are
m + 1 equations in m + 2 unknowns; the curve is continued by Keller's pseudo-arclength method,
adding ⟨t_k, z − z_k − Δs t_k⟩_W = 0 (the weighted inner product ⟨a, b⟩_W = Σ aᵢbᵢ/dᵢ², d = Y√m
for the state, Y = max(1, ‖y₀‖_∞), and the ranges of λ₁ and λ₂: a state change the size of the
state counts as much as either whole range).

Why this method: it needs neither second derivatives of the map (a standard, fully extended
system for a fold carries the null vector as m more unknowns and needs D²Pⁿ) nor more
integrations than the m + 3 map evaluations of one Jacobian, which one compiled, batched
:func:`~gearchaos.dynamics.orbits.shooting.shoot` call does (the chains run in parallel): the state
columns of DG are M − I from the variational equations, the parameter columns and the whole
gradient of g are forward differences (step 10⁻⁵ of each unknown's scale) of Pⁿ and M at the
perturbed points. The corrector is a chord Newton iteration with that Jacobian, evaluated at
the predicted point, refreshed once when the iteration stalls; every iteration is one map
evaluation with tangents (g needs M). The bordered test function is as well scaled as the
smallest singular value of M ∓ I, so the corrector's tolerance means the same along the curve.

Between consecutive points the codimension-2 tests of
:func:`~gearchaos.dynamics.curves.defining.codim2_tests` are compared; a sign change is located by
the Illinois iteration on the arclength (every trial corrected onto the curve), a cusp of a fold
curve (the projected tangent reverses) by linear interpolation of the projected tangent between
the two points. The curve ends where it leaves the range of λ₂ (``vary``) or of λ₁ (``within``),
landing exactly on the bound; where the critical multiplier leaves ±1 (the event ceased to exist:
e.g. a fold curve ending at a cusp where the two folds annihilate); or after ``max_points`` points
per direction. A store is written every 20 points, so an interrupted run keeps
its work, and running again with ``resume=True`` extends the ends that did not end for good.

References: Govaerts, *Numerical Methods for Bifurcations of Dynamical Equilibria* (SIAM 2000);
Kuznetsov, *Elements of Applied Bifurcation Theory*, 3rd ed., §10.3 (two-parameter continuation
of codimension-1 bifurcations of maps); Dhooge, Govaerts, Kuznetsov, Meijer & Sautois,
MatCont (2008), which continues the same curves for smooth maps.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import ParameterError
from ...integrate.settings import SolverSettings
from ...model.system import System
from ...model.target import Target, resolve
from ..continuation import events as ev
from ..orbits.orbit import contact_levels
from ..orbits.shooting import Shot, multipliers_of, newton_step, residual_of, shoot
from .defining import TestFunction, changes

__all__ = ["Curve", "CurvePoint", "CurveSteps"]

#: Forward-difference step of the Jacobian, relative to each unknown's scale.
FD_STEP = 1e-5
#: The critical multiplier of a fold or period-doubling curve may differ from ±1 by this much.
MULTIPLIER_DRIFT = 1e-3


@dataclass(eq=False)
class CurvePoint:
    """One corrected curve point: z = (y, λ₁, λ₂), its monodromy, multipliers, test value g,
    residual ‖Pⁿ(y) − y‖, map evaluations of its corrector, the orbit's section states and
    tracked extrema; the unit tangent, the arclength s and whether it was landed on a value."""

    z: np.ndarray
    monodromy: np.ndarray
    mu: np.ndarray
    g: float
    residual: float
    evals: int
    sections: np.ndarray
    obs_min: np.ndarray
    obs_max: np.ndarray
    f: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    tangent: np.ndarray | None = None
    s: float = 0.0
    landed: bool = False
    jac: np.ndarray | None = field(default=None, repr=False)
    #: how far λ₁ and λ₂ move when the point is corrected again with the integrator and the
    #: corrector 100 times tighter: a landed point on its own λ₂ (so λ₂ moves by 0), any other
    #: on its own tangent hyperplane (NaN: not assessed)
    uncertainty: float = math.nan
    uncertainty2: float = math.nan


@dataclass(frozen=True)
class CurveSteps:
    """Step control in the weighted arclength (1 = a whole range)."""

    initial: float
    minimum: float
    maximum: float
    max_points: int
    max_corrector: int


class Curve:
    """The continuation of one boundary curve (see the module docstring)."""

    def __init__(
        self,
        target: Target,
        names: tuple[str, str],
        fixed: dict[str, Any],
        cfg: SolverSettings,
        n: int,
        tol: float,
        fn: TestFunction,
        bounds: tuple[tuple[float, float], tuple[float, float]],
        steps: CurveSteps,
    ):
        self.target, self.names, self.fixed = target, names, fixed
        self.cfg, self.n, self.tol, self.fn = cfg, n, tol, fn
        self.bounds, self.steps = bounds, steps
        self.scale = np.ones(0)
        self.evals = 0
        self._systems: dict[tuple[float, float], System] = {}
        self.events: list[dict[str, Any]] = []
        self.direction = 1  # of the run in progress: events remember it

    # -- systems, weights -----------------------------------------------------------
    def system(self, l1: float, l2: float) -> System:
        key = (float(l1), float(l2))
        sys = self._systems.get(key)
        if sys is None:
            sys = resolve(self.target, {**self.fixed, self.names[0]: key[0], self.names[1]: key[1]})
            if len(self._systems) > 64:
                self._systems.pop(next(iter(self._systems)))
            self._systems[key] = sys
        return sys

    def weight(self, t: np.ndarray) -> np.ndarray:
        return t / self.scale**2

    def wnorm(self, t: np.ndarray) -> float:
        return float(math.sqrt(max(float(t @ self.weight(t)), 0.0)))

    # -- map evaluations --------------------------------------------------------------
    def shots(self, zs: np.ndarray) -> tuple[Shot | None, str]:
        """Pⁿ and M at the points zs (one compiled call)."""
        try:
            systems = [self.system(z[-2], z[-1]) for z in zs]
        except ParameterError as exc:
            return None, f"invalid parameter values: {exc}"
        shot = shoot(systems, zs[:, :-2], self.n, self.cfg, tangents=True)
        self.evals += 1
        if not all(shot.ok(c) for c in range(len(zs))):
            return None, "integration failed"
        return shot, ""

    def residuals(self, shot: Shot, c: int, z: np.ndarray) -> np.ndarray:
        """F = (Pⁿ(y) − y, g) of chain c of ``shot`` at z."""
        assert shot.monodromy is not None
        tests = ev.contact_tests(
            contact_levels(self.system(z[-2], z[-1])), shot.obs_min[c], shot.obs_max[c]
        )
        g = self.fn.value(shot.monodromy[c], None, tests)
        return np.append(shot.end[c] - z[:-2], g)

    def point(self, shot: Shot, z: np.ndarray, evals: int) -> CurvePoint:
        assert shot.monodromy is not None
        f = self.residuals(shot, 0, z)
        return CurvePoint(
            z=z.copy(),
            monodromy=shot.monodromy[0].copy(),
            mu=multipliers_of(shot.monodromy[0]),
            g=float(f[-1]),
            residual=residual_of(f[:-1], z[:-2]),
            evals=evals,
            sections=shot.sections[0].copy(),
            obs_min=shot.obs_min[0].copy(),
            obs_max=shot.obs_max[0].copy(),
            f=f,
        )

    def jacobian(self, z: np.ndarray) -> tuple[np.ndarray, CurvePoint] | None:
        """DF (m + 1, m + 2) at z by forward differences (M − I for the state columns of G),
        with the point data at z: m + 3 chains in one call."""
        k = z.size
        m = k - 2
        h = FD_STEP * np.maximum(np.abs(z), self.scale * 1e-2)
        h[:m] = FD_STEP * max(1.0, float(np.max(np.abs(z[:m]))))
        for j in (k - 2, k - 1):  # a perturbation off the valid range goes the other way
            probe = z.copy()
            probe[j] += h[j]
            try:
                self.system(probe[-2], probe[-1])
            except ParameterError:
                h[j] = -h[j]
        zs = np.repeat(z[None], k + 1, axis=0)
        zs[1:] += np.diag(h)
        shot, _ = self.shots(zs)
        if shot is None or shot.monodromy is None:
            return None
        f0 = self.residuals(shot, 0, z)
        jac = np.empty((m + 1, k))
        for j in range(k):
            jac[:, j] = (self.residuals(shot, j + 1, zs[j + 1]) - f0) / h[j]
        jac[:m, :m] = shot.monodromy[0] - np.eye(m)
        return jac, self.point(shot.chain(0), z, 1)

    # -- corrector and tangent ----------------------------------------------------------
    def correct(
        self, zp: np.ndarray, normal: np.ndarray, offset: float
    ) -> tuple[CurvePoint | None, str]:
        """The curve point on ⟨normal, z⟩ = offset, by the chord Newton iteration from zp with
        the Jacobian at zp (refreshed once where the iteration stalls)."""
        start = self.evals
        got = self.jacobian(zp)
        if got is None:
            return None, "the map failed at the predicted point"
        jac, pt = got
        z = zp.copy()
        refreshed = False
        prev = math.inf
        tol = self.tol
        for it in range(self.steps.max_corrector):
            h = np.append(pt.f, normal @ z - offset)
            dz = newton_step(np.vstack([jac, normal]), -h)
            size = float(np.max(np.abs(dz) / np.maximum(np.abs(z), self.scale)))
            stalled = it >= 2 and size > 0.5 * prev
            if pt.residual <= tol and (size <= 10.0 * tol or stalled):
                pt.evals = self.evals - start
                pt.jac = jac
                return pt, "converged"
            if stalled:
                if refreshed:
                    break
                got = self.jacobian(z)  # a fresh Jacobian where the iteration is
                if got is None:
                    break
                jac, pt = got
                refreshed, prev = True, math.inf
                continue
            prev = size
            z = z + dz
            shot, why = self.shots(z[None])
            if shot is None:
                return None, why
            pt = self.point(shot, z, 0)
        return None, f"no convergence in {self.steps.max_corrector} corrections"

    def tangent(self, p: CurvePoint, prev: np.ndarray) -> np.ndarray:
        """The unit tangent (W norm) at p, oriented like ``prev``: the null vector of DF."""
        assert p.jac is not None
        rhs = np.zeros(p.z.size)
        rhs[-1] = 1.0
        t = newton_step(np.vstack([p.jac, self.weight(prev)]), rhs)
        t /= self.wnorm(t)
        return t if t @ self.weight(prev) >= 0 else -t

    def on_hyperplane(self, p: CurvePoint, sigma: float) -> CurvePoint | None:
        """The curve point at arclength σ from p on p's tangent hyperplane."""
        assert p.tangent is not None
        zp = p.z + sigma * p.tangent
        normal = self.weight(p.tangent)
        q, _ = self.correct(zp, normal, float(normal @ zp))
        return q

    def land(self, p: CurvePoint, j: int, value: float, grid: bool = False) -> CurvePoint | None:
        """The curve point where unknown j (−2: λ₁, −1: λ₂) equals ``value`` (flagged landed
        when ``grid``: a value of ``at``)."""
        assert p.tangent is not None
        tj = float(p.tangent[j])
        sigma = (value - p.z[j]) / tj if tj != 0 else 0.0
        normal = np.zeros(p.z.size)
        normal[j] = 1.0
        q, _ = self.correct(p.z + sigma * p.tangent, normal, value)
        if q is not None:
            q.tangent = self.tangent(q, p.tangent)
            q.landed = grid
        return q

    # -- the continuation loop ----------------------------------------------------------
    def run(
        self,
        pts: list[CurvePoint],
        at: np.ndarray,
        progress: Callable[[CurvePoint], None] | None = None,
    ) -> str:
        """Continue from the last of ``pts`` along its tangent, appending up to ``max_points``
        points to ``pts`` (the caller's list: a checkpoint sees them); returns the stop
        reason."""
        st = self.steps
        ds = st.initial
        first = len(pts)
        while True:
            if len(pts) - first >= st.max_points:
                return f"max_points ({st.max_points}) reached"
            p = pts[-1]
            assert p.tangent is not None
            zp = p.z + ds * p.tangent
            out = self._outside(zp)
            if out is not None and p.z[out[0]] == out[1]:  # already on the bound
                return f"reached the range end {self.names[out[0] + 2]}={out[1]:.8g}"
            normal = self.weight(p.tangent)
            q, why = self.correct(zp, normal, float(normal @ zp))
            if q is not None:
                q.tangent = self.tangent(q, p.tangent)
                cos = float(q.tangent @ self.weight(p.tangent))
                if cos < 0.8 and ds > 4 * st.minimum and not self._cusp_between(p, q):
                    q, why = None, f"the curve turns too sharply (cos {cos:.2f})"
            if q is None and out is not None:  # the predictor left the range: land on it
                q = self.land(p, out[0], out[1])
                if q is not None:
                    self._append(pts, q, at, progress)
                    return f"reached the range end {self.names[out[0] + 2]}={out[1]:.8g}"
            if q is None:
                ds *= 0.5
                if ds < st.minimum:
                    return f"stopped: {why}, even with the minimum step {st.minimum:.3g}"
                continue
            gone = self._left(q)
            if gone:
                return gone
            out = self._outside(q.z)
            if out is not None:
                j, bound = out
                end = self.land(p, j, bound)
                if end is None:
                    return f"could not land on the range end {self.names[j + 2]}={bound:.8g}"
                self._append(pts, end, at, progress)
                return f"reached the range end {self.names[j + 2]}={bound:.8g}"
            self._append(pts, q, at, progress)
            if q.evals <= 3:
                ds = min(ds * 1.5, st.maximum)
            elif q.evals >= 6:
                ds = max(ds * 0.6, st.minimum)

    def _left(self, q: CurvePoint) -> str:
        """Why q is no longer a point of the event continued ("" while it is)."""
        crit = self.fn.critical(q.mu)
        if self.fn.kind in ("fold", "period_doubling"):
            target = self.fn.shift()
            if not abs(crit - target) <= MULTIPLIER_DRIFT:
                return (
                    f"the critical multiplier left {target:+.0f} (μ = {crit:.6g}) at "
                    f"{self.names[0]}={q.z[-2]:.8g}, {self.names[1]}={q.z[-1]:.8g}"
                )
        if self.fn.kind == "neimark_sacker" and not np.isfinite(crit):
            return (
                f"the complex pair turned real at {self.names[0]}={q.z[-2]:.8g}, "
                f"{self.names[1]}={q.z[-1]:.8g} (a 1:1 or 1:2 resonance)"
            )
        return ""

    def _outside(self, z: np.ndarray) -> tuple[int, float] | None:
        for j, (lo, hi) in zip((-2, -1), self.bounds, strict=True):
            if z[j] > hi:
                return j, hi
            if z[j] < lo:
                return j, lo
        return None

    def _cusp_between(self, p: CurvePoint, q: CurvePoint) -> bool:
        assert p.tangent is not None and q.tangent is not None
        return self.fn.kind == "fold" and _projected(self, p) @ _projected(self, q) < 0

    def _append(
        self,
        pts: list[CurvePoint],
        q: CurvePoint,
        at: np.ndarray,
        progress: Callable[[CurvePoint], None] | None,
    ) -> None:
        """Append q after the points landed on the values ``at`` of λ₂ between, detecting the
        codimension-2 points between consecutive points."""
        p = pts[-1]
        lo, hi = sorted((p.z[-1], q.z[-1]))
        inside = at[(at > lo) & (at < hi)]
        for value in inside if q.z[-1] > p.z[-1] else inside[::-1]:
            g = self.land(p, -1, float(value), grid=True)
            if g is not None:
                self._push(pts, g, progress)
                p = g
        self._push(pts, q, progress)

    def _push(
        self, pts: list[CurvePoint], q: CurvePoint, progress: Callable[[CurvePoint], None] | None
    ) -> None:
        p = pts[-1]
        assert p.tangent is not None
        q.s = p.s + float(self.weight(p.tangent) @ (q.z - p.z))
        pts.append(q)
        self.detect(p, q)
        self.fn.adapt(q.monodromy, q.mu)
        if progress is not None:
            progress(q)

    # -- codimension-2 points -------------------------------------------------------------
    def detect(self, p: CurvePoint, q: CurvePoint) -> None:
        """Locate the codimension-2 points between consecutive points p and q."""
        assert p.tangent is not None and q.tangent is not None
        span = abs(q.s - p.s)
        sign = 1.0 if q.s >= p.s else -1.0
        for key, fa, fb in changes(self.fn, p.mu, q.mu):

            def fn(sigma: float, key: str = key) -> float | None:
                pt = self.on_hyperplane(p, sign * sigma)
                if pt is None:
                    return None
                from .defining import codim2_tests

                return codim2_tests(self.fn, pt.mu)[key]

            tol = max(span * 1e-6, 10.0 * self.tol)
            sigma, ok, (lo, hi) = ev.illinois(fn, 0.0, span, fa, fb, tol, max_evaluations=20)
            pt = self.on_hyperplane(p, sign * sigma) or q
            self._record(key, pt, p, sign * sigma, ok, (lo, hi))
        if self._cusp_between(p, q):
            a, b = _projected(self, p), _projected(self, q)
            # the projected tangent along p→q, linear in σ: its component along a vanishes at
            wa, wb = float(a @ a), float(b @ a)
            sigma = span * wa / (wa - wb) if wa != wb else 0.5 * span
            pt = self.on_hyperplane(p, sign * sigma) or q
            self._record("cusp", pt, p, sign * sigma, False, (0.0, span))

    def _record(
        self,
        kind: str,
        pt: CurvePoint,
        p: CurvePoint,
        sigma: float,
        located: bool,
        bracket: tuple[float, float],
    ) -> None:
        assert p.tangent is not None
        half = 0.5 * (bracket[1] - bracket[0])
        unc = np.abs(p.tangent[-2:]) * half
        self.events.append(
            {
                "kind": kind,
                "z": pt.z.copy(),
                "s": p.s + sigma,
                "mu": self.fn.critical(pt.mu),
                "located": located,
                "uncertainty": (float(unc[0]), float(unc[1])),
                "p": p,
                "direction": self.direction,
                "sigma": sigma,
                "bracket": bracket,
            }
        )


def _projected(curve: Curve, p: CurvePoint) -> np.ndarray:
    """The tangent's parameter components, in units of the ranges."""
    assert p.tangent is not None
    return np.asarray(p.tangent[-2:] / curve.scale[-2:])
