"""Which attractor a start reaches: the attractor catalogue of a basin computation.

A basin image or a basin-fraction estimate integrates thousands of starts at one operating
point, and almost all of them end on a few attractors. Deciding every start with the full
motion verdict (:func:`~gearchaos.dynamics.verdict.decide.decide_motion`: shooting, Lyapunov
extensions) would cost far more than the integrations. Instead a :class:`Catalogue` is built
first from a small sample of the starts with
:func:`~gearchaos.dynamics.attractors.coexistence.attractors`
(each attractor decided by the verdict, periodic ones confirmed by shooting with their Floquet
multipliers), and every start's recorded section states are then matched against it
(:meth:`Catalogue.match`), with states scaled per component by ``scale`` = max(1, spread of
the sample's section states):

* a start is on a periodic attractor of period n when each of the last n section points of
  its record lies within ``tol`` (∞-norm, scaled) of one of the attractor's n section points
  and each of those within ``tol`` of one of its points;
* a start is on a non-periodic attractor (QP, chaos, unresolved) when its record repeats with
  no period ≤ :data:`MAX_RECUR` to within 10 ``tol`` and either every one of its section
  points lies within r of a point of the attractor's set (r = 3 × the 90th percentile of the
  set's nearest-neighbour distances: the record is a piece of the set), or, for every state
  component, the 10 %, 50 % and 90 % quantiles of its section points and of the attractor's
  agree to ``spread_fraction`` of the extent of the two sets together (the rule of
  :func:`~gearchaos.dynamics.attractors.coexistence.attractors`).

Only the starts that match nothing (a transient not finished, an attractor the sample missed)
get the full verdict (:func:`identify`), a few at a time: its label and record are matched
again (a confirmed period-n orbit within ``verdict_tol`` of a catalogued one of the same period
is that one), and an attractor still unknown is added to the catalogue, so the next starts
match it cheaply. A start whose integration failed (diverged, step budget) gets the code
:data:`FAILED`.

:func:`link_tracks` follows the attractors of neighbouring parameter values (for basin
fractions across a parameter): same label and nearest section set, within ``link_tol``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..._checks import check_int, check_real
from ...analysis.motion import Motion
from ...errors import ParameterError
from ...integrate.settings import SolverSettings
from ...model.target import Target
from ..verdict.decide import CONFIRM_PERIODS, VerdictSettings, confirmed_settings, decide_motion

__all__ = [
    "FAILED",
    "MAX_RECUR",
    "NOT_RUN",
    "BasinAttractor",
    "Catalogue",
    "catalogue_from_sample",
    "identify",
    "link_tracks",
]

#: Code of a start whose integration failed (diverged, exceeded the step budget).
FAILED = -2
#: Code of a start not computed yet (an interrupted store).
NOT_RUN = -1
#: Longest recurrence checked before a record may match a non-periodic attractor.
MAX_RECUR = 16
#: Most section points an attractor keeps for matching and for the figures.
MAX_POINTS = 256
_Q = np.array([0.1, 0.5, 0.9])


def _periodic(label: str) -> int:
    return Motion.parse(label).period


def _number(v: Any) -> float | None:
    v = float(v)
    return v if math.isfinite(v) else None


@dataclass(frozen=True, eq=False)
class BasinAttractor:
    """One catalogued attractor.

    Attributes
    ----------
    label
        The motion verdict's label (``1T`` … ``nT``, ``QP``, ``chaos``, ``unresolved``).
    period
        n of an nT label, else 0.
    lle
        λ₁ per unit τ (ln max|μ| / (nT) for a confirmed orbit).
    max_multiplier
        max |μ| of its periodic orbit (NaN for a non-periodic attractor).
    evidence
        What decided the label (a key of :data:`~gearchaos.dynamics.verdict.evidence.EVIDENCE`).
    section_states
        (m, n_state) its section states: the n points of a period-n orbit, else up to
        :data:`MAX_POINTS` points of its record.
    """

    label: str
    period: int
    lle: float
    max_multiplier: float
    evidence: str
    section_states: np.ndarray

    def legend(
        self,
        name: str | None = None,
        column: int = 0,
        number: Callable[[float, str], str] = format,
    ) -> str:
        """``1T (x ≈ 0.962, |μ| 0.91)`` or ``chaos (λ₁ 0.071)``: the label with the evidence
        (max |μ| of an orbit, else λ₁) and, given a state ``name`` and its ``column``, where
        the attractor lies (its first section point, or the middle of its set). ``number``
        writes a value with a format spec (figures pass theirs, which writes a true minus)."""
        parts = []
        if name is not None:
            x = self.section_states[:, column]
            where = x[0] if self.period else 0.5 * (np.min(x) + np.max(x))
            parts.append(f"{name} ≈ {number(float(where), '.3g')}")
        if self.period and math.isfinite(self.max_multiplier):
            parts.append(f"|μ| {number(float(self.max_multiplier), '.2f')}")
        elif math.isfinite(self.lle):
            parts.append(f"λ₁ {number(float(self.lle), '.2g')}")
        return f"{self.label} ({', '.join(parts)})" if parts else self.label

    def to_record(self) -> dict[str, Any]:
        """A JSON-ready record (floats written exactly; NaN as null)."""
        return {
            "label": self.label,
            "period": int(self.period),
            "lle": _number(self.lle),
            "max_multiplier": _number(self.max_multiplier),
            "evidence": self.evidence,
            "section_states": [[float(v) for v in row] for row in self.section_states],
        }

    @classmethod
    def from_record(cls, rec: Mapping[str, Any]) -> BasinAttractor:
        def num(v: Any) -> float:
            return math.nan if v is None else float(v)

        return cls(
            label=str(rec["label"]),
            period=int(rec["period"]),
            lle=num(rec["lle"]),
            max_multiplier=num(rec["max_multiplier"]),
            evidence=str(rec["evidence"]),
            section_states=np.array(rec["section_states"], dtype=np.float64),
        )


def _thin(states: np.ndarray, period: int) -> np.ndarray:
    if period:
        return np.array(states[-period:], dtype=np.float64)
    return np.array(states[-MAX_POINTS:], dtype=np.float64)


def _more_points(system: Any, state: np.ndarray, settings: SolverSettings) -> np.ndarray | None:
    """:data:`MAX_POINTS` section states of a non-periodic attractor, integrated on from a
    state on it (the record a verdict saw is too short to describe the set), or None when
    that integration fails."""
    from ...integrate.batch import integrate_batch

    cfg = settings.replace(transient_periods=0, periods=MAX_POINTS, samples_per_period=1)
    out = integrate_batch([system], cfg, y0=np.asarray(state, dtype=np.float64)[None])
    st = np.asarray(out.states[0, :, : system.n_state])
    return st if int(out.status[0]) == 0 and np.all(np.isfinite(st)) else None


def _recurrence(rec: np.ndarray) -> np.ndarray:
    """(K,) the smallest max_k ‖x_{k+p} − x_k‖_∞ over p ≤ MAX_RECUR of scaled records."""
    m = rec.shape[1]
    best = np.full(rec.shape[0], np.inf)
    for p in range(1, min(MAX_RECUR, m - 1) + 1):
        gap = np.max(np.abs(rec[:, p:] - rec[:, :-p]), axis=(1, 2))
        best = np.minimum(best, gap)
    return best


def _same_quantiles(rec: np.ndarray, pts: np.ndarray, fraction: float) -> np.ndarray:
    """(K,) whether the 10/50/90 % quantiles of each record agree with those of ``pts`` to
    ``fraction`` of the two sets' joint extent, in every component."""
    qa = np.quantile(rec, _Q, axis=1)  # (3, K, d)
    qb = np.quantile(pts, _Q, axis=0)  # (3, d)
    hi = np.maximum(rec.max(axis=1), pts.max(axis=0))
    lo = np.minimum(rec.min(axis=1), pts.min(axis=0))
    size = np.maximum(np.max(hi - lo, axis=1), 1e-12)
    gap = np.max(np.abs(qa - qb[:, None, :]), axis=(0, 2))
    return np.asarray(gap <= fraction * size)


def _inside(rec: np.ndarray, pts: np.ndarray, radius: float) -> np.ndarray:
    """(K,) whether every point of each record lies within ``radius`` (∞-norm) of a point
    of ``pts``: the record is a piece of that set."""
    out = np.empty(rec.shape[0], dtype=bool)
    for lo in range(0, rec.shape[0], 64):
        r = rec[lo : lo + 64]
        d = np.max(np.abs(r[:, :, None, :] - pts[None, None, :, :]), axis=3)
        out[lo : lo + 64] = np.all(d.min(axis=2) <= radius, axis=1)
    return out


class Catalogue:
    """The attractors found so far at one operating point, and the matching rules (see the
    module docstring). Indices into :attr:`entries` are the attractor codes of a store."""

    def __init__(
        self,
        entries: Sequence[BasinAttractor],
        scale: np.ndarray,
        *,
        tol: float = 1e-4,
        spread_fraction: float = 0.25,
        verdict_tol: float = 1e-3,
    ):
        self.entries = list(entries)
        self.scale = np.asarray(scale, dtype=np.float64)
        self.tol = check_real("tol", tol, lo=0.0, lo_open=True)
        self.spread_fraction = check_real(
            "spread_fraction", spread_fraction, lo=0.0, hi=1.0, lo_open=True
        )
        self.verdict_tol = check_real("verdict_tol", verdict_tol, lo=0.0, lo_open=True)
        self._radii: dict[int, float] = {}

    def __len__(self) -> int:
        return len(self.entries)

    def _radius(self, i: int, pts: np.ndarray) -> float:
        """The containment radius of non-periodic entry ``i`` (scaled points ``pts``):
        3 × the 90th percentile of the distances of its points to their nearest neighbour."""
        if i not in self._radii:
            d = np.max(np.abs(pts[:, None, :] - pts[None, :, :]), axis=2)
            np.fill_diagonal(d, np.inf)
            nn = d.min(axis=1)
            self._radii[i] = (
                3.0 * float(np.quantile(nn[np.isfinite(nn)], 0.9)) if nn.size > 1 else 0.0
            )
        return self._radii[i]

    def to_record(self) -> dict[str, Any]:
        return {
            "scale": [float(v) for v in self.scale],
            "tol": self.tol,
            "spread_fraction": self.spread_fraction,
            "verdict_tol": self.verdict_tol,
            "entries": [e.to_record() for e in self.entries],
        }

    @classmethod
    def from_record(cls, rec: Mapping[str, Any]) -> Catalogue:
        return cls(
            [BasinAttractor.from_record(e) for e in rec["entries"]],
            np.array(rec["scale"], dtype=np.float64),
            tol=float(rec["tol"]),
            spread_fraction=float(rec["spread_fraction"]),
            verdict_tol=float(rec["verdict_tol"]),
        )

    def add(self, entry: BasinAttractor) -> int:
        self.entries.append(entry)
        return len(self.entries) - 1

    def match(
        self, records: np.ndarray, *, label: str | None = None, tol: float | None = None
    ) -> np.ndarray:
        """(K,) the code of the attractor each record (K, m, n_state) of section states lies
        on, or -1. With ``label`` only attractors of that label are candidates and a
        non-periodic record is not required to be free of short recurrences (the verdict
        decided it); ``tol`` replaces the periodic tolerance."""
        rec = np.asarray(records, dtype=np.float64) / self.scale
        K, m = rec.shape[0], rec.shape[1]
        codes = np.full(K, -1, dtype=np.int64)
        if K == 0:
            return codes
        tol_p = self.tol if tol is None else float(tol)
        free = None
        for i, e in enumerate(self.entries):
            if label is not None and e.label != label:
                continue
            left = codes < 0
            if not np.any(left):
                break
            pts = e.section_states / self.scale
            if e.period:
                n = e.period
                if n > m:
                    continue
                tail = rec[:, -n:]  # (K, n, d) against the orbit's (n, d)
                d = np.max(np.abs(tail[:, :, None, :] - pts[None, None, :, :]), axis=3)
                ok = np.all(d.min(axis=2) <= tol_p, axis=1) & np.all(d.min(axis=1) <= tol_p, axis=1)
            else:
                if free is None:
                    free = (
                        np.ones(K, dtype=bool)
                        if label is not None
                        else _recurrence(rec) > 10.0 * self.tol
                    )
                ok = free & (
                    _inside(rec, pts, self._radius(i, pts))
                    | _same_quantiles(rec, pts, self.spread_fraction)
                )
            codes[left & ok] = i
        return codes


def catalogue_from_sample(
    target: Target,
    values: Mapping[str, Any],
    starts: np.ndarray,
    settings: SolverSettings,
    *,
    tol: float = 1e-4,
    spread_fraction: float = 0.25,
    confirm_periods: int = CONFIRM_PERIODS,
) -> Catalogue:
    """The attractors reached from ``starts`` (K, n_state), by
    :func:`~gearchaos.dynamics.attractors.coexistence.attractors` with the same rules (a chaotic or
    QP
    one confirmed over a last window of ``confirm_periods``); the scale is max(1, the spread
    of their section states) per component."""
    from .coexistence import attractors

    found = attractors(
        target,
        initial_states=starts,
        settings=settings,
        params=dict(values),
        tol=tol,
        spread_fraction=spread_fraction,
        confirm_periods=confirm_periods,
    )
    entries = []
    for a in found:
        if a.label == "failed":
            continue
        mu = a.max_multiplier
        if not math.isfinite(mu) and a.verdict is not None:
            mu = a.verdict.max_multiplier
        states = a.section_states
        if not a.period:
            more = _more_points(a.system, a.final_state, settings)
            states = a.section_states if more is None else more
        entries.append(
            BasinAttractor(
                label=a.label,
                period=a.period,
                lle=a.lle,
                max_multiplier=mu if a.period else math.nan,
                evidence=a.verdict.evidence if a.verdict is not None else "not_computed",
                section_states=_thin(states, a.period),
            )
        )
    pts = [e.section_states for e in entries]
    n = int(np.asarray(starts).shape[1])
    every = np.concatenate(pts) if pts else np.zeros((1, n))
    scale = np.maximum(1.0, np.ptp(every, axis=0))
    # one attractor, not several: a non-periodic set whose points the rule that assigns the
    # starts puts on an attractor already kept is that attractor (short sample records of
    # one chaotic attractor need not overlap enough for the sample's own grouping)
    kept: list[BasinAttractor] = []
    for e in entries:
        if not e.period and kept:
            trial = Catalogue(kept, scale, tol=tol, spread_fraction=spread_fraction)
            if trial.match(e.section_states[None], label=e.label)[0] >= 0:
                continue
        kept.append(e)
    return Catalogue(kept, scale, tol=tol, spread_fraction=spread_fraction)


def identify(
    catalogue: Catalogue,
    target: Target,
    values: Mapping[str, Any],
    system: Any,
    settings: SolverSettings,
    sections: np.ndarray,
    finals: np.ndarray,
    ok: np.ndarray,
    *,
    batch: int = 8,
    verdict: VerdictSettings | None = None,
) -> np.ndarray:
    """(K,) the attractor code of each start from its record: ``sections`` (K, m, n_state)
    section states, ``finals`` (K, n_state), ``ok`` (K,) whether its integration succeeded.

    Records that match the catalogue take its code; the others are decided ``batch`` at a
    time by the motion verdict (``verdict``; default
    :func:`~gearchaos.dynamics.verdict.decide.confirmed_settings`, chaos and QP confirmed over a
    last
    window of :data:`~gearchaos.dynamics.verdict.decide.CONFIRM_PERIODS`), matched again with its
    label and record, and added to ``catalogue`` (which grows) when still unknown; failed runs
    get :data:`FAILED`."""
    batch = check_int("batch", batch, lo=1, hi=10_000)
    sec = np.asarray(sections, dtype=np.float64)
    fin = np.asarray(finals, dtype=np.float64)
    if sec.ndim != 3 or fin.shape != (sec.shape[0], sec.shape[2]):
        raise ParameterError(
            f"sections must be (K, m, n) and finals (K, n): got {sec.shape} and {fin.shape}"
        )
    K = sec.shape[0]
    good = np.asarray(ok, dtype=bool) & np.all(np.isfinite(sec), axis=(1, 2))
    good &= np.all(np.isfinite(fin), axis=1)
    codes = np.full(K, FAILED, dtype=np.int64)
    idx = np.flatnonzero(good)
    codes[idx] = catalogue.match(sec[idx])
    left = np.flatnonzero(codes == -1)
    while left.size:
        take, rest = left[:batch], left[batch:]
        verdicts = decide_motion(
            target,
            [values] * take.size,
            [system] * take.size,
            sec[take],
            fin[take],
            np.ones(take.size, dtype=bool),
            settings,
            confirmed_settings() if verdict is None else verdict,
        )
        for k, v in zip(take, verdicts, strict=True):
            if v.label == "failed":
                codes[k] = FAILED
                continue
            # the verdict's whole record (an extension is longer than the original)
            rec = sec[k] if v.record is None else np.asarray(v.record.states)
            n = _periodic(v.label)
            code = int(
                catalogue.match(rec[None], label=v.label, tol=catalogue.verdict_tol if n else None)[
                    0
                ]
            )
            if code < 0:
                if not n:
                    end = fin[k] if v.record is None else np.asarray(v.record.final_state)
                    more = _more_points(system, end, settings)
                    rec = rec if more is None else more
                code = catalogue.add(
                    BasinAttractor(
                        label=v.label,
                        period=n,
                        lle=v.lle,
                        max_multiplier=v.max_multiplier if n else math.nan,
                        evidence=v.evidence,
                        section_states=_thin(rec, n),
                    )
                )
            codes[k] = code
        if rest.size:
            codes[rest] = catalogue.match(sec[rest])
        left = rest[codes[rest] == -1]
    return codes


def _distance(a: BasinAttractor, b: BasinAttractor, scale: np.ndarray) -> float:
    """Distance of two attractors' section sets (scaled): the symmetric Hausdorff distance
    of two orbits' points, the largest quantile gap of two non-periodic sets."""
    pa, pb = a.section_states / scale, b.section_states / scale
    if a.period:
        d = np.max(np.abs(pa[:, None, :] - pb[None, :, :]), axis=2)
        return float(max(d.min(axis=1).max(), d.min(axis=0).max()))
    qa, qb = np.quantile(pa, _Q, axis=0), np.quantile(pb, _Q, axis=0)
    return float(np.max(np.abs(qa - qb)))


def link_tracks(
    catalogues: Sequence[Catalogue | None], *, link_tol: float = 0.2
) -> list[list[int]]:
    """Follow attractors across consecutive parameter values: track ids (one list per
    catalogue, one id per entry). An entry continues the track of the nearest entry of the
    previous catalogue with the same label (not taken by a nearer one) when their section sets
    are within ``link_tol`` (scaled; :func:`_distance`); otherwise it starts a new track."""
    check_real("link_tol", link_tol, lo=0.0)
    tracks: list[list[int]] = []
    prev: Catalogue | None = None
    prev_ids: list[int] = []
    count = 0
    for cat in catalogues:
        ids: list[int] = []
        if cat is None:
            tracks.append(ids)
            prev, prev_ids = None, []
            continue
        pairs = []
        if prev is not None:
            scale = np.maximum(cat.scale, prev.scale)
            for i, e in enumerate(cat.entries):
                for j, f in enumerate(prev.entries):
                    if e.label == f.label:
                        d = _distance(e, f, scale)
                        if d <= link_tol:
                            pairs.append((d, i, j))
        linked: dict[int, int] = {}
        used: set[int] = set()
        for _, i, j in sorted(pairs):
            if i not in linked and j not in used:
                linked[i] = prev_ids[j]
                used.add(j)
        for i in range(len(cat.entries)):
            if i in linked:
                ids.append(linked[i])
            else:
                ids.append(count)
                count += 1
        tracks.append(ids)
        prev, prev_ids = cat, ids
    return tracks
