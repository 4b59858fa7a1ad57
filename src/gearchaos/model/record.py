"""What a file records about its model, and what figures and tables call a model.

A store, branch file or curve file records what it was computed on: a gear set (its TOML,
``gearset_toml``) or a model reference (``model_class``/``model_fields``,
:func:`~gearchaos.model.loading.model_reference`). :func:`recorded_target` turns either into a
target (:mod:`gearchaos.model.target`), from which :func:`~gearchaos.model.target.model_for`
builds the model; the layers above then ask the model's
:class:`~gearchaos.model.capabilities.Capabilities` (its symbols, quantities, scales, names),
never which kind of record it was. :func:`model_title` is how a title names a model.
"""

from __future__ import annotations

from typing import Any

from .contract import Capabilities

__all__ = ["model_title", "parameter_value", "recorded_target", "with_values"]


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
        from ..gearset.io import from_toml_string

        return from_toml_string(text)
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


def parameter_value(target: Any, name: str) -> Any:
    """The value of the parameter ``name`` on ``target``: a gear set's by its dotted name
    (``gs["backlash.sun_planet"]``), a :class:`~gearchaos.model.System`'s the field of its
    model."""
    from ..gearset import GearSet

    if isinstance(target, GearSet):
        return target[name]
    return getattr(target.model, name)


def with_values(target: Any, changes: Any) -> Any:
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
