"""TOML input and output of gear sets, dotted-name access and ``evolve``.

A gear-set file has two top-level keys, ``name`` and ``description``, and one table per record
of :class:`~gearchaos.gearset.records.GearSet`, named as the GearSet field::

    name = "sheng2016"
    description = "..."

    [teeth]
    sun = 34          # [1]
    ...

    [backlash]
    units = "dimensionless"
    sun_planet = 3.0  # [b_c or m (backlash.units)]

Every parameter has a stable dotted name (``teeth.sun``, ``backlash.sun_planet``; see
:func:`field_names`) used alike by :func:`evolve`, :func:`get_value`, the CLI and sweep stores.

Reading (:func:`from_toml`, :func:`from_toml_string`, :func:`from_dict`) is strict: unknown
tables or keys raise :class:`~gearchaos.errors.ParameterError` suggesting the closest valid
name, missing required keys are named, integers are accepted (and converted) where floats are
expected but not the reverse, and every value passes :func:`~gearchaos.gearset.validation.validate`.

Writing (:func:`to_toml`) needs no TOML library: floats are written in a shortest form that
parses back to the identical double (checked as it is written), so
``from_toml_string(to_toml(gs)) == gs`` holds exactly.
"""

from __future__ import annotations

import difflib
import math
import numbers
import os
import tomllib
from collections.abc import Callable, Iterable, Mapping
from dataclasses import MISSING, fields
from pathlib import Path
from typing import Final

from ..errors import ParameterError
from .records import UNITS, GearSet
from .validation import CHOICES, FIELD_KINDS, RECORD_CLASSES

__all__ = [
    "ALIASES",
    "evolve",
    "field_names",
    "from_dict",
    "from_toml",
    "from_toml_string",
    "get_value",
    "template_toml",
    "to_dict",
    "to_toml",
]

_META: Final = ("name", "description")

#: Names that :func:`evolve` accepts besides the dotted fields: alias -> the fields it sets.
ALIASES: Final[dict[str, tuple[str, ...]]] = {
    "xi": ("damping.sun_planet", "damping.planet_ring", "damping.sun_bearing"),
}


# --------------------------------------------------------------------------- names
def field_names() -> list[str]:
    """All dotted parameter names, table by table in record order.

    Returns
    -------
    list of str
        ``["teeth.sun", "teeth.planet", ..., "mesh_phasing.ring_sun"]``. ``name``,
        ``description`` and the alias ``xi`` are accepted by :func:`evolve` and
        :func:`get_value` as well but are not listed.
    """
    return list(FIELD_KINDS)


def _valid_names() -> list[str]:
    return [*FIELD_KINDS, *_META, *ALIASES]


def _unknown(name: str, candidates: Iterable[str], what: str = "parameter") -> ParameterError:
    """A ParameterError for an unknown name that suggests the closest candidate(s)."""
    cands = list(candidates)
    key = name.strip().lower()
    hint = ""
    if "." not in key:
        same_leaf = [c for c in cands if "." in c and c.rsplit(".", 1)[1] == key]
        if same_leaf:
            hint = "did you mean one of " + ", ".join(repr(c) for c in same_leaf) + "?"
    if not hint:
        close = difflib.get_close_matches(key, cands, n=1, cutoff=0.6)
        if close:
            hint = f"did you mean {close[0]!r}?"
        else:
            hint = "valid names are " + ", ".join(cands)
    return ParameterError(f"unknown {what} {name!r}; {hint}")


# --------------------------------------------------------------------------- coercion
def _as_float(value: object) -> object:
    """Real numbers (Python or numpy ints and floats, not bools) become Python floats."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        try:
            return float(value)
        except OverflowError:
            return value  # validation reports it as non-finite
    return value


def _coerce(dotted: str, value: object) -> object:
    """Convert a value to the Python type of a field where that loses nothing.

    ints -> float for float fields, numpy integers -> int for integer fields, lists/tuples/
    arrays -> tuples of floats for harmonics. Anything else is left for :func:`validate` to
    reject with a message naming ``dotted``.
    """
    kind = FIELD_KINDS[dotted]
    if kind == "float":
        return _as_float(value)
    if kind == "int":
        if isinstance(value, numbers.Integral) and not isinstance(value, bool):
            return int(value)
        return value
    if kind == "floats":
        if hasattr(value, "tolist") and not isinstance(value, (str, bytes)):
            value = value.tolist()
        if isinstance(value, (list, tuple)):
            return tuple(_as_float(v) for v in value)
        return value
    if kind == "str" and isinstance(value, str):
        return str(value)
    return value


def _record_values(gs: GearSet) -> dict[str, dict[str, object]]:
    return {
        table: {f.name: getattr(getattr(gs, table), f.name) for f in fields(cls)}
        for table, cls in RECORD_CLASSES.items()
    }


def _build(tables: Mapping[str, Mapping[str, object]], meta: Mapping[str, object]) -> GearSet:
    records = {table: cls(**tables[table]) for table, cls in RECORD_CLASSES.items()}
    return GearSet(**records, **meta)  # type: ignore[arg-type]


# --------------------------------------------------------------------------- evolve / get
def evolve(gs: GearSet, changes: Mapping[str, object]) -> GearSet:
    """A validated copy of a gear set with some parameters changed.

    Parameters
    ----------
    gs : GearSet
        The gear set to copy.
    changes : mapping of str to object
        New values by dotted name (``"backlash.sun_planet"``, ``"teeth.sun"``), or ``"name"``,
        ``"description"``, a table name (``"backlash"``) with a record instance or a mapping of
        some of its fields, or the alias ``"xi"`` that sets ``damping.sun_planet``,
        ``damping.planet_ring`` and ``damping.sun_bearing`` at once (a dotted damping name in
        the same call overrides the alias for that ratio). Integers are accepted for float
        fields and sequences for the harmonics; they are converted to float and tuple.

    Returns
    -------
    GearSet
        The new gear set, validated as a whole (so a change of ``teeth.planet`` must come with a
        consistent ``teeth.ring``).

    Raises
    ------
    ParameterError
        For an unknown name (suggesting the closest valid one) or an invalid resulting set.
    """
    if not isinstance(gs, GearSet):
        raise TypeError(f"evolve() expects a GearSet: got {type(gs).__name__}")
    tables = _record_values(gs)
    meta: dict[str, object] = {"name": gs.name, "description": gs.description}

    def set_dotted(dotted: str, value: object) -> None:
        table, attr = dotted.split(".", 1)
        tables[table][attr] = _coerce(dotted, value)

    for alias, targets in ALIASES.items():
        if alias in changes:
            for dotted in targets:
                set_dotted(dotted, changes[alias])
    for key, value in changes.items():
        if not isinstance(key, str):
            raise ParameterError(f"parameter names must be strings: got {key!r}")
        if key in ALIASES:
            continue
        if key in _META:
            meta[key] = value
        elif key in FIELD_KINDS:
            set_dotted(key, value)
        elif key in RECORD_CLASSES:
            cls = RECORD_CLASSES[key]
            if isinstance(value, cls):
                tables[key] = {f.name: getattr(value, f.name) for f in fields(cls)}
            elif isinstance(value, Mapping):
                for attr, item in value.items():
                    dotted = f"{key}.{attr}"
                    if dotted not in FIELD_KINDS:
                        raise _unknown(dotted, _valid_names())
                    set_dotted(dotted, item)
            else:
                raise ParameterError(
                    f"{key} must be a {cls.__name__} record or a mapping of its fields: "
                    f"got {value!r} ({type(value).__name__})"
                )
        else:
            raise _unknown(key, _valid_names())
    return _build(tables, meta)


def get_value(gs: GearSet, dotted: str) -> object:
    """The value of one parameter by dotted name.

    Parameters
    ----------
    gs : GearSet
        The gear set.
    dotted : str
        A name from :func:`field_names`, ``"name"``, ``"description"`` or ``"xi"`` (defined
        only while the three damping ratios are equal).

    Returns
    -------
    object
        The stored value (int, float, str or tuple of floats).

    Raises
    ------
    ParameterError
        For an unknown name (suggesting the closest valid one), or ``xi`` with unequal ratios.
    """
    if dotted in _META:
        return getattr(gs, dotted)
    if dotted in FIELD_KINDS:
        table, attr = dotted.split(".", 1)
        return getattr(getattr(gs, table), attr)
    if dotted in ALIASES:
        values = {get_value(gs, t) for t in ALIASES[dotted]}
        if len(values) != 1:
            raise ParameterError(
                f"{dotted} is an alias of {', '.join(ALIASES[dotted])}, which differ: "
                f"got {[get_value(gs, t) for t in ALIASES[dotted]]!r}"
            )
        return values.pop()
    raise _unknown(str(dotted), _valid_names())


# --------------------------------------------------------------------------- dict / reading
def to_dict(gs: GearSet) -> dict[str, object]:
    """The gear set as a nested plain dictionary in TOML layout.

    Returns
    -------
    dict
        ``{"name": ..., "description": ..., "teeth": {"sun": 34, ...}, ...}`` with one
        sub-dictionary per record, named as the GearSet field; tuples become lists.
    """
    out: dict[str, object] = {"name": gs.name, "description": gs.description}
    for table, values in _record_values(gs).items():
        out[table] = {k: (list(v) if isinstance(v, tuple) else v) for k, v in values.items()}
    return out


def _has_default(f: object) -> bool:
    return f.default is not MISSING or f.default_factory is not MISSING  # type: ignore[attr-defined]


def from_dict(data: Mapping[str, object]) -> GearSet:
    """Build a gear set from a nested mapping in TOML layout (the inverse of :func:`to_dict`).

    Parameters
    ----------
    data : mapping
        Top-level ``name`` and ``description`` (optional) and one table per record. Tables
        whose fields all have defaults (``transmission_error``, ``eccentricity``,
        ``mesh_phasing``) and fields with defaults may be omitted.

    Returns
    -------
    GearSet

    Raises
    ------
    ParameterError
        For unknown tables or keys (suggesting the closest valid name), missing required keys,
        values of the wrong type and values that break a rule of
        :func:`~gearchaos.gearset.validation.validate`.
    """
    if not isinstance(data, Mapping):
        raise ParameterError(f"a gear set must be a table: got {type(data).__name__}")
    meta: dict[str, object] = {}
    for key, value in data.items():
        if key in _META:
            meta[key] = value
        elif key not in RECORD_CLASSES:
            if isinstance(value, Mapping):
                close = difflib.get_close_matches(str(key).lower(), list(RECORD_CLASSES), n=1)
                hint = (
                    f"did you mean [{close[0]}]?"
                    if close
                    else "valid tables are " + ", ".join(f"[{t}]" for t in RECORD_CLASSES)
                )
                raise ParameterError(f"unknown table [{key}]; {hint}")
            raise _unknown(str(key), [*_META, *RECORD_CLASSES, *FIELD_KINDS])
        elif not isinstance(value, Mapping):
            raise ParameterError(
                f"{key} must be a table ([{key}]): got {value!r} ({type(value).__name__})"
            )

    gs_fields = {f.name: f for f in fields(GearSet)}
    records: dict[str, object] = {}
    for table, cls in RECORD_CLASSES.items():
        raw = data.get(table)
        if raw is None:
            if _has_default(gs_fields[table]):
                continue
            required = [f"{table}.{f.name}" for f in fields(cls) if not _has_default(f)]
            raise ParameterError(f"missing required table [{table}] (with {', '.join(required)})")
        assert isinstance(raw, Mapping)
        values: dict[str, object] = {}
        for key, value in raw.items():
            dotted = f"{table}.{key}"
            if dotted not in FIELD_KINDS:
                raise _unknown(dotted, field_names())
            values[key] = _coerce(dotted, value)
        for f in fields(cls):
            if f.name not in values and not _has_default(f):
                raise ParameterError(f"missing required parameter '{table}.{f.name}'")
        records[table] = cls(**values)
    return GearSet(**records, **meta)  # type: ignore[arg-type]


def from_toml_string(text: str) -> GearSet:
    """Parse a gear set from TOML text.

    Parameters
    ----------
    text : str
        TOML in the layout of :func:`to_toml` (see :func:`template_toml`).

    Returns
    -------
    GearSet

    Raises
    ------
    ParameterError
        For invalid TOML and for everything :func:`from_dict` rejects.
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"invalid TOML: {exc}") from exc
    return from_dict(data)


def from_toml(path: str | os.PathLike[str] | object) -> GearSet:
    """Read a gear set from a UTF-8 TOML file.

    Parameters
    ----------
    path : str or path-like
        The file (``gearchaos init-gearset`` writes a commented template).

    Returns
    -------
    GearSet

    Raises
    ------
    TypeError
        If ``path`` is neither a string nor path-like.
    FileNotFoundError
        If there is no such file.
    ParameterError
        For undecodable or invalid TOML and invalid parameters; the message starts with the
        path.
    """
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"from_toml() expects a str or path-like: got {type(path).__name__}")
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise FileNotFoundError(f"gear-set file not found: '{p}'") from None
    except UnicodeDecodeError as exc:
        raise ParameterError(f"{p}: not UTF-8 text: {exc}") from exc
    try:
        return from_toml_string(text)
    except ParameterError as exc:
        raise ParameterError(f"{p}: {exc}") from exc


# --------------------------------------------------------------------------- writing
def _toml_string(text: str) -> str:
    """A TOML basic string: backslash, quote and control characters escaped."""
    named = {
        '"': '\\"',
        "\\": "\\\\",
        "\b": "\\b",
        "\t": "\\t",
        "\n": "\\n",
        "\f": "\\f",
        "\r": "\\r",
    }
    out = []
    for ch in text:
        if ch in named:
            out.append(named[ch])
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _toml_float(value: float) -> str:
    """Shortest TOML float that parses back to exactly ``value``.

    ``repr`` (the shortest round-trip form) for moderate magnitudes; for very large or small
    ones the shortest round-trip scientific form, written the TOML way (``6.2e8``, ``5e-6``).
    """
    x = float(value)
    r = repr(x)
    if not math.isfinite(x) or x == 0.0 or 1e-4 <= abs(x) < 1e6:
        return r
    for digits in range(17):
        s = f"{x:.{digits}e}"
        if float(s) == x:
            mantissa, exponent = s.split("e")
            s = f"{mantissa}e{int(exponent)}"
            if float(s) == x:
                return s
            break
    return r


def _toml_value(kind: str, value: object) -> str:
    if kind == "int":
        return str(int(value))  # type: ignore[call-overload]
    if kind == "float":
        return _toml_float(value)  # type: ignore[arg-type]
    if kind == "str":
        return _toml_string(str(value))
    if kind == "floats":
        return "[" + ", ".join(_toml_float(v) for v in value) + "]"  # type: ignore[attr-defined]
    raise AssertionError(kind)  # pragma: no cover


def _unit_comment(dotted: str) -> str:
    if dotted in _META:
        return ""
    if dotted in CHOICES:
        return "one of " + ", ".join(CHOICES[dotted])
    return f"[{UNITS[dotted]}]"


def _table_order(cls: type) -> list[str]:
    # ``units`` first, so that it is read before the clearances it qualifies.
    names = [f.name for f in fields(cls)]
    return sorted(names, key=lambda n: n != "units")


def _write(
    gs: GearSet,
    comment: Callable[[str], str],
    header: Iterable[str],
    table_header: Callable[[str], Iterable[str]] = lambda table: (),
) -> str:
    lines = [*header]
    for key in _META:
        text = f"{key} = {_toml_string(getattr(gs, key))}"
        note = comment(key)
        lines.append(f"{text}  # {note}" if note else text)
    for table, cls in RECORD_CLASSES.items():
        record = getattr(gs, table)
        entries = []
        for attr in _table_order(cls):
            dotted = f"{table}.{attr}"
            text = f"{attr} = {_toml_value(FIELD_KINDS[dotted], getattr(record, attr))}"
            entries.append((text, comment(dotted)))
        width = max(len(text) for text, _ in entries) + 2
        lines.append("")
        lines.extend(table_header(table))
        lines.append(f"[{table}]")
        lines.extend(f"{text:<{width}}# {note}" if note else text for text, note in entries)
    return "\n".join(lines) + "\n"


def to_toml(gs: GearSet) -> str:
    """The gear set as TOML text with the units of every value in a trailing comment.

    Parameters
    ----------
    gs : GearSet

    Returns
    -------
    str
        TOML in the layout of :func:`to_dict`. Integers are written as integers, floats in the
        shortest form that parses back to the same double, strings as escaped basic strings,
        harmonics as arrays of floats; ``from_toml_string(to_toml(gs)) == gs`` exactly.
    """
    header = [
        "# gearchaos gear set. Units in the trailing comments; clearances are in units of",
        '# clearance.characteristic_length (b_c) when their `units` is "dimensionless".',
    ]
    return _write(gs, _unit_comment, header)


# Symbol and meaning of every field, for the commented template (symbols of MODEL.md).
_DOC: Final[dict[str, tuple[str, str]]] = {
    "teeth.sun": ("z_s", "number of sun teeth"),
    "teeth.planet": ("z_p", "number of teeth of each planet"),
    "teeth.ring": ("z_r", "number of ring teeth (internal gear); must equal z_s + 2 z_p"),
    "geometry.planets": ("N", "number of equally spaced planets; (z_s + z_r)/N must be an integer"),
    "geometry.module": ("m", "module; pitch radius r = m z / 2"),
    "geometry.pressure_angle_sun": ("α_s", "pressure angle of the sun–planet meshes, in (0, 45)"),
    "geometry.pressure_angle_ring": ("α_r", "pressure angle of the ring–planet meshes, in (0, 45)"),
    "mass.sun": ("m_s", "translational mass of the sun (moves in x and y on its bearing)"),
    "mass.planet": ("m_p", "mass of each planet (rides on the carrier)"),
    "inertia.sun": ("J_s", "polar moment of inertia of the sun; m_s* = J_s / r_bs²"),
    "inertia.planet": ("J_p", "polar moment of inertia of each planet; m_p* = J_p / r_bp²"),
    "inertia.carrier": ("J_c", "polar moment of inertia of the carrier; m_c* = J_c / r_c² + N m_p"),
    "stiffness.sun_planet_mean": ("k_m,sp", "mean sun–planet mesh stiffness"),
    "stiffness.sun_planet_alternating": (
        "k_a,sp",
        "amplitude of its mesh-frequency variation; needs k_a + Σ|k_h| < k_m",
    ),
    "stiffness.planet_ring_mean": ("k_m,rp", "mean planet–ring mesh stiffness"),
    "stiffness.planet_ring_alternating": (
        "k_a,rp",
        "amplitude of its mesh-frequency variation; needs k_a + Σ|k_h| < k_m",
    ),
    "stiffness.sun_bearing": ("k_s", "sun bearing (support) stiffness, along x and along y"),
    "stiffness.sun_planet_harmonics": (
        "k_2, k_3, …",
        "optional higher harmonics of the sun–planet mesh stiffness (any sign)",
    ),
    "stiffness.planet_ring_harmonics": (
        "k_2, k_3, …",
        "optional higher harmonics of the planet–ring mesh stiffness (any sign)",
    ),
    "damping.sun_planet": ("ξ_sp", "sun–planet mesh damping ratio; c_sp = 2 ξ_sp √(k_m,sp m_e)"),
    "damping.planet_ring": ("ξ_rp", "planet–ring mesh damping ratio; c_rp = 2 ξ_rp √(k_m,rp m_p*)"),
    "damping.sun_bearing": ("ξ_s", "sun bearing damping ratio; c_s = 2 ξ_s √(k_s m_s)"),
    "torque.input": ("T_D", "input torque on the sun; output torque T_L = T_D (1 + z_r/z_s)"),
    "torque.mode": ("", "constant_torque: T_D fixed; constant_power: T_D Ω_ref / Ω"),
    "torque.reference_omega": (
        "Ω_ref",
        "dimensionless mesh frequency at which T_D applies (constant_power only)",
    ),
    "transmission_error.sun_planet": ("A_sp", "sun–planet static transmission-error amplitude"),
    "transmission_error.planet_ring": ("A_rp", "planet–ring static transmission-error amplitude"),
    "transmission_error.sun_planet_phase": (
        "",
        "phase of A_sp relative to the sun–planet mesh-stiffness phase",
    ),
    "transmission_error.planet_ring_phase": (
        "",
        "phase of A_rp relative to the planet–ring mesh-stiffness phase",
    ),
    "eccentricity.sun": (
        "E_s",
        "sun eccentricity; any E ≠ 0 makes the forcing lcm(z_s, z_p, z_r)-periodic",
    ),
    "eccentricity.planet": ("E_p", "planet eccentricity"),
    "eccentricity.ring": ("E_r", "ring eccentricity"),
    "eccentricity.sun_phase": ("β_s", "phase of the sun eccentricity"),
    "eccentricity.planet_phase": ("β_p", "phase of the planet eccentricity"),
    "eccentricity.ring_phase": ("β_r", "phase of the ring eccentricity"),
    "backlash.units": ("", "units of the two half backlashes below: b/b_c or metres"),
    "backlash.sun_planet": ("b_sp", "half backlash of the sun–planet meshes (total 2 b_sp)"),
    "backlash.planet_ring": ("b_rp", "half backlash of the planet–ring meshes (total 2 b_rp)"),
    "clearance.units": ("", "units of clearance.sun_bearing: b/b_c or metres"),
    "clearance.sun_bearing": ("b_s", "sun bearing half clearance, along x and along y"),
    "clearance.characteristic_length": (
        "b_c",
        "length scale of the dimensionless model (always in metres)",
    ),
    "mesh_phasing.model": (
        "",
        "parker (the default): Parker & Lin (2004) phases; "
        "in_phase: all φ = 0 (as sheng2016, MODEL.md §9)",
    ),
    "mesh_phasing.ring_sun": (
        "γ_rs",
        "ring-mesh phase of planet 1 relative to its sun mesh (parker only)",
    ),
}

_TABLE_DOC: Final[dict[str, str]] = {
    "teeth": "Tooth numbers (standard gears).",
    "geometry": "Planet count, module and pressure angles.",
    "mass": "Translational masses.",
    "inertia": "Polar moments of inertia.",
    "stiffness": "Mesh stiffness k(t) = k_m + k_a cos(ωt + φ) + Σ_h k_h cos(h(ωt + φ)); support.",
    "damping": "Viscous damping ratios (MODEL.md §4).",
    "torque": "Load.",
    "transmission_error": "Static transmission errors A sin(ωt + φ) (MODEL.md §3).",
    "eccentricity": "Geometric eccentricities (MODEL.md §3); keep 0 for Poincaré analyses.",
    "backlash": "Mesh half backlashes (dead zone of half width b).",
    "clearance": "Sun bearing clearance and the characteristic length b_c.",
    "mesh_phasing": "Mesh phase model (MODEL.md §3).",
}


def _template_comment(dotted: str) -> str:
    if dotted == "name":
        return "short identifier of the gear set"
    if dotted == "description":
        return "one line describing it"
    symbol, meaning = _DOC[dotted]
    if dotted in CHOICES:
        return f"one of {', '.join(CHOICES[dotted])} — {meaning}"
    unit = UNITS[dotted]
    return f"{symbol} [{unit}]: {meaning}" if symbol else f"[{unit}]: {meaning}"


def template_toml() -> str:
    """A commented gear-set file to start from: the values of the default preset ``sheng2016``
    (the calibrated stand-in for the seed's Table 1), every line explained.

    Returns
    -------
    str
        TOML that :func:`from_toml_string` reads back to the ``sheng2016`` preset (except for
        ``name`` and ``description``); each parameter line carries its symbol, units and meaning.
    """
    from .presets import preset

    gs = evolve(
        preset("sheng2016"),
        {
            "name": "my_gearset",
            "description": "describe the gear set here (values: the sheng2016 preset)",
        },
    )
    header = [
        "# gearchaos gear-set file (TOML). Start from these values (the sheng2016 preset, the",
        "# default: MODEL.md §9 calibrated against the seed paper, docs/reproduction.md; the",
        "# uncalibrated §9 set is preset hindawi2021) and edit. Every parameter has a dotted",
        "# name, e.g. backlash.sun_planet, the same in Python (GearSet.evolve), on the command",
        "# line and in sweep results.",
        "# Units are SI with angles in degrees; clearances are in units of",
        '# clearance.characteristic_length (b_c) when their table\'s `units` is "dimensionless".',
        "# Tables transmission_error, eccentricity and mesh_phasing, and keys with defaults",
        "# (pressure angles, harmonics, torque.mode, units, ...), may be left out.",
        "",
    ]
    return _write(
        gs,
        _template_comment,
        header,
        table_header=lambda table: [f"# {_TABLE_DOC[table]}"],
    )
