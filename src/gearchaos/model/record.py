"""What a file records about its model, written, checked and read in one place, and what
figures and tables call a model.

Every store, simulation result, branch and curve file carries the same attributes to say
which model it ran and how to build that model again:

``model``
    ``planetary`` for a gear set (or a model built from one), else the model's name;
``model_class``, ``model_fields``
    the model reference, what :func:`~gearchaos.model.loading.rebuild_model` needs to build
    the model again (:func:`~gearchaos.model.loading.model_reference`; absent where it
    cannot): for a gear set the planetary model and, as its fields, the gear set's TOML
    (:mod:`gearchaos.model.gearset_record`);
``gearset_toml``
    the gear set's TOML text again, empty for any other model: the previous release (and
    every file written before gear sets recorded their model reference) reads the gear set
    from here only, so files written now stay readable by it;
``model_parameters``
    the model's ``repr`` (empty for a gear set, whose TOML says it all).

:func:`target_record` writes them for what a sweep or basin scan ran on, :func:`model_record`
for the model a :class:`~gearchaos.model.System` runs, :func:`record_problem` says what is
wrong with a stored record, and :func:`recorded_target`, the one reader of every record (new
or old), turns a record back into a target (:mod:`gearchaos.model.target`), from which
:func:`~gearchaos.model.target.model_for` builds the model (:func:`recorded_gearset` is its
gear set alone, never needing the user's consent, and :func:`recorded_parameters` the values
of a model that is no gear set, for titles); the layers above then ask the model's
:class:`~gearchaos.model.capabilities.Capabilities` (its contacts, symbols, quantities,
scales, names), never which kind of record it was. :func:`model_title` is how a title names a
model, and :func:`sidebands` where a spectrum marks the sidebands of its forcing.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

from ..errors import ParameterError
from ..gearset import GearSet
from .contract import Capabilities
from .gearset_record import PLANETARY_MODEL, gearset_problem, gearset_reference, recorded_gearset
from .loading import LAYOUT_FIELDS, model_reference, rebuild_model
from .system import System
from .target import Target

__all__ = [
    "PLANETARY",
    "model_record",
    "model_title",
    "parameter_value",
    "record_problem",
    "recorded_gearset",
    "recorded_parameters",
    "recorded_target",
    "sidebands",
    "target_record",
    "with_values",
]

#: The ``model`` attribute of a file of a gear set.
PLANETARY = "planetary"


def _gearset_record(gs: GearSet) -> dict[str, str]:
    """The record of a gear set: the reference of the planetary model built from it (whose
    fields are the gear set: :func:`~gearchaos.model.loading.model_reference` of that model)
    and, for the previous release, the same TOML in ``gearset_toml``."""
    text = gs.to_toml()
    return {
        "model": PLANETARY,
        "gearset_toml": text,
        "model_parameters": "",
        **gearset_reference(gs, text),
    }


def target_record(target: Target) -> dict[str, str]:
    """The record of what a sweep or basin scan ran on: a gear set (or a
    :class:`System` of a model built from one) records the planetary model's reference and
    the gear set's TOML (the store's fixed values apply to the gear set); any other
    :class:`System` records its model by name, ``repr`` and, where it can, the reference that
    builds it again (the store's fixed values are fields of that model)."""
    if isinstance(target, GearSet):
        return _gearset_record(target)
    if target.capabilities.gearset is not None:
        return _gearset_record(target.capabilities.gearset)
    model = target.model
    return {
        "model": str(model.name),
        "gearset_toml": "",
        "model_parameters": repr(model),
        **model_reference(model),
    }


def model_record(system: System) -> dict[str, str]:
    """The record of the model ``system`` runs, as built: a model built from a gear set
    records that gear set (every value applied), any other model itself
    (:func:`target_record`)."""
    return target_record(system)


def record_problem(attrs: Mapping[str, Any]) -> str | None:
    """What is wrong with the record in a file's attributes ``attrs``, in words, or ``None``:
    ``model`` must name the model, ``gearset_toml`` be text, a valid gear set for a
    ``planetary`` file and empty for any other; ``model_class`` (where there is one) must be
    a name with ``model_fields`` text beside it, and ``model_fields`` have a ``model_class``;
    the planetary model's ``model_fields`` must be a valid gear set, the one of
    ``gearset_toml`` (:func:`~gearchaos.model.gearset_record.gearset_problem`). The fields of
    any other model are checked when it is built (it may need the user's consent)."""
    model, gtext = attrs.get("model"), attrs.get("gearset_toml")
    spec, fields = attrs.get("model_class"), attrs.get("model_fields")
    if not isinstance(model, str) or not model:
        return f"the attribute model must name the model: got {_short(model)}"
    if not isinstance(gtext, str):
        return f"the attribute gearset_toml must be text: got {_short(gtext)}"
    if spec is not None and (not isinstance(spec, str) or not spec):
        return f"the attribute model_class must name the model's class: got {_short(spec)}"
    if spec is None and fields is not None:
        return "the attribute model_fields has no model_class beside it"
    if spec is not None and not isinstance(fields, str):
        return f"the attribute model_fields must be JSON text: got {_short(fields)}"
    problem = gearset_problem(attrs)
    if problem is not None:
        return problem
    if model == PLANETARY:
        if not gtext.strip():
            return "the attribute gearset_toml (the gear set) is empty"
    elif gtext:
        return f"a {model} store carries a gear set (gearset_toml)"
    return None


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:57]}..."


def recorded_target(attrs: Any, given: Any = None, *, where: str = "the file") -> Any:
    """The target a file's attributes ``attrs`` record: ``given`` when there is one (a gear
    set with a store's fixed values applied), else the gear set of a planetary model's
    reference (or of ``gearset_toml`` in a file written before gear sets recorded one:
    :func:`~gearchaos.model.gearset_record.recorded_gearset`), else a
    :class:`~gearchaos.model.System` at Ω = 1 of the model that ``model_class`` and
    ``model_fields`` describe (:func:`~gearchaos.model.loading.rebuild_model`); ``None`` when
    the file records neither.

    Raises
    ------
    ModelConsentError
        The file needs a model the user has not named (``where`` names the file).
    ParameterError
        The record is damaged: no valid gear set, two gear sets that differ, fields the model
        refuses (``where`` names the file).
    """
    if given is not None:
        return given
    gearset = recorded_gearset(attrs, where=where)
    if gearset is not None:
        return gearset
    model = rebuild_model(attrs, where=where)
    return None if model is None else System(model, 1.0)


def recorded_parameters(attrs: Mapping[str, Any]) -> dict[str, Any]:
    """The parameter values a file records for a model that is no gear set: its
    ``model_fields`` without the fields of its layout (kind, name, sizes, state and
    observable names), read without building the model; ``{}`` for a gear set (the gear
    set's registry names its parameters) or a file without ``model_fields``.

    Raises
    ------
    ParameterError
        ``model_fields`` is no JSON object.
    """
    fields = attrs.get("model_fields")
    if fields is None or attrs.get("model_class") == PLANETARY_MODEL:
        return {}
    try:
        values = json.loads(str(fields))
    except ValueError:
        values = None
    if not isinstance(values, dict):
        raise ParameterError(
            f"the attribute model_fields must be a JSON object of the model's fields: got "
            f"{_short(fields)}"
        )
    return {str(k): v for k, v in values.items() if k not in LAYOUT_FIELDS}


def model_title(model: Any) -> tuple[str, str]:
    """(what, name) of ``model`` as titles and summaries name it: ``("gear set",
    "sheng2016")`` for a model built from a gear set (a gear set named after a built-in preset
    whose values are another preset's named by that one), else ``("model", its name)``."""
    caps = Capabilities.of(model)
    if caps.gearset is None:
        return ("model", caps.name)
    from ..gearset import list_presets, preset_of

    name = str(caps.gearset.name)
    if name in {n for n, _ in list_presets()}:
        shown = preset_of(caps.gearset)
        if shown is not None:
            return ("gear set", shown)
    return ("gear set", name)


def parameter_value(target: Target, name: str) -> float:
    """The current value of the numeric parameter ``name`` of ``target``: a gear set's by its
    dotted name (``gs["backlash.sun_planet"]``), a :class:`~gearchaos.model.System`'s the field
    of its model, or its Ω. A gear set has no Ω of its own, and a parameter that is not a
    number cannot be varied: both are refused (:class:`~gearchaos.errors.ParameterError`)."""
    from ..gearset.mapping import get_value
    from .target import OMEGA

    if isinstance(target, System):
        if name == OMEGA:
            return float(target.omega)
        if hasattr(target.model, name):
            value = getattr(target.model, name)
            if isinstance(value, int | float) and not isinstance(value, bool):
                return float(value)
        raise ParameterError(f"{name} is no numeric field of the model {target.name}")
    if name == OMEGA:
        raise ParameterError("omega has no value of its own in a gear set: fix it (omega=1.5)")
    value = get_value(target, name)
    if not isinstance(value, int | float) or isinstance(value, bool):
        raise ParameterError(f"{name} must be a numeric parameter to vary: got {value!r}")
    return float(value)


def with_values(target: Target, changes: Any) -> Any:
    """``target`` with the parameter ``changes`` (no Ω) applied, of the same kind: a gear set
    evolved by dotted name, a :class:`~gearchaos.model.System` whose model has the changed
    fields (at the same Ω). Unknown names are refused
    (:class:`~gearchaos.errors.ParameterError`)."""
    from ..gearset import GearSet
    from .system import System
    from .target import model_for

    if isinstance(target, GearSet):
        return target.evolve(dict(changes))
    return System(model_for(target, dict(changes)), target.omega)


def sidebands(model: Any) -> tuple[float, ...]:
    """The offsets s of the sidebands h ± s around each harmonic h of ``model``'s forcing
    frequency, in multiples of it, that its spectrum marks: a model built from a gear set with
    eccentricities has s = f_s/f_m = 1/z_s (the eccentricities modulate the meshes at the
    sun's speed relative to the carrier, f_s = f_m/z_s); other models have none."""
    gearset = Capabilities.of(model).gearset
    if gearset is None or not gearset.has_eccentricity:
        return ()
    return (1.0 / float(gearset.teeth.sun),)
