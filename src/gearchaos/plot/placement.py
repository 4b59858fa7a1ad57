"""Names written beside markers, placed where they cover least.

:func:`place_event_labels` moves the short name of every event of a figure (``PD``, ``fold``,
``graze`` beside its marker, :func:`~gearchaos.plot.branch.mark_event`) to the side of its
marker where it covers the fewest curve segments, points, other names, other events' markers
and legends: above the marker a name sat on a steep branch, on a jump arrow or on the
diagram's dots. Events whose markers crowd together (a fold and two grazings within 0.01 of
Ω) get one name for the group (``graze ×2, fold``), and a name that finds no free place next
to its marker may sit two or three times as far away.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["CROWDED_PX", "EVENT_LABEL_GID", "LABEL_PLACES", "LABEL_RINGS", "place_event_labels"]

#: ``gid`` of the short names written beside the event markers.
EVENT_LABEL_GID = "branch:event-label"

#: Where an event's name may sit, in order of preference: offset (points) from the marker's
#: centre and alignment — above, below, right, left, then the four diagonals.
LABEL_PLACES: tuple[tuple[float, float, str, str], ...] = (
    (0.0, 5.0, "center", "bottom"),
    (0.0, -5.0, "center", "top"),
    (6.0, 0.0, "left", "center"),
    (-6.0, 0.0, "right", "center"),
    (5.0, 4.0, "left", "bottom"),
    (-5.0, 4.0, "right", "bottom"),
    (5.0, -4.0, "left", "top"),
    (-5.0, -4.0, "right", "top"),
)
#: How far from the marker a name may sit, as multiples of :data:`LABEL_PLACES`' offsets,
#: nearest first: a farther ring is taken only where every nearer place covers something.
LABEL_RINGS: tuple[float, ...] = (1.0, 2.2, 3.4)
#: Markers closer than this (display pixels at the figure's dpi, per 100 dpi) share one name.
CROWDED_PX = 14.0
# what covering costs: a curve's segment, a point (marker, diagram dot), another name or the
# legend, another event's marker, leaving the axes; and each ring farther out
_COST_SEGMENT, _COST_POINT, _COST_BOX, _COST_OUTSIDE = 10.0, 1.0, 100.0, 1000.0
_COST_MARKER, _COST_RING = 60.0, 4.0


def place_event_labels(fig: Any) -> None:
    """Put the short name of every event marked in ``fig``
    (:func:`~gearchaos.plot.branch.mark_event`) on the side of its marker where it covers
    least: the first place of :data:`LABEL_PLACES` with the fewest curve segments, points
    (markers, diagram dots), other names and legends under it, inside the axes. Lays the
    figure out first (the final axes), so a figure calls it last."""
    todo = [(ax, t) for ax in fig.axes for t in ax.texts if t.get_gid() == EVENT_LABEL_GID]
    if not todo:
        return
    fig.draw_without_rendering()
    todo = _merge_crowded(fig, todo)
    obstacles = {id(ax): _obstacles(ax) for ax, _ in todo}
    markers = {id(ax): _event_markers(ax) for ax, _ in todo}
    placed: dict[int, list[Any]] = {}
    for ax, text in todo:
        segments, points, boxes = obstacles[id(ax)]
        boxes = boxes + placed.setdefault(id(ax), [])
        frame = ax.get_window_extent()
        best, best_cost = (*LABEL_PLACES[0][:2], *LABEL_PLACES[0][2:]), np.inf
        for ring, scale in enumerate(LABEL_RINGS):
            for dx, dy, ha, va in LABEL_PLACES:
                place = (dx * scale, dy * scale, ha, va)
                text.xyann = place[:2]
                text.set_ha(ha)
                text.set_va(va)
                box = text.get_window_extent()
                cost = _COST_RING * ring
                cost += _COST_SEGMENT * sum(_crossings(box.padded(1.0), xy) for xy in segments)
                grown = box.padded(2.0)
                cost += _COST_POINT * int(
                    np.sum(
                        (points[:, 0] >= grown.x0) & (points[:, 0] <= grown.x1)
                        & (points[:, 1] >= grown.y0) & (points[:, 1] <= grown.y1)
                    )
                )  # fmt: skip
                cost += _COST_BOX * sum(_overlaps(box, other) for other in boxes)
                cost += _COST_MARKER * sum(_overlaps(box, m) for m in markers[id(ax)])
                inside = frame.x0 <= box.x0 and box.x1 <= frame.x1
                inside = inside and frame.y0 <= box.y0 and box.y1 <= frame.y1
                cost += 0.0 if inside else _COST_OUTSIDE
                if cost < best_cost:
                    best, best_cost = place, cost
            if best_cost < _COST_POINT * 3:  # free enough: no need to look farther out
                break
        text.xyann = best[:2]
        text.set_ha(best[2])
        text.set_va(best[3])
        placed[id(ax)].append(text.get_window_extent())


def _anchor(ax: Any, text: Any) -> np.ndarray:
    """The display position of the marker a name belongs to."""
    return np.asarray(ax.transData.transform(np.asarray(text.xy, dtype=np.float64)))


def _merge_crowded(fig: Any, todo: list[tuple[Any, Any]]) -> list[tuple[Any, Any]]:
    """Give every group of names whose markers lie within :data:`CROWDED_PX` of each other
    (chained) one name — the kinds in order along x, a repeated one as ``graze ×2`` — written
    by the group's first name (grey when the kinds differ); the others are removed. Returns
    the names left."""
    limit = CROWDED_PX * fig.dpi / 100.0
    keep: list[tuple[Any, Any]] = []
    for ax in dict.fromkeys(ax for ax, _ in todo):
        texts = sorted((t for a, t in todo if a is ax), key=lambda t: float(t.xy[0]))
        groups: list[list[Any]] = []
        for t in texts:
            here = _anchor(ax, t)
            near = [g for g in groups if any(np.hypot(*(here - _anchor(ax, o))) < limit for o in g)]
            if not near:
                groups.append([t])
                continue
            for g in near[1:]:  # t joins groups that were apart until now
                near[0].extend(g)
                groups.remove(g)
            near[0].append(t)
        for group in groups:
            first = group[0]
            if len(group) > 1:
                names = [t.get_text() for t in sorted(group, key=lambda t: float(t.xy[0]))]
                counts = dict.fromkeys(names, 0)
                for name in names:
                    counts[name] += 1
                first.set_text(", ".join(n if k == 1 else f"{n} ×{k}" for n, k in counts.items()))
                if len({str(t.get_color()) for t in group}) > 1:
                    first.set_color("0.25")
                top = max(group, key=lambda t: float(t.xy[1]))
                first.xy = top.xy  # beside the highest marker of the group
                for other in group[1:]:
                    other.remove()
            keep.append((ax, first))
    return keep


def _event_markers(ax: Any) -> list[Any]:
    """Display boxes of the event markers of ``ax`` (``gid`` ``…:event:<kind>``)."""
    from matplotlib.transforms import Bbox

    boxes = []
    for coll in ax.collections:
        if ":event:" not in str(coll.get_gid() or "") or not len(coll.get_offsets()):
            continue
        xy = coll.get_offset_transform().transform(np.asarray(coll.get_offsets(), dtype=float))
        sizes = np.asarray(coll.get_sizes(), dtype=float)
        r = 0.5 * math.sqrt(float(sizes.max()) if sizes.size else 36.0) * ax.figure.dpi / 72.0
        boxes += [
            Bbox([[x - r, y - r], [x + r, y + r]]) for x, y in xy if np.isfinite([x, y]).all()
        ]
    return boxes


def _obstacles(ax: Any) -> tuple[list[np.ndarray], np.ndarray, list[Any]]:
    """What an event's name should not cover in ``ax``, in display coordinates: the drawn
    curves (polylines, NaN breaking them; arrows between data points), the points (line
    markers, scatter dots and markers) and the legend's box."""
    segments: list[np.ndarray] = []
    points: list[np.ndarray] = []
    for line in ax.get_lines():
        if not line.get_visible():
            continue
        xy = line.get_transform().transform(np.asarray(line.get_xydata(), dtype=np.float64))
        if str(line.get_linestyle()).lower() not in ("none", "", " "):
            segments.append(xy)
        if str(line.get_marker()).lower() not in ("none", "", " "):
            points.append(xy)
    for coll in ax.collections:
        if coll.get_visible() and hasattr(coll, "get_offsets") and len(coll.get_offsets()):
            offsets = np.asarray(coll.get_offsets(), dtype=np.float64)
            points.append(coll.get_offset_transform().transform(offsets))
    for text in ax.texts:  # arrows of annotations in data coordinates (the jumps)
        if getattr(text, "arrow_patch", None) is not None and text.get_anncoords() == "data":
            ends = np.array([text.xyann, text.xy], dtype=np.float64)
            segments.append(ax.transData.transform(ends))
    legend = ax.get_legend()
    boxes = [legend.get_window_extent()] if legend is not None else []
    cloud = np.concatenate(points) if points else np.empty((0, 2))
    return segments, cloud[np.all(np.isfinite(cloud), axis=1)], boxes


def _overlaps(a: Any, b: Any) -> bool:
    return min(a.x1, b.x1) > max(a.x0, b.x0) and min(a.y1, b.y1) > max(a.y0, b.y0)


def _crossings(box: Any, xy: np.ndarray) -> int:
    """How many segments of the polyline ``xy`` (display, n × 2; NaN breaks it) enter
    ``box`` (Liang–Barsky clipping of every segment)."""
    p, q = xy[:-1], xy[1:]
    ok = np.all(np.isfinite(p), axis=1) & np.all(np.isfinite(q), axis=1)
    p, q = p[ok], q[ok]
    d = q - p
    t0, t1 = np.zeros(len(p)), np.ones(len(p))
    hit = np.ones(len(p), dtype=bool)
    for k, lo, hi in ((0, box.x0, box.x1), (1, box.y0, box.y1)):
        for pk, qk in ((-d[:, k], p[:, k] - lo), (d[:, k], hi - p[:, k])):
            parallel = pk == 0
            hit &= ~(parallel & (qk < 0))
            with np.errstate(divide="ignore", invalid="ignore"):
                r = qk / pk
            t0 = np.where(~parallel & (pk < 0), np.maximum(t0, r), t0)
            t1 = np.where(~parallel & (pk > 0), np.minimum(t1, r), t1)
    return int(np.sum(hit & (t0 <= t1)))
