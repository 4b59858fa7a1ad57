"""The parameter registry against the record dataclasses, its derived views, ``parse_text``,
and the import structure of the gear-set layer (acyclic, also inside functions)."""

from __future__ import annotations

import ast
import dataclasses
import re
import typing
from pathlib import Path

import pytest

import gearchaos.gearset as gearset_pkg
from gearchaos.errors import ParameterError
from gearchaos.gearset import GearSet
from gearchaos.gearset.mapping import optional_tables
from gearchaos.gearset.parsing import parse_text
from gearchaos.gearset.schema import (
    ALIASES,
    CHOICES,
    CLEARANCES,
    EXTRA,
    FIELDS,
    META,
    MODULE_BOUNDED,
    TABLES,
    UNITS,
)
from gearchaos.gearset.validation import FIELD_KINDS, RECORD_CLASSES

KIND_OF_HINT = {int: "int", float: "float", str: "str", tuple[float, ...]: "floats"}


def _record_classes() -> dict[str, type]:
    """GearSet field -> record class, from the type hints of GearSet alone."""
    hints = typing.get_type_hints(GearSet)
    return {f.name: hints[f.name] for f in dataclasses.fields(GearSet) if f.name not in META}


# ----------------------------------------------------------------------------- registry
def test_registry_matches_the_record_dataclasses_exactly() -> None:
    classes = _record_classes()
    assert list(classes) == list(TABLES) == list(RECORD_CLASSES)
    assert classes == dict(RECORD_CLASSES)
    expected: list[tuple[str, str]] = []
    for table, cls in classes.items():
        hints = typing.get_type_hints(cls)
        for f in dataclasses.fields(cls):
            expected.append((f"{table}.{f.name}", KIND_OF_HINT[hints[f.name]]))
    assert [(name, f.kind) for name, f in FIELDS.items()] == expected  # names, order, kinds
    assert all(f.name == name for name, f in FIELDS.items())
    assert [f.name for f in dataclasses.fields(GearSet)][-2:] == list(META)


def test_every_field_has_unit_meaning_and_tex_symbol() -> None:
    for name, f in {**FIELDS, **EXTRA}.items():
        assert f.meaning.strip(), name
        assert f.tex.strip(), name
        if f.kind == "str":
            assert f.unit == "" and len(f.choices) >= 2, name  # a switch: choices, no unit
        else:
            assert f.unit.strip(), name
            assert not f.choices, name


def test_rules_and_plausible_ranges_are_consistent() -> None:
    for name, f in FIELDS.items():
        if f.kind in ("int", "float", "floats") and f.limits is not None:
            lo, hi = f.limits.lo, f.limits.hi
            assert lo is not None and hi is not None and lo < hi, name
            # the plausible range lies inside what the rule allows (ends may touch open ends)
            if f.rule is not None:
                inside = [x for x in (lo, hi) if f.rule.holds(x)]
                assert hi in inside, name
                assert lo in inside or (f.rule.lo == lo and f.rule.lo_open), name
        if f.kind == "str":
            assert f.rule is None and f.limits is None, name
    # every length bounded by the module is a non-negative float with no range of its own
    for name, units in MODULE_BOUNDED.items():
        f = FIELDS[name]
        assert f.kind == "float" and f.limits is None and f.rule is not None, name
        assert f.rule.lo == 0.0 and not f.rule.lo_open, name
        assert units is None or FIELDS[units].choices == ("dimensionless", "m"), name
    # every number without a rule or range of its own is bounded by a relation
    unbounded = {n for n, f in FIELDS.items() if f.kind != "str" and f.limits is None}
    angles = {"geometry.pressure_angle_sun", "geometry.pressure_angle_ring"}
    assert unbounded == set(MODULE_BOUNDED) | angles


def test_derived_views_are_the_registry() -> None:
    assert dict(FIELD_KINDS) == {n: f.kind for n, f in FIELDS.items()}
    assert dict(CHOICES) == {n: f.choices for n, f in FIELDS.items() if f.choices}
    assert dict(UNITS) == {n: f.unit for n, f in FIELDS.items()}
    assert gearset_pkg.UNITS is UNITS
    for targets in ALIASES.values():
        assert all(t in FIELDS for t in targets)
    for clearance, units, _ in CLEARANCES.values():
        assert clearance in MODULE_BOUNDED and MODULE_BOUNDED[clearance] == units


def test_optional_tables_are_the_gearset_defaults() -> None:
    with_default = [
        f.name
        for f in dataclasses.fields(GearSet)
        if f.name not in META and f.default_factory is not dataclasses.MISSING
    ]
    assert list(optional_tables()) == with_default
    assert with_default == ["transmission_error", "eccentricity", "mesh_phasing"]


# ----------------------------------------------------------------------------- parse_text
@pytest.mark.parametrize(
    ("name", "raw", "value"),
    [
        ("teeth.sun", "34", 34),
        ("geometry.planets", "5.0", 5),
        ("geometry.planets", "1e1", 10),
        ("backlash.sun_planet", "2.5", 2.5),
        ("omega", "1.5", 1.5),
        ("xi", "0.05", 0.05),
        ("stiffness.sun_planet_harmonics", "[1e7, -2e7]", (1e7, -2e7)),
        ("stiffness.planet_ring_harmonics", "3e6", (3e6,)),
        ("stiffness.planet_ring_harmonics", "", ()),
        ("stiffness.planet_ring_harmonics", "[]", ()),
        ("torque.mode", "constant_power", "constant_power"),
        ("backlash.units", "'m'", "m"),
        ("name", '"my set"', "my set"),
        ("description", "it's", "it's"),
        ("backlash.sun_plnet", "3", "3"),  # unknown: left for evolve to refuse with a hint
    ],
)
def test_parse_text_kinds(name: str, raw: str, value: object) -> None:
    got = parse_text(name, raw)
    assert got == value
    assert type(got) is type(value)
    if isinstance(got, tuple):
        assert all(type(x) is float for x in got)


@pytest.mark.parametrize(
    ("name", "raw", "message"),
    [
        ("teeth.sun", "34.5", "teeth.sun must be an integer: got '34.5'"),
        ("teeth.sun", "abc", "teeth.sun must be an integer: got 'abc'"),
        ("teeth.sun", "inf", "teeth.sun must be an integer: got 'inf'"),
        ("xi", "much", "xi must be a number: got 'much'"),
        ("omega", "fast", "omega must be a number: got 'fast'"),
        ("mass.sun", "1,5", "mass.sun must be a number: got '1,5'"),
        (
            "stiffness.sun_planet_harmonics",
            "[1e7, x]",
            "stiffness.sun_planet_harmonics[1] must be a number: got 'x'",
        ),
        ("omegaa", "1", "unknown parameter 'omegaa'; did you mean 'omega'?"),
        ("backlash", "3", "backlash is a table, not a parameter; set one of its fields: "),
        ("teeth.sun", 34, "--set value must be text: got 34 (int)"),
    ],
)
def test_parse_text_refuses(name: str, raw: str, message: str) -> None:
    with pytest.raises(ParameterError, match=re.escape(message)):
        parse_text(name, raw)


def test_parse_text_table_message_lists_its_fields() -> None:
    with pytest.raises(ParameterError) as info:
        parse_text("backlash", "3")
    assert str(info.value).endswith("backlash.sun_planet, backlash.planet_ring, backlash.units")


# ----------------------------------------------------------------------------- imports
GEARSET = Path(gearset_pkg.__file__).parent

#: The layers of the gear-set package, lowest first: a module imports only from lower layers.
LAYERS = [
    {"fieldtypes", "tables"},
    {"schema"},
    {"validation", "parsing"},
    {"mapping", "tomltext"},
    {"records"},
    {"presets"},
    {"io"},
    {"__init__"},
]


def _imports(path: Path, package: str) -> set[str]:
    """Every gearchaos module a file imports, at any depth (functions included)."""
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                module = ".".join([*base, *([node.module] if node.module else [])])
            else:
                module = node.module or ""
            out.add(module)
            out.update(f"{module}.{a.name}" for a in node.names)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
    return {m for m in out if m.startswith("gearchaos")}


def _module_files() -> dict[str, Path]:
    files = {p.stem: p for p in GEARSET.glob("*.py")}
    files["presets"] = GEARSET / "presets" / "__init__.py"
    return files


def test_gearset_modules_are_layered_and_acyclic() -> None:
    files = _module_files()
    layer_of = {m: i for i, layer in enumerate(LAYERS) for m in layer}
    assert set(files) == set(layer_of), "a new gearset module must be placed in LAYERS"
    for name, path in files.items():
        package = "gearchaos.gearset.presets" if name == "presets" else "gearchaos.gearset"
        for target in _imports(path, package):
            if target == "gearchaos.gearset" or target.startswith("gearchaos.gearset."):
                parts = target.split(".")
                if len(parts) < 3:
                    # ``from . import x`` (the package itself) only from the package
                    assert name == "__init__", f"{name} imports the package gearchaos.gearset"
                    continue
                sub = parts[2]
                if sub in layer_of and sub != name:
                    assert layer_of[sub] < layer_of[name], f"{name} imports {sub} (not lower)"
            else:
                # below the gear-set layer there are only the package's leaf modules
                allowed = {"gearchaos.errors", "gearchaos._files", "gearchaos._checks"}
                assert target in allowed or target.rsplit(".", 1)[0] in allowed, (
                    f"{name} imports {target}"
                )


def test_files_module_is_a_leaf() -> None:
    path = GEARSET.parent / "_files.py"
    assert _imports(path, "gearchaos") <= {
        "gearchaos.errors",
        "gearchaos.errors.ParameterError",
        "gearchaos.errors.StoreError",
    }
