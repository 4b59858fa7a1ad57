"""The shipped presets: hindawi2021 against MODEL.md §9, with derived quantities recomputed here;
sheng2016 (the default) against the calibration log it was made from."""

from __future__ import annotations

import dataclasses
import math
from fractions import Fraction

import pytest

from gearchaos.errors import ParameterError
from gearchaos.gearset import GearSet, list_presets, preset
from gearchaos.gearset.io import evolve

REL = 1e-12
ALPHA = math.pi / 8  # 22.5 degrees


@pytest.fixture(scope="module")
def gs() -> GearSet:
    return preset("hindawi2021")  # the gear set of MODEL.md §9


def test_list_presets() -> None:
    presets = dict(list_presets())
    assert set(presets) >= {"sheng2016", "hindawi2021"}
    assert "MODEL.md §9" in presets["hindawi2021"]
    assert "calibrated" in presets["sheng2016"]
    assert all(isinstance(n, str) and isinstance(d, str) for n, d in list_presets())


def test_unknown_preset_suggests_and_lists() -> None:
    with pytest.raises(ParameterError) as info:
        preset("sheng2061")
    msg = str(info.value)
    assert msg.startswith("unknown preset 'sheng2061'; did you mean 'sheng2016'?")
    assert "available presets:" in msg and "sheng2016" in msg.split("available presets:")[1]


@pytest.mark.parametrize("name", ["../io", "", "sheng2016.toml", "zzz"])
def test_bad_preset_names(name: str) -> None:
    with pytest.raises(ParameterError, match="unknown preset"):
        preset(name)


def test_preset_is_immutable_and_stable(gs: GearSet) -> None:
    assert preset("hindawi2021") == gs
    with pytest.raises(dataclasses.FrozenInstanceError):
        gs.name = "x"  # type: ignore[misc]


def test_hindawi2021_table_values(gs: GearSet) -> None:
    assert gs.name == "hindawi2021"
    assert gs.n_planets == 5
    assert (gs.teeth.sun, gs.teeth.planet, gs.teeth.ring) == (34, 31, 96)
    assert gs.geometry.module == 0.004
    assert gs.geometry.pressure_angle_sun == 22.5
    assert gs.geometry.pressure_angle_ring == 22.5
    assert (gs.mass.sun, gs.mass.planet) == (10.6, 8.35)
    assert gs.stiffness.sun_planet_mean == 0.62e9
    assert gs.stiffness.sun_planet_alternating == 0.14e9
    assert gs.stiffness.planet_ring_mean == 0.85e9
    assert gs.stiffness.planet_ring_alternating == 0.11e9
    assert gs.stiffness.sun_bearing == 4.2e7
    assert gs.torque.input == 1130.0
    assert gs.torque.mode == "constant_torque"
    assert gs.transmission_error.sun_planet == 5e-6
    assert gs.transmission_error.planet_ring == 5e-6
    e = gs.eccentricity
    assert (e.sun, e.planet, e.ring) == (0.0, 0.0, 0.0)
    assert not gs.has_eccentricity
    assert gs.clearance.characteristic_length == 1e-5
    assert gs.backlash_bar() == (3.0, 3.5)
    assert gs.sun_bearing_clearance_bar() == 2.0
    assert (gs.damping.sun_planet, gs.damping.planet_ring, gs.damping.sun_bearing) == (
        0.03,
        0.03,
        0.03,
    )
    assert gs.mesh_phasing.model == "in_phase"


def test_hindawi2021_equivalent_masses(gs: GearSet) -> None:
    assert gs.equivalent_mass_sun == pytest.approx(6.21, rel=REL)
    assert gs.equivalent_mass_planet == pytest.approx(4.89, rel=REL)
    assert gs.inertia.carrier / gs.radius_carrier**2 == pytest.approx(10.0, rel=REL)
    # recomputed from the stored inertias and r_b = m z cos(α) / 2
    r_bs = 0.004 * 34 / 2 * math.cos(ALPHA)
    r_bp = 0.004 * 31 / 2 * math.cos(ALPHA)
    assert gs.inertia.sun / r_bs**2 == pytest.approx(6.21, rel=REL)
    assert gs.inertia.planet / r_bp**2 == pytest.approx(4.89, rel=REL)
    assert gs.equivalent_mass_carrier == pytest.approx(10.0 + 5 * 8.35, rel=REL)
    assert gs.equivalent_mass_mesh == pytest.approx(6.21 * 4.89 / (6.21 + 4.89), rel=REL)


def test_hindawi2021_radii(gs: GearSet) -> None:
    assert gs.radius_sun == pytest.approx(0.004 * 34 / 2, rel=REL)
    assert gs.radius_planet == pytest.approx(0.004 * 31 / 2, rel=REL)
    assert gs.radius_ring == pytest.approx(0.004 * 96 / 2, rel=REL)
    assert gs.radius_carrier == pytest.approx(0.13, rel=REL)  # (34 + 31) * 4 mm / 2
    assert gs.base_radius_sun == pytest.approx(0.068 * math.cos(ALPHA), rel=REL)


def test_hindawi2021_output_torque(gs: GearSet) -> None:
    assert gs.output_torque == pytest.approx(1130.0 * (1 + 96 / 34), rel=REL)


def test_hindawi2021_natural_frequency(gs: GearSet) -> None:
    me = 6.21 * 4.89 / (6.21 + 4.89)
    assert gs.omega_n == pytest.approx(math.sqrt(0.62e9 / me), rel=REL)
    # ω = ω_s z_s z_r / (z_s + z_r) for 1000 rpm
    assert gs.mesh_frequency(1000.0) == pytest.approx(
        1000 * 2 * math.pi / 60 * 34 * 96 / 130, rel=REL
    )


def test_hindawi2021_is_sequentially_phased(gs: GearSet) -> None:
    # k = z_r mod N = 96 mod 5 = 1: sequential, whatever the mesh_phasing model says
    assert gs.phasing_class == "sequential"
    assert gs.mesh_phasing.model == "in_phase"
    assert gs.mesh_phases() == ((0.0,) * 5, (0.0,) * 5)


@pytest.mark.parametrize(
    ("teeth", "planets", "expected"),
    [
        ((20, 18, 56), 4, "in_phase"),  # 56 mod 4 = 0
        ((20, 19, 58), 3, "sequential"),  # 58 mod 3 = 1
        ((23, 17, 57), 5, "counter_phase"),  # 57 mod 5 = 2
    ],
)
def test_phasing_class_from_tooth_numbers(
    gs: GearSet, teeth: tuple[int, int, int], planets: int, expected: str
) -> None:
    small = evolve(
        gs,
        {
            "teeth.sun": teeth[0],
            "teeth.planet": teeth[1],
            "teeth.ring": teeth[2],
            "geometry.planets": planets,
        },
    )
    assert small.phasing_class == expected


def _parker(zs: int, zr: int, n: int, gamma_rs: float) -> tuple[list[float], list[float]]:
    """MODEL.md §3: γ_spi = frac(z_s ψ_i/2π), γ_rpi = frac(−z_r ψ_i/2π) + γ_rs, φ = −2πγ."""
    g_sp = [Fraction(zs * i, n) % 1 for i in range(n)]  # ψ_i/2π = (i−1)/N, i = 1..N
    g_rp = [Fraction(-zr * i, n) % 1 for i in range(n)]
    return (
        [-2 * math.pi * float(g) for g in g_sp],
        [-2 * math.pi * (float(g) + gamma_rs) for g in g_rp],
    )


def test_parker_phases_small_case(gs: GearSet) -> None:
    small = evolve(
        gs,
        {
            "teeth.sun": 20,
            "teeth.planet": 19,
            "teeth.ring": 58,
            "geometry.planets": 3,
            "mesh_phasing.model": "parker",
            "mesh_phasing.ring_sun": 0.25,
        },
    )
    phi_sp, phi_rp = small.mesh_phases()
    # by hand: 20·(0, 1, 2)/3 → fractions 0, 2/3, 1/3; −58·(0, 1, 2)/3 → 0, 2/3, 1/3
    assert phi_sp == pytest.approx([0.0, -4 * math.pi / 3, -2 * math.pi / 3], abs=1e-12)
    assert phi_rp == pytest.approx(
        [-math.pi / 2, -2 * math.pi * (2 / 3 + 0.25), -2 * math.pi * (1 / 3 + 0.25)], abs=1e-12
    )
    expected_sp, expected_rp = _parker(20, 58, 3, 0.25)
    assert phi_sp == pytest.approx(expected_sp, abs=1e-12)
    assert phi_rp == pytest.approx(expected_rp, abs=1e-12)


def test_parker_phases_of_hindawi2021_teeth(gs: GearSet) -> None:
    parker = evolve(gs, {"mesh_phasing.model": "parker"})
    phi_sp, phi_rp = parker.mesh_phases()
    # 34 i/5 → .0 .8 .6 .4 .2 ; −96 i/5 → .0 .8 .6 .4 .2 (sequential: both meshes alike)
    fractions = [0.0, 0.8, 0.6, 0.4, 0.2]
    assert phi_sp == pytest.approx([-2 * math.pi * f for f in fractions], abs=1e-12)
    assert phi_rp == pytest.approx([-2 * math.pi * f for f in fractions], abs=1e-12)
    expected_sp, expected_rp = _parker(34, 96, 5, 0.0)
    assert phi_sp == pytest.approx(expected_sp, abs=1e-12)
    assert phi_rp == pytest.approx(expected_rp, abs=1e-12)


def test_clearances_in_metres(gs: GearSet) -> None:
    metres = evolve(
        gs,
        {
            "backlash.units": "m",
            "backlash.sun_planet": 3e-5,
            "backlash.planet_ring": 3.5e-5,
            "clearance.units": "m",
            "clearance.sun_bearing": 2e-5,
        },
    )
    assert metres.backlash_bar() == pytest.approx((3.0, 3.5), rel=REL)
    assert metres.sun_bearing_clearance_bar() == pytest.approx(2.0, rel=REL)
