"""Routes to chaos from bifurcation events of continued branches (:mod:`gearchaos.paper.routes`).

Synthetic events tables with known answers: a period doubling at 2.0 before an onset of chaos
names period doubling and cites 2.0; a Neimark–Sacker names Hopf; an event of a period-3
branch a 3T channel; no event (or only events of branches that are unstable on the periodic
side) leaves crisis. The conclusions then cite the events, with the label reading as a second
line. One real continuation: the backlash oscillator's cascade 1T → 2T → 4T → chaos, where the
labels read the onset as Hopf (a QP label just before it, a slow transient) while the branches
locate the period doublings, each within one grid step of the label change of the sweep.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import gearchaos as gc
from gearchaos.paper.conclusions import conclusion_4, conclusion_5, conclusion_6
from gearchaos.paper.evidence import chaos_onsets
from gearchaos.paper.landmarks import Landmark, LandmarkResult
from gearchaos.paper.routes import (
    BRANCH_ROW,
    event_rows,
    follow_branches,
    landmarks_from_events,
    route_of,
    routes_from_events,
)

X = np.round(np.linspace(1.0, 3.0, 21), 10)  # grid step 0.1


def sweep(labels: list[str], name: str = "omega") -> xr.Dataset:
    sec = np.zeros((len(labels), 4))
    for k, lab in enumerate(labels):  # chaos spreads, periodic points do not
        sec[k] = [0.0, 1.0, 2.0, 3.0] if lab == "chaos" else 0.5
    return xr.Dataset(
        {
            "motion": ((name,), np.array(labels)),
            "delta_sp": ((name, "section"), sec),
        },
        coords={name: X[: len(labels)]},
    )


LABELS = ["1T"] * 10 + ["2T"] * 2 + ["chaos"] * 9  # onset of chaos at 2.2, after 2T at 2.1


def row(kind: str, value: float, period: int = 1, stable_below: bool = True) -> dict:
    return {
        "kind": kind,
        "value": value,
        "period": period,
        "stable_below": stable_below,
        "stable_above": not stable_below,
        "panel": None,
    }


def test_a_period_doubling_before_the_onset_names_period_doubling_and_cites_it() -> None:
    rows = [row("period_doubling", 2.0), row("period_doubling", 2.15, period=2)]
    route, ev = route_of(2.2, 2.1, rows, window=0.1)
    assert route == "period doubling" and ev is not None and ev["value"] == 2.15
    verdict = conclusion_4({"fig4": sweep(LABELS)}, branches={"fig4": rows})
    (onset,) = verdict.measured["onsets"]
    assert onset["route"] == "period doubling" and onset["event"] == pytest.approx(2.15)
    assert "PD of the period-2 branch at 2.15" in verdict.evidence
    assert "brute-force labels say" in verdict.evidence


@pytest.mark.parametrize(
    ("rows", "route"),
    [
        ([row("neimark_sacker", 2.12)], "Hopf"),
        ([row("fold", 2.18, period=3)], "3T channel"),
        ([row("fold", 2.18)], "fold"),
        ([row("grazing", 2.15)], "grazing"),
        ([], "crisis"),
        ([row("period_doubling", 1.5)], "crisis"),  # far from the onset
        ([row("period_doubling", 2.15, stable_below=False)], "crisis"),  # not the attractor
    ],
)
def test_each_event_kind_names_its_route(rows: list, route: str) -> None:
    (found,) = routes_from_events(
        chaos_onsets(X, np.array(LABELS)), X, np.array(LABELS), rows, window_steps=1
    )
    assert found["route"] == route
    assert (found["event"] is None) == (route == "crisis")


def test_crisis_and_pd_under_bsp_make_conclusion_5_hold() -> None:
    name = "backlash.sun_planet"
    two = ["1T"] * 5 + ["chaos"] * 3 + ["1T"] * 4 + ["2T"] * 2 + ["chaos"] * 7
    rows = [row("period_doubling", 2.25)]
    v = conclusion_5({"fig6": sweep(two, name)}, branches={"fig6": rows})
    assert [o["route"] for o in v.measured["onsets"]] == ["crisis", "period doubling"]
    assert v.verdict == "holds"
    # labels only: the same sweep reads no period doubling (one doubling, to 2T only)
    assert conclusion_5({"fig6": sweep(two, name)}).verdict == "partly"


def test_conclusion_6_counts_route_types_from_events() -> None:
    name = "backlash.planet_ring"
    labels = ["1T"] * 3 + ["chaos"] * 2 + ["1T"] * 3 + ["chaos"] * 2 + ["3T"] * 3 + ["chaos"] * 8
    rows = [row("neimark_sacker", 1.75), row("fold", 2.25, period=3)]
    v = conclusion_6({"fig9": sweep(labels, name)}, branches={"fig9": rows})
    assert [o["route"] for o in v.measured["onsets"]] == ["crisis", "Hopf", "3T channel"]
    assert v.measured["route_types"] == ["crisis", "Hopf", "3T channel"]
    assert v.verdict == "holds"


FIG4 = {
    "xi": 0.03,
    "backlash.sun_planet": 3.0,
    "backlash.planet_ring": 3.5,
    "clearance.sun_bearing": 2.0,
}


def test_a_panel_without_followed_branches_keeps_the_label_routes() -> None:
    """Rows of another panel only: the labels' route stands; a marker row of a followed branch
    on this panel (no event near the onset) makes the onset a crisis."""
    cascade = ["1T"] * 8 + ["2T"] * 2 + ["4T"] * 2 + ["chaos"] * 9  # labels: period doubling
    fam = xr.concat([sweep(cascade), sweep(cascade)], dim="xi").assign_coords(xi=[0.03, 0.05])
    fam["motion"] = fam["motion"].transpose("xi", "omega")
    other = [{**row("neimark_sacker", 2.15, period=4), "panel": 0.05}]
    v = conclusion_4({"fig4": fam}, branches={"fig4": other})
    routes = {o["panel"]: o["route"] for o in v.measured["onsets"]}
    assert routes[0.05] == "Hopf"
    assert routes[0.03] == "period doubling"  # from the labels
    marker = {**row(BRANCH_ROW, float("nan")), "panel": 0.03}
    v = conclusion_4({"fig4": fam}, branches={"fig4": [*other, marker]})
    assert {o["panel"]: o["route"] for o in v.measured["onsets"]}[0.03] == "crisis"
    assert "routes from 1 event(s)" in v.evidence


def landmark(event: str, at: float, tol: float = 0.05) -> Landmark:
    return Landmark(
        id="x", figure="fig4", panel={"xi": 0.03}, quote="q", axis="omega", kind="transition",
        expected=("QP",), fixed=FIG4, tolerance=tol, at=at, from_labels=("2T",),
        event=event,
    )  # fmt: skip


def test_landmarks_that_name_a_bifurcation_read_the_events() -> None:
    rows = [{**row("neimark_sacker", 1.93), "panel": 0.03}, {**row("fold", 2.5), "panel": 0.03}]
    marks = [landmark("neimark_sacker", 1.926), landmark("period_doubling", 1.9)]
    marks.append(landmark("", 1.9))
    before = [LandmarkResult(m, "does not hold", 0.0, "labels: no 2T → QP", {}) for m in marks]
    after = landmarks_from_events(before, {"fig4": rows})
    assert after[0].verdict == "holds" and "1.93" in after[0].evidence
    assert "brute-force labels say: labels: no 2T → QP" in after[0].evidence
    assert after[1].verdict == "does not hold" and "no period doubling" in after[1].evidence
    assert after[2] is before[2]  # names no bifurcation: unchanged
    far = landmarks_from_events(before[:1], {"fig4": [{**rows[0], "value": 2.05}]})
    assert far[0].verdict == "partly"  # 0.124 from 1.926: within three tolerances
    # no branch followed on the landmark's panel: the label verdict stands
    elsewhere = [{**r, "panel": 0.05} for r in rows]
    assert landmarks_from_events(before[:1], {"fig4": elsewhere})[0] is before[0]


def test_backlash_cascade_routes_chaos_by_period_doubling() -> None:
    """Ω from 2.1 down to 1.7: 1T, PD to 2T, 4T, then chaos. The branches followed from the 1T
    stretch locate the period doublings; each lies within one grid step of the sweep's label
    change, and the onset of chaos is routed by the last one, not by the QP label before it."""
    system = gc.backlash_oscillator(1.0, zeta=0.05, f_alt=0.1, f_mean=0.1)
    ds = gc.bifurcation(
        system, "omega=2.10:1.70:17", initial_conditions="continuation", lyapunov=True,
        transient_periods=600, periods=64, progress=False,
    )  # fmt: skip
    x, lab = ds.omega.values, ds.motion.values
    branches = follow_branches(system, "omega", x, lab, {}, max_period=4, steps=50)
    rows = [r for b in branches for r in event_rows(b)]
    pds = sorted((r for r in rows if r["kind"] == "period_doubling"), key=lambda r: r["period"])
    assert [r["period"] for r in pds][:3] == [1, 2, 4]
    step = abs(x[1] - x[0])
    per = [int(s[:-1]) if s.endswith("T") else 0 for s in lab]
    for r, hi_n in zip(pds[:2], (1, 2), strict=False):
        # the sweep goes down: its label leaves nT between two grid points (2T → 4T reads
        # 6T at one point: a slow transient near the doubling)
        k = next(i for i in range(len(per) - 1) if per[i] == hi_n and per[i + 1] != hi_n)
        assert x[k + 1] - step <= r["value"] <= x[k] + step
        assert not r["stable_below"] and r["stable_above"]  # stable on the periodic side
    onsets = chaos_onsets(x, lab, ds.x.values)
    assert onsets
    (found,) = routes_from_events(onsets[:1], x, lab, rows)
    assert found["route"] == "period doubling"
    assert found["event_period"] >= 2
