"""What a file records about its model, written, checked and read in one place, and what
figures and tables call a model.

Every store, simulation result, branch and curve file carries the same attributes to say
which model it ran and how to build that model again:

``model``
    ``planetary`` for a gear set (or a model built from one), else the model's name;
``gearset_toml``
    the gear set's TOML text, empty for any other model;
``model_parameters``
    the model's ``repr`` (empty for a gear set, whose TOML says it all);
``model_class``, ``model_fields``
    what :func:`~gearchaos.model.loading.rebuild_model` needs to build a model that is no gear
    set again (:func:`~gearchaos.model.loading.model_reference`; absent where it cannot).

:func:`target_record` writes them for what a sweep or basin scan ran on, :func:`model_record`
for the model a :class:`~gearchaos.model.System` runs, :func:`record_problem` says what is
wrong with a stored record, and :func:`recorded_target` turns a record back into a target
(:mod:`gearchaos.model.target`), from which :func:`~gearchaos.model.target.model_for` builds
the model; the layers above then ask the model's
:class:`~gearchaos.model.capabilities.Capabilities` (its contacts, symbols, quantities,
scales, names), never which kind of record it was. :func:`model_title` is how a title names a
model, and :func:`sidebands` where a spectrum marks the sidebands of its forcing.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..errors import ParameterError
from ..gearset import GearSet
from .contract import Capabilities
from .loading import model_reference
from .system import System
from .target import Target

__all__ = [
    "PLANETARY",
    "model_record",
    "model_title",
    "parameter_value",
    "record_problem",
    "recorded_target",
    "sidebands",
    "target_record",
    "with_values",
]

#: The ``model`` attribute of a file of a gear set.
PLANETARY = "planetary"


def _gearset_record(gs: GearSet) -> dict[str, str]:
    return {"model": PLANETARY, "gearset_toml": gs.to_toml(), "model_parameters": ""}


def target_record(target: Target) -> dict[str, str]:
    """The record of what a sweep or basin scan ran on: a gear set records its TOML (the
    store's fixed values apply to it); a :class:`System` records its model by name,
    ``repr`` and, where it can, the reference that builds it again (the store's fixed values
    are fields of that model)."""
    if isinstance(target, GearSet):
        return _gearset_record(target)
    model = target.model
    return {
        "model": str(model.name),
        "gearset_toml": "",
        "model_parameters": repr(model),
        **model_reference(model),
    }


def model_record(system: System) -> dict[str, str]:
    """The record of the model ``system`` runs, as built: a model built from a gear set
    records that gear set (its TOML, every value applied), any other model itself
    (:func:`target_record`)."""
    gs = system.capabilities.gearset
    return _gearset_record(gs) if gs is not None else target_record(system)


def record_problem(attrs: Mapping[str, Any]) -> str | None:
    """What is wrong with the record in a file's attributes ``attrs``, in words, or ``None``:
    ``model`` must name the model, ``gearset_toml`` be text, a valid gear set for a
    ``planetary`` file and empty for any other."""
    model, gtext = attrs.get("model"), attrs.get("gearset_toml")
    if not isinstance(model, str) or not model:
        return f"the attribute model must name the model: got {_short(model)}"
    if not isinstance(gtext, str):
        return f"the attribute gearset_toml must be text: got {_short(gtext)}"
    if model == PLANETARY:
        if not gtext.strip():
            return "the attribute gearset_toml (the gear set) is empty"
        try:
            GearSet.from_toml_string(gtext)
        except ParameterError as exc:
            return f"the stored gear set (gearset_toml) is invalid: {exc}"
    elif gtext:
        return f"a {model} store carries a gear set (gearset_toml)"
    return None


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:57]}..."


def recorded_target(attrs: Any, given: Any = None, *, where: str = "the file") -> Any:
    """The target a file's attributes ``attrs`` record: ``given`` when there is one (a gear
    set with a store's fixed values applied), else the gear set of ``gearset_toml``, else a
    :class:`~gearchaos.model.System` at Ω = 1 of the model that ``model_class`` and
    ``model_fields`` describe (:func:`~gearchaos.model.loading.rebuild_model`); ``None`` when
    the file records neither.

    Raises
    ------
    ModelConsentError
        The file needs a model the user has not named (``where`` names the file).
    """
    if given is not None:
        return given
    text = str(attrs.get("gearset_toml", "") or "")
    if text:
        return GearSet.from_toml_string(text)
    from .loading import rebuild_model
    from .system import System

    model = rebuild_model(attrs, where=where)
    return None if model is None else System(model, 1.0)


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
