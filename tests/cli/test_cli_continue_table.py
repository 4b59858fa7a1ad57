"""The events table of ``gearchaos continue`` shows every detail in full (issue 35, item 6).

A grazing event of a four-planet set names every mesh that starts or ends contact
(``planet_ring_1,planet_ring_2,planet_ring_3,planet_ring_4 none → single_sided``); at 100
columns the table cut it to ``planet_ring_1,plan…``. Here the table is printed at several
widths and every mesh name and the regime change must be readable in it.
"""

from __future__ import annotations

import re

import pytest
from rich.console import Console

from gearchaos.cli.orbits import _print_branch

DETAIL = "planet_ring_1,planet_ring_2,planet_ring_3,planet_ring_4 none → single_sided"


def _summary() -> dict:
    return {
        "points": 120,
        "stop_reason": "reached the end of the range",
        "segments": [{"stable": True, "from": 0.4, "to": 0.79, "points": 60}],
        "events": [
            {"kind": "grazing", "value": 0.79762499, "uncertainty": 1e-8, "multiplier": None,
             "detail": DETAIL},
            {"kind": "fold", "value": 0.806643192, "uncertainty": 1e-8,
             "multiplier": {"re": 1.0, "im": 0.0, "abs": 1.0}, "detail": ""},
        ],
    }  # fmt: skip


@pytest.mark.parametrize("width", [80, 100, 120])
@pytest.mark.parametrize("rpm", [None, 5269.0])
def test_detail_column_is_never_cut_off(width: int, rpm: float | None) -> None:
    console = Console(width=width, record=True, color_system=None)
    _print_branch(console, _summary(), "branch", "omega", rpm)
    text = console.export_text()
    assert "…" not in text.split("events along the branch")[1]
    rows = [ln for ln in text.splitlines() if ln.startswith("│")]
    detail = " ".join(ln.strip("│").split("│")[-1].strip() for ln in rows)
    joined = re.sub(r"\s+", "", detail)
    for mesh in DETAIL.split(" ")[0].split(","):
        assert mesh in joined
    assert "none→single_sided" in joined
