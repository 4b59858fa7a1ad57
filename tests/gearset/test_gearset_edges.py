"""The edges of a valid gear set (docs/gearset-rules.md): plausible ranges, the one-module bound
on clearances, errors and eccentricities, the derived-quantity guard, ``evolve``'s argument,
and the claim behind the ranges — at every corner of them, each quantity the model derives
(MODEL.md §1, §4, §7) is finite, and positive where the model divides by it."""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from gearchaos.errors import ParameterError
from gearchaos.gearset import GearSet, preset
from gearchaos.gearset.io import evolve, get_value
from gearchaos.gearset.schema import FIELDS, MAX_HARMONICS, MODULE_BOUNDED
from gearchaos.model.planetary import nondimensionalise, pack_planetary


@pytest.fixture(scope="module")
def base() -> GearSet:
    return preset("hindawi2021")  # module 4 mm, b_c = 10 µm


def raises_exactly(message: str) -> pytest.RaisesExc[ParameterError]:
    return pytest.raises(ParameterError, match=re.escape(message))


# ----------------------------------------------------------------------------- the cases
def test_one_planet_is_a_valid_gear_set(base: GearSet) -> None:
    gs = evolve(base, {"geometry.planets": 1})
    assert gs.planet_angles == (0.0,)
    assert gs.phasing_class == "in_phase"  # k = z_r mod 1 = 0
    par, _ = nondimensionalise(gs)
    assert par.n_planets == 1 and math.isfinite(par.mu_c_star)


@pytest.mark.parametrize(
    ("value", "shown"), [(1e-300, "1e-300"), (1e308, "1e+308"), (2.0, "2.0"), (5e-7, "5e-07")]
)
def test_module_outside_the_plausible_range(base: GearSet, value: float, shown: str) -> None:
    # 1e308 m used to end in a ZeroDivisionError (r_bs overflows, m_s* = J_s/r_bs² = 0)
    message = f"geometry.module must lie in the plausible range [1e-06, 1] m: got {shown}"
    with raises_exactly(message):
        evolve(base, {"geometry.module": value})


@pytest.mark.parametrize("value", [1e-6, 1.0])
def test_module_range_ends_are_valid(base: GearSet, value: float) -> None:
    # clearances are in units of b_c = 10 µm: b̄ = 3 is 30 µm, above a 1 µm module; A = 5 µm too
    changes = {
        "geometry.module": value,
        "clearance.characteristic_length": 1e-8,
        "transmission_error.sun_planet": 1e-7,
        "transmission_error.planet_ring": 1e-7,
    }
    assert evolve(base, changes).geometry.module == value


def test_backlash_in_metres_is_bounded_by_the_module(base: GearSet) -> None:
    # the case: switching backlash.units to "m" leaves b = 3 "m" on a 4 mm module
    with pytest.raises(ParameterError) as info:
        evolve(base, {"backlash.units": "m"})
    assert str(info.value) == (
        "backlash.sun_planet must be <= geometry.module = 0.004 m (one module, the addendum of "
        "a standard tooth: a larger clearance, transmission error or eccentricity would "
        "disengage the teeth): got 3.0 m"
    )
    ok = {"backlash.units": "m", "backlash.sun_planet": 4e-3, "backlash.planet_ring": 1e-4}
    assert evolve(base, ok).backlash_bar() == pytest.approx((400.0, 10.0), rel=1e-12)


@pytest.mark.parametrize("name", sorted(MODULE_BOUNDED))
def test_every_module_bounded_length(base: GearSet, name: str) -> None:
    dimensionless = MODULE_BOUNDED[name] is not None  # the preset's clearances are in b_c
    inside, outside = (399.0, 401.0) if dimensionless else (3.99e-3, 4.01e-3)
    assert get_value(evolve(base, {name: inside}), name) == inside
    with pytest.raises(ParameterError, match=rf"^{re.escape(name)} must be <= geometry\.module"):
        evolve(base, {name: outside})
    if dimensionless:
        with pytest.raises(ParameterError, match=r"got 401\.0 × b_c = 401\.0 × 1e-05 m = "):
            evolve(base, {name: outside})


def test_module_bound_follows_a_module_change(base: GearSet) -> None:
    # b̄_sp = 3 (30 µm) is fine on 4 mm but not on a 20 µm module
    with pytest.raises(ParameterError, match=r"^backlash\.sun_planet must be <= geometry\.module"):
        evolve(base, {"geometry.module": 2e-5})


@pytest.mark.parametrize(
    ("name", "inside", "outside", "range_text"),
    [
        ("teeth.sun", 10_000, 10_001, "[1, 10000]"),
        ("geometry.planets", 100, 101, "[1, 100]"),
        ("mass.planet", 1e6, 1.5e6, "[1e-12, 1e+06] kg"),
        ("inertia.carrier", 1e-24, 1e-25, "[1e-24, 1e+06] kg m^2"),
        ("stiffness.sun_bearing", 1e-3, 1e-4, "[0.001, 1e+13] N/m"),
        ("damping.sun_bearing", 10.0, 10.5, "[0, 10]"),
        ("torque.input", -1e9, -1.1e9, "[-1e+09, 1e+09] N m"),
        ("torque.reference_omega", 1e6, 2e6, "[1e-06, 1e+06]"),
        ("clearance.characteristic_length", 1e-9, 2.0, "[1e-09, 1] m"),
        ("eccentricity.ring_phase", 1e6, -1.5e6, "[-1e+06, 1e+06] degrees"),
        ("mesh_phasing.ring_sun", -1e6, 1e7, "[-1e+06, 1e+06] mesh cycles"),
    ],
)
def test_plausible_ranges(
    base: GearSet, name: str, inside: float, outside: float, range_text: str
) -> None:
    changes: dict[str, object] = {name: inside}
    if name == "teeth.sun":  # keep z_r = z_s + 2 z_p and (z_s + z_r)/N whole
        changes = {"teeth.sun": 9_936, "teeth.ring": 10_000, "teeth.planet": 32}
        changes["geometry.planets"] = 4  # (9936 + 10000)/4 = 4984
        inside = 9_936
    if name == "geometry.planets":
        # (980 + 1020)/100 = 20, and 100 planets of 20 teeth clear each other around a sun
        # of 980: (980 + 20)·sin(π/100) = 31.4 > 22 modules
        changes = {
            "geometry.planets": 100,
            "teeth.sun": 980,
            "teeth.planet": 20,
            "teeth.ring": 1020,
        }
    assert get_value(evolve(base, changes), name) == inside
    with raises_exactly(f"{name} must lie in the plausible range {range_text}: got {outside!r}"):
        evolve(base, {name: outside})


def test_huge_integer_is_shown_short(base: GearSet) -> None:
    with pytest.raises(ParameterError) as info:
        evolve(base, {"teeth.sun": 10**5000})
    msg = str(info.value)
    assert msg == (
        "teeth.sun must lie in the plausible range [1, 10000]: "
        "got <an integer of about 5001 digits>"
    )


def test_harmonics_count_and_size(base: GearSet) -> None:
    ok = evolve(base, {"stiffness.sun_planet_harmonics": [1e5] * MAX_HARMONICS})
    assert len(ok.stiffness.sun_planet_harmonics) == 64
    with raises_exactly("stiffness.sun_planet_harmonics must list at most 64 harmonics: got 65"):
        evolve(base, {"stiffness.sun_planet_harmonics": [1e5] * 65})
    with raises_exactly(
        "stiffness.planet_ring_harmonics[1] must lie in the plausible range [-1e+13, 1e+13] N/m: "
        "got -20000000000000.0"
    ):
        evolve(base, {"stiffness.planet_ring_harmonics": [1.0, -2e13]})


def test_alternating_stiffness_beyond_range_is_caught_first(base: GearSet) -> None:
    with raises_exactly(
        "stiffness.sun_planet_alternating must lie in the plausible range [0, 1e+13] N/m: "
        "got 1e+300"
    ):
        evolve(base, {"stiffness.sun_planet_alternating": 1e300})


# ----------------------------------------------------------------------------- evolve's argument
@pytest.mark.parametrize(
    ("changes", "shown"),
    [
        (None, "None (NoneType)"),
        ([("xi", 0.1)], "[('xi', 0.1)] (list)"),
        ("xi=0.1", "'xi=0.1' (str)"),
        (0.1, "0.1 (float)"),
    ],
)
def test_evolve_refuses_anything_but_a_mapping(base: GearSet, changes: object, shown: str) -> None:
    message = (
        "changes must be a mapping of parameter names to values, "
        f"e.g. {{'backlash.sun_planet': 4.0}}: got {shown}"
    )
    with raises_exactly(message):
        base.evolve(changes)  # type: ignore[arg-type]
    with raises_exactly(message):
        evolve(base, changes)  # type: ignore[arg-type]


def test_evolve_without_changes_is_an_equal_copy(base: GearSet) -> None:
    assert base.evolve() == base
    assert base.evolve({}) == base
    assert evolve(base, {}) == base


def test_get_value_refuses_a_non_string_name(base: GearSet) -> None:
    with raises_exactly("parameter names must be strings: got 3"):
        get_value(base, 3)  # type: ignore[arg-type]


# ----------------------------------------------------------------------------- derived guard
class _BrokenOmega(GearSet):
    """A gear set whose ω_n cannot be represented (as a relaxed range could make it)."""

    @property
    def omega_n(self) -> float:
        return math.inf


def test_derived_quantity_guard_names_the_quantity(base: GearSet) -> None:
    records = {f.name: getattr(base, f.name) for f in dataclasses.fields(base)}
    with raises_exactly("derived quantity ω_n = √(k_m,sp / m_e) must be finite and > 0: got inf"):
        _BrokenOmega(**records)


# ----------------------------------------------------------------------------- corners
def _limits(name: str) -> tuple[float, float]:
    rule = FIELDS[name].limits
    assert rule is not None and rule.lo is not None and rule.hi is not None
    return rule.lo, rule.hi


#: (z_s, z_p, N): the extreme tooth numbers and planet counts that the relations allow.
#: (z_s, z_p, N) at the ends of the ranges whose planets still clear each other:
#: (z_s + z_p)·sin(π/N) > z_p + 2 — e.g. 100 planets of 50 teeth around a sun of 9900
TEETH_CORNERS = [(1, 1, 1), (3, 1, 2), (9_900, 50, 100), (9_998, 1, 2), (34, 31, 5), (2, 4_999, 1)]


@st.composite
def corner_sets(draw: st.DrawFn) -> GearSet:
    """Gear sets with every number at an end of its plausible range (or of its relation)."""
    zs, zp, n = draw(st.sampled_from(TEETH_CORNERS))
    module = draw(st.sampled_from(_limits("geometry.module")))
    bc = draw(st.sampled_from(_limits("clearance.characteristic_length")))
    units = {t: draw(st.sampled_from(["dimensionless", "m"])) for t in ("backlash", "clearance")}
    ch: dict[str, object] = {
        "teeth.sun": zs,
        "teeth.planet": zp,
        "teeth.ring": zs + 2 * zp,
        "geometry.planets": n,
        "geometry.module": module,
        "clearance.characteristic_length": bc,
        "backlash.units": units["backlash"],
        "clearance.units": units["clearance"],
        "torque.mode": draw(st.sampled_from(["constant_torque", "constant_power"])),
        "mesh_phasing.model": draw(st.sampled_from(["parker", "in_phase"])),
    }
    for name in ("geometry.pressure_angle_sun", "geometry.pressure_angle_ring"):
        ch[name] = draw(st.sampled_from([1e-9, 45.0 - 1e-9]))
    ranged = [n for n, f in FIELDS.items() if f.limits is not None and f.kind == "float"]
    for name in ranged:
        if name not in ch and "alternating" not in name:
            ends = [*_limits(name), 0.0] if name == "torque.input" else list(_limits(name))
            ch[name] = draw(st.sampled_from(ends))
    for mesh in ("sun_planet", "planet_ring"):
        km = ch[f"stiffness.{mesh}_mean"]
        assert isinstance(km, float)
        count = draw(st.sampled_from([0, MAX_HARMONICS]))
        share = draw(st.sampled_from([0.0, 0.999]))  # of k_m taken by k_a, the rest by harmonics
        ch[f"stiffness.{mesh}_alternating"] = share * km
        sign = draw(st.sampled_from([1.0, -1.0]))
        ch[f"stiffness.{mesh}_harmonics"] = [sign * (0.999 - share) * km / 64] * count
    for name, units_field in MODULE_BOUNDED.items():
        scale = bc if units_field is not None and ch[units_field] == "dimensionless" else 1.0
        ch[name] = draw(st.sampled_from([0.0, 0.999 * module / scale]))
    return preset("hindawi2021").evolve(ch)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(corner_sets(), st.sampled_from([1e-3, 1.0, 10.0]))
def test_every_derived_quantity_is_finite_at_the_corners(gs: GearSet, omega: float) -> None:
    quantities = {
        "r_bs": gs.base_radius_sun,
        "r_bp": gs.base_radius_planet,
        "r_c": gs.radius_carrier,
        "m_s*": gs.equivalent_mass_sun,
        "m_p*": gs.equivalent_mass_planet,
        "m_c*": gs.equivalent_mass_carrier,
        "m_e": gs.equivalent_mass_mesh,
        "omega_n": gs.omega_n,
    }
    for name, x in quantities.items():
        assert math.isfinite(x) and x > 0.0, name
    for x in (gs.damping_sun_planet, gs.damping_planet_ring, gs.damping_sun_bearing):
        assert math.isfinite(x) and x >= 0.0
    par, scales = nondimensionalise(gs)
    for f in dataclasses.fields(par):
        value = getattr(par, f.name)
        for x in value if isinstance(value, tuple) else (value,):
            if isinstance(x, float):
                assert math.isfinite(x), f.name
    for name in ("mu_s", "mu_s_star", "mu_p_star", "mu_c_star", "kappa_b", "kappa_rp_mean"):
        assert getattr(par, name) > 0.0, name
    assert all(math.isfinite(x) and x > 0 for x in dataclasses.astuple(scales))
    assert np.isfinite(pack_planetary(par, omega)).all()


def test_planets_that_overlap_are_refused_with_the_numbers() -> None:
    # issue 23: `simulate --set geometry.planets=13` ran; so did teeth 10/40/90 with 10 planets
    # (centres 15.5 modules apart against tip diameters of 42 modules)
    sheng = preset("sheng2016-v1")  # 33/32/97: (33 + 32)·sin(π/13) = 15.6 < 34 modules
    with pytest.raises(ParameterError, match=r"geometry.planets = 13: the planets do not fit"):
        sheng.evolve({"geometry.planets": 13})
    with pytest.raises(ParameterError, match=r"= 15\.45 modules .* = 42 modules"):
        sheng.evolve(
            {"teeth.sun": 10, "teeth.planet": 40, "teeth.ring": 90, "geometry.planets": 10}
        )
    # the largest count that fits is accepted: (33 + 32)·sin(π/5) = 38.2 > 34
    assert sheng.evolve({"geometry.planets": 5}).geometry.planets == 5
