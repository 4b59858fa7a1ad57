"""TOML text of gear sets: parsing with every failure as a ``ParameterError``, and writing.

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

Writing (:func:`to_toml`, :func:`template_text`) needs no TOML library: floats are written in
a shortest form that parses back to the identical double (checked as it is written), so a
gear set read back from its text is equal to it. The unit and meaning comments come from the
registry (:mod:`gearchaos.gearset.schema`).
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Callable, Iterable
from dataclasses import fields
from typing import Any, Final

from ..errors import ParameterError
from .schema import CHOICES, FIELDS, META
from .tables import RECORD_CLASSES
from .validation import show

__all__ = [
    "MAX_FILE_BYTES",
    "float_text",
    "parse",
    "string_text",
    "template_text",
    "to_toml",
]

#: Largest gear-set file read (a gear set takes about 3 KiB; the commented template 7 KiB).
MAX_FILE_BYTES: Final = 1 << 20


def parse(text: object) -> dict[str, Any]:
    """The tables of TOML text.

    Raises
    ------
    ParameterError
        ``invalid TOML: ...`` for text that is not a ``str``, longer than
        :data:`MAX_FILE_BYTES` characters (refused before parsing), not TOML, nested too deeply
        for the parser (arrays or inline tables hundreds of levels deep) or holding an integer
        of more than 4300 digits.
    """
    if not isinstance(text, str):
        raise ParameterError(
            f"invalid TOML: the text must be a str: got {show(text)} ({type(text).__name__})"
        )
    if len(text) > MAX_FILE_BYTES:
        raise ParameterError(
            f"invalid TOML: the text is {len(text)} characters, more than the {MAX_FILE_BYTES} "
            "a gear set may take"
        )
    try:
        return tomllib.loads(text)
    except RecursionError:
        raise ParameterError(
            "invalid TOML: arrays or inline tables nested too deeply to parse"
        ) from None
    except ValueError as exc:  # TOMLDecodeError, and int() of more than 4300 digits
        raise ParameterError(f"invalid TOML: {exc}") from None


def string_text(text: str) -> str:
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


def float_text(value: float) -> str:
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


def _value_text(kind: str, value: Any) -> str:
    if kind == "int":
        return str(int(value))
    if kind == "float":
        return float_text(value)
    if kind == "str":
        return string_text(str(value))
    if kind == "floats":
        return "[" + ", ".join(float_text(v) for v in value) + "]"
    raise AssertionError(kind)  # pragma: no cover


def _unit_comment(dotted: str) -> str:
    if dotted in META:
        return ""
    if dotted in CHOICES:
        return "one of " + ", ".join(CHOICES[dotted])
    return f"[{FIELDS[dotted].unit}]"


def _table_order(cls: type) -> list[str]:
    # ``units`` first, so that it is read before the clearances it qualifies.
    names = [f.name for f in fields(cls)]
    return sorted(names, key=lambda n: n != "units")


def _write(
    gs: Any,
    comment: Callable[[str], str],
    header: Iterable[str],
    table_header: Callable[[str], Iterable[str]] = lambda table: (),
) -> str:
    lines = [*header]
    for key in META:
        text = f"{key} = {string_text(getattr(gs, key))}"
        note = comment(key)
        lines.append(f"{text}  # {note}" if note else text)
    for table, cls in RECORD_CLASSES.items():
        record = getattr(gs, table)
        entries = []
        for attr in _table_order(cls):
            dotted = f"{table}.{attr}"
            text = f"{attr} = {_value_text(FIELDS[dotted].kind, getattr(record, attr))}"
            entries.append((text, comment(dotted)))
        width = max(len(text) for text, _ in entries) + 2
        lines.append("")
        lines.extend(table_header(table))
        lines.append(f"[{table}]")
        lines.extend(f"{text:<{width}}# {note}" if note else text for text, note in entries)
    return "\n".join(lines) + "\n"


def to_toml(gs: Any) -> str:
    """The gear set as TOML text with the units of every value in a trailing comment.

    Parameters
    ----------
    gs : GearSet

    Returns
    -------
    str
        TOML in the layout of ``to_dict``. Integers are written as integers, floats in the
        shortest form that parses back to the same double, strings as escaped basic strings,
        harmonics as arrays of floats; reading the text back gives an equal gear set.
    """
    header = [
        "# gearchaos gear set. Units in the trailing comments; clearances are in units of",
        '# clearance.characteristic_length (b_c) when their `units` is "dimensionless".',
    ]
    return _write(gs, _unit_comment, header)


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
    f = FIELDS[dotted]
    if dotted in CHOICES:
        return f"one of {', '.join(CHOICES[dotted])} — {f.meaning}"
    return f"{f.symbol} [{f.unit}]: {f.meaning}" if f.symbol else f"[{f.unit}]: {f.meaning}"


def template_text(gs: Any) -> str:
    """A commented gear-set file with the values of ``gs``: every line says its symbol, units
    and meaning (the text of ``gearchaos init-gearset``, which passes the default preset)."""
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
        gs, _template_comment, header, table_header=lambda table: [f"# {_TABLE_DOC[table]}"]
    )
