"""The motion verdict's periodic evidence: shooting the candidate periods of K records and
judging each orbit found against the record (:func:`shoot_candidates`).

For every converged orbit the multipliers are computed once more with the tangents at the
state's own tolerances (the chord iteration's cheaper tangents are good for Newton, not for
the stated max |μ|), its structural multipliers are set aside
(:func:`~gearchaos.dynamics.orbits.stability.structural_multipliers`) and it is stable or not by the
one criterion of :mod:`~gearchaos.dynamics.orbits.stability`. A stable orbit is then

* **the record's** when every recorded section lies within ``reach`` of it: the label stands;
* **approached** when the distance from the recorded sections to it shrinks at a rate its
  multipliers allow (:func:`approach_rate`): the run is continued until the record lies within
  ``reach`` of it (:class:`Settle`), and only then labelled — the record shown is always the
  trajectory's own;
* otherwise **coexisting**: an attractor beside the recorded motion, reported as evidence,
  never as its label.

A candidate of period n that does not converge has its proper divisors shot next (a record
that alternates while it approaches an orbit of period n/2 along a multiplier near −1 repeats
with period n); an orbit of minimal period d < n found from any candidate is taken as a
period-d orbit.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...analysis.recurrence import distance_to_orbit
from ...errors import ParameterError
from ...integrate.settings import SolverSettings
from ...model.system import System
from ...model.target import Target
from ..orbits.shooting import multipliers_of, shoot
from ..orbits.stability import stability_of, structural_multipliers
from .evidence import Verdict

__all__ = [
    "Found",
    "Settle",
    "approach_rate",
    "beyond_budget",
    "measure_periods",
    "shoot_candidates",
]

#: Least fall of ln d over the half record an approach is measured on, at the slowest rate
#: the multipliers predict, for :func:`approach_rate` to measure it (a fall by 1.25²).
MEASURE_FALL = 2.0 * math.log(1.25)
#: The fall a run that lengthens a record too short to measure its approach is sized for:
#: twice the least, so that the scatter of the fit about its line (the envelope of a spiral
#: wobbles) does not decide whether the record approaches.
MEASURE_TARGET = 2.0 * MEASURE_FALL
#: Fewest sections of the half record an approach is measured on.
MEASURE_MIN = 16


@dataclass(frozen=True, eq=False)
class Found:
    """A converged orbit of minimal period ``period``: its section states (d, n_state), its
    state, ``max_multiplier`` over the non-structural multipliers (accurate tangents),
    ``stable``, ``structural`` (how many multipliers are structural) and the monodromy of
    Pᵈ."""

    period: int
    state: np.ndarray
    sections: np.ndarray
    max_multiplier: float
    stable: bool
    structural: int
    monodromy: np.ndarray
    rates: np.ndarray  # ln|μ_j| / d per section, non-structural multipliers

    def distances(self, record: np.ndarray) -> np.ndarray:
        return np.asarray(distance_to_orbit(record, self.sections))


@dataclass(frozen=True, eq=False)
class Settle:
    """A run continued towards a stable orbit for ``periods`` (no tangents), whose last
    ``record`` periods are run on their own (the record, its sections and extrema) and must
    lie within reach of it: a record approaching the orbit at
    the rate its multipliers allow (observed slope ``rate`` of ln d per section), or, with
    ``measure``, a record too short to measure that approach at the slowest rate the
    multipliers predict (it is measured afterwards, over ``periods`` more sections).
    ``predicted``: the periods until the record would lie within reach at the slowest rate
    the multipliers predict, ln(reach/d)/max(ln|μ_j|/d)."""

    orbit: Found
    periods: int
    rate: float
    record: int
    predicted: int
    measure: bool = False


def beyond_budget(s: Settle, p: Any, vs: Any) -> Verdict:
    """``unresolved`` (evidence ``converging``) for point ``p`` whose settle ``s`` would pass
    ``vs.settle_budget``: the periods the approach predicts against that budget."""
    f = s.orbit
    spent = f", after {p.settled_extra} spent on it" if p.settled_extra else ""
    orbit = f"a stable period-{f.period} orbit (max |μ| = {f.max_multiplier:.6g})"
    if s.measure:
        what = (
            f"lies near {orbit}, but measuring its approach at the slowest rate the "
            f"multipliers predict ({float(np.max(f.rates)):.3g} per period) needs a record of "
            f"{measure_periods(f.rates, MEASURE_TARGET)} periods ({s.periods} more), and "
            f"reaching it (every "
            f"section within the reach of its record) about {s.predicted}"
        )
    else:
        what = (
            f"approaches {orbit} at the rate its multipliers allow, but would reach it (every "
            f"section within the reach of its record) only after {s.predicted} more periods "
            f"(and {s.record} on it)"
        )
    return Verdict(
        label="unresolved",
        period=0,
        evidence="converging",
        max_multiplier=f.max_multiplier,
        extra_periods=p.extra,
        record=p.record,
        reason=f"the record {what}{spent}: beyond the settle budget of {vs.settle_budget} periods",
    )


def measure_periods(rates: np.ndarray, fall: float = MEASURE_FALL) -> int:
    """Sections of record over whose second half an approach at the slowest rate the
    multipliers predict, ``max(rates)`` (ln|μ_j|/d per section), falls by ``fall`` in ln d:
    2 · max(16, ⌈fall/|max rates|⌉). With :data:`MEASURE_FALL` the least record
    :func:`approach_rate` measures (|μ| = 0.9985 per period: 596; 0.9995: 1786), with
    :data:`MEASURE_TARGET` the record a measuring run lengthens it to. Undefined (a
    ParameterError) for rates that do not all fall."""
    slowest = float(np.max(rates)) if np.size(rates) else math.nan
    if not slowest < 0:
        raise ParameterError(f"rates must all be < 0 (a stable orbit): got max {slowest!r}")
    return 2 * max(MEASURE_MIN, math.ceil(fall / -slowest))


def approach_rate(d: np.ndarray, floor: float, rates: np.ndarray) -> tuple[str, float]:
    """Whether the distances ``d`` from a record to an orbit shrink at a rate the orbit's
    multipliers allow: ``(verdict, slope)`` with verdict ``allowed``, ``inconsistent`` or
    ``unmeasured`` and the observed slope of ln d per section.

    The slope is fitted through the maxima of 8 blocks of the record's second half (the upper
    envelope: a complex pair makes d oscillate under it), from the blocks above 10 × the
    noise ``floor``. The predicted rates are ln|μ_j|/d per section. It is *allowed* when the
    fall is significant (more than four times the scatter about the line, and at least 20 %),
    no slower than half the slowest predicted rate and no faster than twice the fastest;
    *unmeasured* when even the slowest predicted rate would fall by less than that over the
    half record (too short to tell: run on), or fewer than four blocks lie above the floor;
    *inconsistent* otherwise (a trajectory that stays away, leaves or only passes by)."""
    m = d.size
    half = d[m // 2 :]
    if rates.size == 0:
        return "inconsistent", math.nan
    slowest, fastest = float(np.max(rates)), float(np.min(rates))
    if slowest >= 0:
        return "inconsistent", math.nan
    if half.size < MEASURE_MIN or -slowest * half.size < MEASURE_FALL:
        return "unmeasured", math.nan
    blocks = np.array_split(np.arange(half.size), 8)
    centres = np.array([b.mean() for b in blocks])
    tops = np.array([float(np.max(half[b])) for b in blocks])
    use = tops > 10.0 * floor
    if np.count_nonzero(use) < 4:
        return "unmeasured", math.nan
    k, y = centres[use], np.log(tops[use])
    kc = k - k.mean()
    slope = float(kc @ (y - y.mean()) / (kc @ kc))
    scatter = float(np.std(y - y.mean() - slope * kc))
    drop = -slope * (k[-1] - k[0])
    ok = slope < 0 and drop > max(4.0 * scatter, math.log(1.25))
    if ok and 2.0 * fastest <= slope <= 0.5 * slowest:
        return "allowed", slope
    return "inconsistent", slope


def accurate(
    systems: Sequence[System], states: np.ndarray, n: int, settings: SolverSettings
) -> list[np.ndarray | None]:
    """Monodromies of Pⁿ at the given orbit states with the tangents at the state's own
    tolerances (one batched call)."""
    shot = shoot(systems, states, n, settings, tangents=True, tangent_tol=1.0)
    assert shot.monodromy is not None
    return [shot.monodromy[c] if shot.ok(c) else None for c in range(len(systems))]


def _found(
    system: System, orb: Any, M: np.ndarray, settings: SolverSettings, margin: float
) -> Found | None:
    """The orbit as a :class:`Found` of its minimal period d (M is the accurate monodromy of
    Pⁿ; the multipliers of Pᵈ are its eigenvalues to the power d/n)."""
    n = int(orb.period)
    d = int(orb.minimal_period)
    mus = multipliers_of(M)
    if not np.all(np.isfinite(mus)):
        return None
    structural = structural_multipliers(system, orb.state, n, M, settings)
    stable, top_n = stability_of(mus, structural, 0.0)
    top = top_n ** (d / n) if top_n > 0 else 0.0
    stable = top < 1.0 - margin
    keep = np.abs(mus[~structural])
    with np.errstate(divide="ignore"):
        rates = np.log(np.maximum(keep, 1e-300)) / n
    return Found(
        period=d,
        state=np.asarray(orb.state, dtype=np.float64).copy(),
        sections=np.asarray(orb.sections)[:d].copy(),
        max_multiplier=float(top),
        stable=bool(stable),
        structural=int(np.count_nonzero(structural)),
        monodromy=M,
        rates=rates,
    )


def shoot_candidates(
    target: Target,
    values: Sequence[Mapping[str, Any]],
    systems: Sequence[System],
    starts: Mapping[int, np.ndarray],
    cands: Mapping[int, list[tuple[int, str]]],
    settings: SolverSettings,
    vs: Any,
    judge: Callable[[int, str, Found], bool],
) -> None:
    """Shoot the candidates {point: [(n, how)]} from each point's final state, ``how``
    ``repeat`` (the record repeats with period n) or ``approach`` (it converges or lingers
    near a period-n orbit), shortest period first; a repeat candidate that does not converge
    has its proper divisors shot next. Every converged orbit goes to ``judge(point, how,
    orbit)``, which returns True when it decided the point (no further candidate of the point
    is then shot)."""
    from ..orbits.batch import periodic_orbits

    pending = {k: list(cs) for k, cs in cands.items()}
    settled: set[int] = set()
    shot: dict[int, set[int]] = {k: set() for k in cands}
    while True:
        wave = sorted({c for k, cs in pending.items() if k not in settled for c in cs})
        if not wave:
            break
        n, how = wave[0]
        idx = [k for k, cs in pending.items() if (n, how) in cs and k not in settled]
        for k in idx:
            pending[k].remove((n, how))
            shot[k].add(n)
        if not idx:
            continue
        orbits = periodic_orbits(
            target,
            [values[k] for k in idx],
            period=n,
            guesses=np.array([starts[k] for k in idx]),
            settings=settings,
            max_iterations=vs.newton_iterations,
            contraction=vs.newton_contraction,
            chord=True,
            tangent_tol=vs.tangent_tol,
            tol=vs.newton_tol,
            systems=[systems[k] for k in idx],
        )
        good = [i for i, o in enumerate(orbits) if o.converged and np.isfinite(o.max_multiplier)]
        mons = (
            accurate(
                [systems[idx[i]] for i in good],
                np.array([orbits[i].state for i in good]),
                n,
                settings,
            )
            if good
            else []
        )
        by_i = dict(zip(good, mons, strict=True))
        for i, k in enumerate(idx):
            M = by_i.get(i)
            f = None if M is None else _found(systems[k], orbits[i], M, settings, vs.margin)
            if f is None:
                if how == "repeat":  # an alternating approach: its divisors next
                    for dv in range(1, n):
                        if n % dv == 0 and dv not in shot[k]:
                            pending[k].append((dv, "approach"))
                continue
            if judge(k, how, f):
                settled.add(k)
