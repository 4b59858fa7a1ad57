"""TOML round trip, the template, dotted names, ``evolve`` and strict reading."""

from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from gearchaos.errors import ParameterError
from gearchaos.gearset import UNITS, GearSet, preset
from gearchaos.gearset.io import (
    evolve,
    field_names,
    from_dict,
    from_toml,
    from_toml_string,
    get_value,
    template_toml,
    to_dict,
    to_toml,
)
from gearchaos.gearset.schema import FIELDS
from gearchaos.gearset.tomltext import float_text

TABLES = [
    "teeth",
    "geometry",
    "mass",
    "inertia",
    "stiffness",
    "damping",
    "torque",
    "backlash",
    "clearance",
    "transmission_error",
    "eccentricity",
    "mesh_phasing",
]

# Only the required keys; values written by hand (a small 3-planet set).
MINIMAL = """
name = "small"

[teeth]
sun = 20
planet = 19
ring = 58

[geometry]
planets = 3
module = 0.002

[mass]
sun = 1.5
planet = 0.8

[inertia]
sun = 1e-3
planet = 5e-4
carrier = 2e-2

[stiffness]
sun_planet_mean = 3e8
sun_planet_alternating = 5e7
planet_ring_mean = 4e8
planet_ring_alternating = 6e7
sun_bearing = 1e8

[damping]
sun_planet = 0.05
planet_ring = 0.04
sun_bearing = 0.02

[torque]
input = 50.0

[backlash]
sun_planet = 1.0
planet_ring = 1.5

[clearance]
sun_bearing = 0.5
characteristic_length = 1e-5
"""


@pytest.fixture(scope="module")
def base() -> GearSet:
    return preset("hindawi2021")  # the MODEL.md §9 set


def _without(text: str, line: str) -> str:
    assert line + "\n" in text
    return text.replace(line + "\n", "", 1)


# ----------------------------------------------------------------------------- strategies
def _floats(
    lo: float, hi: float, *, exclude_min: bool = False, exclude_max: bool = False
) -> st.SearchStrategy[float]:
    return st.floats(
        lo,
        hi,
        allow_nan=False,
        allow_infinity=False,
        exclude_min=exclude_min,
        exclude_max=exclude_max,
    )


def _plausible(name: str) -> st.SearchStrategy[float]:
    """Any float in the plausible range of a field (docs/gearset-rules.md), ends included."""
    limits = FIELDS[name].limits
    assert limits is not None and limits.lo is not None and limits.hi is not None
    return _floats(limits.lo, limits.hi)


@st.composite
def gear_sets(draw: st.DrawFn) -> GearSet:
    """Valid gear sets: hindawi2021 evolved with random valid values for every field, over the
    whole plausible range of each (clearances, errors and eccentricities up to one module)."""
    n = draw(st.integers(1, 12))
    zs = draw(st.integers(1, 400))
    zp = draw(st.integers(1, 400))
    # (z_s + z_r)/N = 2(z_s + z_p)/N must be an integer, and N ≥ 2 planets must clear
    # each other: (z_s + z_p)·sin(π/N) > z_p + 2
    while (2 * (zs + zp)) % n or (n > 1 and (zs + zp) * math.sin(math.pi / n) <= zp + 2):
        zs += 1
    module = draw(_plausible("geometry.module"))
    bc = draw(_plausible("clearance.characteristic_length"))
    changes: dict[str, object] = {
        "name": draw(st.text(max_size=20)),
        "description": draw(st.text(max_size=60)),
        "teeth.sun": zs,
        "teeth.planet": zp,
        "teeth.ring": zs + 2 * zp,
        "geometry.planets": n,
        "geometry.module": module,
        "geometry.pressure_angle_sun": draw(_floats(0.0, 45.0, exclude_min=True, exclude_max=True)),
        "geometry.pressure_angle_ring": draw(
            _floats(0.0, 45.0, exclude_min=True, exclude_max=True)
        ),
        "torque.mode": draw(st.sampled_from(["constant_torque", "constant_power"])),
        "backlash.units": draw(st.sampled_from(["dimensionless", "m"])),
        "clearance.units": draw(st.sampled_from(["dimensionless", "m"])),
        "clearance.characteristic_length": bc,
        "mesh_phasing.model": draw(st.sampled_from(["parker", "in_phase"])),
    }
    for name in [
        "mass.sun",
        "mass.planet",
        "inertia.sun",
        "inertia.planet",
        "inertia.carrier",
        "stiffness.sun_bearing",
        "damping.sun_planet",
        "damping.planet_ring",
        "damping.sun_bearing",
        "torque.input",
        "torque.reference_omega",
        "transmission_error.sun_planet_phase",
        "transmission_error.planet_ring_phase",
        "eccentricity.sun_phase",
        "eccentricity.planet_phase",
        "eccentricity.ring_phase",
        "mesh_phasing.ring_sun",
    ]:
        changes[name] = draw(_plausible(name))
    for mesh in ["sun_planet", "planet_ring"]:
        km = draw(_plausible(f"stiffness.{mesh}_mean"))
        changes[f"stiffness.{mesh}_mean"] = km
        changes[f"stiffness.{mesh}_alternating"] = km * draw(_floats(0.0, 0.5))
        fractions = draw(st.lists(_floats(-0.1, 0.1), max_size=4))
        changes[f"stiffness.{mesh}_harmonics"] = [km * f for f in fractions]
    # lengths bounded by one module, in metres or in units of b_c
    for name, units in [
        ("backlash.sun_planet", "backlash.units"),
        ("backlash.planet_ring", "backlash.units"),
        ("clearance.sun_bearing", "clearance.units"),
        ("transmission_error.sun_planet", None),
        ("transmission_error.planet_ring", None),
        ("eccentricity.sun", None),
        ("eccentricity.planet", None),
        ("eccentricity.ring", None),
    ]:
        scale = bc if units is not None and changes[units] == "dimensionless" else 1.0
        changes[name] = draw(_floats(0.0, 0.999 * module / scale))
    return evolve(preset("hindawi2021"), changes)


# ----------------------------------------------------------------------------- round trip
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(gear_sets())
def test_toml_round_trip_is_exact(gs: GearSet) -> None:
    text = to_toml(gs)
    back = from_toml_string(text)
    assert back == gs
    # == treats 0.0 and -0.0 alike; the text of the copy pins every bit as well
    assert to_toml(back) == text
    for name in field_names():
        a, b = get_value(gs, name), get_value(back, name)
        assert type(a) is type(b)
        if isinstance(a, float):
            assert math.copysign(1.0, a) == math.copysign(1.0, b)  # type: ignore[arg-type]


@settings(max_examples=100, deadline=None)
@given(gear_sets())
def test_dict_round_trip(gs: GearSet) -> None:
    assert from_dict(to_dict(gs)) == gs


def test_preset_round_trip(base: GearSet) -> None:
    assert from_toml_string(to_toml(base)) == base
    assert base.to_toml() == to_toml(base)
    assert GearSet.from_toml_string(base.to_toml()) == base


def test_to_toml_types_and_layout(base: GearSet) -> None:
    data = tomllib.loads(to_toml(evolve(base, {"stiffness.sun_planet_harmonics": [1e7, -2e7]})))
    assert list(data) == ["name", "description", *TABLES]
    assert type(data["teeth"]["sun"]) is int
    assert type(data["geometry"]["planets"]) is int
    assert type(data["geometry"]["module"]) is float
    assert type(data["torque"]["input"]) is float  # 1130.0, not 1130
    assert data["stiffness"]["sun_planet_harmonics"] == [1e7, -2e7]
    assert data["stiffness"]["planet_ring_harmonics"] == []
    assert data["backlash"]["units"] == "dimensionless"


def test_to_toml_writes_a_unit_comment_on_every_parameter_line(base: GearSet) -> None:
    lines = to_toml(base).splitlines()
    table = ""
    seen = []
    for line in lines:
        if m := re.fullmatch(r"\[(\w+)\]", line):
            table = m.group(1)
        elif line and not line.startswith("#") and table:
            key = line.split("=")[0].strip()
            dotted = f"{table}.{key}"
            seen.append(dotted)
            assert "#" in line, line
            if UNITS[dotted]:
                assert f"[{UNITS[dotted]}]" in line.split("#", 1)[1], line
    assert sorted(seen) == sorted(UNITS)
    assert any(re.match(r"module = 0\.004 +# \[m\]$", line) for line in lines)


@pytest.mark.parametrize(
    "text",
    ['quote " and backslash \\', "line\nbreak\ttab\r\f\b", "ctrl \x01 \x1f \x7f", "µ ξ — 齿轮", ""],
)
def test_strings_are_escaped(base: GearSet, text: str) -> None:
    gs = evolve(base, {"name": text, "description": text + "!"})
    back = from_toml_string(to_toml(gs))
    assert (back.name, back.description) == (text, text + "!")


@pytest.mark.parametrize(
    "value", [1e-300, 5e-324, 1.7976931348623157e308, -2.5e-320, 0.1 + 0.2, 1 / 3, 123456789.0]
)
def test_awkward_floats_round_trip(base: GearSet, value: float) -> None:
    # the writer alone, at any magnitude: the shortest text that reads back to the same double
    assert tomllib.loads(f"x = {float_text(value)}")["x"] == value
    if not 0.0 <= value <= 1e9:  # outside the plausible ranges of T_D and b̄_sp
        return
    gs = evolve(base, {"torque.input": value, "backlash.sun_planet": min(value, 100.0)})
    back = from_toml_string(to_toml(gs))
    assert back.torque.input == value
    assert back.backlash.sun_planet == min(value, 100.0)


def test_to_dict_layout(base: GearSet) -> None:
    gs = evolve(base, {"stiffness.planet_ring_harmonics": (3e7,)})
    d = to_dict(gs)
    assert list(d) == ["name", "description", *TABLES]
    assert d["teeth"] == {"sun": 34, "planet": 31, "ring": 96}
    assert d["stiffness"]["planet_ring_harmonics"] == [3e7]  # type: ignore[index]
    assert gs.to_dict() == d


# ----------------------------------------------------------------------------- template
def test_template_reads_back_to_the_default_preset() -> None:
    default = preset("sheng2016")
    text = template_toml()
    gs = from_toml_string(text)
    assert evolve(gs, {"name": default.name, "description": default.description}) == default
    assert gs.name == "my_gearset"
    assert "the sheng2016 preset" in text.splitlines()[0]


def test_template_comments_every_parameter_line() -> None:
    table = ""
    count = 0
    for line in template_toml().splitlines():
        if m := re.fullmatch(r"\[(\w+)\]", line):
            table = m.group(1)
            continue
        if not line or line.startswith("#"):
            continue
        assert "#" in line, line
        comment = line.split("#", 1)[1]
        if table:
            key = line.split("=")[0].strip()
            unit = UNITS[f"{table}.{key}"]
            if unit:
                assert f"[{unit}]" in comment, line
            assert len(comment.strip()) > len(unit) + 10, line  # says what it means
            count += 1
    assert count == len(UNITS)


def test_template_names_symbols() -> None:
    text = template_toml()
    for symbol in [
        "z_s",
        "z_p",
        "z_r",
        "α_s",
        "J_c",
        "k_m,sp",
        "ξ_sp",
        "T_D",
        "A_sp",
        "E_s",
        "b_c",
    ]:
        assert f"# {symbol} [" in text, symbol


# ----------------------------------------------------------------------------- names, evolve
def test_field_names_are_the_units_table(base: GearSet) -> None:
    names = field_names()
    assert len(names) == len(set(names)) == 43
    assert set(names) == set(UNITS)
    assert names[:3] == ["teeth.sun", "teeth.planet", "teeth.ring"]


def test_get_value(base: GearSet) -> None:
    assert get_value(base, "teeth.ring") == 96
    assert get_value(base, "backlash.planet_ring") == 3.5
    assert get_value(base, "name") == "hindawi2021"
    assert get_value(base, "xi") == 0.03
    with pytest.raises(ParameterError, match="xi is an alias"):
        get_value(evolve(base, {"damping.sun_bearing": 0.1}), "xi")
    with pytest.raises(ParameterError, match=r"did you mean 'teeth\.ring'\?"):
        get_value(base, "teeth.rign")


def test_evolve_by_dotted_names(base: GearSet) -> None:
    gs = evolve(base, {"backlash.sun_planet": 4.0, "name": "wider", "torque.input": 500})
    assert gs.backlash.sun_planet == 4.0
    assert gs.backlash.planet_ring == 3.5
    assert gs.name == "wider"
    assert gs.torque.input == 500.0
    assert type(gs.torque.input) is float
    assert base.backlash.sun_planet == 3.0  # the original is untouched


def test_evolve_teeth(base: GearSet) -> None:
    gs = evolve(base, {"teeth.sun": 36, "teeth.ring": 98, "geometry.planets": 2})
    assert gs.radius_sun == pytest.approx(0.004 * 36 / 2, rel=1e-15)


def test_evolve_xi_sets_all_three_damping_ratios(base: GearSet) -> None:
    gs = evolve(base, {"xi": 0.07})
    assert (gs.damping.sun_planet, gs.damping.planet_ring, gs.damping.sun_bearing) == (
        0.07,
        0.07,
        0.07,
    )


def test_dotted_damping_name_overrides_xi_in_either_order(base: GearSet) -> None:
    for changes in (
        {"xi": 0.07, "damping.sun_bearing": 0.1},
        {"damping.sun_bearing": 0.1, "xi": 0.07},
    ):
        gs = evolve(base, changes)
        assert (gs.damping.sun_planet, gs.damping.planet_ring, gs.damping.sun_bearing) == (
            0.07,
            0.07,
            0.1,
        )


def test_evolve_converts_ints_and_sequences(base: GearSet) -> None:
    gs = evolve(base, {"xi": 0, "stiffness.sun_planet_harmonics": [1, 2], "geometry.module": 1})
    assert gs.damping.sun_planet == 0.0 and type(gs.damping.sun_planet) is float
    assert gs.stiffness.sun_planet_harmonics == (1.0, 2.0)
    assert all(type(h) is float for h in gs.stiffness.sun_planet_harmonics)
    assert type(gs.geometry.module) is float


def test_evolve_whole_table(base: GearSet) -> None:
    gs = evolve(base, {"backlash": {"sun_planet": 1e-5, "planet_ring": 2e-5, "units": "m"}})
    assert gs.backlash_bar() == pytest.approx((1.0, 2.0), rel=1e-12)
    assert evolve(base, {"mass": gs.mass}) == base


def test_gearset_evolve_method_with_keywords(base: GearSet) -> None:
    gs = base.evolve(backlash__sun_planet=4.5, xi=0.05)
    assert gs.backlash.sun_planet == 4.5
    assert gs.damping.planet_ring == 0.05
    assert base.evolve({"teeth.sun": 36, "teeth.ring": 98, "geometry.planets": 2}).teeth.sun == 36


def test_evolve_unknown_name_suggests_closest(base: GearSet) -> None:
    with pytest.raises(ParameterError) as info:
        evolve(base, {"backlash.sun_plnet": 4.0})
    assert str(info.value) == (
        "unknown parameter 'backlash.sun_plnet'; did you mean 'backlash.sun_planet'?"
    )


def test_evolve_bare_leaf_name_lists_the_candidates(base: GearSet) -> None:
    with pytest.raises(ParameterError, match="unknown parameter 'sun_planet'") as info:
        evolve(base, {"sun_planet": 4.0})
    for dotted in ["backlash.sun_planet", "damping.sun_planet", "transmission_error.sun_planet"]:
        assert repr(dotted) in str(info.value)


def test_evolve_unknown_field_in_table_mapping(base: GearSet) -> None:
    with pytest.raises(ParameterError, match=r"did you mean 'backlash\.planet_ring'\?"):
        evolve(base, {"backlash": {"planet_rng": 1.0}})


# ----------------------------------------------------------------------------- reading
def test_minimal_file_uses_defaults() -> None:
    gs = from_toml_string(MINIMAL)
    assert gs.name == "small"
    assert gs.description == ""
    assert gs.geometry.pressure_angle_sun == 20.0
    assert gs.torque.mode == "constant_torque"
    assert gs.torque.reference_omega == 1.0
    assert gs.backlash.units == "dimensionless"
    assert gs.mesh_phasing.model == "parker"
    assert gs.eccentricity.sun == 0.0
    assert gs.stiffness.sun_planet_harmonics == ()


def test_ints_become_floats() -> None:
    gs = from_toml_string(MINIMAL.replace("module = 0.002", "module = 1"))
    assert gs.geometry.module == 1.0
    assert type(gs.geometry.module) is float
    gs = from_toml_string(
        MINIMAL.replace("sun_bearing = 1e8", "sun_bearing = 1e8\nsun_planet_harmonics = [1, -2]")
    )
    assert gs.stiffness.sun_planet_harmonics == (1.0, -2.0)
    assert all(type(h) is float for h in gs.stiffness.sun_planet_harmonics)


def test_float_for_integer_field_is_an_error() -> None:
    with pytest.raises(ParameterError, match=re.escape("teeth.sun must be an integer: got 20.0")):
        from_toml_string(MINIMAL.replace("sun = 20", "sun = 20.0"))
    with pytest.raises(
        ParameterError, match=re.escape("geometry.planets must be an integer: got 3.0")
    ):
        from_toml_string(MINIMAL.replace("planets = 3", "planets = 3.0"))


def test_wrong_type_in_file_names_the_parameter() -> None:
    with pytest.raises(
        ParameterError, match=re.escape("mass.sun must be a number: got 'abc' (str)")
    ):
        from_toml_string(MINIMAL.replace("sun = 1.5", 'sun = "abc"'))
    with pytest.raises(
        ParameterError, match=re.escape("mass.planet must be a number: got True (bool)")
    ):
        from_toml_string(MINIMAL.replace("planet = 0.8", "planet = true"))


def test_unknown_key_suggests_closest() -> None:
    text = MINIMAL.replace("sun_planet = 1.0", "sun_plnet = 1.0")
    with pytest.raises(ParameterError) as info:
        from_toml_string(text)
    assert "unknown parameter 'backlash.sun_plnet'; did you mean 'backlash.sun_planet'?" in str(
        info.value
    )


def test_unknown_table_suggests_closest() -> None:
    with pytest.raises(
        ParameterError, match=re.escape("unknown table [backlsh]; did you mean [backlash]?")
    ):
        from_toml_string(MINIMAL.replace("[backlash]", "[backlsh]"))


def test_unknown_top_level_key_suggests_closest() -> None:
    with pytest.raises(
        ParameterError, match=re.escape("unknown parameter 'nmae'; did you mean 'name'?")
    ):
        from_toml_string(MINIMAL.replace('name = "small"', 'nmae = "small"'))


def test_missing_required_key_is_named() -> None:
    with pytest.raises(ParameterError, match=re.escape("missing required parameter 'teeth.ring'")):
        from_toml_string(_without(MINIMAL, "ring = 58"))
    with pytest.raises(
        ParameterError,
        match=re.escape("missing required parameter 'clearance.characteristic_length'"),
    ):
        from_toml_string(_without(MINIMAL, "characteristic_length = 1e-5"))


def test_missing_required_table_is_named() -> None:
    text = MINIMAL.split("[damping]")[0] + "[torque]" + MINIMAL.split("[torque]")[1]
    with pytest.raises(ParameterError, match=re.escape("missing required table [damping]")) as info:
        from_toml_string(text)
    assert "damping.sun_planet" in str(info.value)


def test_table_given_as_a_value() -> None:
    text = "teeth = 5\n" + MINIMAL.replace("[teeth]\nsun = 20\nplanet = 19\nring = 58\n", "")
    with pytest.raises(
        ParameterError, match=re.escape("teeth must be a table ([teeth]): got 5 (int)")
    ):
        from_toml_string(text)


def test_invalid_toml() -> None:
    with pytest.raises(ParameterError, match="invalid TOML"):
        from_toml_string("[teeth\nsun = 3")


def test_rule_violations_in_files_are_reported() -> None:
    with pytest.raises(
        ParameterError, match=re.escape("backlash.sun_planet must be >= 0: got -3.0")
    ):
        from_toml_string(MINIMAL.replace("sun_planet = 1.0", "sun_planet = -3.0"))


def test_from_toml_path_and_str(tmp_path: Path, base: GearSet) -> None:
    path = tmp_path / "gs.toml"
    path.write_text(to_toml(base), encoding="utf-8")
    assert from_toml(path) == base
    assert from_toml(str(path)) == base
    assert GearSet.from_toml(path) == base


def test_from_toml_missing_file(tmp_path: Path) -> None:
    missing = tmp_path / "nope.toml"
    with pytest.raises(FileNotFoundError, match="gear-set file not found") as info:
        from_toml(missing)
    assert "nope.toml" in str(info.value)


def test_from_toml_errors_name_the_file(tmp_path: Path) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(MINIMAL.replace("ring = 58", "ring = 57"), encoding="utf-8")
    with pytest.raises(ParameterError, match=r"bad\.toml: teeth\.ring must equal") as info:
        from_toml(path)
    assert "(20 + 2*19 = 58): got 57" in str(info.value)
