"""Every verdict function of gearchaos.paper.conclusions on synthetic sweeps with a known answer.

The synthetic datasets have exactly the shape of the stores `reproduce` writes: ``motion``
(family, vary) labels and ``delta_sp`` (family, vary, section, planet) section values.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from gearchaos.paper.conclusions import (
    CONCLUSIONS,
    WEAK_COUPLING_RATIO,
    Verdict,
    attractor_size,
    chaos_onsets,
    chaotic_fraction,
    conclusion_1,
    conclusion_2,
    conclusion_3,
    conclusion_4,
    conclusion_5,
    conclusion_6,
    conclusion_7,
    conclusion_8,
    evaluate_conclusions,
    qp_near_3t,
    section_spread,
)

NSEC = 16
RNG = np.random.default_rng(0)


def _sections(label: str, centre: float = 5.0, size: float = 1.0) -> np.ndarray:
    """Section values that look like ``label``: n distinct points, or a cloud."""
    if label.endswith("T") and label[:-1].isdigit():
        n = int(label[:-1])
        pts = centre + size * 0.1 * np.arange(n)
        return np.resize(pts, NSEC)
    if label == "chaos":
        return centre + size * RNG.uniform(-2, 2, NSEC)
    if label == "QP":
        return centre + 0.3 * size * np.sin(np.arange(NSEC) * 0.7)
    return np.full(NSEC, np.nan)


def sweep(
    rows: list[list[str]],
    *,
    family: str = "xi",
    fvalues: list[float] | None = None,
    vary: str = "omega",
    x: np.ndarray | None = None,
    sections: np.ndarray | None = None,
) -> xr.Dataset:
    labels = np.array(rows, dtype="<U10")
    nf, nv = labels.shape
    fvalues = fvalues if fvalues is not None else [0.03 + 0.02 * i for i in range(nf)]
    x = x if x is not None else np.linspace(1.0, 4.0, nv)
    if sections is None:
        sections = np.stack([[_sections(s) for s in row] for row in labels])
    return xr.Dataset(
        {
            "motion": ((family, vary), labels),
            "delta_sp": ((family, vary, "section", "planet"), sections[..., None]),
            "status": ((family, vary), np.zeros((nf, nv), dtype=np.int8)),
        },
        coords={family: fvalues, vary: x},
    )


def _row(n_chaos: int, n: int = 10) -> list[str]:
    return ["1T"] * (n - n_chaos) + ["chaos"] * n_chaos


# --------------------------------------------------------------------------- helpers
def test_chaotic_fraction_per_family_value() -> None:
    ds = sweep([_row(5), _row(2), ["unresolved"] * 5 + ["chaos"] * 5])
    frac = chaotic_fraction(ds)
    assert frac[0.03] == pytest.approx(0.5)
    assert frac[0.05] == pytest.approx(0.2)
    assert frac[0.07] == pytest.approx(1.0)  # unresolved points are left out


def test_attractor_size() -> None:
    s = np.array([[1.0, 1.0, 1.0], [0.0, 2.0, 1.0]])
    assert attractor_size(s).tolist() == [0.0, 2.0]


def test_qp_near_3t() -> None:
    x = np.linspace(0, 10, 11)
    lab = np.array(["1T", "QP", "3T", "1T", "1T", "1T", "1T", "1T", "QP", "1T", "1T"])
    assert qp_near_3t(x, lab, tol=1.0) == (2, 1)


# --------------------------------------------------------------------------- routes
def test_period_doubling_route() -> None:
    lab = np.array(["1T", "1T", "2T", "4T", "chaos", "chaos"])
    (o,) = chaos_onsets(np.arange(6.0), lab, np.stack([_sections(s) for s in lab]))
    assert o["route"] == "period doubling"
    assert o["at"] == 4.0


def test_crisis_route_is_a_jump_of_the_attractor() -> None:
    lab = np.array(["1T", "1T", "1T", "chaos", "chaos"])
    sec = np.stack([_sections(s, size=1.0 if s == "1T" else 5.0) for s in lab])
    (o,) = chaos_onsets(np.arange(5.0), lab, sec)
    assert o["route"] == "crisis"
    assert o["size_at"] > 2 * o["size_before"]


def test_no_jump_and_no_precursor_is_abrupt_not_crisis() -> None:
    lab = np.array(["1T", "1T", "chaos"])
    sec = np.stack([np.full(NSEC, 5.0), np.full(NSEC, 5.0), np.full(NSEC, 5.0)])
    sec[:, 0] = 0.0  # same spread everywhere
    (o,) = chaos_onsets(np.arange(3.0), lab, sec)
    assert o["route"] == "abrupt"


def test_hopf_and_3t_channel_routes() -> None:
    lab = np.array(["1T", "QP", "chaos", "1T", "3T", "3T", "chaos"])
    routes = [o["route"] for o in chaos_onsets(np.arange(7.0), lab, None)]
    assert routes == ["Hopf", "3T channel"]


def test_unresolved_points_are_skipped_between_precursor_and_chaos() -> None:
    lab = np.array(["1T", "2T", "unresolved", "4T", "unresolved", "chaos"])
    (o,) = chaos_onsets(np.arange(6.0), lab, None)
    assert o["route"] == "period doubling"


# --------------------------------------------------------------------------- conclusion 3
def test_damping_shrinking_chaos_holds() -> None:
    stores = {f: sweep([_row(6), _row(4), _row(2), _row(0)]) for f in ("fig4", "fig6", "fig9")}
    v = conclusion_3(stores)
    assert v.verdict == "holds"
    assert "0.6" in v.evidence and "0.2" in v.evidence


def test_damping_growing_chaos_does_not_hold() -> None:
    stores = {"fig4": sweep([_row(0), _row(2), _row(4), _row(6)])}
    v = conclusion_3(stores)
    assert v.verdict == "does not hold"
    assert v.measured["fig4"]["monotone"] is False


def test_damping_mixed_sweeps_partly() -> None:
    shrink = sweep([_row(6), _row(4), _row(2), _row(0)])
    grow = sweep([_row(0), _row(2), _row(4), _row(6)])
    v = conclusion_3({"fig4": shrink, "fig6": shrink, "fig9": grow})
    assert v.verdict == "partly"


def test_damping_all_unresolved_not_evaluated() -> None:
    v = conclusion_3({"fig4": sweep([["unresolved"] * 10] * 4)})
    assert v.verdict == "not evaluated"
    assert conclusion_3({}).verdict == "not evaluated"


# --------------------------------------------------------------------------- conclusions 4–6
def _crisis_panel() -> tuple[list[str], np.ndarray]:
    lab = ["1T"] * 5 + ["chaos"] * 3 + ["1T"] * 2
    sec = np.stack([_sections(s, size=1.0 if s == "1T" else 5.0) for s in lab])
    return lab, sec


def _pd_panel() -> tuple[list[str], np.ndarray]:
    lab = ["1T", "1T", "2T", "2T", "4T", "chaos", "chaos", "1T", "1T", "1T"]
    sec = np.stack([_sections(s) for s in lab])
    return lab, sec


def _one_panel(lab: list[str], sec: np.ndarray, vary: str = "omega") -> xr.Dataset:
    return sweep([lab], family="xi", fvalues=[0.03], vary=vary, sections=sec[None])


def test_crisis_in_omega_holds() -> None:
    v = conclusion_4({"fig4": _one_panel(*_crisis_panel())})
    assert v.verdict == "holds"
    assert v.measured["route_counts"] == {"crisis": 1}


def test_period_doubling_only_in_omega_does_not_hold() -> None:
    v = conclusion_4({"fig4": _one_panel(*_pd_panel())})
    assert v.verdict == "does not hold"


def test_omega_without_chaos_does_not_hold_when_labelled() -> None:
    v = conclusion_4({"fig4": sweep([["1T"] * 10])})
    assert v.verdict == "does not hold"
    assert conclusion_4({"fig4": sweep([["unresolved"] * 10])}).verdict == "not evaluated"


def test_crisis_and_period_doubling_in_bsp() -> None:
    c_lab, c_sec = _crisis_panel()
    p_lab, p_sec = _pd_panel()
    both = sweep([c_lab, p_lab], vary="backlash.sun_planet", sections=np.stack([c_sec, p_sec]))
    assert conclusion_5({"fig6": both}).verdict == "holds"
    only_pd = _one_panel(p_lab, p_sec, vary="backlash.sun_planet")
    assert conclusion_5({"fig6": only_pd}).verdict == "partly"


def test_several_routes_in_brp() -> None:
    c_lab, c_sec = _crisis_panel()
    p_lab, p_sec = _pd_panel()
    h_lab = ["1T", "1T", "QP", "chaos", "chaos", "1T", "3T", "3T", "chaos", "1T"]
    h_sec = np.stack([_sections(s) for s in h_lab])
    ds = sweep(
        [c_lab, p_lab, h_lab], vary="backlash.planet_ring", sections=np.stack([c_sec, p_sec, h_sec])
    )
    v = conclusion_6({"fig9": ds})
    assert v.verdict == "holds"
    assert set(v.measured["route_types"]) == {"crisis", "period doubling", "Hopf", "3T channel"}
    one = _one_panel(c_lab, c_sec, vary="backlash.planet_ring")
    assert conclusion_6({"fig9": one}).verdict == "does not hold"
    two = sweep([c_lab, p_lab], vary="backlash.planet_ring", sections=np.stack([c_sec, p_sec]))
    assert conclusion_6({"fig9": two}).verdict == "partly"


# --------------------------------------------------------------------------- conclusion 7
def _flat_bs() -> xr.Dataset:
    n = 10
    sec = np.full((1, n, NSEC), 5.0) + 1e-3 * np.arange(n)[None, :, None]
    return sweep(
        [["1T"] * n], family="omega", fvalues=[1.5], vary="clearance.sun_bearing", sections=sec
    )


def _wild_brp(spread: float) -> xr.Dataset:
    n = 10
    base = np.linspace(0.0, spread, n)
    sec = np.broadcast_to(base[None, :, None], (2, n, NSEC)).copy()
    return sweep(
        [["chaos"] * n, ["2T"] * n],
        fvalues=[0.03, 0.05],
        vary="backlash.planet_ring",
        sections=sec,
    )


def test_weak_bs_strong_brp_holds() -> None:
    v = conclusion_7({"fig12": _flat_bs(), "fig9": _wild_brp(10.0)})
    assert v.verdict == "holds"
    assert v.measured["ratio"] < 0.01


def test_bs_spread_like_brp_is_not_weak() -> None:
    n = 10
    sec = np.broadcast_to(np.linspace(0.0, 10.0, n)[None, :, None], (1, n, NSEC)).copy()
    bs = sweep(
        [["1T"] * n], family="omega", fvalues=[1.5], vary="clearance.sun_bearing", sections=sec
    )
    v = conclusion_7({"fig12": bs, "fig9": _wild_brp(10.0)})
    assert v.verdict == "partly"  # no bifurcation, but strong coupling
    chaotic = sweep(
        [["1T"] * 5 + ["chaos"] * 5],
        family="omega",
        fvalues=[1.5],
        vary="clearance.sun_bearing",
        sections=sec,
    )
    assert conclusion_7({"fig12": chaotic, "fig9": _wild_brp(10.0)}).verdict == "does not hold"


def _bs(sections: np.ndarray, label: str = "1T") -> xr.Dataset:
    n = sections.shape[0]
    return sweep(
        [[label] * n],
        family="omega",
        fvalues=[1.5],
        vary="clearance.sun_bearing",
        sections=sections[None],
    )


def test_c7_measures_the_change_of_each_points_attractor_not_the_pooled_spread() -> None:
    n = 10
    brp = _wild_brp(1.0)  # along b̄_rp the attractor's centre moves by 1.0
    # every point along b̄_s keeps the same wide record (a transient left in it, QP-like): its
    # pooled spread is large, but nothing changes from one b̄_s to the next
    record = 5.0 + np.random.default_rng(3).uniform(-2.0, 2.0, NSEC)
    wide = _bs(np.tile(record, (n, 1)))
    v = conclusion_7({"fig12": wide, "fig9": brp})
    assert v.measured["change_bs"]["change"] == 0.0
    assert v.measured["ratio"] == 0.0 and v.verdict == "holds"
    assert section_spread(wide) / section_spread(brp, 0.05) > WEAK_COUPLING_RATIO  # old: strong
    # only the transient changes: a narrower record at every point moves nothing either
    narrow = _bs(np.tile(5.0 + 0.1 * (record - 5.0), (n, 1)))
    assert conclusion_7({"fig12": narrow, "fig9": brp}).measured["ratio"] == 0.0
    # the attractors themselves change along b̄_s: their size grows from 0.4 to 4
    grow = 5.0 + np.linspace(0.1, 1.0, n)[:, None] * (record - 5.0)[None, :]
    moved = conclusion_7({"fig12": _bs(grow), "fig9": brp})
    change = moved.measured["change_bs"]
    assert change["size"] == pytest.approx(0.9 * float(np.ptp(record)))
    assert moved.measured["ratio"] > WEAK_COUPLING_RATIO
    assert moved.verdict == "partly"  # periodic, no bifurcation, but not weakly coupled


# --------------------------------------------------------------------------- conclusion 8
def test_qp_near_3t_everywhere_holds_else_partly() -> None:
    lab = ["1T", "QP", "3T", "1T", "1T", "1T", "1T", "1T", "1T", "1T"]
    far = ["1T", "QP", "1T", "1T", "1T", "1T", "1T", "1T", "3T", "1T"]
    stores = {
        "fig4": sweep([lab]),
        "fig6": sweep([lab], vary="backlash.sun_planet"),
        "fig9": sweep([lab], vary="backlash.planet_ring"),
    }
    assert conclusion_8(stores).verdict == "holds"
    stores["fig9"] = sweep([far], vary="backlash.planet_ring")
    assert conclusion_8(stores).verdict == "partly"
    none = {k: sweep([["1T"] * 10]) for k in ("fig4", "fig6", "fig9")}
    assert conclusion_8(none).verdict == "does not hold"


# --------------------------------------------------------------------------- 1, 2 and all
def test_conclusion_1_counts_swept_parameters() -> None:
    stores = {
        "fig4": sweep([["1T"] * 4]),
        "fig6": sweep([["1T"] * 4], vary="backlash.sun_planet"),
        "fig9": sweep([["1T"] * 4], vary="backlash.planet_ring"),
        "fig12": sweep([["1T"] * 4], vary="clearance.sun_bearing"),
    }
    assert conclusion_1(stores).verdict == "holds"
    del stores["fig12"]
    assert conclusion_1(stores).verdict == "partly"
    assert conclusion_1({}).verdict == "not evaluated"


def test_conclusion_2_reads_the_gear_set() -> None:
    from gearchaos.gearset import preset

    ds = sweep([["1T"] * 4])
    ds.attrs["gearset_toml"] = preset("hindawi2021").to_toml()
    ds["x_s_max"] = (("xi", "omega"), np.zeros((1, 4)))
    v = conclusion_2({"fig4": ds})
    assert v.verdict == "partly"  # every ingredient, but the sun never moves
    assert v.measured["sun_translation_excited"] is False
    ds["x_s_max"] = (("xi", "omega"), np.full((1, 4), 0.5))
    assert conclusion_2({"fig4": ds}).verdict == "holds"
    assert conclusion_2({}).verdict == "not evaluated"


def test_evaluate_conclusions_returns_all_eight() -> None:
    out = evaluate_conclusions({"fig4": sweep([_row(3), _row(1)])})
    assert [v.conclusion_id for v in out] == list(range(1, 9)) == sorted(CONCLUSIONS)
    assert all(isinstance(v, Verdict) and v.statement for v in out)


def test_verdict_rejects_unknown_value() -> None:
    with pytest.raises(ValueError):
        Verdict(1, "s", "maybe", "e")
