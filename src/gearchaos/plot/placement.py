"""Names written beside markers, placed where they cover least.

:func:`place_event_labels` moves the short name of every event of a figure (``PD``, ``fold``,
``graze`` beside its marker, :func:`~gearchaos.plot.branch.mark_event`) to the side of its
marker where it covers the fewest curve segments, points, other names and legends: above the
marker a name sat on a steep branch, on a jump arrow or on the diagram's dots.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["EVENT_LABEL_GID", "LABEL_PLACES", "place_event_labels"]

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
# what covering costs: a curve's segment, a point (marker, diagram dot), another name or the
# legend, leaving the axes
_COST_SEGMENT, _COST_POINT, _COST_BOX, _COST_OUTSIDE = 10.0, 1.0, 100.0, 1000.0


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
    obstacles = {id(ax): _obstacles(ax) for ax, _ in todo}
    placed: dict[int, list[Any]] = {}
    for ax, text in todo:
        segments, points, boxes = obstacles[id(ax)]
        boxes = boxes + placed.setdefault(id(ax), [])
        frame = ax.get_window_extent()
        best, best_cost = LABEL_PLACES[0], np.inf
        for place in LABEL_PLACES:
            text.xyann = place[:2]
            text.set_ha(place[2])
            text.set_va(place[3])
            box = text.get_window_extent()
            cost = _COST_SEGMENT * sum(_crossings(box.padded(1.0), xy) for xy in segments)
            grown = box.padded(2.0)
            cost += _COST_POINT * int(
                np.sum(
                    (points[:, 0] >= grown.x0) & (points[:, 0] <= grown.x1)
                    & (points[:, 1] >= grown.y0) & (points[:, 1] <= grown.y1)
                )
            )  # fmt: skip
            cost += _COST_BOX * sum(_overlaps(box, other) for other in boxes)
            inside = frame.x0 <= box.x0 and box.x1 <= frame.x1
            cost += 0.0 if inside and frame.y0 <= box.y0 and box.y1 <= frame.y1 else _COST_OUTSIDE
            if cost < best_cost:
                best, best_cost = place, cost
        text.xyann = best[:2]
        text.set_ha(best[2])
        text.set_va(best[3])
        placed[id(ax)].append(text.get_window_extent())


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
