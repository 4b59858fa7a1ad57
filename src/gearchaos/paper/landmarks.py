"""The seed paper's quantitative statements (Section 3) as data, and their check on sweep stores.

``landmarks.toml`` (packaged beside this module; a copy sits at the repository's
``paper/landmarks.toml``) holds one ``[[landmark]]`` per statement of Sheng et al. (2016)
about Figs. 4–12: the swept axis, the panel and fixed parameters, and one of three kinds:

``label``
    the motion label is one of ``expected`` over ``[lo, hi]`` (or within ``±tolerance`` of
    ``at``). Score ``min(1, f / min_fraction)`` with ``f`` the fraction of grid points whose
    label is expected; *holds* when ``f ≥ min_fraction`` (0.8 unless the landmark says
    otherwise), *partly* when ``f ≥ min_fraction / 2``.
``transition``
    reading the axis upwards, a point labelled in ``from`` is followed by one labelled in
    ``expected``, at ``at`` (or anywhere inside ``[lo, hi]``). The change is placed at the
    midpoint of the two points (``failed`` and ``unresolved`` points are skipped); ``d`` is the
    distance of the nearest change to ``at`` (or to ``[lo, hi]``). Score 1 (*holds*) for
    ``d ≤ tol``, 0.75 → 0.25 (*partly*) for ``tol < d ≤ 3 tol``, then down to 0 at ``6 tol``.
``window``
    a regime window ``lo``–``hi``: score ``0.5 min(1, f / min_fraction) + 0.25 s_lo + 0.25 s_hi``
    with ``f`` the fraction of points inside carrying an expected label and ``s_lo``, ``s_hi``
    the distance scores (as for transitions) of the window's measured edges (the nearest entry
    into / exit from the expected labels). *holds* ≥ 0.8, *partly* ≥ 0.4.
``negligible``
    the swept parameter affects the motion negligibly over ``[lo, hi]``: per point the centre
    (mean) and the size (max − min) of its X̄_sp1 section values; ``c`` the larger of their
    ranges along the axis over the points inside (``failed`` left out), relative to the largest
    |X̄_sp1| there. Score 1 (*holds*) for ``c ≤ max_change`` (0.05 unless the landmark says
    otherwise), then as a transition's distance score with ``max_change`` for the tolerance.

A label landmark with ``contrast = "below"`` (or ``"above"``) says its labels *become*
dominant at the range: the fraction ``f_out`` of expected labels over the rest of the sweep on
that side must stay below ``min_fraction``; when they are dominant there too the verdict is at
most *partly* (score ≤ 0.5: dominant, but no trend).

The label ``nT`` in a landmark stands for any n-periodic label with n ≥ 2.

A hold is only as good as the swept parameter's effect: :mod:`gearchaos.paper.action` tests,
per panel, whether the parameter acts at all, and :func:`gearchaos.paper.action.apply_actions`
turns a hold on a panel where it does not into ``holds (constant)``, counted apart.

>>> from gearchaos.paper.landmarks import load_landmarks, evaluate_all, score
>>> marks = load_landmarks()
>>> results = evaluate_all(marks, {"fig4": ds4})   # doctest: +SKIP
>>> score(results)                                  # doctest: +SKIP

Limits: a landmark is checked on the motion labels (a negligible one on the section values) of
one planet-independent sweep store; the seed's own reading of its figures was by eye, so the
verdicts measure agreement with the labels, not with the seed's pictures. Amplitude statements
are not landmarks, except "affected negligibly" (Fig. 12).
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from ..analysis.motion import Motion
from ..sweep.result import SweepResult
from .landmark_data import (
    AXES,
    CONTRASTS,
    EVENTS,
    KINDS,
    MAX_LANDMARKS_BYTES,
    VERDICTS,
    AxisAction,
    Landmark,
    LandmarkResult,
    Verdict,
    _close,
    load_landmarks,
    recipe_for,
)

__all__ = [
    "AXES",
    "CONTRASTS",
    "EVENTS",
    "KINDS",
    "MAX_LANDMARKS_BYTES",
    "VERDICTS",
    "AxisAction",
    "Landmark",
    "LandmarkResult",
    "Verdict",
    "evaluate",
    "evaluate_all",
    "load_landmarks",
    "recipe_for",
    "score",
]

#: Labels that say nothing about the motion: skipped when locating changes.
_NO_LABEL = ("failed", "unresolved")


# ---------------------------------------------------------------------------- evaluation
def _matches(label: str, accepted: Sequence[str]) -> bool:
    if label in accepted:
        return True
    if "nT" in accepted:
        return Motion.parse(label).period >= 2
    return False


def _dist_score(d: float, tol: float) -> float:
    if d <= tol:
        return 1.0
    if d <= 3 * tol:
        return 0.75 - 0.25 * (d - tol) / tol
    return max(0.0, 0.25 * (1.0 - (d - 3 * tol) / (3 * tol)))


def _not_evaluated(mark: Landmark, why: str) -> LandmarkResult:
    return LandmarkResult(mark, "not evaluated", 0.0, why, {})


def _select(mark: Landmark, ds: Any, planet: int) -> dict[str, Any] | str:
    """Positions (``planet`` by value) of the landmark's panel in every dimension of ``motion``
    but the swept one; or why there is none."""
    if "motion" not in getattr(ds, "data_vars", {}):
        return "the dataset has no motion labels (classify the sweep store first)"
    motion = ds["motion"]
    if mark.axis not in motion.dims:
        return f"the dataset does not sweep {mark.axis} (dims: {', '.join(map(str, motion.dims))})"
    sel: dict[str, Any] = {}
    for dim in motion.dims:
        if dim == mark.axis:
            continue
        if dim == "planet":
            if planet not in ds["planet"].values:
                return f"planet {planet} is not in the dataset"
            sel[dim] = planet
            continue
        if dim not in mark.fixed:
            return f"the dataset has a dimension {dim} that the landmark does not fix"
        coords = np.asarray(ds[dim].values, dtype=float)
        want = mark.fixed[dim]
        j = int(np.argmin(np.abs(coords - want)))
        if not _close(float(coords[j]), want):
            have = ", ".join(f"{c:g}" for c in coords)
            return f"no panel {dim} = {want:g} in the dataset (has {have})"
        sel[dim] = j
    stored = _stored_fixed(ds)
    for k, v in stored.items():
        if k in mark.fixed and k not in motion.dims and not _close(float(v), mark.fixed[k]):
            return f"the dataset fixes {k} = {float(v):g}, the landmark {mark.fixed[k]:g}"
    return sel


def _take(var: Any, sel: Mapping[str, Any], planet: int) -> Any:
    """``var`` at the panel ``sel`` (planet by value when ``var`` has planets)."""
    idx = {k: v for k, v in sel.items() if k != "planet" and k in var.dims}
    if "planet" in var.dims:
        var = var.sel(planet=planet) if "planet" in var.coords else var.isel(planet=planet - 1)
    return var.isel(idx) if idx else var


def _panel(mark: Landmark, ds: Any, planet: int) -> tuple[np.ndarray, np.ndarray] | str:
    """(axis values, labels) of the landmark's panel, sorted by axis; or why not."""
    got = _panel_order(mark, ds, planet)
    if isinstance(got, str):
        return got
    x, labels, _, _ = got
    return x, labels


def _panel_order(
    mark: Landmark, ds: Any, planet: int
) -> tuple[np.ndarray, np.ndarray, dict[str, Any], np.ndarray] | str:
    """(sorted axis values, labels, the panel's positions, the sorting order); or why not."""
    sel = _select(mark, ds, planet)
    if isinstance(sel, str):
        return sel
    panel = _take(ds["motion"], sel, planet)
    x = np.asarray(ds[mark.axis].values, dtype=float)
    labels = np.asarray(panel.transpose(mark.axis).values).astype(str)
    order = np.argsort(x, kind="stable")
    x, labels = x[order], labels[order]
    tol = mark.tolerance
    lo, hi = mark.span
    if lo < x[0] - tol or hi > x[-1] + tol:
        return f"the dataset sweeps {mark.axis} over [{x[0]:g}, {x[-1]:g}], not {mark.where()}"
    return x, labels, sel, order


def _stored_fixed(ds: Any) -> dict[str, Any]:
    """The sweep's numeric fixed values by dotted name (none for a dataset without a spec)."""
    if not getattr(ds, "attrs", {}).get("sweep_toml"):
        return {}
    fixed = SweepResult.of(ds).fixed
    return {k: v for k, v in fixed.items() if isinstance(v, int | float)}


def _counts(labels: np.ndarray) -> str:
    c = Counter(labels.tolist())
    return ", ".join(f"{k} {n}" for k, n in c.most_common())


def _changes(
    x: np.ndarray, labels: np.ndarray, before: Sequence[str], after: Sequence[str]
) -> list[float]:
    """Midpoints of every change, axis increasing, from a label in ``before`` to one in
    ``after`` (points labelled failed/unresolved skipped)."""
    keep = np.array([lab not in _NO_LABEL for lab in labels.tolist()], dtype=bool)
    xs, ls = x[keep], labels[keep].tolist()
    out = []
    for i in range(len(ls) - 1):
        if ls[i] != ls[i + 1] and _matches(ls[i], before) and _matches(ls[i + 1], after):
            out.append(0.5 * (float(xs[i]) + float(xs[i + 1])))
    return out


def _distance(loc: float, lo: float, hi: float) -> float:
    return max(lo - loc, 0.0, loc - hi)


def _label(mark: Landmark, x: np.ndarray, labels: np.ndarray) -> LandmarkResult:
    lo, hi = mark.span
    tol = mark.tolerance
    if mark.at is not None:
        inside = np.abs(x - mark.at) <= tol
        where = f"within ±{tol:g} of {mark.at:g}"
    else:
        inside = (x >= lo - 1e-12 * max(1.0, abs(lo))) & (x <= hi + 1e-12 * max(1.0, abs(hi)))
        where = f"in [{lo:g}, {hi:g}]"
    n = int(inside.sum())
    if n == 0:
        return _not_evaluated(mark, f"no grid point {where} (grid step too coarse)")
    sub = labels[inside]
    ok = np.array([_matches(s, mark.expected) for s in sub.tolist()], dtype=bool)
    frac = float(ok.mean())
    sc = min(1.0, frac / mark.min_fraction)
    verdict: Verdict = (
        "holds" if frac >= mark.min_fraction else "partly" if sc >= 0.5 else "does not hold"
    )
    exp = "/".join(mark.expected)
    evidence = f"{exp} at {frac:.0%} of {n} points {where} (found: {_counts(sub)})"
    measured: dict[str, Any] = {
        "fraction": frac,
        "points": n,
        "counts": dict(Counter(sub.tolist())),
    }
    if mark.contrast:
        return _contrast(mark, x, labels, LandmarkResult(mark, verdict, sc, evidence, measured))
    return LandmarkResult(mark, verdict, sc, evidence, measured)


def _contrast(
    mark: Landmark, x: np.ndarray, labels: np.ndarray, inside: LandmarkResult
) -> LandmarkResult:
    """A label landmark whose labels *become* dominant at its range (``contrast``): at most
    *partly* (score ≤ 0.5) unless they are not dominant over the sweep on the other side."""
    lo, hi = mark.span
    if mark.contrast == "below":
        out = x < lo - 1e-12 * max(1.0, abs(lo))
        side = f"below {lo:g}"
    else:
        out = x > hi + 1e-12 * max(1.0, abs(hi))
        side = f"above {hi:g}"
    sub = labels[out]
    n = int(sub.size)
    frac = float(np.mean([_matches(s, mark.expected) for s in sub.tolist()])) if n else math.nan
    trend = n > 0 and frac < mark.min_fraction
    measured = {**inside.measured, "fraction_outside": frac, "points_outside": n, "trend": trend}
    if n == 0:
        tail = f"; no point {side} to show that they become dominant: no trend shown"
    elif trend:
        tail = f"; {side}: {frac:.0%} of {n} points (found: {_counts(sub)}): a trend"
    else:
        tail = (
            f"; {side}: {frac:.0%} of {n} points (found: {_counts(sub)}): dominant on both "
            "sides, no trend"
        )
    verdict, sc = inside.verdict, inside.score
    if not trend and verdict == "holds":
        verdict, sc = "partly", min(sc, 0.5)
    elif not trend:
        sc = min(sc, 0.5)
    return LandmarkResult(mark, verdict, sc, inside.evidence + tail, measured)


def _negligible(
    mark: Landmark, x: np.ndarray, labels: np.ndarray, sections: np.ndarray | None
) -> LandmarkResult:
    """Per-point attractor (centre, size of the section values) unchanged along the axis."""
    lo, hi = mark.span
    if sections is None:
        return _not_evaluated(mark, "the dataset has no delta_sp section values")
    inside = (x >= lo - 1e-12 * max(1.0, abs(lo))) & (x <= hi + 1e-12 * max(1.0, abs(hi)))
    inside &= labels != "failed"
    sec = np.asarray(sections, dtype=float)[inside]
    finite = np.isfinite(sec).any(axis=1)
    sec = sec[finite]
    n = int(sec.shape[0])
    if n < 2:
        return _not_evaluated(mark, f"fewer than 2 computed points in [{lo:g}, {hi:g}]")
    with np.errstate(all="ignore"):
        centre = np.nanmean(sec, axis=1)
        size = np.nanmax(sec, axis=1) - np.nanmin(sec, axis=1)
        scale = float(np.nanmax(np.abs(sec)))
    d_centre, d_size = float(np.ptp(centre)), float(np.ptp(size))
    change = max(d_centre, d_size) / scale if scale > 0 else 0.0
    m = mark.max_change
    sc = _dist_score(change, m)
    verdict: Verdict = "holds" if change <= m else "partly" if change <= 3 * m else "does not hold"
    evidence = (
        f"over {n} points in [{lo:g}, {hi:g}] the centre of the X̄_sp1 section values moves by "
        f"{d_centre:.3g} and their spread changes by {d_size:.3g}: {change:.2%} of the largest "
        f"|X̄_sp1| {scale:.3g} (negligible up to {m:.0%})"
    )
    measured = {
        "points": n,
        "centre_change": d_centre,
        "size_change": d_size,
        "scale": scale,
        "relative_change": change,
    }
    return LandmarkResult(mark, verdict, sc, evidence, measured)


def _transition(mark: Landmark, x: np.ndarray, labels: np.ndarray) -> LandmarkResult:
    lo, hi = mark.span
    tol = mark.tolerance
    locs = _changes(x, labels, mark.from_labels, mark.expected)
    change = f"{'/'.join(mark.from_labels)} → {'/'.join(mark.expected)}"
    target = f"{mark.at:g}" if mark.at is not None else f"[{lo:g}, {hi:g}]"
    if not locs:
        return LandmarkResult(
            mark,
            "does not hold",
            0.0,
            f"no change {change} anywhere in [{x[0]:g}, {x[-1]:g}] (expected at {target})",
            {"location": None, "distance": None, "changes": []},
        )
    dists = [_distance(v, lo, hi) for v in locs]
    j = int(np.argmin(dists))
    d = dists[j]
    sc = _dist_score(d, tol)
    verdict: Verdict = "holds" if d <= tol else "partly" if d <= 3 * tol else "does not hold"
    evidence = (
        f"change {change} at {locs[j]:.4g} (expected {target}, distance {d:.3g}, "
        f"tolerance {tol:g}); {len(locs)} such change(s) in the sweep"
    )
    measured = {"location": locs[j], "distance": d, "changes": locs}
    return LandmarkResult(mark, verdict, sc, evidence, measured)


def _window(mark: Landmark, x: np.ndarray, labels: np.ndarray) -> LandmarkResult:
    assert mark.lo is not None and mark.hi is not None
    lo, hi, tol = mark.lo, mark.hi, mark.tolerance
    inside = (x >= lo - 1e-12 * max(1.0, abs(lo))) & (x <= hi + 1e-12 * max(1.0, abs(hi)))
    n = int(inside.sum())
    if n == 0:
        return _not_evaluated(mark, f"no grid point in [{lo:g}, {hi:g}] (grid step too coarse)")
    sub = labels[inside]
    frac = float(np.mean([_matches(s, mark.expected) for s in sub.tolist()]))

    def _not_expected(lab: str) -> bool:
        return not _matches(lab, mark.expected)

    keep = np.array([lab not in _NO_LABEL for lab in labels.tolist()], dtype=bool)
    xs, ls = x[keep], labels[keep].tolist()
    ups, downs = [], []
    for i in range(len(ls) - 1):
        mid = 0.5 * (float(xs[i]) + float(xs[i + 1]))
        if _not_expected(ls[i]) and not _not_expected(ls[i + 1]):
            ups.append(mid)
        elif not _not_expected(ls[i]) and _not_expected(ls[i + 1]):
            downs.append(mid)
    # a window that touches the end of the sweep has no edge to find there
    if ls and lo <= float(xs[0]) + tol and not _not_expected(ls[0]):
        ups.append(float(xs[0]))
    if ls and hi >= float(xs[-1]) - tol and not _not_expected(ls[-1]):
        downs.append(float(xs[-1]))
    e_lo = min(ups, key=lambda v: abs(v - lo)) if ups else None
    e_hi = min(downs, key=lambda v: abs(v - hi)) if downs else None
    s_lo = _dist_score(abs(e_lo - lo), tol) if e_lo is not None else 0.0
    s_hi = _dist_score(abs(e_hi - hi), tol) if e_hi is not None else 0.0
    sc = 0.5 * min(1.0, frac / mark.min_fraction) + 0.25 * s_lo + 0.25 * s_hi
    verdict: Verdict = "holds" if sc >= 0.8 else "partly" if sc >= 0.4 else "does not hold"
    exp = "/".join(mark.expected)

    def edge(v: float | None) -> str:
        return "none" if v is None else f"{v:.4g}"

    evidence = (
        f"{exp} at {frac:.0%} of {n} points in [{lo:g}, {hi:g}] (found: {_counts(sub)}); "
        f"edges found at {edge(e_lo)}, {edge(e_hi)} (tolerance {tol:g})"
    )
    measured = {"fraction": frac, "points": n, "lower_edge": e_lo, "upper_edge": e_hi}
    return LandmarkResult(mark, verdict, sc, evidence, measured)


def evaluate(landmark: Landmark, ds: Any, *, planet: int = 1) -> LandmarkResult:
    """Check one landmark on a classified sweep dataset whose swept axis is ``landmark.axis``.

    The panel is chosen by nearest value of every non-swept dimension (it must match the
    landmark's fixed value to 1e-9 relative); fixed values stored in the sweep's ``sweep_toml``
    must agree too. When the dataset does not cover the landmark (no ``motion``, another axis,
    a missing panel, a range outside the sweep, no grid point in the range) the verdict is
    ``not evaluated`` with the reason as evidence. ``planet`` selects the planet when the
    labels (or, for a negligible landmark, the ``delta_sp`` section values) carry a
    ``planet`` dimension.
    """
    got = _panel_order(landmark, ds, planet)
    if isinstance(got, str):
        return _not_evaluated(landmark, got)
    x, labels, sel, order = got
    if landmark.kind == "label":
        return _label(landmark, x, labels)
    if landmark.kind == "transition":
        return _transition(landmark, x, labels)
    if landmark.kind == "negligible":
        sections = None
        if "delta_sp" in ds.data_vars:
            var = _take(ds["delta_sp"], sel, planet)
            sections = np.asarray(var.transpose(landmark.axis, "section").values, dtype=float)
            sections = sections[order]
        return _negligible(landmark, x, labels, sections)
    return _window(landmark, x, labels)


def evaluate_all(
    landmarks: Iterable[Landmark], stores: Mapping[str, Any], *, planet: int = 1
) -> list[LandmarkResult]:
    """Evaluate every landmark on the store of the recipe that covers it
    (:func:`recipe_for`; ``stores`` maps recipe names such as ``fig4`` to datasets). A landmark
    whose recipe has no store is ``not evaluated``."""
    out = []
    for m in landmarks:
        name = recipe_for(m)
        ds = stores.get(name)
        if ds is None:
            out.append(_not_evaluated(m, f"no sweep of {name} given"))
        else:
            out.append(evaluate(m, ds, planet=planet))
    return out


def score(results: Iterable[LandmarkResult]) -> float:
    """Sum of the scores (``not evaluated`` counts 0): the calibration's objective."""
    return float(sum(r.score for r in results))
