"""The motion verdict: one decision procedure for what an attractor is, with its evidence.

A label is a claim about the motion, and the project owns the tools to check it. The verdict
asks them, for K points at once (a sweep task, or one point):

1. **Candidates from the record.** The recorded section sequence (full states where available)
   repeats with period n when ‖x_{k+n} − x_k‖ ≤ ``period_rtol``·S + ε for every k, S the
   attractor's size (largest coordinate range) and ε = ``noise_factor``·(atol + rtol·max|x|)
   the integration's noise floor; a sequence whose spread is within ε is one point (period 1).
   A sequence that does not repeat but whose recurrence gaps ‖x_{k+n} − x_k‖ decay
   geometrically (a transient still converging) gives the candidate n of the fastest decay.
2. **Confirmation by shooting.** Newton on Pⁿ(y) − y = 0 from the final state
   (:func:`~gearchaos.dynamics.orbit_batch.periodic_orbits`, every point of one n in one batch).
   The label nT stands when Newton converged, the orbit is the record's (its section points
   lie within ``same_orbit`` of the final state, or the record was converging), its minimal
   period d (the label is then dT) and every Floquet multiplier |μ| < 1 − ``margin``. Its
   λ₁ is then exactly ln max|μ| / (dT). An orbit found unstable is never labelled: the run is
   continued from the final state pushed along the unstable eigenvector.
3. **Extension with a Lyapunov exponent.** Every point not yet decided is integrated further,
   ``extension_periods`` at a time, with one tangent vector from a seeded random start; λ₁
   and its standard error σ come from block means
   (:func:`~gearchaos.dynamics.lyapunov.exponent_estimate`). The new record goes back to
   step 1 (a transient may now have finished). Without a confirmed period, with θ = c_θ/t
   the finite-time bias bound of a regular attractor (t the extension's duration,
   :func:`~gearchaos.analysis.classify.lle_threshold_for`) and K the 0–1 test of the
   extension's record: ``chaos`` when λ₁ − cσ > 0 and (λ₁ > θ or K > 0.8); ``QP`` when
   λ₁ + cσ ≥ 0, λ₁ ≤ θ, K ≤ 0.8 and (the interval holds 0 or K < 0.2). Anything else — a
   contracting exponent (λ₁ + cσ < 0), a positive interval below θ that the 0–1 test does not
   settle — is extended again (θ shrinks like 1/t, a torus's estimate like ln t / t), within
   ``budget_periods``. A candidate period n > ``max_period`` (too long to shoot) is labelled
   nT when the record repeats and λ₁ + cσ < 0 (a contracting periodic attractor).
4. **Unresolved, with its reason**, when the budget is spent: contracting without a period
   found, an interval that straddles θ, or an unstable orbit the motion did not leave.

Every :class:`Verdict` carries the label, the evidence code (:data:`EVIDENCE`), max |μ| of the
orbit shot (confirmed or unstable), λ₁ ± σ, the periods integrated, the 0–1 test value where
computed, and a sentence saying why. The extension's record replaces the original one where
it was used (``Verdict.record``), so a label is never shown beside the unfinished transient
that preceded it.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._checks import check_int, check_real
from ..analysis.chaos01 import MIN_LENGTH as MIN_LENGTH_01
from ..analysis.chaos01 import chaos01
from ..analysis.classify import K_CHAOS, K_REGULAR, LLE_C
from ..analysis.periodicity import periods_of
from ..analysis.recurrence import (
    approaches,
    converging_period,
    distance_to_orbit,
    near_period,
    noise_floor,
)
from ..errors import ParameterError
from ..integrate.settings import SolverSettings
from ..model.system import System
from .evidence import Verdict
from .extension import VerdictRecord, extend
from .lyapunov import LYAPUNOV_BLOCKS, exponent_estimate

__all__ = ["VerdictSettings", "decide_motion"]


@dataclass(frozen=True)
class VerdictSettings:
    """Tolerances and budget of :func:`decide_motion`.

    Parameters
    ----------
    max_period
        Longest period confirmed by shooting (Newton with the full monodromy over n periods).
    longest_period
        Longest period recognised in a record at all.
    period_rtol
        Recurrence tolerance relative to the attractor's size S.
    noise_factor
        The noise floor ε = noise_factor · (atol + rtol · max|x|) of the section points.
    margin
        Stability margin: confirmed orbits have every |μ| < 1 − margin.
    same_orbit
        Largest distance (∞-norm, relative to max(1, ‖y*‖)) between the final state and the
        orbit's section points for the orbit to be the record's.
    approach
        A record whose recurrence gaps over its last quarter stay within this fraction of
        max(1, max|x|) lingers near a periodic orbit: it is shot, and the orbit confirmed when
        stable and the record comes closer to it.
    extension_periods
        Periods per extension (None: the record's length, at least ``min_extension``).
    min_extension
        Shortest extension when ``extension_periods`` is None: the bias bound θ = c_θ/t
        shrinks with the extension's duration t, and a short one (θ large) would call a
        slowly contracting motion QP.
    budget_periods
        Most periods added to a point by extensions (one extension always runs: an
        undecided point needs λ₁).
    newton_iterations
        Most Newton iterations of a shooting (period 1 is tried first for a record that
        converges onto or lingers near an orbit, and a period that failed is not shot again
        for that point — if the run later settles, its record repeats and is shot as such).
    newton_contraction
        A shooting is given up early when three iterations have not shrunk its residual by
        this factor (a start inside Newton's basin converges far faster; one outside it
        wanders and would only spend the budget).
    tangent_tol
        Factor on the integrator's tolerances for the monodromy's columns: multipliers need a
        few digits, not the state's ten; 1000 makes a tangent period a fraction as costly as at
        1 and moves max |μ| by a few 10⁻⁶ (0.997019 → 0.997015 at Ω = 1.5 on ``sheng2016``),
        far inside ``margin``.
    newton_tol
        Residual and correction tolerance of the shooting (relative to max(1, ‖y‖)): the
        verdict needs the orbit's multipliers, which a 10⁻⁷ orbit gives to far better than
        ``margin``; a record already on its orbit then converges in one Newton iteration.
    lyapunov_tol
        The same factor for the extension's Lyapunov vector. Infinite (the default): the vector
        is left out of the error control and takes the state's steps, so the extended state is
        bitwise the one a plain run gives and a tangent period costs several times less than
        at factor 1 (``benchmarks/bench_verdicts.py``); λ₁ then agrees with that of a fully
        controlled vector within its standard error (``tests/dynamics/test_verdict.py``). The
        Floquet evidence, which needs the multipliers to a few digits, keeps ``tangent_tol``.
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
    margin: float = 1e-4
    same_orbit: float = 1e-2
    approach: float = 2e-2
    extension_periods: int | None = None
    min_extension: int = 100
    budget_periods: int = 400
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
        check_real("approach", self.approach, lo=0.0, hi=1.0)
        if self.extension_periods is not None:
            check_int("extension_periods", self.extension_periods, lo=2 * self.blocks + 1)
        check_int("min_extension", self.min_extension, lo=2 * self.blocks + 1, hi=10**6)
        check_int("budget_periods", self.budget_periods, lo=0, hi=10**7)
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
        """Periods of one extension of a record of ``record_periods``."""
        if self.extension_periods is not None:
            return int(self.extension_periods)
        return max(int(record_periods), self.min_extension)


# ----------------------------------------------------------------------------- decision
@dataclass
class _Point:
    """Working state of one undecided point."""

    sections: np.ndarray
    final: np.ndarray
    extra: int = 0
    lle: float = math.nan
    err: float = math.nan
    theta: float = math.nan
    unstable: tuple[int, float, np.ndarray] | None = None
    record: VerdictRecord | None = None
    long_period: int = 0
    tried: set[int] = field(default_factory=set)  # approach periods shot in vain


def _shoot_candidates(
    target: Any,
    values: Sequence[Mapping[str, Any]],
    pts: dict[int, _Point],
    cands: dict[int, list[tuple[int, str]]],
    settings: SolverSettings,
    vs: VerdictSettings,
    done: dict[int, Verdict],
    systems: Sequence[System],
) -> None:
    """Shoot the candidates {point: (n, how)}, ``how`` ``repeat`` (the record repeats: the
    orbit must be the record's) or ``approach`` (the record converges or lingers near an
    orbit: a full-state record must come closer to it); decide the confirmed ones in
    ``done``, and note an unstable orbit the record sits on."""
    from .orbit_batch import periodic_orbits

    finish: list[int] = []  # confirmed while the record was converging: show the orbit
    for n, how in sorted({c for cs in cands.values() for c in cs}):
        idx = [k for k, cs in cands.items() if (n, how) in cs and k not in done]
        if not idx:
            continue
        orbits = periodic_orbits(
            target,
            [values[k] for k in idx],
            period=n,
            guesses=np.array([pts[k].final for k in idx]),
            settings=settings,
            max_iterations=vs.newton_iterations,
            contraction=vs.newton_contraction,
            chord=True,
            tangent_tol=vs.tangent_tol,
            tol=vs.newton_tol,
            systems=[systems[k] for k in idx],
        )
        for k, orb in zip(idx, orbits, strict=True):
            p = pts[k]
            if how == "approach":
                p.tried.add(n)  # not shot again at this period if it does not confirm
            if not orb.converged or not np.isfinite(orb.max_multiplier):
                continue
            d = orb.minimal_period
            mu_n = float(orb.max_multiplier)  # of Pⁿ: the d-periodic orbit's to the power n/d
            mu = mu_n ** (d / n)
            secs = orb.sections
            scale = max(1.0, float(np.max(np.abs(orb.state))))
            gap = float(distance_to_orbit(p.final, secs))
            near = gap <= vs.same_orbit * scale
            # settled: the whole record on the orbit to the integration's noise floor (else the
            # orbit's own record is shown, not one still converging within the tolerance)
            if p.sections.shape[1] == secs.shape[1]:
                gap = max(gap, float(np.max(distance_to_orbit(p.sections, secs))))
            settled = gap <= vs.noise_factor * (settings.atol + settings.rtol * scale)
            repeat = how == "repeat"
            if repeat:
                follows = near
            elif p.sections.shape[1] == secs.shape[1]:
                follows = approaches(p.sections, secs)
            else:  # a projected record: its recurrence gaps decayed (the trend test)
                follows = True
            if mu < 1.0 - vs.margin and follows:
                T = systems[k].period
                record = (
                    "the record repeats with this period"
                    if repeat and settled
                    else "the record was still converging onto it"
                )
                done[k] = Verdict(
                    label=f"{d}T",
                    period=d,
                    evidence="floquet",
                    max_multiplier=mu,
                    lle=math.log(mu) / (d * T),
                    lle_error=0.0,
                    extra_periods=p.extra,
                    reason=(
                        f"a period-{d} orbit converged by shooting, every Floquet multiplier "
                        f"|μ| ≤ {mu:.6g} < 1; {record}"
                    ),
                    record=p.record,
                    orbit_state=orb.state.copy(),
                )
                if not (repeat and settled):
                    finish.append(k)
            elif mu >= 1.0 - vs.margin and near and repeat:
                w, v = np.linalg.eig(orb.monodromy)
                vec = np.real(v[:, int(np.argmax(np.abs(w)))])
                p.unstable = (d, mu, vec / max(float(np.max(np.abs(vec))), 1e-300))
    if finish:
        _orbit_records(finish, pts, done, systems, settings)


def _orbit_records(
    finish: list[int],
    pts: dict[int, _Point],
    done: dict[int, Verdict],
    systems: Sequence[System],
    settings: SolverSettings,
) -> None:
    """Give each confirmed point in ``finish`` its orbit's own record, as long as its original
    one: d periods integrated from the orbit's state, repeated (a d-periodic orbit's section
    states, section observables and extrema repeat with period d)."""
    n_state = systems[0].n_state
    by_period: dict[int, list[int]] = {}
    for k in finish:
        by_period.setdefault(done[k].period, []).append(k)
    for d, ks in sorted(by_period.items()):
        ys = np.array([done[k].orbit_state for k in ks])
        out = extend([systems[k] for k in ks], ys, settings, d, None)
        for i, k in enumerate(ks):
            if int(out.status[i, 0]) != 0:
                continue
            m = max(pts[k].sections.shape[0], 2)
            tile = np.arange(m) % d
            rec = VerdictRecord(
                out.states[i, 0, tile, :n_state].copy(),
                out.observables[i, 0, tile].copy(),
                out.states[i, 0, (m - 1) % d, :n_state].copy(),
                out.obs_min[i, 0].copy(),
                out.obs_max[i, 0].copy(),
                source="orbit",
            )
            done[k] = dataclasses.replace(done[k], record=rec)


def _decide_by_exponent(k: int, p: _Point, vs: VerdictSettings, last: bool) -> Verdict | None:
    """The λ₁ rules for a point with no confirmed period (None: extend again)."""
    lam, err, theta, c = p.lle, p.err, p.theta, vs.confidence
    if not math.isfinite(lam) or not math.isfinite(err):
        return None
    lo, hi = lam - c * err, lam + c * err
    text = f"λ₁ = {lam:.4g} ± {err:.2g} (θ = {theta:.3g})"
    k01 = math.nan
    if p.sections.shape[0] >= MIN_LENGTH_01:
        k01 = chaos01(p.sections[:, :2])
    common: dict[str, Any] = {
        "lle": lam,
        "lle_error": err,
        "k01": k01,
        "extra_periods": p.extra,
        "record": p.record,
    }
    if p.long_period and hi < 0:
        n = p.long_period
        return Verdict(
            label=f"{n}T",
            period=n,
            evidence="record_contracting",
            reason=f"the record repeats with period {n} (too long to shoot) and {text} < 0",
            **common,
        )
    kk = f"0–1 test K = {k01:.3g}" if math.isfinite(k01) else "no 0–1 test"
    chaotic01 = math.isfinite(k01) and k01 > K_CHAOS
    regular01 = math.isfinite(k01) and k01 < K_REGULAR
    if lo > 0 and (lam > theta or chaotic01):
        why = "λ₁ > θ" if lam > theta else f"{kk} > {K_CHAOS} (λ₁ ≤ θ)"
        return Verdict(
            label="chaos",
            period=0,
            evidence="lyapunov",
            reason=f"no period ≤ {vs.longest_period} confirmed; {text}: λ₁ − {c:g}σ > 0, {why}",
            **common,
        )
    if hi >= 0 and lam <= theta and p.unstable is None and (lo <= 0 or regular01):
        if not chaotic01:
            why = "the interval holds 0" if lo <= 0 else f"{kk} < {K_REGULAR}"
            return Verdict(
                label="QP",
                period=0,
                evidence="lyapunov",
                reason=(
                    f"no period ≤ {vs.longest_period} and no converging orbit; {text}: "
                    f"λ₁ ≤ θ, the finite-time bias bound of a regular attractor, and {why}"
                ),
                **common,
            )
    if not last:
        return None
    if p.unstable is not None:
        d, mu, _ = p.unstable
        return Verdict(
            label="unresolved",
            period=0,
            evidence="unstable_orbit",
            max_multiplier=mu,
            reason=(
                f"the motion stays near an unstable period-{d} orbit (max |μ| = {mu:.6g}) "
                f"and was not decided within {p.extra} further periods; {text}"
            ),
            **common,
        )
    if hi < 0:
        return Verdict(
            label="unresolved",
            period=0,
            evidence="contracting",
            reason=(
                f"{text} < 0: a contracting (periodic) attractor, but no period "
                f"≤ {vs.longest_period} was found or confirmed within {p.extra} further periods"
            ),
            **common,
        )
    return Verdict(
        label="unresolved",
        period=0,
        evidence="ambiguous",
        reason=f"{text}: the interval straddles θ after {p.extra} further periods",
        **common,
    )


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
        (K, m, d) the recorded section sequence of every point (full states preferably;
        any d ≥ 1 columns).
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
            pts[k] = _Point(sections=sec[k], final=fin[k].copy())
    ext_periods = vs.extension_for(sec.shape[1])
    # one extension at least (λ₁ needs one), more within the budget
    rounds = max(1, vs.budget_periods // ext_periods)
    for r in range(rounds + 1):
        live = [k for k in pts if k not in done]
        if not live:
            break
        # 1. candidates: a repeating record, else a converging one
        cands: dict[int, list[tuple[int, str]]] = {}
        periods = _record_periods([pts[k].sections for k in live], settings, vs)
        for k, n in zip(live, periods, strict=True):
            p = pts[k]
            p.long_period = n if n > vs.max_period else 0
            if 1 <= n <= vs.max_period:
                cands[k] = [(n, "repeat")]
            elif n == 0 and not p.lle - vs.confidence * p.err > 0:
                # (a record whose λ₁ is surely positive converges onto nothing)
                nc = converging_period(p.sections, vs.max_period) or near_period(
                    p.sections, vs.max_period, vs.approach
                )
                # a spiralling transient recurs at its rotation period, its orbit may be
                # shorter: the cheap period 1 is shot first
                tries = [(m, "approach") for m in sorted({1, nc}) if nc and m not in p.tried]
                if tries:
                    cands[k] = tries
        for k in live:
            pts[k].unstable = None
        if cands:
            _shoot_candidates(target, values, pts, cands, settings, vs, done, systems)
        # 2. the exponent of the last extension decides the rest, or they are extended
        last = r == rounds
        for k in [k for k in live if k not in done]:
            if r > 0:
                v = _decide_by_exponent(k, pts[k], vs, last)
                if v is not None:
                    done[k] = v
        todo = [k for k in live if k not in done]
        if last or not todo:
            break
        starts = []
        for k in todo:
            p = pts[k]
            y = p.final.copy()
            if p.unstable is not None:  # leave the unstable orbit along its eigenvector
                y = y + 1e-3 * max(1.0, float(np.max(np.abs(y)))) * p.unstable[2]
            starts.append(y)
        out = extend(
            [systems[k] for k in todo],
            np.array(starts),
            settings,
            ext_periods,
            vs.seed + r,
            tangent_tol=vs.lyapunov_tol,
        )
        n_state = systems[0].n_state
        stretch = out.stretch(n_state)
        for i, k in enumerate(todo):
            p = pts[k]
            p.extra += ext_periods
            if int(out.status[i, 0]) != 0:
                done[k] = Verdict(
                    "failed",
                    0,
                    "failed",
                    extra_periods=p.extra,
                    reason="the integration failed while the run was extended",
                )
                continue
            T = systems[k].period
            p.lle, p.err = exponent_estimate(stretch[i, 0], T, blocks=vs.blocks)
            p.theta = vs.lle_c / ((ext_periods - 1) * T)
            states = out.states[i, 0, :, :n_state].copy()
            p.sections = states
            p.final = out.final_state[i, 0, :n_state].copy()
            p.record = VerdictRecord(
                states,
                out.observables[i, 0].copy(),
                p.final.copy(),
                out.obs_min[i, 0].copy(),
                out.obs_max[i, 0].copy(),
            )
    for k in pts:  # not reached: the last round decides every point it extends
        done.setdefault(
            k, Verdict("unresolved", 0, "ambiguous", reason="not decided within the budget")
        )
    return [done[k] for k in range(K)]
