"""Evidence from the motion labels of sweep datasets: panels, label fractions, onsets of chaos
and the route that leads to each (:mod:`gearchaos.paper.conclusions` reads its verdicts from
these; the conventions are in its module docstring).
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = [
    "CRISIS_FLOOR",
    "CRISIS_RATIO",
    "MIN_RESOLVED",
    "attractor_size",
    "chaos_onsets",
    "chaotic_fraction",
    "label_fraction",
    "panels",
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
_PERIODIC = re.compile(r"^(\d+)T$")


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
    m = _PERIODIC.match(label)
    return int(m.group(1)) if m else None


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
