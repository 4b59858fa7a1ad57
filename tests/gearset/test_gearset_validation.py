"""Every validation rule of a gear set, and the eccentricity warning.

Each case checks that the message names the dotted parameter, the rule and the value.
"""

from __future__ import annotations

import dataclasses
import math
import re
import warnings

import pytest

from gearchaos.errors import ParameterError
from gearchaos.gearset import GearSet, Inertia, Mass, Teeth, preset
from gearchaos.gearset.io import evolve
from gearchaos.gearset.validation import validate, warn_if_eccentric

FLOAT_FIELDS = [
    "geometry.module",
    "geometry.pressure_angle_sun",
    "geometry.pressure_angle_ring",
    "mass.sun",
    "mass.planet",
    "inertia.sun",
    "inertia.planet",
    "inertia.carrier",
    "stiffness.sun_planet_mean",
    "stiffness.sun_planet_alternating",
    "stiffness.planet_ring_mean",
    "stiffness.planet_ring_alternating",
    "stiffness.sun_bearing",
    "damping.sun_planet",
    "damping.planet_ring",
    "damping.sun_bearing",
    "torque.input",
    "torque.reference_omega",
    "transmission_error.sun_planet",
    "transmission_error.planet_ring",
    "transmission_error.sun_planet_phase",
    "transmission_error.planet_ring_phase",
    "eccentricity.sun",
    "eccentricity.planet",
    "eccentricity.ring",
    "eccentricity.sun_phase",
    "eccentricity.planet_phase",
    "eccentricity.ring_phase",
    "backlash.sun_planet",
    "backlash.planet_ring",
    "clearance.sun_bearing",
    "clearance.characteristic_length",
    "mesh_phasing.ring_sun",
]

POSITIVE = [
    "geometry.module",
    "mass.sun",
    "mass.planet",
    "inertia.sun",
    "inertia.planet",
    "inertia.carrier",
    "stiffness.sun_planet_mean",
    "stiffness.planet_ring_mean",
    "stiffness.sun_bearing",
    "clearance.characteristic_length",
    "torque.reference_omega",
]

NON_NEGATIVE = [
    "stiffness.sun_planet_alternating",
    "stiffness.planet_ring_alternating",
    "damping.sun_planet",
    "damping.planet_ring",
    "damping.sun_bearing",
    "transmission_error.sun_planet",
    "transmission_error.planet_ring",
    "eccentricity.sun",
    "eccentricity.planet",
    "eccentricity.ring",
    "backlash.sun_planet",
    "backlash.planet_ring",
    "clearance.sun_bearing",
]

ANY_SIGN = [
    "torque.input",
    "transmission_error.sun_planet_phase",
    "transmission_error.planet_ring_phase",
    "eccentricity.sun_phase",
    "eccentricity.planet_phase",
    "eccentricity.ring_phase",
    "mesh_phasing.ring_sun",
]


@pytest.fixture(scope="module")
def base() -> GearSet:
    return preset("hindawi2021")


def raises_exactly(message: str) -> pytest.RaisesExc[ParameterError]:
    """pytest.raises(ParameterError) whose message must contain ``message`` literally."""
    return pytest.raises(ParameterError, match=re.escape(message))


# ----------------------------------------------------------------------------- teeth
def test_ring_teeth_must_match_sun_plus_two_planets(base: GearSet) -> None:
    with raises_exactly(
        "teeth.ring must equal teeth.sun + 2*teeth.planet (34 + 2*31 = 96): got 95"
    ):
        evolve(base, {"teeth.ring": 95})


@pytest.mark.parametrize("member", ["sun", "planet", "ring"])
@pytest.mark.parametrize("value", [0, -31])
def test_teeth_must_be_positive(base: GearSet, member: str, value: int) -> None:
    with raises_exactly(f"teeth.{member} must be > 0: got {value}"):
        evolve(base, {f"teeth.{member}": value})


@pytest.mark.parametrize(
    ("value", "shown"), [(34.0, "34.0 (float)"), (True, "True (bool)"), ("34", "'34' (str)")]
)
def test_teeth_must_be_integers(base: GearSet, value: object, shown: str) -> None:
    with raises_exactly(f"teeth.sun must be an integer: got {shown}"):
        evolve(base, {"teeth.sun": value})


def test_planets_must_be_equally_spaceable(base: GearSet) -> None:
    # (34 + 96) / 4 = 32.5 is not an integer.
    with pytest.raises(ParameterError, match="planets cannot be equally spaced") as info:
        evolve(base, {"geometry.planets": 4})
    assert "geometry.planets" in str(info.value)
    assert "(34 + 96)/4 = 32.5" in str(info.value)


def test_equal_spacing_also_checked_when_teeth_change(base: GearSet) -> None:
    # 35 + 2*31 = 97, (35 + 97)/5 = 26.4.
    with pytest.raises(ParameterError, match=r"\(35 \+ 97\)/5 = 26\.4"):
        evolve(base, {"teeth.sun": 35, "teeth.ring": 97})
    # (36 + 98)/5 is not an integer either, but (36 + 98)/2 = 67 is.
    ok = evolve(base, {"teeth.sun": 36, "teeth.ring": 98, "geometry.planets": 2})
    assert (ok.teeth.sun, ok.teeth.ring, ok.geometry.planets) == (36, 98, 2)


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (0, "geometry.planets must be >= 1: got 0"),
        (-5, "geometry.planets must be >= 1: got -5"),
        (5.0, "geometry.planets must be an integer: got 5.0 (float)"),
        (True, "geometry.planets must be an integer: got True (bool)"),
    ],
)
def test_planet_count(base: GearSet, value: object, message: str) -> None:
    with raises_exactly(message):
        evolve(base, {"geometry.planets": value})


def test_single_planet_is_allowed(base: GearSet) -> None:
    assert evolve(base, {"geometry.planets": 1}).n_planets == 1


# ----------------------------------------------------------------------------- signs
@pytest.mark.parametrize("name", POSITIVE)
@pytest.mark.parametrize("value", [0.0, -1.5])
def test_positive_fields(base: GearSet, name: str, value: float) -> None:
    with raises_exactly(f"{name} must be > 0: got {value!r}"):
        evolve(base, {name: value})


@pytest.mark.parametrize("name", NON_NEGATIVE)
def test_non_negative_fields_reject_negative(base: GearSet, name: str) -> None:
    with raises_exactly(f"{name} must be >= 0: got -3.0"):
        evolve(base, {name: -3.0})


@pytest.mark.parametrize("name", NON_NEGATIVE)
def test_non_negative_fields_accept_zero(base: GearSet, name: str) -> None:
    gs = evolve(base, {name: 0.0})
    table, attr = name.split(".")
    assert getattr(getattr(gs, table), attr) == 0.0


@pytest.mark.parametrize("name", ANY_SIGN)
@pytest.mark.parametrize("value", [-500.0, 0.0, 1e6])
def test_any_finite_value_allowed(base: GearSet, name: str, value: float) -> None:
    gs = evolve(base, {name: value})
    table, attr = name.split(".")
    assert getattr(getattr(gs, table), attr) == value


def test_backlash_message_from_style_guide(base: GearSet) -> None:
    with raises_exactly("backlash.sun_planet must be >= 0: got -3.0"):
        evolve(base, {"backlash.sun_planet": -3.0})


@pytest.mark.parametrize("name", ["geometry.pressure_angle_sun", "geometry.pressure_angle_ring"])
@pytest.mark.parametrize("value", [0.0, 45.0, -5.0, 60.0])
def test_pressure_angle_open_interval(base: GearSet, name: str, value: float) -> None:
    with raises_exactly(f"{name} must lie in the open interval (0, 45) degrees: got {value!r}"):
        evolve(base, {name: value})


@pytest.mark.parametrize("value", [1e-3, 14.5, 44.999])
def test_pressure_angle_inside_interval(base: GearSet, value: float) -> None:
    gs = evolve(base, {"geometry.pressure_angle_ring": value})
    assert gs.alpha_r == pytest.approx(value * math.pi / 180.0, rel=1e-15)


# ----------------------------------------------------------------------------- stiffness
@pytest.mark.parametrize("mesh", ["sun_planet", "planet_ring"])
def test_alternating_stiffness_equal_to_mean_is_an_error(base: GearSet, mesh: str) -> None:
    km = {"sun_planet": 0.62e9, "planet_ring": 0.85e9}[mesh]
    with pytest.raises(ParameterError, match="stiffness would turn negative") as info:
        evolve(base, {f"stiffness.{mesh}_alternating": km})
    msg = str(info.value)
    assert msg.startswith(f"stiffness.{mesh}_alternating must be < stiffness.{mesh}_mean")
    assert msg.endswith(f"got {km!r}")


def test_alternating_stiffness_just_below_mean_is_allowed(base: GearSet) -> None:
    gs = evolve(base, {"stiffness.sun_planet_alternating": 0.6199e9})
    assert gs.stiffness.sun_planet_alternating == 0.6199e9


def test_harmonics_count_in_the_stiffness_bound(base: GearSet) -> None:
    # 0.14e9 + |0.3e9| + |-0.2e9| = 0.64e9 >= 0.62e9
    with pytest.raises(ParameterError, match="stiffness would turn negative") as info:
        evolve(base, {"stiffness.sun_planet_harmonics": (0.3e9, -0.2e9)})
    msg = str(info.value)
    assert "stiffness.sun_planet_harmonics" in msg
    assert "got 140000000.0 + 500000000.0 = 640000000.0" in msg


def test_harmonics_of_either_sign_allowed(base: GearSet) -> None:
    gs = evolve(base, {"stiffness.planet_ring_harmonics": [-0.1e9, 0.05e9]})
    assert gs.stiffness.planet_ring_harmonics == (-0.1e9, 0.05e9)


def test_negative_alternating_stiffness(base: GearSet) -> None:
    with raises_exactly("stiffness.planet_ring_alternating must be >= 0: got -1.0"):
        evolve(base, {"stiffness.planet_ring_alternating": -1.0})


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (5.0, "stiffness.sun_planet_harmonics must be a tuple of numbers: got 5.0 (float)"),
        (("a",), "stiffness.sun_planet_harmonics[0] must be a number: got 'a' (str)"),
        ((1.0, math.nan), "stiffness.sun_planet_harmonics[1] must be finite: got nan"),
        ((math.inf,), "stiffness.sun_planet_harmonics[0] must be finite: got inf"),
    ],
)
def test_harmonics_types(base: GearSet, value: object, message: str) -> None:
    with raises_exactly(message):
        evolve(base, {"stiffness.sun_planet_harmonics": value})


def test_harmonics_list_in_direct_construction_is_rejected(base: GearSet) -> None:
    stiffness = dataclasses.replace(base.stiffness, sun_planet_harmonics=[1.0])  # type: ignore[arg-type]
    with raises_exactly("stiffness.sun_planet_harmonics must be a tuple of numbers: got [1.0]"):
        dataclasses.replace(base, stiffness=stiffness)


# ----------------------------------------------------------------------------- finiteness, types
@pytest.mark.parametrize("name", FLOAT_FIELDS)
@pytest.mark.parametrize(
    ("value", "shown"), [(math.nan, "nan"), (math.inf, "inf"), (-math.inf, "-inf")]
)
def test_every_float_must_be_finite(base: GearSet, name: str, value: float, shown: str) -> None:
    with raises_exactly(f"{name} must be finite: got {shown}"):
        evolve(base, {name: value})


@pytest.mark.parametrize("name", FLOAT_FIELDS)
@pytest.mark.parametrize(
    ("value", "shown"), [("abc", "'abc' (str)"), (True, "True (bool)"), (None, "None (NoneType)")]
)
def test_every_float_must_be_a_number(base: GearSet, name: str, value: object, shown: str) -> None:
    with raises_exactly(f"{name} must be a number: got {shown}"):
        evolve(base, {name: value})


def test_python_ints_are_numbers_in_direct_construction(base: GearSet) -> None:
    gs = dataclasses.replace(base, mass=Mass(sun=10, planet=8))
    assert gs.mass.sun == 10


@pytest.mark.parametrize(
    ("name", "value", "allowed"),
    [
        ("torque.mode", "constant_speed", "'constant_torque', 'constant_power'"),
        ("backlash.units", "mm", "'dimensionless', 'm'"),
        ("clearance.units", "um", "'dimensionless', 'm'"),
        ("mesh_phasing.model", "random", "'parker', 'in_phase'"),
    ],
)
def test_choices(base: GearSet, name: str, value: str, allowed: str) -> None:
    with raises_exactly(f"{name} must be one of {allowed}: got {value!r}"):
        evolve(base, {name: value})


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("torque.mode", "constant_power"),
        ("backlash.units", "m"),
        ("clearance.units", "m"),
        ("mesh_phasing.model", "parker"),
    ],
)
def test_choices_accept_every_allowed_value(base: GearSet, name: str, value: str) -> None:
    table, attr = name.split(".")
    # clearances switched to metres are given in metres (3 m would exceed the 4 mm module)
    changes: dict[str, object] = {name: value}
    if table == "backlash" and value == "m":
        changes = {"backlash": {"units": "m", "sun_planet": 3e-5, "planet_ring": 3.5e-5}}
    if table == "clearance" and value == "m":
        changes = {"clearance": {"units": "m", "sun_bearing": 2e-5}}
    assert getattr(getattr(evolve(base, changes), table), attr) == value


@pytest.mark.parametrize("name", ["torque.mode", "backlash.units", "mesh_phasing.model"])
def test_string_fields_must_be_strings(base: GearSet, name: str) -> None:
    with raises_exactly(f"{name} must be a string: got 3 (int)"):
        evolve(base, {name: 3})


@pytest.mark.parametrize("name", ["name", "description"])
def test_name_and_description_must_be_strings(base: GearSet, name: str) -> None:
    with raises_exactly(f"{name} must be a string: got 3 (int)"):
        dataclasses.replace(base, **{name: 3})  # type: ignore[arg-type]


def test_lone_surrogate_in_name_is_rejected(base: GearSet) -> None:
    with pytest.raises(ParameterError, match="name must be valid Unicode text"):
        evolve(base, {"name": "bad\ud800"})


def test_nested_records_must_have_their_class(base: GearSet) -> None:
    with pytest.raises(ParameterError, match=r"mass must be a Mass record: got Inertia\(") as info:
        dataclasses.replace(base, mass=base.inertia)  # type: ignore[arg-type]
    assert str(info.value).endswith("(Inertia)")
    with raises_exactly("teeth must be a Teeth record: got 'abc' (str)"):
        dataclasses.replace(base, teeth="abc")  # type: ignore[arg-type]


def test_direct_construction_is_validated(base: GearSet) -> None:
    good = dict(
        teeth=Teeth(20, 19, 58),
        geometry=base.geometry,
        mass=base.mass,
        inertia=Inertia(sun=0.01, planet=0.01, carrier=0.1),
        stiffness=base.stiffness,
        damping=base.damping,
        torque=base.torque,
        backlash=base.backlash,
        clearance=base.clearance,
    )
    # 20 + 58 = 78 is not divisible by 5 planets.
    with pytest.raises(ParameterError, match="planets cannot be equally spaced"):
        GearSet(**good)  # type: ignore[arg-type]
    gs = GearSet(**{**good, "geometry": dataclasses.replace(base.geometry, planets=3)})  # type: ignore[arg-type]
    assert gs.n_planets == 3
    assert gs.name == "custom"


def test_validate_accepts_valid_sets(base: GearSet) -> None:
    validate(base)  # no exception
    validate(evolve(base, {"xi": 0.0, "torque.input": -1.0}))


def test_torque_input_may_be_negative(base: GearSet) -> None:
    assert evolve(base, {"torque.input": -1130}).torque.input == -1130.0


# ----------------------------------------------------------------------------- eccentricity
def test_eccentricity_is_not_an_error(base: GearSet) -> None:
    gs = evolve(base, {"eccentricity.planet": 2e-6})
    assert gs.has_eccentricity


@pytest.mark.parametrize("analysis", ["poincare", "Poincaré", "bifurcation", "poincare-map"])
def test_eccentricity_warns_for_poincare_analyses(base: GearSet, analysis: str) -> None:
    gs = evolve(base, {"eccentricity.sun": 1e-6})
    with pytest.warns(UserWarning, match="lcm") as record:
        assert warn_if_eccentric(gs, analysis) is True
    msg = str(record[0].message)
    # lcm(34, 31, 96) = 2^5 * 3 * 17 * 31 = 50592
    assert "50592" in msg
    assert "1T" in msg
    assert "eccentricity.sun = 1e-06" in msg


def test_no_warning_without_eccentricity(base: GearSet) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert warn_if_eccentric(base, "poincare") is False


def test_no_warning_for_analyses_without_a_section(base: GearSet) -> None:
    gs = evolve(base, {"eccentricity.ring": 1e-6})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert warn_if_eccentric(gs, "spectrum") is False
