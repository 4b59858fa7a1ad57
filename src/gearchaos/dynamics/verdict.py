"""The motion verdict: one decision procedure for what an attractor is, with its evidence.

A label is a claim about the motion, and the project owns the tools to check it. The verdict
asks them, for K points at once (a sweep task, or one point):

1. **Candidates from the record.** The recorded section sequence (full states), with the
   windows of any extension appended, repeats with period n when ‖x_{k+n} − x_k‖ ≤
   ``period_rtol``·S + ε for every k, S the attractor's size and ε = ``noise_factor``·(atol +
   rtol·max|x|) the integration's noise floor. A sequence that does not repeat but whose
   recurrence gaps decay geometrically, or that lingers near a period, gives an *approach*
   candidate.
2. **Orbits by shooting** (:mod:`~gearchaos.dynamics.verdict_orbits`): Newton on Pⁿ(y) − y = 0
   from the final state; a repeat candidate that fails has its divisors shot (an alternating
   approach along a multiplier near −1). A converged orbit has its multipliers computed with
   accurate tangents, its structural multipliers set aside, and is stable by the one criterion
   of :mod:`~gearchaos.dynamics.stability` (every other |μ| < 1 − ``margin``). A stable orbit
   is the label only when the record lies within ``reach`` of it; when the record's distance
   from it shrinks at a rate its multipliers allow, the run is continued until it does
   (``settle_budget``), and the record shown is that continuation — never the orbit's own
   points in place of the trajectory. A stable orbit the record does not approach *coexists*:
   it is reported with the verdict, not as its label. An unstable orbit the record sits on is
   left along its unstable eigenvector.
3. **Windows with a Lyapunov exponent** (:mod:`~gearchaos.dynamics.verdict_rules`): every point
   not decided is integrated further, one window at a time (the first as long as the record,
   at least ``min_extension``, the second as long, each next one twice as long, at most
   ``max_window``), with one
   tangent vector: λ₁ ± σ per window, θ = c_θ/t its bias bound. Chaos needs the interval above
   the bound (or positive with the 0–1 test chaotic on every band) in two consecutive windows;
   QP needs the interval within the bound and a torus on the section (the rotation test on
   each band, or a regular 0–1 test for every stride). Each window goes back to step 1.
4. **Unresolved, with its reason**, when ``budget_periods`` is spent.

Every :class:`~gearchaos.dynamics.evidence.Verdict` carries the label, the evidence code, the
max |μ| of the orbit (confirmed or unstable), λ₁ ± σ with the window it was measured over, the
0–1 test, the periods integrated, the stable orbits that coexist and a sentence saying why.
Where the run was continued, its record (``Verdict.record``) is the continuation's, so a label
is never shown beside the unfinished transient that preceded it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._checks import check_int, check_real
from ..analysis.classify import LLE_C
from ..analysis.motion import Motion
from ..analysis.periodicity import periods_of
from ..analysis.recurrence import converging_period, near_period, noise_floor
from ..errors import ParameterError
from ..integrate.settings import SolverSettings
from ..model.system import System
from .evidence import Verdict
from .extension import VerdictRecord, extend
from .lyapunov import LYAPUNOV_BLOCKS, exponent_estimate
from .stability import STABILITY_MARGIN
from .verdict_orbits import Found, Settle, approach_rate, shoot_candidates
from .verdict_rules import SectionTests, Window, decide_by_exponent

__all__ = ["CONFIRM_PERIODS", "VerdictSettings", "confirmed_settings", "decide_motion"]

#: Default length of the last window behind a chaos or QP entry of ``attractors``, ``basins``
#: and ``basin_fractions``: a long continuation that a chaotic transient rarely survives.
CONFIRM_PERIODS = 2000


@dataclass(frozen=True)
class VerdictSettings:
    """Tolerances and budget of :func:`decide_motion`.

    Parameters
    ----------
    max_period
        Longest period confirmed by shooting (Newton with the full monodromy over n periods).
    longest_period
        Longest period recognised in a record at all; QP is considered only once the record
        is at least twice this long.
    period_rtol
        Recurrence tolerance relative to the attractor's size S.
    noise_factor
        The noise floor ε = noise_factor · (atol + rtol · max|x|) of the section points.
    margin
        Stability margin: a stable orbit has every non-structural |μ| < 1 − margin
        (:data:`~gearchaos.dynamics.stability.STABILITY_MARGIN`).
    same_orbit
        Largest distance (∞-norm, relative to max(1, ‖y*‖)) between the final state and an
        unstable orbit's section points for the motion to sit on it.
    reach
        A record lies on its orbit when every recorded section is within reach ·
        max(1, ‖y*‖) (∞-norm) of the orbit's section points: the tolerance of every nT
        label's record.
    approach
        A record whose recurrence gaps over its last quarter stay within this fraction of
        max(1, max|x|) lingers near a periodic orbit: that period is shot.
    extension_periods
        Length of the first window (None: the record's length, at least ``min_extension``).
    min_extension
        Shortest first window when ``extension_periods`` is None.
    max_window
        Longest window (each window is twice as long as the one before).
    budget_periods
        Most periods added to a point by windows.
    settle_budget
        Most periods integrated to bring a record that approaches a stable orbit onto it.
    confirm_periods
        Chaos and QP need a last window at least this long (0: any; ``attractors`` and the
        basin tools use 2000, a long continuation that a chaotic transient rarely survives).
    max_bands
        Most curves or bands of the section the torus test looks for.
    newton_iterations, newton_contraction, newton_tol
        The shooting's iteration limit, early give-up factor over three iterations and
        tolerance (relative to max(1, ‖y‖)).
    tangent_tol
        Factor on the integrator's tolerances for the Newton iteration's monodromy columns
        (cheap tangents for Newton; the multipliers stated are computed once more at the
        state's tolerances, factor 1).
    lyapunov_tol
        The same factor for a window's Lyapunov vector (infinite: the vector takes the state's
        steps, and the state is bitwise that of a plain run).
    blocks, confidence
        Block means of the λ₁ error estimate, and the half-width c of its interval in
        standard errors.
    lle_c
        c_θ of the finite-time bias bound θ = c_θ / t.
    seed
        Seed of the random initial tangent vectors.
    """

    max_period: int = 8
    longest_period: int = 64
    period_rtol: float = 1e-3
    noise_factor: float = 1e3
    margin: float = STABILITY_MARGIN
    same_orbit: float = 1e-2
    reach: float = 1e-3
    approach: float = 2e-2
    extension_periods: int | None = None
    min_extension: int = 100
    max_window: int = 1600
    budget_periods: int = 6300
    settle_budget: int = 6000
    confirm_periods: int = 0
    max_bands: int = 8
    tangent_tol: float = 1000.0
    lyapunov_tol: float = math.inf
    newton_tol: float = 1e-7
    newton_iterations: int = 10
    newton_contraction: float = 0.25
    blocks: int = LYAPUNOV_BLOCKS
    confidence: float = 2.0
    lle_c: float = LLE_C
    seed: int = 0

    def __post_init__(self) -> None:
        check_int("max_period", self.max_period, lo=1, hi=64)
        check_int("longest_period", self.longest_period, lo=self.max_period, hi=10_000)
        check_real("period_rtol", self.period_rtol, lo=0.0, hi=0.5, lo_open=True)
        check_real("noise_factor", self.noise_factor, lo=1.0)
        check_real("margin", self.margin, lo=0.0, hi=0.5)
        check_real("same_orbit", self.same_orbit, lo=0.0, hi=1.0, lo_open=True)
        check_real("reach", self.reach, lo=0.0, hi=1.0, lo_open=True)
        check_real("approach", self.approach, lo=0.0, hi=1.0)
        if self.extension_periods is not None:
            check_int("extension_periods", self.extension_periods, lo=2 * self.blocks + 1)
        check_int("min_extension", self.min_extension, lo=2 * self.blocks + 1, hi=10**6)
        check_int("max_window", self.max_window, lo=2 * self.blocks + 1, hi=10**7)
        check_int("budget_periods", self.budget_periods, lo=0, hi=10**7)
        check_int("settle_budget", self.settle_budget, lo=0, hi=10**7)
        check_int("confirm_periods", self.confirm_periods, lo=0, hi=10**7)
        check_int("max_bands", self.max_bands, lo=1, hi=64)
        check_real("tangent_tol", self.tangent_tol, lo=1.0, hi=1e6)
        if not (isinstance(self.lyapunov_tol, int | float) and self.lyapunov_tol == math.inf):
            check_real("lyapunov_tol", self.lyapunov_tol, lo=1.0, hi=1e8)
        check_real("newton_tol", self.newton_tol, lo=0.0, hi=1e-3, lo_open=True)
        check_int("newton_iterations", self.newton_iterations, lo=1, hi=100)
        check_real("newton_contraction", self.newton_contraction, lo=0.0, hi=1.0, lo_open=True)
        check_int("blocks", self.blocks, lo=2, hi=1000)
        check_real("confidence", self.confidence, lo=0.0, lo_open=True)
        check_real("lle_c", self.lle_c, lo=0.0, lo_open=True)
        check_int("seed", self.seed, lo=0)

    def extension_for(self, record_periods: int) -> int:
        """Periods of the first window after a record of ``record_periods``."""
        if self.extension_periods is not None:
            return int(self.extension_periods)
        return min(max(int(record_periods), self.min_extension), self.max_window)

    def next_window(self, previous: int, count: int) -> int:
        """Periods of the window after ``count`` windows, the last of ``previous`` periods:
        the second as long as the first (a later window to confirm what the first says),
        each one after it twice as long (θ and σ shrink for a weak exponent), at most
        ``max_window``, and at least ``confirm_periods`` once a window has run."""
        grow = 1 if count == 1 else 2
        return max(min(grow * int(previous), self.max_window), self.confirm_periods)


def confirmed_settings(confirm_periods: int = CONFIRM_PERIODS) -> VerdictSettings:
    """The verdict of the attractor tools: chaos and QP need a last window of at least
    ``confirm_periods`` (and the budget for two such windows after the first)."""
    c = check_int("confirm_periods", confirm_periods, lo=0, hi=10**6)
    base = VerdictSettings()
    return VerdictSettings(confirm_periods=c, budget_periods=max(base.budget_periods, 2 * c + 600))


#: Most section states of a point's contiguous history kept (slow approaches are measured
#: over it).
HISTORY = 1000


# ----------------------------------------------------------------------------- decision
@dataclass
class _Point:
    """Working state of one undecided point."""

    sections: np.ndarray  # the latest record (window)
    final: np.ndarray
    history: np.ndarray  # the contiguous records so far, newest last (capped)
    extra: int = 0
    windows: list[Window] = field(default_factory=list)
    tests: SectionTests | None = None
    prev_tests: SectionTests | None = None
    unstable: tuple[int, float, np.ndarray] | None = None
    record: VerdictRecord | None = None
    long_period: int = 0
    tried: set[int] = field(default_factory=set)  # approach periods shot in vain
    coexisting: dict[int, float] = field(default_factory=dict)
    settle: Settle | None = None
    settled_extra: int = 0  # periods spent settling
    approaching: int = 0  # a stable orbit the record may approach (too short to tell): its period
    fresh: bool = False  # the latest window's λ₁ belongs to the current record


def _record_periods(
    records: list[np.ndarray], settings: SolverSettings, vs: VerdictSettings
) -> list[int]:
    """The record period of each section record (0: none), at its own noise floor; records of
    one shape in one batch."""
    out = [0] * len(records)
    by_shape: dict[tuple[int, ...], list[int]] = {}
    for i, x in enumerate(records):
        by_shape.setdefault(x.shape, []).append(i)
    for idx in by_shape.values():
        batch = np.stack([records[i] for i in idx])
        floor = noise_floor(batch, settings, vs.noise_factor)
        found = periods_of(
            batch, max_period=vs.longest_period, rtol=vs.period_rtol, atol=floor, floor=floor
        )
        for i, n in zip(idx, found.tolist(), strict=True):
            out[i] = int(n)
    return out


def _floquet(p: _Point, f: Found, system: System, how: str) -> Verdict:
    T = system.period
    d, mu = f.period, f.max_multiplier
    structural = (
        f"; {f.structural} structural multiplier(s) equal to 1 (a free direction) set aside"
        if f.structural
        else ""
    )
    record = (
        "the record lies on it"
        if p.record is None
        else f"the run was continued {p.extra} periods until its record lay on it"
    )
    return Verdict(
        label=Motion.periodic(d).format(),
        period=d,
        evidence="floquet",
        max_multiplier=mu,
        lle=math.log(mu) / (d * T) if mu > 0 else -math.inf,
        lle_error=0.0,
        extra_periods=p.extra,
        reason=(
            f"a period-{d} orbit converged by shooting, every Floquet multiplier "
            f"|μ| ≤ {mu:.6g} < 1{structural}; {record}"
        ),
        record=p.record,
        orbit_state=f.state.copy(),
        coexisting=tuple(sorted((k, v) for k, v in p.coexisting.items() if k != d)),
    )


def _reach(f: Found, record: np.ndarray, settings: SolverSettings, vs: VerdictSettings) -> float:
    """How close every recorded section must lie to orbit f for the record to be on it:
    ``reach`` · max(1, ‖y*‖), and at most half the recurrence tolerance of the record
    (period_rtol · S + ε, S the orbit's size, ε the noise floor at unit magnitude): a record
    on its orbit then also repeats with its period by the record's own test, so its figure
    shows n points."""
    scale = max(1.0, float(np.max(np.abs(f.state))))
    size = float(np.max(np.ptp(f.sections, axis=0))) if f.sections.shape[0] > 1 else 0.0
    # the noise floor at unit magnitude: a figure's observable (a mesh deflection of order
    # one) must repeat by its own test too, whatever the largest state component
    eps = vs.noise_factor * (settings.atol + settings.rtol)
    return min(vs.reach * scale, 0.5 * (vs.period_rtol * size + eps))


def _judge(
    k: int,
    how: str,
    f: Found,
    pts: dict[int, _Point],
    done: dict[int, Verdict],
    systems: Sequence[System],
    settings: SolverSettings,
    vs: VerdictSettings,
) -> bool:
    """Decide point k by orbit f (see the module docstring); True when it is decided or set
    to settle onto f."""
    p = pts[k]
    scale = max(1.0, float(np.max(np.abs(f.state))))
    rec = p.sections
    if rec.shape[1] != f.state.size:
        raise ParameterError(
            f"the verdict needs full-state section records ({f.state.size} columns): "
            f"got {rec.shape[1]}"
        )
    d = f.distances(rec)
    if not f.stable:
        near = float(d[-1]) <= vs.same_orbit * scale
        if near and how == "repeat":
            w, v = np.linalg.eig(f.monodromy)
            vec = np.real(v[:, int(np.argmax(np.abs(w)))])
            p.unstable = (f.period, f.max_multiplier, vec / max(float(np.max(np.abs(vec))), 1e-300))
        return False
    target = _reach(f, rec, settings, vs)
    if float(np.max(d)) <= target:
        done[k] = _floquet(p, f, systems[k], how)
        return True
    hist = f.distances(p.history)
    # distances are known to the orbit's accuracy (Newton's tolerance, the integration's)
    floor = (vs.newton_tol + settings.rtol) * scale + settings.atol
    how_close, rate = approach_rate(hist, floor, f.rates)
    if how_close == "unmeasured":  # too short a record to tell: the next window will
        p.tried.discard(f.period)
        p.approaching = f.period
        return False
    if how_close == "inconsistent":
        p.coexisting[f.period] = f.max_multiplier
        return False
    # periods until the distance falls below the reach at the slower of the observed rate
    # and the slowest the multipliers predict (it dominates in the end), then a record's
    # length on the orbit
    slow = max(rate, float(np.max(f.rates)))
    need = math.log(target / max(float(hist[-1]), target)) / slow
    periods = math.ceil(need) + rec.shape[0]
    p.settle = Settle(f, periods, rate)
    return True


def decide_motion(
    target: Any,
    values: Sequence[Mapping[str, Any]],
    systems: Sequence[System],
    sections: np.ndarray,
    final_states: np.ndarray,
    ok: Sequence[bool] | np.ndarray,
    settings: SolverSettings,
    verdict: VerdictSettings | None = None,
) -> list[Verdict]:
    """The motion verdict of K points (see the module docstring).

    Parameters
    ----------
    target, values, systems
        The gear set or system, each point's parameter values by name, and its resolved
        :class:`~gearchaos.model.System` (one kind and layout).
    sections
        (K, m, n_state) the recorded section states of every point.
    final_states
        (K, n_state) the state at the end of the record, on the section of ``settings``.
    ok
        (K,) whether each integration succeeded (a failed point is labelled ``failed``).
    settings
        The solver settings of the record (tolerances, section).
    verdict
        :class:`VerdictSettings` (default: the defaults).

    Returns
    -------
    list of Verdict
        One per point, in order.
    """
    vs = VerdictSettings() if verdict is None else verdict
    if not isinstance(vs, VerdictSettings):
        raise ParameterError(f"verdict must be a VerdictSettings: got {type(vs).__name__}")
    K = len(systems)
    sec = np.asarray(sections, dtype=np.float64)
    if sec.ndim != 3 or sec.shape[0] != K:
        raise ParameterError(f"sections must have shape ({K}, m, d): got {sec.shape}")
    fin = np.asarray(final_states, dtype=np.float64).reshape(K, -1)
    okv = np.asarray(ok, dtype=bool).reshape(K)
    done: dict[int, Verdict] = {}
    pts: dict[int, _Point] = {}
    for k in range(K):
        if not okv[k] or not np.all(np.isfinite(fin[k])) or not np.all(np.isfinite(sec[k])):
            done[k] = Verdict("failed", 0, "failed", reason="the integration failed")
        else:
            pts[k] = _Point(sections=sec[k], final=fin[k].copy(), history=sec[k])
    keep = max(2 * vs.longest_period + 2, sec.shape[1], HISTORY)
    length = {k: vs.extension_for(sec.shape[1]) for k in pts}
    while True:
        live = [k for k in pts if k not in done]
        if not live:
            break
        # settling runs end here: on the orbit, or back to the ordinary rounds
        for k in live:
            p = pts[k]
            if p.settle is not None:
                f = p.settle.orbit
                if float(np.max(f.distances(p.sections))) <= _reach(f, p.sections, settings, vs):
                    done[k] = _floquet(p, f, systems[k], "approach")
                else:  # not there yet: every candidate may be shot again
                    p.tried.clear()
                p.settle = None
        live = [k for k in live if k not in done]
        # 1. candidates: a repeating record, else a converging one
        cands: dict[int, list[tuple[int, str]]] = {}
        # the latest window, or the newest sections of the history where it is too short
        span = 2 * vs.longest_period + 2
        periods = _record_periods(
            [pts[k].history[-max(span, pts[k].sections.shape[0]) :] for k in live],
            settings,
            vs,
        )
        for k, n in zip(live, periods, strict=True):
            p = pts[k]
            p.long_period = n if n > vs.max_period else 0
            lle_pos = bool(p.windows) and p.windows[-1].lle - vs.confidence * p.windows[-1].err > 0
            if 1 <= n <= vs.max_period:
                cands[k] = [(n, "repeat")]
            elif not lle_pos:  # no period, or one too long to shoot: a slow spiral recurs too
                nc = converging_period(p.history, vs.max_period) or near_period(
                    p.history, vs.max_period, vs.approach
                )
                tries = [(m, "approach") for m in sorted({1, nc}) if nc and m not in p.tried]
                for m, _ in tries:
                    p.tried.add(m)
                if tries:
                    cands[k] = tries
            p.unstable = None
            p.approaching = 0
        if cands:
            shoot_candidates(
                target,
                values,
                systems,
                {k: pts[k].final for k in cands},
                cands,
                settings,
                vs,
                lambda k, how, f: _judge(k, how, f, pts, done, systems, settings, vs),
            )
        # 2. the windows decide the rest, or they are extended
        spent = {k: pts[k].extra - pts[k].settled_extra for k in live}
        for k in [k for k in live if k not in done and pts[k].settle is None]:
            nxt = vs.next_window(length[k], len(pts[k].windows))
            last = spent[k] + nxt > vs.budget_periods
            v = decide_by_exponent(pts[k], vs, last)
            if v is not None:
                done[k] = v
        todo = [k for k in live if k not in done]
        if not todo:
            break
        for k in todo:  # settling beyond its budget: unresolved with what was found
            p = pts[k]
            if p.settle is not None and p.settled_extra + p.settle.periods > vs.settle_budget:
                f = p.settle.orbit
                done[k] = Verdict(
                    label="unresolved",
                    period=0,
                    evidence="converging",
                    max_multiplier=f.max_multiplier,
                    extra_periods=p.extra,
                    record=p.record,
                    reason=(
                        f"the record approaches a stable period-{f.period} orbit (max |μ| = "
                        f"{f.max_multiplier:.6g}) at the rate its multipliers allow, but would "
                        f"reach it within {vs.reach:g} only after {p.settle.periods} more "
                        f"periods (settle budget {vs.settle_budget})"
                    ),
                )
        todo = [k for k in todo if k not in done]
        if not todo:
            break
        _extend(todo, pts, done, systems, settings, vs, length, keep)
    return [done[k] for k in range(K)]


def _extend(
    todo: list[int],
    pts: dict[int, _Point],
    done: dict[int, Verdict],
    systems: Sequence[System],
    settings: SolverSettings,
    vs: VerdictSettings,
    length: dict[int, int],
    keep: int,
) -> None:
    """Run every point of ``todo`` on: a settling point without tangents for its settle
    length, the others for their next window with one tangent vector (λ₁)."""
    groups: dict[tuple[int, bool], list[int]] = {}
    for k in todo:
        p = pts[k]
        if p.settle is not None:
            groups.setdefault((p.settle.periods, False), []).append(k)
        else:
            if p.windows:
                length[k] = vs.next_window(length[k], len(p.windows))
            groups.setdefault((length[k], True), []).append(k)
    n_state = systems[0].n_state
    for (periods, tangents), ks in sorted(groups.items()):
        starts = []
        for k in ks:
            p = pts[k]
            y = p.final.copy()
            if p.unstable is not None:  # leave the unstable orbit along its eigenvector
                y = y + 1e-3 * max(1.0, float(np.max(np.abs(y)))) * p.unstable[2]
            starts.append(y)
        seed = (vs.seed + len(pts[ks[0]].windows)) if tangents else None
        out = extend(
            [systems[k] for k in ks],
            np.array(starts),
            settings,
            periods,
            seed,
            tangent_tol=vs.lyapunov_tol,
        )
        stretch = out.stretch(n_state) if tangents else None
        for i, k in enumerate(ks):
            p = pts[k]
            start = p.extra
            p.extra += periods
            p.fresh = tangents
            if not tangents:
                p.settled_extra += periods
            if int(out.status[i, 0]) != 0:
                done[k] = Verdict(
                    "failed",
                    0,
                    "failed",
                    extra_periods=p.extra,
                    reason="the integration failed while the run was continued",
                )
                continue
            states = out.states[i, 0, :, :n_state].copy()
            contiguous = p.unstable is None
            p.history = np.concatenate([p.history, states])[-keep:] if contiguous else states
            p.sections = states
            p.final = out.final_state[i, 0, :n_state].copy()
            p.record = VerdictRecord(
                states,
                out.observables[i, 0].copy(),
                p.final.copy(),
                out.obs_min[i, 0].copy(),
                out.obs_max[i, 0].copy(),
            )
            if tangents:
                T = systems[k].period
                assert stretch is not None
                lam, err = exponent_estimate(stretch[i, 0], T, blocks=vs.blocks)
                theta = vs.lle_c / ((periods - 1) * T)
                p.prev_tests = p.tests
                p.windows.append(Window(start, periods, lam, err, theta))
