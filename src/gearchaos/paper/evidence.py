"""Evidence from the motion labels of sweep datasets: panels, label fractions, onsets of chaos
and the route that leads to each (:mod:`gearchaos.paper.conclusions` reads its verdicts from
these; the conventions are in its module docstring).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from ..analysis.motion import Motion

__all__ = [
    "CRISIS_FLOOR",
    "CRISIS_RATIO",
    "MIN_RESOLVED",
    "attractor_change",
    "attractor_size",
    "chaos_onsets",
    "chaotic_fraction",
    "clearance_reach",
    "label_fraction",
    "panel_values",
    "panels",
    "point_statistics",
    "qp_near_3t",
    "section_spread",
]

#: Fraction of a sweep's points that must carry a motion label for the sweep to be used.
MIN_RESOLVED = 0.5
#: Onset is a crisis when the attractor grows by this factor …
CRISIS_RATIO = 2.0
#: … and by at least this fraction of the sweep's largest attractor.
CRISIS_FLOOR = 0.05

_UNINFORMATIVE = ("unresolved", "failed", "")


def _labels(ds: Any) -> np.ndarray:
    return np.asarray(ds["motion"].values).astype(str)


def _dims(ds: Any) -> tuple[str | None, str]:
    """(family dimension or None, swept dimension) of a sweep dataset's ``motion``."""
    dims = tuple(ds["motion"].dims)
    if len(dims) == 1:
        return None, dims[0]
    if len(dims) == 2:
        return dims[0], dims[1]
    raise ValueError(f"motion must have 1 or 2 dimensions: got {dims}")


def panels(ds: Any) -> list[tuple[float | None, np.ndarray, np.ndarray, np.ndarray | None]]:
    """One ``(family value, swept values, labels, sections)`` per panel of a sweep.

    ``sections`` has shape (swept points, sections) — X̄_sp1 of the first stored planet — or is
    ``None`` when the dataset holds no ``delta_sp``.
    """
    fam, vary = _dims(ds)
    x = np.asarray(ds[vary].values, dtype=float)
    labels = _labels(ds)
    sec: np.ndarray | None = None
    if "delta_sp" in ds.data_vars:
        v = ds["delta_sp"]
        if "planet" in v.dims:
            v = v.isel(planet=0)
        order = [d for d in (fam, vary, "section") if d is not None]
        sec = np.asarray(v.transpose(*order).values, dtype=float)
    out: list[tuple[float | None, np.ndarray, np.ndarray, np.ndarray | None]] = []
    if fam is None:
        out.append((None, x, labels, sec))
    else:
        for i, fv in enumerate(np.asarray(ds[fam].values, dtype=float)):
            out.append((float(fv), x, labels[i], None if sec is None else sec[i]))
    return out


def _resolved(labels: np.ndarray) -> np.ndarray:
    return ~np.isin(labels, _UNINFORMATIVE)


def _period(label: str) -> int | None:
    return Motion.parse(label).period or None


def label_fraction(labels: np.ndarray, which: Callable[[str], bool]) -> float:
    """Fraction of the labelled points (``unresolved`` / ``failed`` left out) where ``which``."""
    lab = np.asarray(labels).astype(str).ravel()
    lab = lab[_resolved(lab)]
    if lab.size == 0:
        return math.nan
    return float(np.mean([which(str(s)) for s in lab]))


def chaotic_fraction(ds: Any) -> dict[float, float]:
    """Chaotic fraction of the labelled points per family value (key ``nan`` without family)."""
    return {
        (math.nan if fv is None else fv): label_fraction(lab, lambda s: s == "chaos")
        for fv, _, lab, _ in panels(ds)
    }


def _nonperiodic(s: str) -> bool:
    return s in ("chaos", "QP")


def attractor_size(sections: np.ndarray) -> np.ndarray:
    """Spread (max − min) of the section values of each point: the attractor's size."""
    s = np.asarray(sections, dtype=float)
    with np.errstate(all="ignore"):
        size = np.nanmax(s, axis=-1) - np.nanmin(s, axis=-1)
    return np.where(np.isfinite(size), size, np.nan)


def _route(before: list[str], size_before: float, size_at: float, scale: float) -> str:
    periods: list[int] = []
    for s in reversed(before):  # the periodic run just before the onset, nearest first
        p = _period(s)
        if p is None:
            break
        if not periods or periods[-1] != p:
            periods.append(p)
    periods.reverse()
    doublings = sum(1 for a, b in itertools.pairwise(periods) if b == 2 * a)
    if periods and (doublings >= 2 or (doublings >= 1 and periods[-1] >= 4)):
        return "period doubling"
    last = before[-1] if before else ""
    if _period(last) in (3, 6):
        return "3T channel"
    if last == "QP":
        return "Hopf"
    if (
        math.isfinite(size_before)
        and math.isfinite(size_at)
        and size_at >= CRISIS_RATIO * size_before
        and size_at - size_before >= CRISIS_FLOOR * scale
    ):
        return "crisis"
    return "abrupt"


def chaos_onsets(
    x: np.ndarray, labels: np.ndarray, sections: np.ndarray | None = None, *, history: int = 6
) -> list[dict[str, Any]]:
    """Every onset of chaos along one panel, with its route (see the module's conventions).

    Returns ``[{"at": swept value, "route": ..., "before": [labels], "size_before",
    "size_at"}]``; unlabelled points are dropped from the sequence first.
    """
    lab = np.asarray(labels).astype(str)
    keep = np.flatnonzero(_resolved(lab))
    sizes = (
        attractor_size(np.asarray(sections)[keep])
        if sections is not None
        else np.full(keep.size, np.nan)
    )
    scale = float(np.nanmax(sizes)) if np.isfinite(sizes).any() else math.nan
    seq = [str(s) for s in lab[keep]]
    out: list[dict[str, Any]] = []
    for j in range(1, len(seq)):
        if seq[j] == "chaos" and seq[j - 1] != "chaos":
            before = seq[max(0, j - history) : j]
            sb, sa = float(sizes[j - 1]), float(sizes[j])
            out.append(
                {
                    "at": float(np.asarray(x)[keep[j]]),
                    "route": _route(before, sb, sa, scale),
                    "before": before,
                    "size_before": sb,
                    "size_at": sa,
                }
            )
    return out


def section_spread(ds: Any, family_value: float | None = None) -> float:
    """Standard deviation of all X̄_sp1 section values of one panel (all points pooled)."""
    for fv, _, lab, sec in panels(ds):
        if family_value is None or (fv is not None and math.isclose(fv, family_value)):
            if sec is None:
                return math.nan
            ok = np.asarray(lab).astype(str) != "failed"
            vals = sec[ok].ravel()
            vals = vals[np.isfinite(vals)]
            return float(np.std(vals)) if vals.size else math.nan
    return math.nan


def panel_values(ds: Any, name: str, family_value: float | None = None) -> np.ndarray | None:
    """The variable ``name`` on one panel (first stored planet), the swept axis first
    (further dimensions after it); ``None`` when the dataset has no such variable or panel."""
    if name not in ds.data_vars:
        return None
    fam, vary = _dims(ds)
    v = ds[name]
    for d in ("planet",):
        if d in v.dims:
            v = v.isel({d: 0})
    if fam is not None and fam in v.dims:
        fv = np.asarray(ds[fam].values, dtype=float)
        if family_value is None:
            return None
        hit = np.flatnonzero(np.isclose(fv, family_value, rtol=1e-9, atol=0.0))
        if hit.size == 0:
            return None
        v = v.isel({fam: int(hit[0])})
    rest = [d for d in v.dims if d != vary]
    return np.asarray(v.transpose(vary, *rest).values)


def point_statistics(ds: Any, family_value: float | None = None) -> dict[str, np.ndarray] | None:
    """Per labelled point of one panel (``unresolved`` / ``failed`` left out): ``x`` (the
    swept value), ``centre`` (mean) and ``size`` (max − min) of its X̄_sp1 section values,
    ``distinct`` (section values distinct to 10⁻³ of the point's attractor size, at least
    10⁻⁶ of the panel's largest |X̄_sp1|: n for an nT orbit, many for QP or chaos) and
    ``lle``, ``lle_error`` (NaN without them). ``None`` without section values or panel."""
    for fv, x, lab, sec in panels(ds):
        if family_value is not None and (fv is None or not math.isclose(fv, family_value)):
            continue
        if sec is None:
            return None
        keep = _resolved(np.asarray(lab).astype(str)) & np.isfinite(sec).any(axis=1)
        s = sec[keep]
        with np.errstate(all="ignore"):
            centre = np.nanmean(s, axis=1) if s.size else np.zeros(0)
            size = attractor_size(s) if s.size else np.zeros(0)
            scale = float(np.nanmax(np.abs(s))) if s.size else 0.0
        floor = 1e-6 * scale if scale > 0 else 1e-12
        distinct = np.array(
            [
                np.unique(np.round(r[np.isfinite(r)] / max(1e-3 * z, floor))).size
                for r, z in zip(s, size, strict=True)
            ],
            dtype=int,
        )
        out = {"x": np.asarray(x, dtype=float)[keep], "centre": centre, "size": size}
        out["distinct"] = distinct
        for name in ("lle", "lle_error"):
            v = panel_values(ds, name, fv)
            out[name] = (
                np.asarray(v, dtype=float)[keep] if v is not None else np.full(s.shape[0], np.nan)
            )
        return out
    return None


def attractor_change(stats: dict[str, np.ndarray]) -> dict[str, Any]:
    """How much the per-point attractor changes along the axis: the ranges (max − min over
    the points) of its centre and size, ``change`` the larger of the two (X̄_sp1 units), the
    distinct-point counts found, and the range of λ₁ with the largest error."""

    def rng(v: np.ndarray) -> float:
        v = v[np.isfinite(v)]
        return float(np.ptp(v)) if v.size else math.nan

    centre, size = rng(stats["centre"]), rng(stats["size"])
    lle = stats["lle"][np.isfinite(stats["lle"])]
    err = stats["lle_error"][np.isfinite(stats["lle_error"])]
    return {
        "points": int(stats["x"].size),
        "centre": centre,
        "size": size,
        "change": max(centre, size) if math.isfinite(centre) and math.isfinite(size) else math.nan,
        "distinct": sorted({int(n) for n in stats["distinct"]}),
        "lle": [float(lle.min()), float(lle.max())] if lle.size else None,
        "lle_error": float(err.max()) if err.size else None,
    }


#: Swept clearances → the stored contact regime that says their flank is reached (2 =
#: double-sided impact) and the minimum deflection beside it.
_MESH_CONTACT = {
    "backlash.sun_planet": ("contact_sp", "delta_sp_min"),
    "backlash.planet_ring": ("contact_rp", "delta_rp_min"),
}
_BEARING = ("x_s_max", "x_s_min", "y_s_max", "y_s_min")
_DOUBLE_SIDED = 2


def clearance_reach(ds: Any, axis: str, family_value: float | None = None) -> dict[str, Any] | None:
    """Whether the swept clearance is ever reached on one panel of a sweep whose swept axis
    is that clearance: a backlash when some mesh of that kind reaches its back flank (stored
    contact regime 2, double-sided impact), the sun's bearing clearance b̄_s when |x̄_s| or
    |ȳ_s| exceeds it (its dead zones act in x and y). ``{"reached": points, "points":
    computed points, "depth": largest −δ_min/b̄ (meshes) or max(|x̄_s|, |ȳ_s|)/b̄_s (bearing),
    1 where the clearance is just reached}``; ``None`` when ``axis`` is not a clearance or
    the dataset lacks the records."""
    _, vary = _dims(ds)
    if vary != axis:
        return None
    b = np.asarray(ds[vary].values, dtype=float)
    status = panel_values(ds, "status", family_value)
    ok = np.ones(b.size, dtype=bool) if status is None else np.asarray(status) == 0
    if axis in _MESH_CONTACT:
        code_name, dmin_name = _MESH_CONTACT[axis]
        code = panel_values(ds, code_name, family_value)
        if code is None:
            return None
        hit = np.any(np.asarray(code).reshape(b.size, -1) == _DOUBLE_SIDED, axis=1)
        dmin = panel_values(ds, dmin_name, family_value)
        depth = (
            -np.nanmin(np.asarray(dmin, dtype=float).reshape(b.size, -1), axis=1) / b
            if dmin is not None
            else np.full(b.size, np.nan)
        )
    elif axis == "clearance.sun_bearing":
        parts = [panel_values(ds, n, family_value) for n in _BEARING]
        if any(p is None for p in parts):
            return None
        reach = np.max(np.abs(np.stack([np.asarray(p, dtype=float) for p in parts])), axis=0)
        depth = reach / b
        hit = depth > 1.0
    else:
        return None
    with np.errstate(all="ignore"):
        deepest = float(np.nanmax(depth[ok])) if np.isfinite(depth[ok]).any() else math.nan
    return {
        "reached": int(np.count_nonzero(hit & ok)),
        "points": int(np.count_nonzero(ok)),
        "depth": deepest,
    }


def qp_near_3t(x: np.ndarray, labels: np.ndarray, tol: float) -> tuple[int, int]:
    """(quasi-periodic points, those with a 3T/6T point within ``tol`` along the swept axis)."""
    lab = np.asarray(labels).astype(str)
    xs = np.asarray(x, dtype=float)
    qp = xs[lab == "QP"]
    three = xs[np.isin(lab, ("3T", "6T"))]
    near = int(sum(1 for q in qp if three.size and np.min(np.abs(three - q)) <= tol))
    return int(qp.size), near


def _informative(ds: Any) -> bool:
    lab = _labels(ds).ravel()
    return bool(lab.size) and float(np.mean(_resolved(lab))) >= MIN_RESOLVED


def _fmt(v: float | None) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "—"
    return f"{v:.3g}"


def _family_name(ds: Any) -> str:
    fam, _ = _dims(ds)
    return fam or ""
