"""A gear set as files record it: the model reference of the planetary model built from it.

A gear set is an input that builds a :class:`~gearchaos.model.planetary.PlanetaryModel`
(:meth:`~gearchaos.model.planetary.PlanetaryModel.from_gearset`). A file records that model
as it records any other (:func:`~gearchaos.model.loading.model_reference`):

``model_class``
    :data:`PLANETARY_MODEL`, ``gearchaos.model.planetary:PlanetaryModel``: gearchaos's own
    class, which the record alone builds again (a built-in, never imported by the recorded
    name);
``model_fields``
    the JSON object ``{"gearset": TOML}`` (:func:`gearset_reference`): the gear set's TOML text,
    which :meth:`~gearchaos.gearset.GearSet.from_toml_string` reads back to an equal gear set
    and validates against the gear-set schema, exactly as the text of a gear-set file.

Beside them a file keeps ``gearset_toml``, the same TOML text, which is all that files written
before this record (and the release that wrote them) read; :func:`recorded_gearset` reads
both kinds of record, and refuses a file whose two copies of the gear set differ.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

from .._text import escape_text
from ..errors import ParameterError
from ..gearset import GearSet
from .planetary import PlanetaryModel

__all__ = [
    "GEARSET_FIELD",
    "PLANETARY_MODEL",
    "gearset_problem",
    "gearset_reference",
    "recorded_gearset",
]

#: The ``model_class`` of a model built from a gear set (``MODULE:CLASS``).
PLANETARY_MODEL = f"{PlanetaryModel.__module__}:{PlanetaryModel.__qualname__}"
#: The one key of the ``model_fields`` of :data:`PLANETARY_MODEL`: the gear set's TOML text.
GEARSET_FIELD = "gearset"


def gearset_reference(gs: GearSet, toml: str | None = None) -> dict[str, str]:
    """The reference of the planetary model built from ``gs``: ``model_class``
    :data:`PLANETARY_MODEL` and ``model_fields`` the JSON object ``{"gearset": TOML}`` (the
    TOML text reads back to a gear set equal to ``gs``); ``toml`` is ``gs.to_toml()`` when the
    caller has it already."""
    text = gs.to_toml() if toml is None else toml
    return {"model_class": PLANETARY_MODEL, "model_fields": json.dumps({GEARSET_FIELD: text})}


def _short(value: Any) -> str:
    text = escape_text(repr(value))
    return text if len(text) <= 60 else f"{text[:57]}..."


def _fields_gearset(fields: Any) -> GearSet:
    """The gear set of the ``model_fields`` of a :data:`PLANETARY_MODEL` record."""
    rule = (
        f"the attribute model_fields of the model {PLANETARY_MODEL} must be the JSON "
        f'object {{"{GEARSET_FIELD}": the gear set\'s TOML text}}'
    )
    if not isinstance(fields, str):
        raise ParameterError(f"{rule}: got {_short(fields)}")
    try:
        values = json.loads(fields)
    except ValueError:
        values = None
    if not isinstance(values, dict):
        raise ParameterError(f"{rule}: got {_short(fields)}")
    if set(values) != {GEARSET_FIELD}:
        keys = ", ".join(escape_text(k) for k in sorted(values)) or "none"
        raise ParameterError(f"{rule}: got the keys {keys}")
    text = values[GEARSET_FIELD]
    if not isinstance(text, str) or not text.strip():
        raise ParameterError(f"{rule}: its {GEARSET_FIELD} is {_short(text)}")
    try:
        return GearSet.from_toml_string(text)
    except ParameterError as exc:
        raise ParameterError(
            f"the gear set of the attribute model_fields is invalid: {escape_text(exc)}"
        ) from None


def _differences(a: GearSet, b: GearSet) -> str:
    """The dotted names whose values differ between ``a`` and ``b`` (at most three)."""
    from ..gearset.mapping import flatten

    fa, fb = flatten(a.to_dict()), flatten(b.to_dict())
    names = sorted(k for k in fa.keys() | fb.keys() if fa.get(k) != fb.get(k))
    shown = ", ".join(escape_text(n) for n in names[:3])
    shown += f" and {len(names) - 3} more" if len(names) > 3 else ""
    return f"{shown} {'differs' if len(names) == 1 else 'differ'}"


def recorded_gearset(attrs: Mapping[str, Any], *, where: str = "the file") -> GearSet | None:
    """The gear set a file's attributes ``attrs`` record, or ``None`` for any other model
    (:func:`gearset_problem` says which record is read and what is refused).

    Raises
    ------
    ParameterError
        The record is damaged or forged: one line naming ``where`` (the file), the attribute
        and the rule it breaks.
    """
    try:
        return _recorded(attrs)
    except ParameterError as exc:
        raise ParameterError(f"{where} is damaged: {exc}") from None


def gearset_problem(attrs: Mapping[str, Any]) -> str | None:
    """What is wrong with the gear set that ``attrs`` record, in words, or ``None``
    (:func:`recorded_gearset` reads it)."""
    try:
        _recorded(attrs)
    except ParameterError as exc:
        return str(exc)
    return None


def _recorded(attrs: Mapping[str, Any]) -> GearSet | None:
    """The gear set ``attrs`` record, or ``None`` for any other model:

    * ``model_class`` is :data:`PLANETARY_MODEL`: the gear set of ``model_fields``; a
      ``gearset_toml`` beside it (files keep one for the previous release) must be the same
      gear set.
    * ``model_class`` names another model: ``None``; a gear set in ``gearset_toml`` beside it
      says the file is damaged.
    * no ``model_class`` (a file written before gear sets recorded their model reference, or
      a model that could not record one): the gear set of ``gearset_toml``, ``None`` when that
      is empty or absent, exactly as such files were always read.

    Raises
    ------
    ParameterError
        The record is damaged or forged: one line naming the attribute and the rule it breaks.
    """
    spec, gtext = attrs.get("model_class"), attrs.get("gearset_toml")
    if gtext is not None and not isinstance(gtext, str):
        raise ParameterError(
            f"the attribute gearset_toml must be the gear set's TOML text: got {_short(gtext)}"
        )
    if spec is not None and not isinstance(spec, str):
        raise ParameterError(
            f"the attribute model_class must name a model class: got {_short(spec)}"
        )
    if spec == PLANETARY_MODEL:
        gs = _fields_gearset(attrs.get("model_fields"))
        if gtext is not None:
            old = _toml_gearset(gtext) if gtext.strip() else None
            if old != gs:
                what = "none" if old is None else f"another ({_differences(old, gs)})"
                raise ParameterError(
                    f"the attribute gearset_toml must record the gear set of the "
                    f"attribute model_fields ({escape_text(gs.name)}), and records {what}"
                )
        return gs
    if spec:
        if gtext:
            raise ParameterError(
                f"the record names the model {escape_text(spec)} (model_class) and a gear "
                "set (gearset_toml), which only the planetary model has"
            )
        return None
    return _toml_gearset(gtext) if gtext else None


def _toml_gearset(text: str) -> GearSet:
    try:
        return GearSet.from_toml_string(text)
    except ParameterError as exc:
        raise ParameterError(
            f"the attribute gearset_toml is no valid gear set: {escape_text(exc)}"
        ) from None
