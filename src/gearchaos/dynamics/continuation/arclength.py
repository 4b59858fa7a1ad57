"""Pseudo-arclength continuation of periodic orbits in any parameter, with event detection.

A branch of period-n orbits is the curve of solutions z = (y, λ) of

    G(y, λ) = Pⁿ_λ(y) − y = 0,

P_λ the stroboscopic map at parameter value λ (any dotted parameter: ``omega``,
``backlash.sun_planet``, ``xi`` … or a reference system's field). From a point z_k with unit
tangent t_k the predictor is z_k + Δs t_k and the corrector solves, by Newton's method,

    G(y, λ) = 0,    ⟨t_k, z − z_k − Δs t_k⟩_W = 0

(Keller's pseudo-arclength; the second equation fixes the position along the branch, so folds
are passed), by the quasi-Newton corrector of :mod:`gearchaos.dynamics.orbits.corrector` with the
bordered Jacobian [[M − I, G_λ], [W t_kᵀ]]: M = DPⁿ from the variational equations, G_λ by a
forward difference (two chains of one compiled call), both started from the previous point's,
extrapolated along the branch. The next tangent solves [[M − I, G_λ], [W t_kᵀ]] t = (0, 1)
with M and G_λ at the new point. The weighted inner product
⟨a, b⟩_W = κ² a_y·b_y + a_λ b_λ, κ = (λ range)/(Y √n_state), Y = max(1, ‖y_0‖_∞), measures
arclength in units of the parameter: a state change of the size of the state counts as the
whole range. The step grows after corrector solves of ≤ 3 Newton steps, shrinks after ≥ 6,
and halves after a failure, down to ``min_step`` where the continuation stops with the reason.

Between consecutive points the test functions of :mod:`gearchaos.dynamics.continuation.events`
detect
folds, branch points, period doublings, Neimark–Sacker and grazing events; each is located by
the Illinois iteration on the arclength, every trial point corrected onto the branch. A branch
started at a period-doubling event (``start=event``) is the period-2n branch, so cascades can
be followed; at a branch point the same switch starts the other branch.

Every map evaluation is one compiled :func:`~gearchaos.integrate._chains.run_chains` call
(:func:`~gearchaos.dynamics.orbits.shooting.shoot`).
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..._checks import check_bool, check_int, check_real, got
from ...errors import IntegrationError, ParameterError
from ...integrate.settings import SolverSettings, split_keywords
from ...model.system import System
from ...model.target import OMEGA, Target, resolve
from ..orbits.corrector import Problem, Solution, Start, correct
from ..orbits.orbit import (
    ORBIT_SETTINGS,
    PeriodicOrbit,
    check_tol,
    contact_levels,
    initial_guess,
    settled_orbit,
    solve_orbit,
)
from ..orbits.shooting import newton_step
from . import events as ev
from .cascade import check_cascade
from .locate import detect

__all__ = ["continuation", "parse_vary"]


# ------------------------------------------------------------------------------ arguments
def parse_vary(vary: Any, what: str = "vary") -> tuple[str, float, float]:
    """``"omega=0.2:4"``, ``("omega", 0.2, 4)`` or ``{"omega": (0.2, 4)}`` → (name, a, b).

    ``what`` is the keyword the range was given as (``vary``, ``within``): every refusal starts
    with it and carries it as its :attr:`~gearchaos.errors.ParameterError.name`, so that a
    front end can name its own option."""
    example = f"{what} must look like 'omega=0.2:4' (NAME=START:STOP): got {vary!r}"
    if isinstance(vary, str):
        name, sep, rng = vary.partition("=")
        parts = rng.split(":")
        if not sep or len(parts) != 2 or not name.strip():
            raise ParameterError(example, name=what)
        try:
            a, b = float(parts[0]), float(parts[1])
        except ValueError:
            raise ParameterError(example, name=what) from None
        name = name.strip()
    elif isinstance(vary, Mapping) and len(vary) == 1:
        ((name, rng),) = vary.items()
        if not isinstance(rng, tuple | list) or len(rng) != 2:
            raise ParameterError(
                f"{what} must map one name to (start, stop): got {vary!r}", name=what
            )
        a, b = rng
    elif isinstance(vary, tuple | list) and len(vary) == 3:
        name, a, b = vary
    else:
        raise ParameterError(
            f"{what} must be 'NAME=START:STOP', (NAME, START, STOP) or {{NAME: (START, STOP)}}: "
            f"got {vary!r}",
            name=what,
        )
    if not isinstance(name, str) or not name.strip():
        raise ParameterError(f"{what} must name a parameter: got {vary!r}", name=what)
    ends = []
    for which, value in (("start", a), ("stop", b)):
        try:
            ends.append(check_real(which, value))
        except ParameterError:
            raise ParameterError(
                f"{what} {name}: its {which} must be a finite number: {got(value)} (in {vary!r})",
                name=what,
            ) from None
    a, b = ends
    if a == b:
        raise ParameterError(
            f"{what} {name}: its start and stop must differ: got {a!r} twice", name=what
        )
    return str(name), a, b


# ------------------------------------------------------------------------------ the branch
@dataclass(frozen=True)
class Steps:
    """Step control of a continuation, in arclength (parameter units)."""

    initial: float
    minimum: float
    maximum: float
    max_points: int
    max_corrector: int
    event_tol: float


class _Branch:
    """The continuation of one branch: corrector, tangents, steps and events."""

    def __init__(
        self,
        target: Target,
        name: str,
        fixed: dict[str, Any],
        cfg: SolverSettings,
        n: int,
        tol: float,
        steps: Steps,
        lo: float,
        hi: float,
    ):
        self.target, self.name, self.fixed = target, name, fixed
        self.cfg, self.n, self.tol, self.steps = cfg, n, tol, steps
        self.lo, self.hi = lo, hi
        self.kappa = 1.0
        self.evals = 0
        self.jacobians = 0
        self.stop = math.nan
        self.levels: list[tuple[str, int, float, str]] = []
        self.found: list[ev.Event] = []
        self._systems: dict[float, System] = {}
        self.grid = np.empty(0)
        self.switched = False
        self._slopes: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        self.prob = Problem(
            n, cfg, tol, steps.max_corrector, fd_step=1e-6 * max(1.0, abs(lo), abs(hi))
        )

    # -- systems and the weighted norm ----------------------------------------------
    def system(self, lam: float) -> System:
        """The system at parameter value λ (the last few kept: corrector, finite differences
        and event location ask for the same values again)."""
        lam = float(lam)
        sys = self._systems.get(lam)
        if sys is None:
            sys = resolve(self.target, {**self.fixed, self.name: lam})
            if len(self._systems) > 16:
                self._systems.pop(next(iter(self._systems)))
            self._systems[lam] = sys
        return sys

    def weight(self, t: np.ndarray) -> np.ndarray:
        """W t."""
        w = t.copy()
        w[:-1] *= self.kappa**2
        return w

    def wnorm(self, t: np.ndarray) -> float:
        return float(math.sqrt(max(float(t @ self.weight(t)), 0.0)))

    # -- corrector ------------------------------------------------------------------
    def correct(
        self,
        z: np.ndarray,
        normal: np.ndarray,
        offset: float,
        near: Solution | None = None,
        sigma: float = 0.0,
    ) -> tuple[Solution | None, str]:
        """The branch point on the hyperplane ⟨normal, z⟩ = offset, by a quasi-Newton
        iteration from ``near``'s Jacobian, extrapolated along the branch by σ with the slope
        from the point before it (a Jacobian evaluation when there is no ``near``)."""
        mono = g_lam = None
        if near is not None:
            mono, g_lam = near.monodromy, near.g_lam
            slope = self._slopes.get(id(near))
            if slope is not None:
                mono = mono + sigma * slope[0]
                g_lam = g_lam + sigma * slope[1]
        sol, why = correct(self.prob, Start(self.system, z, normal, offset, mono, g_lam))
        if sol is not None:
            self.evals += sol.evals
            self.jacobians += sol.jacobians
        return sol, why

    def tangent(self, p: Solution, prev: np.ndarray) -> np.ndarray:
        """The unit tangent at p, oriented like ``prev`` (in the W inner product)."""
        m = p.y.size
        jac = np.zeros((m + 1, m + 1))
        jac[:-1, :-1] = p.monodromy - np.eye(m)
        jac[:-1, -1] = p.g_lam
        jac[-1] = self.weight(prev)
        rhs = np.zeros(m + 1)
        rhs[-1] = 1.0
        t = newton_step(jac, rhs)
        t /= self.wnorm(t)
        if t @ self.weight(prev) < 0:
            t = -t
        return t

    def at_arclength(self, p: Solution, sigma: float) -> Solution | None:
        """The branch point at arclength σ from p along p's tangent hyperplane."""
        assert p.tangent is not None
        zp = p.z + sigma * p.tangent
        normal = self.weight(p.tangent)
        q, _ = self.correct(zp, normal, float(normal @ zp), near=p, sigma=sigma)
        return q

    # -- the continuation loop --------------------------------------------------------
    def run(self, p0: Solution, t0: np.ndarray, switched: str) -> tuple[list[Solution], str]:
        """Continue from p0 with tangent t0 until the range ends, a step fails at the minimum
        step or ``max_points`` is reached; returns the points and the stop reason.
        ``switched`` names the event kind a switched branch starts from ("" otherwise)."""
        p0.tangent = t0
        self.switched = bool(switched)
        pts = [p0]
        st = self.steps
        ds = st.initial
        while True:
            if len(pts) >= st.max_points:
                return pts, f"max_points ({st.max_points}) reached"
            p = pts[-1]
            assert p.tangent is not None
            zp = p.z + ds * p.tangent
            normal = self.weight(p.tangent)
            q, why = self.correct(zp, normal, float(normal @ zp), near=p, sigma=ds)
            doubled = switched == "period_doubling" and len(pts) == 1
            if q is not None and doubled and self._is_subharmonic_lost(q):
                q, why = None, "the corrector fell back onto the period-n/2 branch"
            if q is not None:
                q.tangent = self.tangent(q, p.tangent)
                cos = float(q.tangent @ self.weight(p.tangent))
                if cos < 0.8 and ds > 4 * st.minimum:
                    q, why = None, f"the branch turns too sharply (cos {cos:.2f})"
            if q is None:
                ds *= 0.5
                if ds < st.minimum:
                    return pts, (
                        f"stopped at {self.name}={p.lam:.8g}: {why}, "
                        f"even with the minimum step {st.minimum:.3g}"
                    )
                continue
            if not self.lo <= q.lam <= self.hi:
                bound = self.hi if q.lam > self.hi else self.lo
                end = self._land(p, bound)
                if end is None:
                    return pts, f"could not land on the range end {self.name}={bound:.8g}"
                self._extend(pts, end)
                where = "stop" if bound == self.stop else "start"
                return pts, f"reached the range {where} {self.name}={bound:.8g}"
            self._extend(pts, q)
            if q.corrections <= 3:
                ds = min(ds * 1.5, st.maximum)
            elif q.corrections >= 6:
                ds = max(ds * 0.6, st.minimum)

    def _extend(self, pts: list[Solution], q: Solution) -> None:
        """Append q to the branch, after the points landed on grid values between the last
        point and q, detecting the events between consecutive points."""
        p = pts[-1]
        lo, hi = sorted((p.lam, q.lam))
        inside = self.grid[(self.grid > lo) & (self.grid < hi)]
        ordered = inside if q.lam > p.lam else inside[::-1]
        for value in ordered:
            g = self._land(p, float(value))
            if g is None:  # a grid value the corrector cannot land on: leave it out
                continue
            g.landed = True
            self._append(pts, g)
            p = g
        self._append(pts, q)

    def _append(self, pts: list[Solution], q: Solution) -> None:
        p = pts[-1]
        assert p.tangent is not None
        q.s = p.s + float(self.weight(p.tangent) @ (q.z - p.z))
        if q.s > p.s:  # the change of M and G_λ per unit arclength, to extrapolate from q
            h = q.s - p.s
            self._slopes[id(q)] = ((q.monodromy - p.monodromy) / h, (q.g_lam - p.g_lam) / h)
        pts.append(q)
        self.detect(p, q, len(pts) - 2)

    def _land(self, p: Solution, bound: float) -> Solution | None:
        """The branch point at λ = bound (natural-parameter corrector from p's tangent)."""
        assert p.tangent is not None
        tl = float(p.tangent[-1])
        sigma = (bound - p.lam) / tl if tl != 0 else 0.0
        normal = np.zeros(p.y.size + 1)
        normal[-1] = 1.0
        q, _ = self.correct(p.z + sigma * p.tangent, normal, bound, near=p, sigma=sigma)
        if q is None:
            return None
        q.tangent = self.tangent(q, p.tangent)
        return q

    def _is_subharmonic_lost(self, q: Solution) -> bool:
        """True when a point of a period-2n branch repeats after n periods (a 1T point)."""
        secs = q.shot.sections[0]
        half = self.n // 2
        scale = max(1.0, float(np.max(np.abs(secs))))
        gap = float(np.max(np.abs(q.shot.end[0] - secs[half])))
        gap = max(gap, float(np.max(np.abs(secs[half] - secs[0]))))
        return gap <= max(1e-6, 100 * self.tol) * scale

    # -- events -------------------------------------------------------------------------
    def detect(self, p: Solution, q: Solution, index: int) -> None:
        """Find, locate and record the events between consecutive points p and q
        (:func:`gearchaos.dynamics.continuation.locate.detect`)."""
        self.found.extend(detect(self, p, q, index))


# ------------------------------------------------------------------------------ front door
def continuation(
    target: Target,
    vary: Any,
    *,
    period: int | None = None,
    start: Any = None,
    settings: SolverSettings | None = None,
    params: Mapping[str, Any] | None = None,
    step: float | None = None,
    min_step: float | None = None,
    max_step: float | None = None,
    max_points: int = 2000,
    max_corrector: int = 12,
    tol: float | None = None,
    event_tol: float | None = None,
    grid: Any = None,
    observe: Any = None,
    store: str | os.PathLike[str] | None = None,
    overwrite: bool = False,
    cascade: int | None = None,
    cascade_every: bool = False,
    cascade_range: tuple[float, float] | None = None,
    max_branches: int | None = None,
    **values_and_settings: Any,
) -> Any:
    """Continue a branch of period-n orbits in one parameter (pseudo-arclength).

    Parameters
    ----------
    target
        The gear set (:class:`~gearchaos.gearset.GearSet`) or
        :class:`~gearchaos.model.System` whose orbits are continued.
    vary
        The parameter and its range: ``"omega=0.2:4"``, ``("backlash.sun_planet", 4, 1)`` or
        ``{"xi": (0.03, 0.11)}``. The branch starts at START (or at ``start``) heading towards
        STOP and ends where it leaves [min, max] of the range.
    period
        n, in forcing periods (default 1, or what ``start`` implies).
    start
        ``None`` (the orbit at START from a simulation of ``transient_periods``, as
        :func:`~gearchaos.dynamics.orbits.orbit.periodic_orbit`), a state (the Newton guess at
        START), a :class:`~gearchaos.dynamics.orbits.orbit.PeriodicOrbit` (its state, at its Ω or
        its value of the parameter), or an :class:`~gearchaos.dynamics.Event` of
        kind ``period_doubling`` (start the period-2n branch there) or ``branch_point``
        (the other branch, same n), with the target, fixed values and settings of the
        branch it was found on.
    settings, params, **values_and_settings
        Fixed parameter values by name (``omega=1.5`` when another parameter is varied,
        ``params={"backlash.planet_ring": 3}``) and solver settings by name or as a
        :class:`~gearchaos.integrate.settings.SolverSettings`, as for ``periodic_orbit``.
    step, min_step, max_step
        Initial, smallest and largest arclength step (parameter units; defaults: range/200,
        range·1e-6, range/100).
    max_points, max_corrector
        Most branch points, and rounds of the corrector per solve (a trial step, the damped
        steps of one step, or a fresh Jacobian each).
    tol
        Residual tolerance of every point (default 100·rtol, at least 1e-10).
    event_tol
        Arclength tolerance of the event location (default range·``tol``: a state change of
        relative size ``tol``, what the corrector resolves, counts as that much arclength).
        Every event reports its location uncertainty in the parameter (the final bracket
        and the integrator's error of its test function, see
        :mod:`gearchaos.dynamics.continuation.locate`).
    grid
        Parameter values to land on: every time the branch passes one, a branch point is
        computed exactly there (flagged ``on_grid``), e.g. a sweep's grid, to compare
        orbits with brute-force section points.
    observe
        Variables stored at the section points (default ``delta_sp`` and ``delta_sp_dot``
        for gear sets, the first tracked observable and its derivative otherwise).
    store
        A path ending in ``.nc`` (netCDF-4 via h5netcdf) or ``.zarr`` to save the branch
        (with ``cascade``: ``.nc``, every branch in one file,
        :func:`~gearchaos.dynamics.continuation.cascade.save_cascade`).
    cascade
        After the branch, follow the period-doubling cascade to this depth
        (:mod:`gearchaos.dynamics.continuation.cascade`): at every period doubling the period-2n
        branch
        born there (``start=event``, with the same settings, fixed values and steps), then
        at every period doubling of those, … ``cascade`` doublings deep.
    cascade_every
        Also switch at period doublings where the parent is unstable on both sides (by
        default only where the attractor doubles: stable on one side).
    cascade_range
        (lo, hi): the range of the period-2n branches (default: vary's); each heads for the
        end its parent heads for.
    max_branches
        Most branches of the cascade, this one included (default: no limit).

    Returns
    -------
    xarray.Dataset or list of xarray.Dataset
        One branch: dimension ``point`` (coordinates: the parameter, ``arclength``), per
        point ``orbit_state``, multipliers, ``stable``, ``residual``, ``iterations``,
        section values, extrema and contact regimes; dimension ``event`` with the located
        events; attributes with the stop reason and provenance
        (see :func:`gearchaos.dynamics.continuation.branch.branch_dataset`). With ``cascade`` (even
        0)
        the list of the cascade's branches, this one first, each naming its ``parent`` and
        ``parent_event`` (:func:`~gearchaos.dynamics.continuation.cascade.follow_cascade`).
    """
    from .branch import branch_dataset, check_observe, check_store, save_branch

    name, a, b = parse_vary(vary)
    if store is not None:
        check_store(store, overwrite)
    check_bool("overwrite", overwrite)
    check_bool("cascade_every", cascade_every)
    child_range = check_cascade(cascade, cascade_range, max_branches, store, a, b)
    values, cfg = split_keywords(
        values_and_settings, settings, params, ORBIT_SETTINGS, door=continuation, target=target
    )
    if name in values:
        raise ParameterError(f"{name} is varied and cannot also be fixed")
    lo, hi = min(a, b), max(a, b)
    span = hi - lo
    steps = Steps(
        initial=_pos("step", step, span / 200.0),
        minimum=_pos("min_step", min_step, span * 1e-6),
        maximum=_pos("max_step", max_step, span / 100.0),
        max_points=check_int("max_points", max_points, lo=2, hi=1_000_000),
        max_corrector=check_int("max_corrector", max_corrector, lo=2, hi=1000),
        event_tol=_pos("event_tol", event_tol, math.nan),
    )
    if steps.minimum > steps.maximum or (
        step is not None and not steps.minimum <= steps.initial <= steps.maximum
    ):
        raise ParameterError(
            "the steps must satisfy min_step <= step <= max_step: got min_step = "
            f"{steps.minimum:g}, step = {steps.initial:g}, max_step = {steps.maximum:g}"
        )
    if step is None:  # the default first step inside the bounds given
        steps = replace(steps, initial=min(max(steps.initial, steps.minimum), steps.maximum))
    eps = check_tol(tol, cfg)
    if event_tol is None:  # what the corrector resolves, above the arclength's round-off
        steps = replace(steps, event_tol=span * max(eps, 1e-14))

    n, lam0, guess, switch = _start(start, period, name, a)
    if not lo <= lam0 <= hi:
        raise ParameterError(f"the start {name}={lam0:g} lies outside the range [{lo:g}, {hi:g}]")
    br = _Branch(target, name, values, cfg, n, eps, steps, lo, hi)
    br.stop = b
    if grid is not None:
        try:
            if np.asarray(grid).dtype.kind not in "fiu":  # bools, text, objects
                raise TypeError(grid)
            values_grid = np.asarray(grid, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            raise ParameterError(f"grid must be numbers: got {grid!r}") from None
        if not np.all(np.isfinite(values_grid)):
            raise ParameterError(f"grid must be finite numbers: got {grid!r}")
        br.grid = np.unique(values_grid)
    system0 = br.system(lam0)
    br.system(b)  # the range's other end must be a valid value too (refused before any run)
    check_observe(system0, observe)
    system0.warn_for("Poincaré section")
    br.levels = contact_levels(system0)
    if switch is None:
        if guess is None or (isinstance(guess, PeriodicOrbit) and guess.period != n):
            # from rest, settled longer while the shooting does not converge
            orbit = settled_orbit(system0, n, cfg, eps, 40, want_stable=False)
        else:
            orbit = solve_orbit(
                system0, initial_guess(system0, guess, n, cfg, what="start"), n, cfg, eps, 40
            )
        if not orbit.converged:
            raise IntegrationError(
                f"no period-{n} orbit converged at {name}={lam0:g} ({orbit.message}, residual "
                f"{orbit.residual:.3g}); start from a better state: start= a state or a "
                "PeriodicOrbit (gearchaos continue --from STORE --at NAME=VALUE, a branch or "
                "an orbit file), or settle longer (transient_periods, --transient)"
            )
        y0 = orbit.state
    else:
        y0 = initial_guess(system0, guess, n, cfg, what="start")
    br.kappa = span / (max(1.0, float(np.max(np.abs(y0)))) * math.sqrt(y0.size))
    e_lam = np.zeros(y0.size + 1)
    e_lam[-1] = 1.0
    # a switch starts at the bifurcation point itself (a period-n orbit, M − I singular there)
    p0, why = br.correct(np.append(y0, lam0), e_lam, lam0)
    if p0 is None and switch is not None:  # accept the located event point as it is
        br.prob = replace(br.prob, tol=math.inf)
        p0, why = br.correct(np.append(y0, lam0), e_lam, lam0)
        br.prob = replace(br.prob, tol=eps)
    if p0 is None:
        raise IntegrationError(f"the start point at {name}={lam0:g} failed: {why}")
    p0.landed = bool(np.any(br.grid == lam0))
    if switch is None:
        t0 = br.tangent(p0, e_lam * (1.0 if b > lam0 else -1.0))
    else:
        t0 = np.append(switch, 0.0)
        t0 /= br.wnorm(t0)
    pts, reason = br.run(p0, t0, "" if switch is None else start.kind)
    ds = branch_dataset(
        br, pts, sorted(br.found, key=lambda e: e.arclength), reason, (a, b), observe, start
    )
    if cascade is not None:
        from .cascade import follow_cascade, save_cascade

        def child(event: ev.Event) -> Any:
            return continuation(
                target, (name, *child_range), start=event, settings=cfg, params=values,
                step=step, min_step=min_step, max_step=max_step, max_points=max_points,
                max_corrector=max_corrector, tol=tol, event_tol=event_tol, grid=grid,
                observe=observe,
            )  # fmt: skip

        branches = follow_cascade(
            ds, child, cascade, every=cascade_every, max_branches=max_branches
        )
        if store is not None:
            save_cascade(branches, store, overwrite=overwrite)
        return branches
    if store is not None:
        save_branch(ds, store, overwrite=overwrite)
    return ds


def _pos(name: str, value: float | None, default: float) -> float:
    if value is None:
        return default
    return check_real(name, value, lo=0.0, lo_open=True)


def _start(start: Any, period: int | None, name: str, a: float) -> tuple[int, float, Any, Any]:
    """(period, λ0, guess, switch direction or None) from the ``start`` argument."""
    n = None if period is None else check_int("period", period, lo=1, hi=10_000)
    if isinstance(start, ev.Event):
        if start.kind == "period_doubling":
            want = 2 * start.period
        elif start.kind == "branch_point":
            want = start.period
        else:
            raise ParameterError(
                f"start events must be period_doubling or branch_point: got {start.kind}"
            )
        if start.parameter != name:
            raise ParameterError(f"the event was found varying {start.parameter}, not {name}")
        if n is not None and n != want:
            raise ParameterError(f"period must be {want} to switch at {start!r}: got {n}")
        if not np.any(start.vector):
            raise ParameterError(f"{start!r} carries no eigenvector to switch along")
        return want, float(start.value), start.state, np.asarray(start.vector, dtype=float)
    if isinstance(start, PeriodicOrbit):
        lam0 = start.omega if name == OMEGA else float(start.values.get(name, a))
        return (n or start.period), lam0, start, None
    return (n or 1), a, start, None
