"""Event names that crowd (issue 35, item 6): on the branch of a four-planet set a fold and two
grazings lie within 0.01 of Ω near 0.8, and their names were written over each other and over
the markers. Every name must now be readable — no two overlap, none covers an event's
marker — and names of markers that crowd together are written once for the group, naming
every kind in it.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from figure_checks import draw, overlap
from matplotlib.figure import Figure

from gearchaos.plot.branch import mark_event
from gearchaos.plot.placement import EVENT_LABEL_GID, place_event_labels

#: (kind, Ω, X̄) of the events of `gearchaos continue --vary omega=0.4:1.2` on sheng2016 with
#: four planets (teeth 31/33/97), as that run located them.
EVENTS = [
    ("fold", 0.66847, 2.803),
    ("grazing", 0.79762, 3.087),
    ("grazing", 0.80649, 3.0895),
    ("fold", 0.80664, 3.0905),
    ("grazing", 0.83114, 3.073),
    ("branch_point", 1.01055, 3.075),
    ("branch_point", 1.045, 3.071),
    ("neimark_sacker", 1.09437, 3.066),
    ("neimark_sacker", 1.16228, 3.057),
]


def _figure() -> Figure:
    fig = Figure(figsize=(7.0, 4.7), dpi=150, layout="constrained")
    ax = fig.add_subplot()
    x = np.linspace(0.4, 1.2, 400)
    ax.plot(x, 3.085 + 0.015 * np.exp(-(((x - 0.77) / 0.05) ** 2)) - 0.03 * (x > 0.9) * (x - 0.9))
    named: set[str] = set()
    for kind, omega, value in EVENTS:
        mark_event(ax, kind, omega, [value], named, "branch")
    ax.set_xlim(0.38, 1.22)
    ax.set_ylim(2.78, 3.12)
    ax.legend(loc="lower right", fontsize="small")
    place_event_labels(fig)
    draw(fig)
    return fig


def _marker_boxes(ax) -> list:
    from matplotlib.transforms import Bbox

    boxes = []
    for coll in ax.collections:
        if ":event:" in str(coll.get_gid()):
            (x, y), s = coll.get_offset_transform().transform(coll.get_offsets())[0], 40.0
            r = 0.5 * math.sqrt(s) * ax.figure.dpi / 72.0
            boxes.append(Bbox([[x - r, y - r], [x + r, y + r]]))
    return boxes


def test_no_event_name_covers_another_or_a_marker() -> None:
    fig = _figure()
    ax = fig.axes[0]
    names = [t for t in ax.texts if t.get_gid() == EVENT_LABEL_GID]
    boxes = [t.get_window_extent() for t in names]
    for (a, ta), (b, tb) in itertools.combinations(zip(boxes, names, strict=True), 2):
        assert not overlap(a, b), (ta.get_text(), tb.get_text())
    for box, text in zip(boxes, names, strict=True):
        for marker in _marker_boxes(ax):
            assert not overlap(box, marker), text.get_text()
        frame = ax.get_window_extent()
        assert frame.x0 <= box.x0 and box.x1 <= frame.x1, text.get_text()
        assert frame.y0 <= box.y0 and box.y1 <= frame.y1, text.get_text()


def test_crowded_markers_share_one_name_that_lists_every_kind() -> None:
    ax = _figure().axes[0]
    texts = sorted(t.get_text() for t in ax.texts if t.get_gid() == EVENT_LABEL_GID)
    assert texts == sorted(["fold", "graze ×2, fold", "graze", "BP", "BP", "NS", "NS"])
