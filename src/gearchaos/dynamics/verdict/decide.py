"""The motion verdict: one decision procedure for what an attractor is, with its evidence.

A label is a claim about the motion, and the project owns the tools to check it. The verdict
asks them, for K points at once (a sweep task, or one point):

1. **Candidates from the record.** The recorded section sequence (full states), with the
   windows of any extension appended, repeats with period n when ‖x_{k+n} − x_k‖ ≤
   ``period_rtol``·S + ε for every k, S the attractor's size and ε = ``noise_factor``·(atol +
   rtol·max|x|) the integration's noise floor. A sequence that does not repeat but whose
   recurrence gaps decay geometrically, or that lingers near a period, gives an *approach*
   candidate.
2. **Orbits by shooting** (:mod:`~gearchaos.dynamics.verdict.periodic`): Newton on Pⁿ(y) − y = 0
   from the final state; a repeat candidate that fails has its divisors shot (an alternating
   approach along a multiplier near −1). A converged orbit has its multipliers computed with
   accurate tangents, its structural multipliers set aside, and is stable by the one criterion
   of :mod:`~gearchaos.dynamics.orbits.stability` (every other |μ| < 1 − ``margin``). A stable orbit
   is the label only when the record lies within ``reach`` of it; when the record's distance
   from it shrinks at a rate its multipliers allow, the run is continued until it does
   (``settle_budget``; a record too short to measure that at the slowest rate the multipliers
   predict is first continued until it is long enough), and the record shown is the
   continuation's last periods (the protocol's number, run on their own so that their extrema
   are theirs) — never the orbit's own points in place of the trajectory. A stable orbit the
   record does not approach *coexists*: it is reported with the verdict, not as its label. An
   unstable orbit the record sits on is left along its unstable eigenvector.
3. **Windows with a Lyapunov exponent** (:mod:`~gearchaos.dynamics.verdict.rules`): every point
   not decided is integrated further, one window at a time (the first as long as the record,
   at least ``min_extension``, the second as long, each next one twice as long, at most
   ``max_window``), with one
   tangent vector: λ₁ ± σ per window, θ = c_θ/t its bias bound. Chaos needs the interval above
   the bound (or positive with the 0–1 test chaotic on every band) in two consecutive windows;
   QP needs the interval within the bound and a torus on the section (the rotation test on
   each band, or a regular 0–1 test for every stride). Each window goes back to step 1.
4. **Unresolved, with its reason**, when ``budget_periods`` is spent.

Every :class:`~gearchaos.dynamics.verdict.evidence.Verdict` carries the label, the evidence code,
the
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

from ...analysis.motion import Motion
from ...analysis.periodicity import periods_of
from ...analysis.recurrence import converging_period, near_period, noise_floor
from ...errors import ParameterError
from ...integrate.settings import SolverSettings
from ...model.system import System
from ...model.target import Target
from ..lyapunov import exponent_estimate
from .evidence import Verdict
from .extension import VerdictRecord, extend
from .periodic import (
    MEASURE_TARGET,
    Found,
    Settle,
    approach_rate,
    beyond_budget,
    measure_periods,
    shoot_candidates,
)
from .record import decide_from_record
from .rules import SectionTests, Window, decide_by_exponent
from .settings import CONFIRM_PERIODS, VerdictSettings, confirmed_settings

__all__ = ["CONFIRM_PERIODS", "VerdictSettings", "confirmed_settings", "decide_motion"]

#: Fewest section states of a point's contiguous history kept (approaches are measured over
#: it). A point keeps at least its latest window too, and, once a stable orbit is found whose
#: slowest predicted rate needs a longer record to be measured
#: (:func:`~gearchaos.dynamics.verdict.periodic.measure_periods`), that many: the run is then
#: continued for the missing periods, within ``settle_budget``.
HISTORY = 1000


# ----------------------------------------------------------------------------- decision
@dataclass
class _Point:
    """Working state of one undecided point."""

    sections: np.ndarray  # the latest record (window)
    final: np.ndarray
    history: np.ndarray  # the contiguous records so far, newest last (capped)
    keep: int  # most sections of history kept (at least the latest window)
    shown: int  # sections of the record shown (the protocol's): a settle's record
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


def _on(f: Found, record: np.ndarray, settings: SolverSettings, vs: VerdictSettings) -> bool:
    """Whether every section of ``record`` lies within reach of orbit f."""
    return float(np.max(f.distances(record))) <= _reach(f, settings, vs)


def _reach(f: Found, settings: SolverSettings, vs: VerdictSettings) -> float:
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
    target = _reach(f, settings, vs)
    if float(np.max(d)) <= target:
        done[k] = _floquet(p, f, systems[k], how)
        return True
    hist = f.distances(p.history)
    # distances are known to the orbit's accuracy (Newton's tolerance, the integration's)
    floor = (vs.newton_tol + settings.rtol) * scale + settings.atol
    how_close, rate = approach_rate(hist, floor, f.rates)
    if how_close == "inconsistent":
        p.coexisting[f.period] = f.max_multiplier
        return False
    # ln of the fall still needed from the distances' envelope over the last record (a spiral
    # wobbles under it), and the slowest rate the multipliers predict (it dominates in the
    # end): the periods until the record lies within reach at that rate
    top = float(np.max(hist[-p.shown :]))
    fall, slowest = math.log(target / max(top, target)), float(np.max(f.rates))
    if how_close == "unmeasured":
        have = p.history.shape[0]
        if have < measure_periods(f.rates):  # too short for the slowest predicted rate: run
            # on, to a record sized with a margin, and at least a record's length (the run's
            # last periods are a record, on the orbit or not)
            need = measure_periods(f.rates, MEASURE_TARGET)
            p.keep = max(p.keep, need)
            more = max(need - have, p.shown)
            p.settle = Settle(f, more, math.nan, p.shown, math.ceil(fall / slowest), measure=True)
            return True
        # long enough, but already within the orbit's accuracy: the next window will tell
        p.tried.discard(f.period)
        p.approaching = f.period
        return False
    # at the slower of the observed rate and the slowest predicted, then the record shown
    # (a record's length) on the orbit
    need = math.ceil(fall / max(rate, slowest))
    p.settle = Settle(f, need + p.shown, rate, p.shown, need)
    return True


def decide_motion(
    target: Target,
    values: Sequence[Mapping[str, Any]],
    systems: Sequence[System],
    sections: np.ndarray,
    final_states: np.ndarray,
    ok: Sequence[bool] | np.ndarray,
    settings: SolverSettings,
    verdict: VerdictSettings | None = None,
    *,
    lle: Sequence[float] | np.ndarray | None = None,
) -> list[Verdict]:
    """The motion verdict of K points (see the module docstring), or, with
    ``VerdictSettings(mode="record")``, their labels from the record alone (evidence
    ``record``: :func:`~gearchaos.dynamics.verdict.record.decide_from_record`, nothing
    integrated).

    Parameters
    ----------
    target, values, systems
        The gear set or system, each point's parameter values by name, and its resolved
        :class:`~gearchaos.model.System` (one kind and layout).
    sections
        (K, m, n_state) the recorded section states of every point; in record mode, the
        section values the label is read from ((K, m, d), a sweep's first two observed
        section variables).
    final_states
        (K, n_state) the state at the end of the record, on the section of ``settings``.
    ok
        (K,) whether each integration succeeded (a failed point is labelled ``failed``).
    settings
        The solver settings of the record (tolerances, section).
    verdict
        :class:`VerdictSettings` (default: the defaults).
    lle
        (K,) the λ₁ the run recorded (NaN: none), read by the record mode only: the
        confirming mode measures its own.

    Returns
    -------
    list of Verdict
        One per point, in order.
    """
    vs = VerdictSettings() if verdict is None else verdict
    if not isinstance(vs, VerdictSettings):
        raise ParameterError(f"verdict must be a VerdictSettings: got {type(vs).__name__}")
    if vs.mode == "record":
        return _from_record(systems, sections, ok, settings, vs, lle)
    if lle is not None:
        raise ParameterError(
            "lle (a recorded λ₁) is read only by the record mode (VerdictSettings(mode="
            "'record')): the confirming verdict measures λ₁ itself",
            name="lle",
        )
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
            pts[k] = _Point(
                sections=sec[k],
                final=fin[k].copy(),
                history=sec[k],
                keep=max(2 * vs.longest_period + 2, sec.shape[1], HISTORY),
                shown=sec.shape[1],
            )
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
                if _on(f, p.sections, settings, vs):  # the settle's own record
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
                done[k] = beyond_budget(p.settle, p, vs)
        todo = [k for k in todo if k not in done]
        if not todo:
            break
        _extend(todo, pts, done, systems, settings, vs, length)
    return [done[k] for k in range(K)]


def _from_record(
    systems: Sequence[System],
    sections: np.ndarray,
    ok: Sequence[bool] | np.ndarray,
    settings: SolverSettings,
    vs: VerdictSettings,
    lle: Sequence[float] | np.ndarray | None,
) -> list[Verdict]:
    """The record mode: each point's label from its section values, the λ₁ bound counting
    the record's periods of its system's forcing period."""
    sec = np.asarray(sections, dtype=np.float64)
    K = len(systems)
    if sec.ndim != 3 or sec.shape[0] != K:
        raise ParameterError(f"sections must have shape ({K}, m, d): got {sec.shape}")
    return decide_from_record(
        sec,
        ok,
        lle=None if lle is None else np.asarray(lle, dtype=np.float64).reshape(K),
        run_periods=int(settings.periods),
        forcing_period=np.array([s.period for s in systems], dtype=np.float64),
        period_rtol=vs.period_rtol,
        longest_period=vs.longest_period,
        lle_c=vs.lle_c,
    )


def _extend(
    todo: list[int],
    pts: dict[int, _Point],
    done: dict[int, Verdict],
    systems: Sequence[System],
    settings: SolverSettings,
    vs: VerdictSettings,
    length: dict[int, int],
) -> None:
    """Run every point of ``todo`` on: a settling point without tangents for its settle
    length — the approach, then its last ``record`` periods as a run of their own, so that
    the record (its sections and the extrema between them) is only the part that must lie on
    the orbit —, the others for their next window with one tangent vector (λ₁)."""
    groups: dict[tuple[int, int, bool], list[int]] = {}
    for k in todo:
        p = pts[k]
        if p.settle is not None:
            s = p.settle
            groups.setdefault((s.periods, min(s.record, s.periods), False), []).append(k)
        else:
            if p.windows:
                length[k] = vs.next_window(length[k], len(p.windows))
            groups.setdefault((length[k], length[k], True), []).append(k)
    n_state = systems[0].n_state
    for (periods, shown, tangents), ks in sorted(groups.items()):
        starts = {k: _start(pts[k]) for k in ks}
        lead: dict[int, np.ndarray] = {}  # the approach's sections, before the record
        if periods > shown:
            out = extend(
                [systems[k] for k in ks],
                np.array([starts[k] for k in ks]),
                settings,
                periods - shown,
                None,
                tangent_tol=vs.lyapunov_tol,
            )
            for i, k in enumerate(ks):
                if int(out.status[i, 0]) != 0:
                    _failed(pts[k], k, periods, tangents, done)
                    continue
                lead[k] = out.states[i, 0, :, :n_state].copy()
                starts[k] = out.final_state[i, 0, :n_state].copy()
            ks = [k for k in ks if k not in done]
            if not ks:
                continue
        seed = (vs.seed + len(pts[ks[0]].windows)) if tangents else None
        out = extend(
            [systems[k] for k in ks],
            np.array([starts[k] for k in ks]),
            settings,
            shown,
            seed,
            tangent_tol=vs.lyapunov_tol,
        )
        stretch = out.stretch(n_state) if tangents else None
        for i, k in enumerate(ks):
            p = pts[k]
            if int(out.status[i, 0]) != 0:
                _failed(p, k, periods, tangents, done)
                continue
            start = p.extra
            p.extra += periods
            p.fresh = tangents
            if not tangents:
                p.settled_extra += periods
            states = out.states[i, 0, :, :n_state].copy()
            run = states if k not in lead else np.concatenate([lead[k], states])
            contiguous = p.unstable is None
            keep = max(p.keep, run.shape[0])
            p.history = np.concatenate([p.history, run])[-keep:] if contiguous else run
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


def _start(p: _Point) -> np.ndarray:
    """Where point p runs on from: its final state, pushed off an unstable orbit it sits on
    along the orbit's unstable eigenvector."""
    y = p.final.copy()
    if p.unstable is not None:
        y = y + 1e-3 * max(1.0, float(np.max(np.abs(y)))) * p.unstable[2]
    return y


def _failed(p: _Point, k: int, periods: int, tangents: bool, done: dict[int, Verdict]) -> None:
    p.extra += periods
    if not tangents:
        p.settled_extra += periods
    done[k] = Verdict(
        "failed",
        0,
        "failed",
        extra_periods=p.extra,
        reason="the integration failed while the run was continued",
    )
