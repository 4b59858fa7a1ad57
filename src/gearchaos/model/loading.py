"""Models named by the user, and models named by files.

A model class is found by a name in two ways, with different trust:

* **The user names it**: ``--model FILE.py:CLASS``, ``--model MODULE:CLASS`` or the name of
  a model installed as an entry point of ``gearchaos.models`` (:func:`load_model_class`).
  Naming it is the user's consent to run its code; the class is remembered for this process.
* **A file names it**: a store, branch, orbit or curve file records ``model_class`` and
  ``model_fields`` (:func:`model_reference`) so that the model can be built again
  (:func:`rebuild_model`). A file is data: whoever wrote it may have put any path or module
  there (``evil/evilmod.py:Evil``, ``os:system``), so the record alone never imports
  anything. :func:`stored_model_class` matches it against what the user already trusts:

  1. gearchaos's own models by their recorded name, an allow-list of classes, not of import
     paths: the reference systems (:data:`REFERENCE_MODELS`) and the planetary model, whose
     ``model_fields`` are the gear set it is built from (:mod:`.gearset_record`);
  2. the classes the user named in this process (:func:`load_model_class`), by the recorded
     reference, or by the class name when the file has moved;
  3. the :class:`~gearchaos.model.contract.UserModel` subclasses the user's own code has
     defined in this process, by the recorded reference;
  4. the models installed as entry points of ``gearchaos.models`` whose target is the
     recorded ``MODULE:CLASS`` (or whose class is the recorded one).

  Anything else is refused with :class:`ModelConsentError`, one line saying which model the
  file needs and how to supply it.
"""

from __future__ import annotations

import dataclasses
import json
import os
import sys
from typing import Any

from .._text import escape_text
from ..errors import ParameterError
from .contract import Capabilities, UserModel, check_model
from .gearset_record import PLANETARY_MODEL, gearset_reference, recorded_gearset
from .library import BacklashOscillator, Duffing, LinearSystem, Lorenz
from .planetary import PlanetaryModel

__all__ = [
    "ENTRY_POINT_GROUP",
    "LAYOUT_FIELDS",
    "REFERENCE_MODELS",
    "ModelConsentError",
    "build_model",
    "load_model_class",
    "model_reference",
    "model_spec",
    "name_models",
    "named_models",
    "rebuild_model",
    "stored_model_class",
]

#: The entry-point group under which installed packages offer models (``--model NAME``).
ENTRY_POINT_GROUP = "gearchaos.models"

#: gearchaos's reference systems by the name a file records for them (``MODULE:CLASS``): the
#: only models a file's record alone builds again.
REFERENCE_MODELS: dict[str, type] = {
    f"{cls.__module__}:{cls.__qualname__}": cls
    for cls in (BacklashOscillator, Duffing, LinearSystem, Lorenz)
}

#: Fields of a reference system that are its layout, not parameters: a file's record must
#: leave them at their defaults (another kernel kind or state size would make the compiled
#: right-hand side read and write outside its arrays).
LAYOUT_FIELDS = ("kind", "name", "n_state", "n_track", "n_contact_forces", "state_names",
                  "obs_names")  # fmt: skip

#: The classes the user named in this process, by the name given (:func:`load_model_class`).
_NAMED: dict[str, type] = {}


class ModelConsentError(ParameterError):
    """A file needs a model that the user has not named: gearchaos does not run code a file
    names (the message says which model and how to supply it)."""


# ------------------------------------------------------------------ named by the user
def load_model_class(spec: str) -> type:
    """The model class named by ``spec``: ``path/to/file.py:ClassName`` (the file's directory
    joins ``sys.path`` and the file is imported under its stem, so worker processes import it
    too), ``package.module:ClassName``, or the name of an entry point in the group
    ``gearchaos.models``. Naming a class is consent to build it again from files that record
    it (:func:`rebuild_model`)."""
    import importlib
    import importlib.util

    if not isinstance(spec, str) or not spec.strip():
        raise ParameterError(f"--model must be FILE.py:CLASS, MODULE:CLASS or a name: got {spec!r}")
    shown = escape_text(spec)
    where, sep, attr = spec.rpartition(":")
    if not sep:
        from importlib.metadata import entry_points

        found = [ep for ep in entry_points(group=ENTRY_POINT_GROUP) if ep.name == spec]
        if not found:
            known = sorted(ep.name for ep in entry_points(group=ENTRY_POINT_GROUP))
            raise ParameterError(
                f"--model {shown}: no model of that name is installed (entry points of "
                f"{ENTRY_POINT_GROUP}: {', '.join(known) or 'none'}); or give FILE.py:CLASS"
            )
        cls = _imported(found[0].load, shown)
    else:
        if where.endswith(".py"):
            path = os.path.abspath(where)
            if not os.path.isfile(path):
                raise ParameterError(f"--model {shown}: no such file '{escape_text(where)}'")
            folder, stem = os.path.split(path)[0], os.path.splitext(os.path.basename(path))[0]
            if not stem.isidentifier():
                raise ParameterError(
                    f"--model {shown}: the file name must be a Python identifier (it is "
                    f"imported as a module): got '{escape_text(stem)}'"
                )
            old = sys.modules.get(stem)
            if old is not None and os.path.abspath(getattr(old, "__file__", "") or "") != path:
                raise ParameterError(
                    f"--model {shown}: a different module named {stem!r} is already imported; "
                    "rename the file"
                )
            if folder not in sys.path:
                sys.path.insert(0, folder)
            module = _imported(lambda: importlib.import_module(stem), shown, path)
        else:
            module = _imported(lambda: importlib.import_module(where), shown)
        cls = getattr(module, attr, None)
        if cls is None:
            raise ParameterError(
                f"--model {shown}: {escape_text(where)} defines no '{escape_text(attr)}'"
            )
    if not isinstance(cls, type):
        raise ParameterError(f"--model {shown} must name a model class: got {type(cls).__name__}")
    _NAMED[spec] = cls
    return cls


def _imported(load: Any, shown: str, path: str | None = None) -> Any:
    """``load()``, the import of the user's model (``--model``, shown as ``shown``): whatever
    its code raises while imported — an exception, a syntax error, ``sys.exit`` — is refused
    in one line naming the file, the line and the exception; what it prints goes to stderr,
    so that ``--json`` output stays JSON. Ctrl-C is not caught."""
    import contextlib

    try:
        with contextlib.redirect_stdout(sys.stderr):
            return load()
    except (Exception, SystemExit) as exc:
        where = _raised_at(exc, path)
        kind = type(exc).__name__
        text = exc.msg if isinstance(exc, SyntaxError) else str(exc)
        what = f"{kind}: {text}" if text else kind
        if isinstance(exc, SystemExit):
            what = f"it calls sys.exit({text}) when imported"
        raise ParameterError(
            f"--model {shown}: importing it failed{where}: {escape_text(what)}"
        ) from None


def _raised_at(exc: BaseException, path: str | None) -> str:
    """`` at FILE, line N``: where ``exc`` was raised — a syntax error's own place, else the
    deepest frame of the model's file ``path`` (else of any file that is not importlib's)."""
    import traceback

    if isinstance(exc, SyntaxError) and exc.filename:
        return f" at {escape_text(exc.filename)}, line {exc.lineno}"
    import importlib

    skip = (os.path.dirname(importlib.__file__ or ""), os.path.abspath(__file__))
    frames = [
        f
        for f in traceback.extract_tb(exc.__traceback__)
        if not f.filename.startswith("<") and not os.path.abspath(f.filename).startswith(skip)
    ]
    own = [f for f in frames if path is not None and os.path.abspath(f.filename) == path]
    chosen = own or frames
    if not chosen:
        return ""
    return f" at {escape_text(chosen[-1].filename)}, line {chosen[-1].lineno}"


def named_models() -> tuple[str, ...]:
    """What the user named with :func:`load_model_class` in this process, as given: a worker
    process names them again (:func:`name_models`) to build the same models from files."""
    return tuple(_NAMED)


def name_models(specs: tuple[str, ...] | list[str]) -> None:
    """Name the model classes ``specs`` (:func:`named_models` of the parent process) in this
    process: the initializer of a worker that rebuilds models from files."""
    for spec in specs:
        load_model_class(spec)


def build_model(cls: type, changes: dict[str, Any] | None = None) -> Any:
    """An instance of the dataclass model ``cls`` with ``changes`` by field name (text values,
    as ``--set`` gives them, converted to the field's type), checked against the contract."""
    if not dataclasses.is_dataclass(cls):
        raise ParameterError(f"{cls.__name__} must be a dataclass whose fields are its parameters")
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    values: dict[str, Any] = {}
    for key, value in (changes or {}).items():
        field = fields.get(key)
        if field is None:
            import difflib

            close = difflib.get_close_matches(key, list(fields), n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ParameterError(
                f"unknown parameter {key!r} of {cls.__name__} (its parameters: "
                f"{', '.join(fields)}){hint}"
            )
        default = field.default
        if isinstance(value, str) and not isinstance(default, str):
            kind = int if isinstance(default, int) and not isinstance(default, bool) else float
            try:
                value = kind(value)
            except ValueError:
                raise ParameterError(
                    f"{key} must be {'an integer' if kind is int else 'a number'}: got {value!r}"
                ) from None
        values[key] = value
    return _instantiate(cls, values, cls.__name__)


def _instantiate(cls: type, values: dict[str, Any], what: str) -> Any:
    """``cls(**values)`` checked against the contract; a constructor's refusal of the values
    as :class:`~gearchaos.errors.ParameterError` naming ``what``."""
    try:
        model = cls(**values)
    except TypeError as exc:
        raise ParameterError(f"{what}: the values do not fit the class ({exc})") from None
    check_model(model)
    return model


# ------------------------------------------------------------------ named by a file
def model_spec(cls: type) -> str | None:
    """The name a file records for the model class ``cls``: ``MODULE:CLASS`` for a class of an
    importable package (``gearchaos.model.library:Duffing``), ``/abs/path/FILE.py:CLASS`` for
    one loaded from a file; ``None`` for a class of no module file."""
    module = sys.modules.get(cls.__module__)
    path = getattr(module, "__file__", None) or ""
    package = (getattr(module, "__package__", None) or "").split(".")[0]
    if package and package in sys.modules and not path.endswith(f"{cls.__module__}.py"):
        where = cls.__module__  # importable by name (gearchaos.model.library, a package)
    elif path:
        where = os.path.abspath(path)  # a file loaded with --model FILE.py:CLASS
    else:
        return None
    return f"{where}:{cls.__qualname__}"


def model_reference(model: Any) -> dict[str, str]:
    """What a store or branch file records to build ``model`` again (:func:`rebuild_model`):
    ``model_class`` (:func:`model_spec`) and ``model_fields`` (JSON of its dataclass fields).
    A model built from a gear set records the planetary model and, as its fields, that gear
    set (:func:`~gearchaos.model.gearset_record.gearset_reference`); a model that is no
    dataclass of JSON values records nothing."""
    gearset = Capabilities.of(model).gearset
    if gearset is not None:
        return gearset_reference(gearset)
    if not dataclasses.is_dataclass(model):
        return {}
    fields = {f.name: getattr(model, f.name) for f in dataclasses.fields(model) if f.init}
    try:
        text = json.dumps(fields, allow_nan=False)
    except (TypeError, ValueError):
        return {}
    spec = model_spec(type(model))
    return {} if spec is None else {"model_class": spec, "model_fields": text}


def _user_models() -> list[type]:
    """Every :class:`~gearchaos.model.contract.UserModel` subclass defined in this process."""
    out: list[type] = []
    todo = list(UserModel.__subclasses__())
    while todo:
        cls = todo.pop()
        out.append(cls)
        todo.extend(cls.__subclasses__())
    return out


def _installed(spec: str, name: str) -> type | None:
    """The model installed as an entry point of ``gearchaos.models`` that ``spec`` records:
    the entry point whose target is ``spec``, else one of class ``name`` whose class
    :func:`model_spec` gives ``spec``."""
    from importlib.metadata import entry_points

    points = list(entry_points(group=ENTRY_POINT_GROUP))
    exact = [ep for ep in points if ep.value.replace(" ", "") == spec]
    others = [ep for ep in points if ep not in exact and ep.attr == name]
    for ep in exact + others:
        try:
            cls = ep.load()
        except Exception as exc:  # an installed package that fails to import
            raise ParameterError(
                f"the installed model {ep.name} ({ep.value}) cannot be loaded: "
                f"{type(exc).__name__}: {exc}"
            ) from None
        if isinstance(cls, type) and (ep in exact or model_spec(cls) == spec):
            return cls
    return None


def stored_model_class(spec: str, *, where: str) -> type:
    """The class of the model a file records as ``spec`` (``model_class``), among the classes
    the user trusts (the module docstring's order); never an import of what ``spec`` names.

    Raises
    ------
    ModelConsentError
        No trusted class matches: one line naming ``where`` (the file, as the user gave it),
        the model it needs and the way to supply it (``--model FILE.py:CLASS`` or an entry
        point).
    """
    spec = str(spec)
    name = spec.rpartition(":")[2]
    if spec == PLANETARY_MODEL:
        return PlanetaryModel
    found = REFERENCE_MODELS.get(spec)
    if found is not None:
        return found
    named = list(dict.fromkeys(_NAMED.values()))
    for cls in named + _user_models():
        if model_spec(cls) == spec:
            return cls
    same = [cls for cls in named if cls.__qualname__ == name]
    if len(same) == 1:  # the file the user named is the recorded class, moved
        return same[0]
    installed = _installed(spec, name)
    if installed is not None:
        return installed
    gave = ""
    if named:
        # the classes this process was given (a command gives one; a Python session may
        # have named several): none of them is the recorded one
        gave = "; the model(s) named with --model in this process: " + ", ".join(
            escape_text(c.__qualname__) for c in named
        )
    raise ModelConsentError(
        f"{where} needs the model '{escape_text(spec)}', and gearchaos never runs code that a "
        f"file names: if you trust it, give --model FILE.py:{escape_text(name) or 'CLASS'} "
        f"(the file that defines it){gave}, or install it as an entry point of "
        f"{ENTRY_POINT_GROUP}"
    )


def rebuild_model(attrs: Any, *, where: str = "the file") -> Any:
    """The model a store's or file's ``model_class``/``model_fields`` attributes describe
    (:func:`model_reference`), or ``None`` when they are absent. A model built from a gear set
    is the planetary model of the gear set the record holds
    (:func:`~gearchaos.model.gearset_record.recorded_gearset`: its ``model_fields``, or
    ``gearset_toml`` in a file written before gear sets recorded their model); any other class
    is found by :func:`stored_model_class` (never imported by its recorded name). ``where``
    names the file in messages.

    Raises
    ------
    ModelConsentError
        The file needs a model the user has not named.
    ParameterError
        ``model_fields`` is no JSON object of the class's fields (for the planetary model: no
        valid gear set, or another than ``gearset_toml``'s), a reference system's record
        changes its layout (kind, state names, sizes), or the values break the contract.
    """
    gearset = recorded_gearset(attrs, where=where)
    if gearset is not None:
        return PlanetaryModel.from_gearset(gearset)
    spec, fields = attrs.get("model_class"), attrs.get("model_fields")
    if not spec or fields is None:
        return None
    spec = str(spec)
    cls = stored_model_class(spec, where=where)
    try:
        values = json.loads(str(fields))
    except ValueError:
        values = None
    if not isinstance(values, dict) or not dataclasses.is_dataclass(cls):
        raise ParameterError(
            f"{where}: its attribute model_fields must be a JSON object of the fields of "
            f"{cls.__qualname__}: got '{escape_text(str(fields)[:80])}'"
        )
    for key, value in values.items():  # JSON lists back to the tuples dataclasses hold
        if isinstance(value, list):
            values[key] = tuple(value)
    if cls in REFERENCE_MODELS.values():
        missing = dataclasses.MISSING
        defaults = {f.name: f.default for f in dataclasses.fields(cls) if f.default is not missing}
        for key in LAYOUT_FIELDS:
            if key in values and key in defaults and values[key] != defaults[key]:
                raise ParameterError(
                    f"{where}: its attribute model_fields changes the layout of "
                    f"{cls.__qualname__} ({key} = '{escape_text(values[key])}', not "
                    f"{defaults[key]!r}); the file is damaged or forged"
                )
    return _instantiate(cls, values, f"{where}: {escape_text(spec)} (stored fields)")
