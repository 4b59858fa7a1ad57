"""Landmarks of the seed's Section 3: the data file and their check on hand-built sweeps."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from gearchaos.errors import ParameterError
from gearchaos.paper import GALLERIES, RECIPES
from gearchaos.paper.landmarks import (
    evaluate,
    evaluate_all,
    load_landmarks,
    recipe_for,
    score,
)
from gearchaos.sweep import SweepSpec

ROOT = Path(__file__).resolve().parents[2]
FIG4 = {
    "xi": 0.03,
    "backlash.sun_planet": 3.0,
    "backlash.planet_ring": 3.5,
    "clearance.sun_bearing": 2.0,
}


@pytest.fixture(scope="module")
def marks():
    return {m.id: m for m in load_landmarks()}


def _sweep(omega, labels, xis=(0.03, 0.05)):
    """A classified fig4-like store: dims (xi, omega), the same labels on every panel."""
    lab = np.array(labels, dtype="<U10")
    motion = np.broadcast_to(lab, (len(xis), len(omega))).copy()
    return xr.Dataset(
        {"motion": (("xi", "omega"), motion)},
        coords={"xi": list(xis), "omega": np.asarray(omega, dtype=float)},
    )


def test_repo_copy_equals_packaged_file():
    packaged = ROOT / "src" / "gearchaos" / "paper" / "landmarks.toml"
    assert (ROOT / "paper" / "landmarks.toml").read_text("utf-8") == packaged.read_text("utf-8")


def test_every_landmark_has_a_figure_and_a_covering_recipe(marks):
    assert len(marks) >= 40
    for m in marks.values():
        assert m.figure in RECIPES or m.figure in GALLERIES, m.id
        assert recipe_for(m) in RECIPES
        assert m.tolerance > 0


def test_fig4_and_fig5_numbers_are_the_issues(marks):
    # numbers typed from issue 5, not from the TOML
    fig4 = [m for m in marks.values() if m.figure in ("fig4", "fig5")]
    for m in fig4:
        assert dict(m.fixed) == FIG4
        assert m.axis == "omega"
    spans = {(m.lo, m.hi, m.at, tuple(m.expected)) for m in fig4}
    assert (0.0, 1.35, None, ("1T",)) in spans
    assert (1.35, 1.69, None, ("QP", "3T")) in spans
    assert (None, None, 1.696, ("1T",)) in spans
    assert (None, None, 1.875, ("2T",)) in spans
    assert (None, None, 1.926, ("QP",)) in spans
    assert (None, None, 2.02, ("1T",)) in spans
    assert (2.02, 2.62, None, ("chaos",)) in spans
    assert (2.45, 3.03, None, ("chaos",)) in spans
    assert (None, None, 3.03, ("2T",)) in spans
    assert (None, None, 3.58, ("1T",)) in spans
    assert marks["fig5-chaos-window"].kind == "window"
    assert marks["fig5-NS-at-1.926"].kind == "transition"


def test_other_figures_numbers_from_the_text(marks):
    values = {(m.figure, v) for m in marks.values() for v in (m.lo, m.hi, m.at) if v is not None}
    for v in (2.81, 2.85, 4.83):
        assert ("fig7", v) in values
    for v in (5.5, 8.4, 8.48, 8.8, 9.37):
        assert ("fig8", v) in values
    for v in (11.3, 11.6, 15.1, 15.3):
        assert ("fig9", v) in values
    for v in (1.9, 4.79, 4.84, 4.91, 5.47, 5.55, 5.93, 6.0):
        assert ("fig10", v) in values
    assert ("fig11", 5.2) in values


def test_validation_names_the_landmark_and_the_rule(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(
        '[[landmark]]\nid = "x"\nfigure = "fig4"\npanel = { xi = 0.03 }\nquote = "q"\n'
        'axis = "omega"\nkind = "label"\nlo = 2.0\nhi = 1.0\nexpected = ["1T"]\n'
        "fixed = { xi = 0.03 }\n"
    )
    with pytest.raises(ParameterError, match=r"landmark #1 \(x\): lo must be below hi"):
        load_landmarks(bad)
    bad.write_text(bad.read_text().replace('["1T"]', '["period-1"]').replace("hi = 1.0", "hi = 3"))
    with pytest.raises(ParameterError, match="expected labels must be"):
        load_landmarks(bad)


def test_all_1T_sweep_holds_the_1T_landmark(marks):
    omega = np.linspace(0.01, 4.0, 400)
    res = evaluate(marks["fig4a-1T-low"], _sweep(omega, ["1T"] * omega.size))
    assert res.verdict == "holds"
    assert res.score == 1.0
    assert res.measured["points"] == int(np.sum(omega <= 1.35))
    # and the QP/3T switching does not hold on it
    res = evaluate(marks["fig5-QP-3T-switching"], _sweep(omega, ["1T"] * omega.size))
    assert res.verdict == "does not hold"
    assert res.score == 0.0


def test_label_fraction_decides_partly(marks):
    omega = np.linspace(0.0, 1.35, 11)
    labels = ["1T"] * 6 + ["QP"] * 5  # 6/11 = 55 %: partly (>= 0.4, < 0.8)
    res = evaluate(marks["fig4a-1T-low"], _sweep(omega, labels))
    assert res.verdict == "partly"
    assert res.score == pytest.approx((6 / 11) / 0.8)
    assert "55% of 11 points" in res.evidence


def test_transition_scored_by_distance(marks):
    mark = marks["fig5-1T-at-3.58"]  # 2T/QP -> 1T at 3.58, tolerance 0.0798
    omega = np.linspace(3.0, 4.0, 101)  # step 0.01

    def at(edge):
        return evaluate(mark, _sweep(omega, np.where(omega < edge, "2T", "1T")))

    exact = at(3.58)
    assert exact.verdict == "holds"
    assert exact.measured["location"] == pytest.approx(3.575)
    near = at(3.58 + 0.15)  # 1.9 tolerances away: partly
    assert near.verdict == "partly"
    assert 0.25 < near.score < 0.75
    far = at(3.58 + 0.40)  # 5 tolerances away: does not hold
    assert far.verdict == "does not hold"
    assert far.score < near.score
    none = evaluate(mark, _sweep(omega, ["2T"] * omega.size))
    assert none.verdict == "does not hold" and none.score == 0.0


def test_transition_skips_unresolved_points(marks):
    omega = np.linspace(3.5, 3.66, 17)
    labels = np.where(omega < 3.58, "2T", "1T").astype("<U10")
    labels[8] = "unresolved"
    res = evaluate(marks["fig5-1T-at-3.58"], _sweep(omega, labels))
    assert res.verdict == "holds"


def test_window_fraction_and_edges(marks):
    mark = marks["fig5-chaos-window"]  # chaos 2.45–3.03
    omega = np.linspace(2.0, 3.5, 151)
    inside = (omega > 2.45) & (omega < 3.03)
    good = evaluate(mark, _sweep(omega, np.where(inside, "chaos", "2T")))
    assert good.verdict == "holds"
    assert good.measured["lower_edge"] == pytest.approx(2.455, abs=0.01)
    assert good.measured["upper_edge"] == pytest.approx(3.025, abs=0.01)
    assert "edges found at" in good.evidence
    shifted = (omega > 2.75) & (omega < 3.33)  # the window moved by 0.3 (3.8 tolerances)
    bad = evaluate(mark, _sweep(omega, np.where(shifted, "chaos", "2T")))
    assert bad.verdict in ("partly", "does not hold")
    assert bad.score < good.score


def test_missing_panel_or_axis_is_not_evaluated(marks):
    omega = np.linspace(0.01, 4.0, 50)
    ds = _sweep(omega, ["1T"] * omega.size, xis=(0.05, 0.07))
    res = evaluate(marks["fig4a-1T-low"], ds)
    assert res.verdict == "not evaluated"
    assert "no panel xi = 0.03" in res.evidence
    res = evaluate(marks["fig6a-chaos-dominant"], ds)
    assert res.verdict == "not evaluated"
    assert "does not sweep backlash.sun_planet" in res.evidence
    short = _sweep(np.linspace(0.5, 1.0, 10), ["1T"] * 10)
    assert evaluate(marks["fig5-1T-at-3.58"], short).verdict == "not evaluated"


def test_stored_fixed_values_must_agree(marks):
    omega = np.linspace(0.01, 4.0, 50)
    ds = _sweep(omega, ["1T"] * omega.size)
    spec = SweepSpec.build({"omega": omega}, params={"backlash.sun_planet": 4.0})
    ds.attrs["sweep_toml"] = spec.to_toml()  # what a store made with that value records
    res = evaluate(marks["fig4a-1T-low"], ds)
    assert res.verdict == "not evaluated"
    assert "backlash.sun_planet = 4" in res.evidence


def test_evaluate_all_routes_galleries_to_their_sweep_and_sums(marks):
    omega = np.linspace(0.01, 4.0, 400)
    ds = _sweep(omega, ["1T"] * omega.size)
    chosen = [marks["fig4a-1T-low"], marks["fig5-1T-at-2.02"], marks["fig6a-chaos-dominant"]]
    results = evaluate_all(chosen, {"fig4": ds})
    assert [r.verdict for r in results] == ["holds", "holds", "not evaluated"]
    assert "no sweep of fig6" in results[2].evidence
    assert score(results) == pytest.approx(2.0)


def test_nT_wildcard_accepts_multi_periodic_only(marks):
    mark = marks["fig12-periodic"]  # expected 1T or any nT
    b = np.linspace(1.0, 10.0, 10)
    ds = xr.Dataset(
        {"motion": (("omega", "clearance.sun_bearing"), np.array([["2T"] * 5 + ["12T"] * 5]))},
        coords={"omega": [1.5], "clearance.sun_bearing": b},
    )
    assert evaluate(mark, ds).verdict == "holds"
    ds["motion"][:] = np.array([["QP"] * 10])
    assert evaluate(mark, ds).verdict == "does not hold"
