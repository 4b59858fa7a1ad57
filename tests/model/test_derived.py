"""``gearset_info``: derived quantities of the hindawi2021 preset (MODEL.md §9), recomputed
here from the MODEL.md formulas (§1, §2, §4, §7, §9, §10.1) and the preset's table values."""

from __future__ import annotations

import json
import math

import pytest

import gearchaos as gc
from gearchaos.model.derived import gearset_info

# MODEL.md §9 table values of the hindawi2021 preset.
N = 5
ZS, ZP, ZR = 34, 31, 96
MODULE = 0.004
ALPHA = math.radians(22.5)
MS_STAR, MP_STAR, JC_OVER_RC2 = 6.21, 4.89, 10.0
MS, MP = 10.6, 8.35
KSP, KAS, KRP, KAR, KS = 0.62e9, 0.14e9, 0.85e9, 0.11e9, 4.2e7
TD = 1130.0
BC = 1e-5
XI = 0.03

R_S, R_P, R_R = MODULE * ZS / 2, MODULE * ZP / 2, MODULE * ZR / 2
R_C = R_S + R_P
R_BS, R_BP = R_S * math.cos(ALPHA), R_P * math.cos(ALPHA)
MC_STAR = JC_OVER_RC2 + N * MP
ME = MS_STAR * MP_STAR / (MS_STAR + MP_STAR)
WN = math.sqrt(KSP / ME)
TL = TD * (1 + ZR / ZS)

REL = 1e-9  # the preset stores J = m* r_b² to 16 digits


@pytest.fixture(scope="module")
def info() -> dict:
    return gearset_info(gc.preset("hindawi2021"))


def test_json_round_trip(info: dict) -> None:
    text = json.dumps(info)
    assert json.loads(text) == info


def test_identity_and_geometry(info: dict) -> None:
    assert info["name"] == "hindawi2021"
    assert info["planets"] == N
    assert info["teeth"] == {"sun": ZS, "planet": ZP, "ring": ZR}
    radii = info["radii_m"]
    assert radii == pytest.approx(
        {
            "sun": R_S,
            "planet": R_P,
            "ring": R_R,
            "carrier": R_C,
            "base_sun": R_BS,
            "base_planet": R_BP,
        },
        rel=1e-12,
    )
    assert radii["carrier"] == pytest.approx(0.13, rel=1e-12)


def test_equivalent_masses_and_time_scale(info: dict) -> None:
    assert info["equivalent_masses_kg"] == pytest.approx(
        {"sun": MS_STAR, "planet": MP_STAR, "carrier": 10.0 + 5 * 8.35, "mesh": ME}, rel=REL
    )
    assert info["equivalent_masses_kg"]["mesh"] == pytest.approx(
        6.21 * 4.89 / (6.21 + 4.89), rel=REL
    )
    assert info["omega_n_rad_s"] == pytest.approx(math.sqrt(0.62e9 / ME), rel=REL)
    assert info["omega_n_hz"] == pytest.approx(WN / (2 * math.pi), rel=REL)


def test_damping_coefficients(info: dict) -> None:
    assert info["damping_coefficients_N_s_per_m"] == pytest.approx(
        {
            "sun_planet": 2 * XI * math.sqrt(KSP * ME),
            "planet_ring": 2 * XI * math.sqrt(KRP * MP_STAR),
            "sun_bearing": 2 * XI * math.sqrt(KS * MS),
        },
        rel=REL,
    )


def test_dimensionless_parameters(info: dict) -> None:
    d = info["dimensionless"]
    expected = {
        "mu_s": MS / ME,
        "mu_s_star": MS_STAR / ME,
        "mu_p_star": MP_STAR / ME,
        "mu_c_star": MC_STAR / ME,
        "eps_sp": KAS / KSP,
        "kappa_rp_mean": KRP / KSP,
        "kappa_rp_alt": KAR / KSP,
        "kappa_b": KS / KSP,
        "damping_sun_planet": 2 * XI,
        "damping_planet_ring": 2 * XI * math.sqrt(KRP * MP_STAR) / (ME * WN),
        "damping_sun_bearing": 2 * XI * math.sqrt(KS * MS) / (ME * WN),
        "b_sp": 3.0,
        "b_rp": 3.5,
        "b_s": 2.0,
        "torque_input": TD / (R_BS * KSP * BC),
        "torque_output": TL / (R_C * KSP * BC),
        "te_sp": 5e-6 / BC,
        "te_rp": 5e-6 / BC,
    }
    for key, value in expected.items():
        assert d[key] == pytest.approx(value, rel=REL), key
    assert d["harmonics_sp"] == [] and d["harmonics_rp"] == []
    # The static balance in dimensionless form (MODEL.md §10.1): T̄_L = N F̄ (cos α_s + cos α_r).
    assert d["torque_output"] == pytest.approx(2 * math.cos(ALPHA) * d["torque_input"], rel=1e-12)


def test_loads_and_static_state(info: dict) -> None:
    assert info["torque_ratio"] == pytest.approx(1 + 96 / 34, rel=1e-12)
    assert info["output_torque_N_m"] == pytest.approx(TL, rel=1e-12)
    assert info["load_mode"] == "constant_torque"
    force = TD / (N * R_BS)
    assert info["static_mesh_force_N"] == pytest.approx(force, rel=1e-12)
    assert info["static_deflection"] == pytest.approx(
        {
            "sun_planet_m": force / KSP,
            "sun_planet_bar": force / KSP / BC,
            "planet_ring_m": force / KRP,
            "planet_ring_bar": force / KRP / BC,
        },
        rel=1e-12,
    )


def test_mesh_phasing(info: dict) -> None:
    # 96 mod 5 = 1: sequential phasing; the preset itself uses the in-phase model (MODEL.md §9).
    assert info["mesh_phasing"] == {"model": "in_phase", "class": "sequential", "k": 1}
    other = gearset_info(
        gc.preset("hindawi2021").evolve(
            {
                "geometry.planets": 3,
                "teeth.sun": 30,
                "teeth.planet": 33,
                "mesh_phasing.model": "parker",
            }
        )
    )
    assert other["mesh_phasing"] == {"model": "parker", "class": "in_phase", "k": 0}


def test_natural_frequencies_and_resonances(info: dict) -> None:
    table = info["natural_frequencies"]
    assert all(set(row) == {"hz", "ratio", "kind", "multiplicity"} for row in table)
    assert sum(row["multiplicity"] for row in table) == 4 + N
    assert table[0] == {"hz": 0.0, "ratio": 0.0, "kind": "rotational", "multiplicity": 1}
    for row in table:
        assert row["hz"] == pytest.approx(row["ratio"] * WN / (2 * math.pi), rel=1e-9)
    # Planet modes of MODEL.md §10.3: ω² = (k_sp + k_rp)/m_p*, multiplicity N − 3.
    (planet,) = [row for row in table if row["kind"] == "planet"]
    assert planet["multiplicity"] == N - 3
    assert planet["ratio"] == pytest.approx(math.sqrt((KSP + KRP) / MP_STAR) / WN, rel=REL)

    res = info["omega_at_resonances"]
    nonzero = [row for row in table if row["ratio"] > 0.0]
    assert len(res) == 3 * len(nonzero)
    assert [r["omega"] for r in res] == sorted(r["omega"] for r in res)
    for r in res:
        assert r["harmonic"] in (1, 2, 3)
        assert r["omega"] * r["harmonic"] == pytest.approx(r["mode_ratio"], rel=1e-15)
    assert {(r["mode_ratio"], r["harmonic"]) for r in res} == {
        (row["ratio"], h) for row in nonzero for h in (1, 2, 3)
    }


def test_zero_torque_is_well_defined() -> None:
    info = gearset_info(gc.preset("hindawi2021").evolve({"torque.input": 0.0}))
    assert info["torque_ratio"] == pytest.approx(1 + 96 / 34, rel=1e-12)
    assert info["static_mesh_force_N"] == 0.0
    json.dumps(info)
