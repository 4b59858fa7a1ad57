"""Gear sets as plain mappings: dotted-name look-up, coercion, changes and the TOML layout.

The functions here work on table values (``{"teeth": {"sun": 34, ...}, ...}``) and on any
object with the twelve table attributes; they never build a ``GearSet`` (that class, in
:mod:`gearchaos.gearset.records`, calls them and validates the result). They raise
:class:`~gearchaos.errors.ParameterError` for names that do not exist (suggesting the closest
valid one) and for structure that cannot be a gear set; the values themselves are checked by
:func:`~gearchaos.gearset.validation.validate`.
"""

from __future__ import annotations

import difflib
import numbers
from collections.abc import Iterable, Mapping
from dataclasses import MISSING, fields
from typing import Any

from ..errors import ParameterError
from .schema import ALIASES, FIELDS, META
from .tables import RECORD_CLASSES
from .validation import show

__all__ = [
    "Tables",
    "apply_changes",
    "check_changes",
    "coerce",
    "field_names",
    "flatten",
    "get_value",
    "optional_tables",
    "record_values",
    "records_from_data",
    "to_dict",
    "unknown",
    "valid_names",
]

#: Values by table and key: ``{"teeth": {"sun": 34, ...}, ...}``.
Tables = dict[str, dict[str, object]]


def field_names() -> list[str]:
    """All dotted parameter names, table by table in record order.

    Returns
    -------
    list of str
        ``["teeth.sun", "teeth.planet", ..., "mesh_phasing.ring_sun"]``. ``name``,
        ``description`` and the alias ``xi`` are accepted by ``evolve`` and :func:`get_value`
        as well but are not listed.
    """
    return list(FIELDS)


def valid_names() -> list[str]:
    """Every name ``evolve`` accepts: the dotted fields, ``name``, ``description``, ``xi``."""
    return [*FIELDS, *META, *ALIASES]


def unknown(name: str, candidates: Iterable[str], what: str = "parameter") -> ParameterError:
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
    return ParameterError(f"unknown {what} {show(name)}; {hint}")


def _as_float(value: object) -> object:
    """Real numbers (Python or numpy ints and floats, not bools) become Python floats."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        try:
            return float(value)
        except (OverflowError, ValueError, TypeError):
            return value  # validation reports it as non-finite
    return value


def coerce(dotted: str, value: object) -> object:
    """Convert a value to the Python type of a field where that loses nothing.

    ints -> float for float fields, numpy integers -> int for integer fields, lists/tuples/
    arrays -> tuples of floats for harmonics. Anything else is left for ``validate`` to
    reject with a message naming ``dotted``.
    """
    kind = FIELDS[dotted].kind
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
    return value


def record_values(gs: Any) -> Tables:
    """The values of a gear set by table and key."""
    return {
        table: {f.name: getattr(getattr(gs, table), f.name) for f in fields(cls)}
        for table, cls in RECORD_CLASSES.items()
    }


def check_changes(changes: object) -> Mapping[Any, object]:
    """``changes`` itself if it is a mapping; else a ParameterError naming ``changes``."""
    if not isinstance(changes, Mapping):
        raise ParameterError(
            "changes must be a mapping of parameter names to values, "
            f"e.g. {{'backlash.sun_planet': 4.0}}: got {show(changes)} ({type(changes).__name__})"
        )
    return changes


def apply_changes(gs: Any, changes: object) -> tuple[Tables, dict[str, object]]:
    """The table values and ``name``/``description`` of ``gs`` with ``changes`` applied.

    Parameters
    ----------
    gs : GearSet
        The gear set to copy.
    changes : mapping of str to object
        New values by dotted name, ``name``, ``description``, a table name with a record or a
        mapping of some of its fields, or the alias ``xi`` (a dotted damping name in the same
        call overrides the alias for that ratio). Values are converted by :func:`coerce`.

    Returns
    -------
    tables, meta
        What ``GearSet`` needs to build the changed copy (which validates it).

    Raises
    ------
    ParameterError
        If ``changes`` is not a mapping, for a name that is not a string or not known
        (suggesting the closest valid one), or a table given as something else than its record
        or a mapping.
    """
    changes = check_changes(changes)
    tables = record_values(gs)
    meta: dict[str, object] = {"name": gs.name, "description": gs.description}

    def set_dotted(dotted: str, value: object) -> None:
        table, attr = dotted.split(".", 1)
        tables[table][attr] = coerce(dotted, value)

    for alias, targets in ALIASES.items():
        if alias in changes:
            for dotted in targets:
                set_dotted(dotted, changes[alias])
    for key, value in changes.items():
        if not isinstance(key, str):
            raise ParameterError(f"parameter names must be strings: got {show(key)}")
        if key in ALIASES:
            continue
        if key in META:
            meta[key] = value
        elif key in FIELDS:
            set_dotted(key, value)
        elif key in RECORD_CLASSES:
            cls = RECORD_CLASSES[key]
            if isinstance(value, cls):
                tables[key] = {f.name: getattr(value, f.name) for f in fields(cls)}
            elif isinstance(value, Mapping):
                for attr, item in value.items():
                    dotted = f"{key}.{attr}"
                    if dotted not in FIELDS:
                        raise unknown(dotted, valid_names())
                    set_dotted(dotted, item)
            else:
                raise ParameterError(
                    f"{key} must be a {cls.__name__} record or a mapping of its fields: "
                    f"got {show(value)} ({type(value).__name__})"
                )
        else:
            raise unknown(key, valid_names())
    return tables, meta


def get_value(gs: Any, dotted: str) -> object:
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
    if not isinstance(dotted, str):
        raise ParameterError(f"parameter names must be strings: got {show(dotted)}")
    if dotted in META:
        return getattr(gs, dotted)
    if dotted in FIELDS:
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
    raise unknown(dotted, valid_names())


def to_dict(gs: Any) -> dict[str, object]:
    """The gear set as a nested plain dictionary in TOML layout.

    Returns
    -------
    dict
        ``{"name": ..., "description": ..., "teeth": {"sun": 34, ...}, ...}`` with one
        sub-dictionary per record, named as the GearSet field; tuples become lists.
    """
    out: dict[str, object] = {"name": gs.name, "description": gs.description}
    for table, values in record_values(gs).items():
        out[table] = {k: (list(v) if isinstance(v, tuple) else v) for k, v in values.items()}
    return out


def _has_default(f: Any) -> bool:
    return f.default is not MISSING or f.default_factory is not MISSING


def optional_tables() -> tuple[str, ...]:
    """Tables that a gear-set file may leave out: those whose every key has a default."""
    return tuple(
        table for table, cls in RECORD_CLASSES.items() if all(_has_default(f) for f in fields(cls))
    )


def records_from_data(data: object) -> tuple[dict[str, object], dict[str, object]]:
    """The records and ``name``/``description`` of a mapping in TOML layout.

    Parameters
    ----------
    data : mapping
        Top-level ``name`` and ``description`` (optional) and one table per record; tables in
        :func:`optional_tables` and keys with defaults may be omitted.

    Returns
    -------
    records, meta
        The record instances by table (omitted optional tables are absent) and the meta keys
        given, for ``GearSet(**records, **meta)``.

    Raises
    ------
    ParameterError
        For a non-mapping, unknown tables or keys (suggesting the closest valid name), a table
        that is not a table and missing required tables or keys.
    """
    if not isinstance(data, Mapping):
        raise ParameterError(f"a gear set must be a table: got {type(data).__name__}")
    meta: dict[str, object] = {}
    for key, value in data.items():
        if key in META:
            meta[key] = value
        elif key not in RECORD_CLASSES:
            if isinstance(value, Mapping):
                close = difflib.get_close_matches(str(key).lower(), list(RECORD_CLASSES), n=1)
                hint = (
                    f"did you mean [{close[0]}]?"
                    if close
                    else "valid tables are " + ", ".join(f"[{t}]" for t in RECORD_CLASSES)
                )
                shown = key if isinstance(key, str) and len(key) <= 80 else show(key)
                raise ParameterError(f"unknown table [{shown}]; {hint}")
            raise unknown(str(key), [*META, *RECORD_CLASSES, *FIELDS])
        elif not isinstance(value, Mapping):
            raise ParameterError(
                f"{key} must be a table ([{key}]): got {show(value)} ({type(value).__name__})"
            )

    optional = optional_tables()
    records: dict[str, object] = {}
    for table, cls in RECORD_CLASSES.items():
        raw = data.get(table)
        if raw is None:
            if table in optional:
                continue
            required = [f"{table}.{f.name}" for f in fields(cls) if not _has_default(f)]
            raise ParameterError(f"missing required table [{table}] (with {', '.join(required)})")
        assert isinstance(raw, Mapping)
        values: dict[str, object] = {}
        for key, value in raw.items():
            dotted = f"{table}.{key}"
            if dotted not in FIELDS:
                raise unknown(dotted, field_names())
            values[key] = coerce(dotted, value)
        for f in fields(cls):
            if f.name not in values and not _has_default(f):
                raise ParameterError(f"missing required parameter '{table}.{f.name}'")
        records[table] = cls(**values)
    return records, meta


def flatten(data: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested mappings as one level with dotted keys: ``{"a": {"b": 1}}`` → ``{"a.b": 1}``;
    a list of mappings (a TOML array of tables) becomes ``a[0].b``, ``a[1].b`` …"""
    out: dict[str, Any] = {}
    for k, v in data.items():
        key = f"{prefix}{k}"
        if isinstance(v, Mapping):
            out.update(flatten(v, key + "."))
        elif isinstance(v, list) and v and all(isinstance(x, Mapping) for x in v):
            for i, item in enumerate(v):
                out.update(flatten(item, f"{key}[{i}]."))
        else:
            out[key] = v
    return out
