"""The load check of the calibration (gearchaos.paper.loads): a candidate gear set whose peak
dynamic mesh force exceeds its teeth's strength is not plausible, whatever it scores."""

from __future__ import annotations

import math

import pytest

import gearchaos as gc
from gearchaos.paper import calibrate as cal
from gearchaos.paper.loads import LOAD_OMEGAS, allowable_mesh_force, load_factors
from gearchaos.paper.study import load_constraints


def test_without_excitation_the_dynamic_load_is_the_static_one() -> None:
    """MODEL.md §10.1: with constant mesh stiffness and no transmission error the steady state
    is static equilibrium, every mesh carrying F = T_D/(N r_bs): load factor 1 at every Ω, up to
    what is left of the start's transient. That decays with the time simulated, 2π·150/Ω, so
    it shrinks as Ω falls, from a few per cent at Ω = 3.5 to below 10⁻⁶ at Ω = 0.5."""
    gs = gc.preset("sheng2016-v1").evolve(
        {
            "stiffness.sun_planet_alternating": 0.0,
            "stiffness.planet_ring_alternating": 0.0,
            "transmission_error.sun_planet": 0.0,
            "transmission_error.planet_ring": 0.0,
        }
    )
    out = load_factors(gs)
    assert out["omegas"] == list(LOAD_OMEGAS) and out["status"] == ["ok"] * len(LOAD_OMEGAS)
    assert out["per_omega"] == pytest.approx([1.0] * len(LOAD_OMEGAS), abs=5e-2)
    rest = [lf - 1.0 for lf in out["per_omega"]]
    assert rest[0] < 1e-6  # Ω = 0.5: 1900 time units of decay
    assert rest == sorted(rest)  # less time simulated, more transient left
    assert min(out["per_omega"]) >= 1.0 - 1e-9  # a peak of a motion about the static load
    static = gs.torque.input / (gs.n_planets * gs.base_radius_sun)
    assert out["peak_force_N"] == pytest.approx(static, rel=5e-2)
    assert out["plausible"]


def test_allowable_force_is_iso_6336_bending_strength_at_the_implied_face_width() -> None:
    gs = gc.preset("sheng2016-v1")
    width = 0.62e9 / 20e9  # k_m,sp / c_γ: 31 mm
    assert gs.stiffness.sun_planet_mean == 6.2e8 and gs.geometry.module == 0.004
    assert allowable_mesh_force(gs) == pytest.approx(1000e6 * width * 0.004 / 4.2, rel=1e-12)


def _record(index: int, score: float, loads: dict | None) -> dict:
    rec = {"index": index, "score": score, "structure": 1.0, "key": str(index)}
    rec["parts"] = {} if loads is None else {"loads": loads}
    return rec


def _loads(peak: float, allow: float = 30e3) -> dict:
    return {
        "peak_force_N": peak, "allowable_force_N": allow, "plausible": peak <= allow,
        "max": peak / 1e3, "omega": 1.5,
    }  # fmt: skip


def test_records_whose_teeth_break_rank_after_every_plausible_one() -> None:
    strong = _record(1, 10.0, _loads(5e3))
    broken = _record(2, 22.0, _loads(190e3))
    unknown = _record(3, 12.0, None)  # a record of a calibration before the load check
    assert [r["index"] for r in cal.ranked([broken, strong, unknown])] == [3, 1, 2]
    assert cal.best_record([broken, strong]) is strong
    (why,) = cal.load_problems(broken)
    assert "190 kN" in why and "30 kN" in why and "Ω = 1.5" in why
    assert cal.load_problems(strong) == [] and cal.load_problems(unknown) == []


def test_the_study_constraint_is_feasible_exactly_within_the_strength() -> None:
    assert load_constraints({"loads": _loads(15e3)}) == [pytest.approx(-0.5)]
    assert load_constraints({"loads": _loads(60e3)}) == [pytest.approx(1.0)]
    assert load_constraints({}) == [0.0]
    assert load_constraints({"loads": _loads(math.inf)})[0] > 0
