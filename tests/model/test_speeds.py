"""The operating point as a speed: ``sun_rpm`` and ``mesh_hz`` set Ω through the gear set.

Every expected Ω is computed here from the gear set's own numbers (MODEL.md §1, §2, §7):
m_s* = J_s/r_bs², m_p* = J_p/r_bp² (r_b = m z cos α_s / 2), m_e = m_s* m_p*/(m_s* + m_p*),
ω_n = √(k_m,sp/m_e), the mesh frequency ω = ω_s z_s z_r/(z_s + z_r) with ω_s = 2π n_s/60, and
Ω = ω/ω_n; f_m = Ω ω_n/2π.
"""

from __future__ import annotations

import math
import warnings

import pytest

import gearchaos as gc
from gearchaos.gearset import GearSet
from gearchaos.model.target import operating_omega, resolve, speeds_at


def _omega_n(gs: GearSet) -> float:
    """ω_n = √(k_m,sp/m_e) from the records' numbers (MODEL.md §1, §7)."""
    m, a = gs.geometry.module, math.radians(gs.geometry.pressure_angle_sun)
    r_bs = m * gs.teeth.sun / 2 * math.cos(a)
    r_bp = m * gs.teeth.planet / 2 * math.cos(a)
    ms, mp = gs.inertia.sun / r_bs**2, gs.inertia.planet / r_bp**2
    return math.sqrt(gs.stiffness.sun_planet_mean / (ms * mp / (ms + mp)))


def _omega_at_rpm(gs: GearSet, rpm: float) -> float:
    """Ω of a sun speed in rpm (MODEL.md §2: ω = ω_s z_s z_r/(z_s + z_r))."""
    zs, zr = gs.teeth.sun, gs.teeth.ring
    return rpm * 2 * math.pi / 60 * zs * zr / (zs + zr) / _omega_n(gs)


@pytest.fixture(params=["sheng2016", "hindawi2021"])
def gearset(request: pytest.FixtureRequest) -> GearSet:
    # another stiffness and module than the presets', so no preset number is built in
    return gc.preset(request.param).evolve(
        {"stiffness.sun_planet_mean": 5.1e8, "geometry.module": 0.0037}
    )


def test_sun_rpm_and_mesh_hz_set_omega_through_the_gear_set(gearset: GearSet) -> None:
    for rpm in (1000.0, 7500.0, 20000.0):
        assert resolve(gearset, {"sun_rpm": rpm}).omega == pytest.approx(
            _omega_at_rpm(gearset, rpm), rel=1e-12
        )
    f = 2500.0
    assert resolve(gearset, {"mesh_hz": f}).omega == pytest.approx(
        2 * math.pi * f / _omega_n(gearset), rel=1e-12
    )
    # and back: the speeds at a given Ω
    sp = speeds_at(gc.planetary_system(gearset, 1.3).model, 1.3)
    assert sp["sun_rpm"] == pytest.approx(7500.0 * 1.3 / _omega_at_rpm(gearset, 7500.0), 1e-12)
    assert sp["mesh_hz"] == pytest.approx(1.3 * _omega_n(gearset) / (2 * math.pi), rel=1e-12)


def test_a_speed_converts_through_the_gear_set_with_the_other_values_applied() -> None:
    gs = gc.preset("sheng2016-v1")
    changed = gs.evolve({"stiffness.sun_planet_mean": 3.3e8, "teeth.sun": 28, "teeth.ring": 92})
    omega, rest = operating_omega(
        gs, {"sun_rpm": 6000.0, "stiffness.sun_planet_mean": 3.3e8, "teeth.sun": 28,
             "teeth.ring": 92}
    )  # fmt: skip
    assert omega == pytest.approx(_omega_at_rpm(changed, 6000.0), rel=1e-12)
    assert "sun_rpm" not in rest and rest["stiffness.sun_planet_mean"] == 3.3e8
    # a planetary system built by hand converts through the gear set it was built from
    system = gc.planetary_system(changed, 1.0)
    assert resolve(system, {"sun_rpm": 6000.0}).omega == pytest.approx(omega, rel=1e-12)


def test_the_front_doors_take_a_speed() -> None:
    gs = gc.preset("sheng2016-v1")
    res = gc.simulate(gs, sun_rpm=7500.0, transient_periods=2, periods=2)
    assert res.system.omega == pytest.approx(_omega_at_rpm(gs, 7500.0), rel=1e-12)
    res = gc.simulate(gs, params={"mesh_hz": 3000.0}, transient_periods=2, periods=2)
    assert res.system.omega == pytest.approx(2 * math.pi * 3000.0 / _omega_n(gs), rel=1e-12)


@pytest.mark.parametrize("value", [7000.0, 60.0, 1e6])
def test_an_implausible_omega_is_refused_with_a_hint_at_sun_rpm(value: float) -> None:
    with pytest.raises(gc.ParameterError, match="plausible range") as err:
        resolve(gc.preset("sheng2016-v1"), {"omega": value})
    assert f"got {value:g}" in str(err.value) and f"sun_rpm={value:g}" in str(err.value)


@pytest.mark.parametrize("value", [0.0, -1.5])
def test_omega_at_or_below_zero_is_refused(value: float) -> None:
    with pytest.raises(gc.ParameterError, match="omega"):
        resolve(gc.preset("sheng2016-v1"), {"omega": value})


def test_speed_refusals_name_the_speed_and_the_value() -> None:
    gs = gc.preset("sheng2016-v1")
    with pytest.raises(gc.ParameterError, match="omega and sun_rpm each set Ω"):
        resolve(gs, {"omega": 1.5, "sun_rpm": 7500.0})
    with pytest.raises(gc.ParameterError, match="sun_rpm"):
        resolve(gs, {"sun_rpm": -100.0})
    # 10⁹ rpm is Ω ≈ 2·10⁵ for sheng2016: beyond Ω's plausible range, said in both units
    with pytest.raises(gc.ParameterError, match=r"sun_rpm = 1e\+09 rpm is Ω = .* plausible"):
        resolve(gs, {"sun_rpm": 1e9})


def test_a_model_without_physical_scales_refuses_a_speed() -> None:
    system = gc.backlash_oscillator(1.0)
    for name in ("sun_rpm", "mesh_hz"):
        with pytest.raises(gc.ParameterError, match=rf"{name} sets Ω through a gear set.*omega"):
            resolve(system, {name: 1000.0})
        with pytest.raises(gc.ParameterError, match="not built from a gear set"):
            gc.simulate(system, transient_periods=1, periods=1, **{name: 1000.0})


# ----------------------------------------------------------------------------- clearances
def test_a_clearance_in_metres_given_in_units_of_b_c_is_warned_about() -> None:
    gs = gc.preset("sheng2016-v1")
    b_c = gs.clearance.characteristic_length
    with pytest.warns(UserWarning, match="value in metres given for a parameter in units of b_c"):
        odd = gs.evolve({"backlash.sun_planet": 60e-6})
    assert odd.backlash.sun_planet == 60e-6  # a warning, not a refusal
    with pytest.warns(UserWarning, match=rf"backlash.sun_planet = {60e-6 / b_c:.4g}"):
        gs.evolve({"backlash.sun_planet": 60e-6, "name": "again"})  # it names the b̄ meant
    with pytest.warns(UserWarning, match="clearance.sun_bearing = 2e-05"):
        gs.evolve({"clearance.sun_bearing": 2e-5})


@pytest.mark.parametrize(
    "changes",
    [
        {"backlash.sun_planet": 3.0},
        {"backlash.sun_planet": 0.0},  # no backlash at all is a model, not a mistake
        {"backlash.sun_planet": 2e-3},
        {"backlash.units": "m", "backlash.sun_planet": 60e-6, "backlash.planet_ring": 70e-6},
    ],
)
def test_plausible_clearances_are_not_warned_about(changes: dict[str, object]) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        gc.preset("sheng2016-v1").evolve(changes)
