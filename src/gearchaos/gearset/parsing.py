"""Values of parameters from text: what ``--set NAME=VALUE`` means on the command line.

:func:`parse_text` converts the text of a value to the kind the registry gives the name
(:mod:`gearchaos.gearset.schema`): an integer for tooth and planet numbers, a number for
physical values, ``omega`` and ``xi``, comma-separated numbers (optionally in brackets) for the
stiffness harmonics, text (optionally quoted) for switches, ``name`` and ``description``. It
converts only; the rules (signs, ranges, choices) are checked where the value is used
(``GearSet.evolve``, the callers of Ω).
"""

from __future__ import annotations

import difflib
import math

from ..errors import ParameterError
from .schema import ALIASES, EXTRA, FIELDS, META, OMEGA, SPEEDS
from .tables import RECORD_CLASSES

__all__ = ["parse_float", "parse_floats", "parse_int", "parse_text", "unquote"]


def parse_float(name: str, raw: str) -> float:
    """A number from text (``"1.5"``, ``"6.2e8"``, ``"nan"`` and ``"inf"`` included: the
    rules of the field refuse them later with its name)."""
    try:
        return float(raw)
    except ValueError:
        raise ParameterError(f"{name} must be a number: got {raw!r}") from None


def parse_int(name: str, raw: str) -> int:
    """An integer from text; ``"5.0"`` and ``"1e3"`` are integers, ``"34.5"`` is not."""
    try:
        return int(raw)
    except ValueError:
        pass
    try:
        value = float(raw)
    except ValueError:
        value = math.nan
    if value.is_integer():
        return int(value)
    raise ParameterError(f"{name} must be an integer: got {raw!r}")


def parse_floats(name: str, raw: str) -> tuple[float, ...]:
    """Comma-separated numbers, optionally in brackets (``"[1e7, -2e7]"``; ``""`` is none);
    a bad item is named ``name[i]``."""
    text = raw.strip()
    if text.startswith("[") and text.endswith("]"):
        text = text[1:-1]
    items = [item.strip() for item in text.split(",") if item.strip()]
    return tuple(parse_float(f"{name}[{i}]", item) for i, item in enumerate(items))


def unquote(raw: str) -> str:
    """Text without one pair of enclosing single or double quotes."""
    if len(raw) >= 2 and raw[0] == raw[-1] and raw[0] in "'\"":
        return raw[1:-1]
    return raw


def parse_text(name: str, raw: str) -> object:
    """The value of ``--set name=raw``, converted to the kind of the parameter ``name``.

    Parameters
    ----------
    name : str
        A dotted gear-set field (``backlash.sun_planet``), ``omega``, the alias ``xi``,
        ``name`` or ``description``.
    raw : str
        The text after ``=`` (the caller strips surrounding blanks).

    Returns
    -------
    object
        ``int`` for integer fields, ``float`` for number fields, ``omega`` and ``xi``, a tuple
        of floats for the harmonics, ``str`` (one pair of enclosing quotes removed) for text.
        An unknown name comes back as the text unchanged, for ``GearSet.evolve`` to refuse
        with the closest valid name; a name close to ``omega`` is refused here.

    Raises
    ------
    ParameterError
        If ``raw`` is not text, does not parse as the parameter's kind (``teeth.sun must be an
        integer: got '34.5'``), ``name`` is a table (the message lists its fields) or an
        unknown name close to ``omega``.
    """
    if not isinstance(name, str) or not isinstance(raw, str):
        bad, what = ("name", name) if not isinstance(name, str) else ("value", raw)
        raise ParameterError(f"--set {bad} must be text: got {what!r} ({type(what).__name__})")
    field = FIELDS.get(name) or EXTRA.get(name)
    kind = field.kind if field is not None else None
    if name in ALIASES:
        kind = "float"
    elif name in META:
        kind = "str"
    if kind == "int":
        return parse_int(name, raw)
    if kind == "float":
        return parse_float(name, raw)
    if kind == "floats":
        return parse_floats(name, raw)
    if kind == "str":
        return unquote(raw)
    if name in RECORD_CLASSES:
        names = [n for n in FIELDS if n.startswith(name + ".")]
        raise ParameterError(
            f"{name} is a table, not a parameter; set one of its fields: {', '.join(names)}"
        )
    close = difflib.get_close_matches(name.lower(), [*FIELDS, *ALIASES, OMEGA, *SPEEDS], n=1)
    if close and close[0] in (OMEGA, *SPEEDS):  # the operating point, not a gear-set field
        raise ParameterError(f"unknown parameter {name!r}; did you mean {close[0]!r}?")
    return raw  # GearSet.evolve reports the unknown name with its own suggestion
