"""Does the swept parameter act? (:mod:`gearchaos.paper.action`), and the accounting that keeps a
hold where it does not ("holds (constant)") apart from the holds.

Two backlash oscillators with known answers: one loaded so far onto its drive flank that its
clearance is never crossed (the clearance only shifts the coordinate: the orbit is the linear
oscillator's, whose multipliers are exp((−ζ ± i√(1−ζ²)) 2π/Ω) whatever b is), one whose
motion crosses to the back flank (the clearance enters the motion). Then the direct test on a
sweep when no branch can be followed, on hand-built stores.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

import gearchaos as gc
from gearchaos.paper import action as act
from gearchaos.paper.accounting import landmark_rows, verdict_counts
from gearchaos.paper.landmarks import AxisAction, LandmarkResult, load_landmarks
from gearchaos.paper.report import report_counts

ZETA = 0.05


@pytest.fixture(scope="module")
def mark():
    return next(m for m in load_landmarks() if m.id == "fig8b-1T-2T")


def _holds(mark) -> LandmarkResult:
    return LandmarkResult(mark, "holds", 1.0, "1T/2T at 100% of 301 points", {})


def test_a_clearance_far_from_any_motion_does_not_act_and_its_hold_is_constant(mark) -> None:
    # mean load 0.1 on unit stiffness, forcing 0.01 Ω² at Ω = 0.5: the deflection stays within
    # 0.003 of b + 0.1, far from the back flank at −b, and never leaves the drive flank
    omega = 0.5
    system = gc.backlash_oscillator(omega, zeta=ZETA, f_alt=0.01, f_mean=0.1, b=5.0)
    a = act.axis_action(system, "b", 5.0, 10.0, {}, start=6.0)
    assert a.acts is False and a.word == "constant"
    mu = a.measured["branch"]["mu"]
    linear = math.exp(-ZETA * 2 * math.pi / omega)  # |μ| of the linear oscillator (ω_n = 1)
    assert mu[0] == pytest.approx(linear, rel=1e-6) and mu[1] == pytest.approx(linear, rel=1e-6)
    assert a.measured["branch"]["reached"] == pytest.approx([5.0, 10.0])
    (res,) = act.apply_actions([_holds(mark)], {mark.id: a})
    assert res.verdict == "holds (constant)" and res.action is a
    counts = verdict_counts([res.verdict])
    assert counts["holds"] == 0 and counts["holds (constant)"] == 1


def test_a_clearance_the_motion_crosses_acts_and_its_hold_stays_a_hold(mark) -> None:
    omega, b = 0.8, 0.1
    system = gc.backlash_oscillator(omega, zeta=ZETA, f_alt=0.1, f_mean=0.1, b=b)
    run = gc.simulate(system, transient_periods=200, periods=50)
    assert run.obs_min[0] < -b  # the motion reaches the back flank (double-sided impact)
    a = act.axis_action(system, "b", 0.05, 0.5, {}, start=b)
    assert a.acts is True
    br = a.measured["branch"]
    assert br["events"] > 0 or br["change"] > act.ACT_THRESHOLD
    (res,) = act.apply_actions([_holds(mark)], {mark.id: a})
    assert res.verdict == "holds"
    assert verdict_counts([res.verdict])["holds"] == 1


def _bearing_sweep(sections: np.ndarray, reach: float) -> xr.Dataset:
    """A fig12-like store: b̄_s 1–10, the sun's extrema ±reach."""
    n = sections.shape[0]
    b = np.linspace(1.0, 10.0, n)
    one = np.full((1, n), reach)
    return xr.Dataset(
        {
            "motion": (("omega", "clearance.sun_bearing"), np.full((1, n), "1T", "<U10")),
            "delta_sp": (
                ("omega", "clearance.sun_bearing", "section", "planet"),
                sections[None, ..., None],
            ),
            "status": (("omega", "clearance.sun_bearing"), np.zeros((1, n), np.int8)),
            **{
                v: (("omega", "clearance.sun_bearing"), s * one)
                for v, s in (("x_s_max", 1), ("x_s_min", -1), ("y_s_max", 0.5), ("y_s_min", -0.5))
            },
        },
        coords={"omega": [1.5], "clearance.sun_bearing": b, "planet": [1]},
    )


def test_without_a_branch_the_sweep_decides(monkeypatch: pytest.MonkeyPatch) -> None:
    def no_branch(*args, **kwargs):
        return {"change": math.nan, "mu": None, "events": 0, "kinds": [], "reached": None,
                "reason": "no orbit converged"}  # fmt: skip

    monkeypatch.setattr(act, "branch_action", no_branch)
    n = 10
    same = np.tile(3.0 + 0.1 * np.sin(np.arange(12)), (n, 1))
    kw = {"family_value": 1.5}
    fixed = {"omega": 1.5}
    # the sun moves 0.02 and b̄_s ≥ 1: never reached, every point's record identical
    never = act.axis_action(None, "clearance.sun_bearing", 1.0, 10.0, fixed,
                            ds=_bearing_sweep(same, 0.02), **kw)  # fmt: skip
    assert never.acts is False
    assert never.measured["reach"]["reached"] == 0
    assert never.measured["reach"]["depth"] == pytest.approx(0.02)
    # never reached, but the records differ (another attractor selected): not proven constant
    moved = same + np.linspace(0.0, 0.5, n)[:, None] * np.cos(np.arange(12))[None, :]
    assert act.axis_action(None, "clearance.sun_bearing", 1.0, 10.0, fixed,
                           ds=_bearing_sweep(moved, 0.02), **kw).acts is None  # fmt: skip
    # the sun reaches b̄_s = 1 and 2 (|x̄_s| = 2.5): the clearance acts
    hit = act.axis_action(None, "clearance.sun_bearing", 1.0, 10.0, fixed,
                          ds=_bearing_sweep(same, 2.5), **kw)  # fmt: skip
    assert hit.acts is True and hit.measured["reach"]["reached"] == 2


def test_section_change_ignores_a_pure_shift_only_for_backlashes() -> None:
    n, k = 5, 8
    base = np.sin(np.arange(k))
    shifted = base[None, :] + np.arange(n)[:, None]  # the backlash shifts the coordinate
    lab = np.array(["1T"] * n)
    assert act.section_change(np.arange(n), lab, shifted, centred=True) < 1e-12
    assert act.section_change(np.arange(n), lab, shifted, centred=False) > 0.5


def test_double_sided_contact_on_the_sweep_says_the_backlash_acts() -> None:
    n = 6
    b = np.linspace(1.0, 10.0, n)
    code = np.ones((1, n, 3), dtype=np.int8)
    ds = xr.Dataset(
        {
            "motion": (("omega", "backlash.sun_planet"), np.full((1, n), "chaos", "<U10")),
            "contact_sp": (("omega", "backlash.sun_planet", "planet_all"), code),
            "delta_sp_min": (
                ("omega", "backlash.sun_planet", "planet_all"),
                -0.5 * b[None, :, None] * np.ones((1, n, 3)),
            ),
        },
        coords={"omega": [1.0], "backlash.sun_planet": b},
    )
    none = act.clearance_reach(ds, "backlash.sun_planet", 1.0)
    assert none == {"reached": 0, "points": n, "depth": pytest.approx(0.5)}
    ds["contact_sp"][0, 0, 2] = 2  # planet 3 hits its back flank at b̄_sp = 1
    ds["delta_sp_min"][0, 0, 2] = -1.2
    got = act.clearance_reach(ds, "backlash.sun_planet", 1.0)
    assert got["reached"] == 1 and got["depth"] == pytest.approx(1.2)
    a = act.axis_action(None, "backlash.sun_planet", 1.0, 10.0, {}, ds=ds, family_value=1.0)
    assert a.acts is True and "back flank" in a.evidence


def test_the_counts_keep_constant_holds_apart() -> None:
    rows = [
        {"verdict": "holds", "paper_verdict": "holds"},
        {"verdict": "holds (constant)", "paper_verdict": "holds (constant)"},
        {"verdict": "holds (constant)", "paper_verdict": "does not hold"},
        {"verdict": "partly", "paper_verdict": "not evaluated"},
    ]
    counts = report_counts([], rows)
    assert counts["landmarks"]["holds"] == 1
    assert counts["landmarks"]["holds (constant)"] == 2
    assert counts["landmarks"]["partly"] == 1 and counts["landmarks"]["does not hold"] == 0
    assert counts["landmarks_paper"] == {
        "holds": 1,
        "holds (constant)": 1,
        "partly": 0,
        "does not hold": 1,
        "not evaluated": 1,
    }


def test_landmark_rows_show_the_action_and_the_paper_protocol_column() -> None:
    marks = [m for m in load_landmarks() if m.id in ("fig8b-1T-2T", "fig8d-1T")]
    b = np.linspace(1.0, 10.0, 19)
    omegas = [1.0, 1.5, 2.0, 2.5]

    def store(label: str) -> xr.Dataset:
        lab = np.full((len(omegas), b.size), label, "<U10")
        return xr.Dataset(
            {"motion": (("omega", "backlash.sun_planet"), lab)},
            coords={"omega": omegas, "backlash.sun_planet": b},
        )

    constant = AxisAction(False, "1T branch constant", {})
    rows, note = landmark_rows(
        {"fig8": store("1T")},
        paper_stores={"fig8": store("QP")},  # the zero start's record reads QP everywhere
        actions={m.id: constant for m in marks},
        landmarks=marks,
    )
    assert note == ""
    assert [r["verdict"] for r in rows] == ["holds (constant)", "holds (constant)"]
    assert [r["acts"] for r in rows] == ["constant", "constant"]
    assert [r["paper_verdict"] for r in rows] == ["does not hold", "does not hold"]
    assert "QP" in rows[0]["paper_evidence"]
