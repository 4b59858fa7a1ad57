"""The explorer's point view names a point in the gear set's units: the sun speed beside Ω
(computed here from the gear set's numbers, MODEL.md §2, §7) and a clearance given in metres
in µm; a reference system's point has neither."""

from __future__ import annotations

import math
from pathlib import Path

import gearchaos as gc
from gearchaos.explore.model import ExploreModel
from gearchaos.sweep import open_sweep

TINY = {"transient_periods": 2, "periods": 2, "verdicts": False, "progress": False}


def _rpm(gs: gc.GearSet, omega: float) -> float:
    m, a = gs.geometry.module, math.radians(gs.geometry.pressure_angle_sun)
    r_bs, r_bp = m * gs.teeth.sun / 2 * math.cos(a), m * gs.teeth.planet / 2 * math.cos(a)
    ms, mp = gs.inertia.sun / r_bs**2, gs.inertia.planet / r_bp**2
    omega_n = math.sqrt(gs.stiffness.sun_planet_mean / (ms * mp / (ms + mp)))
    zs, zr = gs.teeth.sun, gs.teeth.ring
    return omega * omega_n * (zs + zr) / (zs * zr) * 60 / (2 * math.pi)


def test_the_point_title_has_the_sun_speed_and_clearances_in_um(gear_store: Path) -> None:
    gs = gc.preset("sheng2016-v1")
    model = ExploreModel(open_sweep(gear_store))
    point = model.point(3)
    omega = point.values["omega"]
    assert point.title() == f"Ω = {omega:.6g}, n_s = {_rpm(gs, omega):.5g} rpm"

    metric = gs.evolve({"backlash.units": "m", "backlash.sun_planet": 80e-6,
                        "backlash.planet_ring": 70e-6})  # fmt: skip
    ds = gc.bifurcation(metric, "backlash.sun_planet=60e-6,90e-6", omega=1.2, **TINY)
    point = ExploreModel(ds).point(1)
    assert point.title() == f"b_sp = 90 µm, n_s = {_rpm(metric, 1.2):.5g} rpm"


def test_a_reference_systems_point_has_no_speed(linear_map_store: Path) -> None:
    point = ExploreModel(open_sweep(linear_map_store)).point(0, 0)
    assert "rpm" not in point.title()
