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


@pytest.mark.parametrize(
    ("kind", "extra", "message"),
    [
        ("window", 'expected = ["chaos"]\ncontrast = "below"', "contrast is only for label"),
        ("label", 'expected = ["chaos"]\ncontrast = "left"', "contrast must be one of below"),
        ("label", 'expected = ["1T"]\nmax_change = 0.1', "max_change is only for negligible"),
        ("negligible", 'expected = ["1T"]', "expected is not for a negligible landmark"),
        ("negligible", "max_change = 2.0", r"max_change must be in \(0, 1\]"),
        ("label", "", "expected is required"),
    ],
)
def test_the_new_keys_are_checked_for_their_kind(tmp_path, kind, extra, message):
    bad = tmp_path / "bad.toml"
    bad.write_text(
        f'[[landmark]]\nid = "x"\nfigure = "fig12"\npanel = {{ omega = 1.5 }}\nquote = "q"\n'
        f'axis = "clearance.sun_bearing"\nkind = "{kind}"\nlo = 1.0\nhi = 10.0\n{extra}\n'
        'fixed = { omega = 1.5, xi = 0.05, "backlash.sun_planet" = 3.0, '
        '"backlash.planet_ring" = 3.5 }\n'
    )
    with pytest.raises(ParameterError, match=rf"landmark #1 \(x\): {message}"):
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
    mark = marks["fig5-QP-3T-switching"]  # QP/3T over 1.35–1.69, the default 0.8
    omega = np.linspace(1.35, 1.69, 11)
    labels = ["QP"] * 6 + ["1T"] * 5  # 6/11 = 55 %: partly (>= 0.4, < 0.8)
    res = evaluate(mark, _sweep(omega, labels))
    assert res.verdict == "partly"
    assert res.score == pytest.approx((6 / 11) / 0.8)
    assert "55% of 11 points" in res.evidence


def test_fig4a_dominant_is_the_files_own_rule_for_dominant(marks):
    # the seed: "1T-periodic motion is in a dominant position within 0 ≤ Ω ≤ 1.35"; the file
    # reads "dominant" as at least half of the points (fig6a, fig9a), so 6 of 11 points hold
    omega = np.linspace(0.0, 1.35, 11)
    mark = marks["fig4a-1T-low"]
    assert mark.min_fraction == 0.5
    assert marks["fig6a-chaos-dominant"].min_fraction == mark.min_fraction
    res = evaluate(mark, _sweep(omega, ["1T"] * 6 + ["QP"] * 5))
    assert res.verdict == "holds" and res.score == 1.0
    less = evaluate(mark, _sweep(omega, ["1T"] * 5 + ["QP"] * 6))  # 5/11 = 45 %
    assert less.verdict == "partly"
    assert less.score == pytest.approx((5 / 11) / 0.5)


def test_becoming_dominant_needs_a_trend(marks):
    mark = marks["fig9a-chaos-dominant"]  # "chaos becomes dominant when b̄_rp is larger than 8"
    assert mark.contrast == "below"
    b = np.linspace(1.0, 16.0, 31)  # step 0.5: 14 points below 8, 17 from 8 on
    ds = xr.Dataset(
        {"motion": (("xi", "backlash.planet_ring"), np.empty((1, b.size), dtype="<U10"))},
        coords={"xi": [0.03], "backlash.planet_ring": b},
    )
    ds["motion"][0] = np.where(b >= 8.0, "chaos", "1T")
    trend = evaluate(mark, ds)
    assert trend.verdict == "holds" and trend.measured["trend"]
    assert trend.measured["fraction_outside"] == 0.0
    # chaotic on both sides, as issue 34 found (73 % below and above 8): dominant, no trend
    ds["motion"][0] = np.where(np.arange(b.size) % 4 == 0, "1T", "chaos")
    flat = evaluate(mark, ds)
    assert flat.measured["fraction"] >= 0.5 and flat.measured["fraction_outside"] >= 0.5
    assert flat.verdict == "partly" and flat.score == 0.5
    assert "no trend" in flat.evidence


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


def _bs_sweep(sections: np.ndarray) -> xr.Dataset:
    b = np.linspace(1.0, 10.0, sections.shape[0])
    return xr.Dataset(
        {
            "motion": (("omega", "clearance.sun_bearing"), np.full((1, b.size), "1T", "<U10")),
            "delta_sp": (
                ("omega", "clearance.sun_bearing", "section", "planet"),
                sections[None, ..., None],
            ),
        },
        coords={"omega": [1.5], "clearance.sun_bearing": b, "planet": [1]},
    )


def test_affected_negligibly_reads_the_section_values(marks):
    mark = marks["fig12-negligible"]
    assert mark.kind == "negligible" and mark.expected == () and mark.max_change == 0.05
    assert "affected negligibly" in mark.quote and "affected" not in marks["fig12-periodic"].quote
    n, k = 10, 8
    cloud = 3.0 + 0.2 * np.sin(np.arange(k))  # the same attractor at every point
    same = evaluate(mark, _bs_sweep(np.tile(cloud, (n, 1))))
    assert same.verdict == "holds" and same.measured["relative_change"] == 0.0
    # the attractor's centre moves by 0.3 along b̄_s: 0.3 / 3.5 = 8.6 % of the largest |X̄_sp1|
    moved = np.tile(cloud, (n, 1)) + np.linspace(0.0, 0.3, n)[:, None]
    res = evaluate(mark, _bs_sweep(moved))
    assert res.measured["centre_change"] == pytest.approx(0.3)
    assert res.measured["relative_change"] == pytest.approx(0.3 / (3.2 + 0.3), rel=0.01)
    assert res.verdict == "partly"
    # its size grows from 0.4 to 2.4: not negligible
    grown = 3.0 + np.linspace(1.0, 6.0, n)[:, None] * 0.2 * np.sin(np.arange(k))[None, :]
    assert evaluate(mark, _bs_sweep(grown)).verdict == "does not hold"


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
