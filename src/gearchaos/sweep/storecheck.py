"""What every reader of a sweep store checks before it trusts it (issue 10).

The chunk manifest (:mod:`.integrity`) covers the data; this module covers the rest of a store:

* :func:`verify_metadata` — every metadata file (``.zgroup``, ``.zattrs``, ``.zarray``) is
  readable JSON equal to its copy in the consolidated metadata ``.zmetadata``, which readers
  use; a metadata file damaged or edited behind the writer's back is reported by name instead
  of being trusted by one reader and failing in another.
* :func:`verify_attributes` — the attributes agree with the stored sweep specification
  (``sweep_toml``): the dimensions, sizes and coordinates, the solver settings repeated as
  attributes, the gear set (``gearset_toml``) and Ω when it is fixed (``omega_fixed``).
* :func:`verify_progress` — in an interrupted store, the chunks of every finished task match
  the checksums in its marker.

Each raises :class:`~gearchaos.errors.StoreError` whose message starts with the store's path.
"""

from __future__ import annotations

import json
import math
import os
import re
from typing import Any

import numpy as np

from ..errors import StoreError
from .integrity import read_json, verify_chunks

__all__ = ["verify_attributes", "verify_metadata", "verify_progress"]

_RERUN = "run the sweep again with --overwrite (overwrite=True)"


#: What the classification of a store (:func:`gearchaos.sweep.classify.classify_store`) writes
#: before it consolidates: a run interrupted there leaves these arrays unlisted, or these root
#: attributes changed, and the next classification rewrites them (readers use .zmetadata).
CLASSIFY_ARRAYS = frozenset(
    {"motion", "period", "k01", "indicators_agree", "contact_sp", "contact_rp"}
)
CLASSIFY_ATTRS = frozenset({"regime_table", "classification_rtol"})


def _classification_left(key: str, actual: Any, consolidated: Any) -> bool:
    """Whether the root ``.zattrs`` differs from its consolidated copy only in the attributes
    an interrupted classification writes."""
    if key != ".zattrs" or not isinstance(actual, dict) or not isinstance(consolidated, dict):
        return False
    keys = set(actual) | set(consolidated)
    return all(actual.get(k) == consolidated.get(k) for k in keys - CLASSIFY_ATTRS)


def _damaged(root: str, what: str) -> StoreError:
    return StoreError(f"{root} is damaged: {what}. Its data cannot be trusted; {_RERUN}")


def _load_json(path: str) -> Any:
    return read_json(path)


def verify_metadata(root: str) -> None:
    """Every metadata file of a consolidated store equals its consolidated copy, and every
    array directory is listed there."""
    zmeta = os.path.join(root, ".zmetadata")
    if not os.path.exists(zmeta):  # every store is consolidated when it is created
        raise StoreError(
            f"{root!r} is not a readable sweep store: its consolidated metadata .zmetadata is "
            f"missing (damaged, or not written by gearchaos); {_RERUN}"
        )
    try:
        listed = _load_json(zmeta)["metadata"]
        if not isinstance(listed, dict):
            raise TypeError(type(listed).__name__)
    except (OSError, ValueError, KeyError, TypeError):
        raise _damaged(root, "the consolidated metadata .zmetadata is not readable") from None
    for key, consolidated in listed.items():
        if not isinstance(key, str) or ".." in key.split("/"):
            raise _damaged(root, f".zmetadata lists a foreign entry {key!r}")
        path = os.path.join(root, *key.split("/"))
        try:
            actual = _load_json(path)
        except FileNotFoundError:
            raise _damaged(root, f"the metadata file {key} is missing") from None
        except OSError as exc:
            raise _damaged(
                root, f"the metadata file {key} cannot be read ({exc.strerror or exc})"
            ) from None
        except ValueError:
            raise _damaged(root, f"the metadata file {key} is not readable JSON") from None
        if actual != consolidated and not _classification_left(key, actual, consolidated):
            raise _damaged(root, f"the metadata file {key} differs from .zmetadata")
        if key.endswith("/.zarray"):
            problem = array_schema_problem(actual)
            if problem:
                raise _damaged(root, f"the array {key[: -len('/.zarray')]} {problem}")
    for entry in sorted(os.listdir(root)):
        if os.path.exists(os.path.join(root, entry, ".zarray")) and (
            f"{entry}/.zarray" not in listed and entry not in CLASSIFY_ARRAYS
        ):
            raise _damaged(root, f"the array {entry} is not in the consolidated metadata")


#: The element types gearchaos writes: little-endian (or byte-order-free) floats, integers,
#: booleans and Unicode labels.
_DTYPES = re.compile(r"(<f8|\|i1|<i2|<i4|<i8|\|b1|<U[0-9]{1,3})")


def array_schema_problem(meta: Any) -> str | None:
    """What is wrong with an array's ``.zarray`` against what gearchaos writes, or None:
    the element type (``dtype``), the memory ``order`` C, no ``filters``, a ``fill_value``
    of NaN for floats and none otherwise, the Blosc compressor. Edited consistently in
    ``.zarray`` and ``.zmetadata``, any of these would make every reader decode garbage."""
    if not isinstance(meta, dict):
        return "has no readable metadata"
    dtype = meta.get("dtype")
    if not isinstance(dtype, str) or not _DTYPES.fullmatch(dtype):
        return f"has the element type {dtype!r}, which gearchaos never writes"
    if meta.get("order") != "C":
        return f"has the memory order {meta.get('order')!r} (gearchaos writes 'C')"
    if meta.get("filters") is not None:
        return "has filters gearchaos never writes"
    fill = meta.get("fill_value")
    if dtype == "<f8":
        if fill != "NaN":
            return f"has the fill value {fill!r} (a float array's is NaN)"
    elif fill is not None:
        return f"has the fill value {fill!r} (only float arrays have one)"
    comp = meta.get("compressor")
    if not (isinstance(comp, dict) and comp.get("id") == "blosc"):
        return f"has the compressor {comp!r} (gearchaos writes Blosc)"
    return None


def _same(got: Any, want: Any) -> bool:
    """Equal, and of the same kind (a bool is not the number 1, a list not a string)."""
    if isinstance(want, bool) or isinstance(got, bool):
        return got is want
    if isinstance(want, int | float):
        return isinstance(got, int | float) and float(got) == float(want)
    return type(got) is type(want) and bool(got == want)


def _recorded_settings(solver: Any, attrs: Any) -> dict[str, Any]:
    """The solver settings a store's attributes must repeat: its record
    (:meth:`~gearchaos.integrate.settings.SolverSettings.to_record`); a setting that older
    stores did not record (:data:`~gearchaos.integrate.settings.UNRECORDED`) only where the
    attribute is there."""
    from ..integrate.settings import UNRECORDED

    record = solver.to_record()
    return {
        name: record.get(name, UNRECORDED.get(name))
        for name in solver.field_names()
        if name not in UNRECORDED or name in attrs
    }


def verify_attributes(root: str, ds: Any) -> Any:
    """Check a sweep dataset's attributes against its sweep specification; return the
    :class:`~gearchaos.sweep.spec.SweepSpec`."""
    from ..gearset.schema import OMEGA
    from .spec import SweepSpec

    attrs = ds.attrs
    text = attrs.get("sweep_toml")
    if not isinstance(text, str) or not text.strip():
        raise _damaged(
            root,
            f"the attribute sweep_toml (the sweep specification) must be TOML text: got "
            f"{_short(text)}",
        )
    try:
        spec = SweepSpec.from_toml(text)
    except StoreError as exc:
        raise _damaged(root, f"sweep_toml: {exc}") from None
    dims = tuple(str(d) for d in ds["status"].dims)
    if dims != spec.dims:
        raise _damaged(
            root, f"status has the dimensions {dims}, the sweep specification {spec.dims}"
        )
    shape = tuple(int(ds.sizes[d]) for d in dims)
    if shape != spec.shape:
        raise _damaged(root, f"status has the shape {shape}, the sweep specification {spec.shape}")
    for axis in spec.axes:
        try:
            values = np.asarray(ds[axis.name].values, dtype=np.float64)
        except (KeyError, TypeError, ValueError):
            raise _damaged(root, f"the coordinate {axis.name} is not readable") from None
        if values.tobytes() != np.asarray(axis.values, dtype=np.float64).tobytes():
            raise _damaged(root, f"the coordinate {axis.name} differs from the sweep specification")
    if "section" in ds.dims and int(ds.sizes["section"]) != spec.solver.periods:
        raise _damaged(
            root,
            f"{ds.sizes['section']} section points per sweep point, the sweep specification "
            f"records {spec.solver.periods} periods",
        )
    expected = {
        **_recorded_settings(spec.solver, attrs),
        "initial_conditions": spec.initial_conditions,
        "direction": spec.direction,
        "dims": list(spec.dims),
    }
    for key, want in expected.items():
        if not _same(attrs.get(key), want):
            raise _damaged(
                root,
                f"the attribute {key} is {_short(attrs.get(key))}, the sweep specification "
                f"says {want!r}",
            )
    if not isinstance(attrs.get("complete"), bool):
        got = _short(attrs.get("complete"))
        raise _damaged(root, f"the attribute complete must be true or false: got {got}")
    _verify_target(root, attrs)
    _verify_element_types(root, ds, spec)
    swept = OMEGA in [a.name for a in spec.axes]
    raw = attrs.get("omega_fixed")
    if swept and "omega_fixed" in attrs:
        raise _damaged(root, f"omega is swept but the attribute omega_fixed is {_short(raw)}")
    if not swept:
        if (
            isinstance(raw, bool)
            or not isinstance(raw, int | float)
            or not (math.isfinite(raw) and raw > 0)
        ):
            raise _damaged(
                root, f"the attribute omega_fixed (Ω) must be a number > 0: got {_short(raw)}"
            )
        fixed = dict(spec.fixed).get(OMEGA)
        if fixed is not None and not _same(raw, fixed):
            raise _damaged(
                root,
                f"the attribute omega_fixed is {raw!r}, the sweep specification fixes "
                f"omega = {fixed!r}",
            )
    table = attrs.get("regime_table")
    if table is not None:
        try:
            parsed = json.loads(table) if isinstance(table, str) else None
        except ValueError:
            parsed = None
        if not isinstance(parsed, dict):
            raise _damaged(root, "the attribute regime_table is not a JSON table")
    return spec


def _verify_element_types(root: str, ds: Any, spec: Any) -> None:
    """The arrays whose element type the sweep's layout fixes have it: floats for its
    coordinates, the section values of the observed variables and the final states; the
    status, step counts, verdict and orbit evidence as their tables say. An array re-typed
    (edited consistently in ``.zarray`` and ``.zmetadata``: ``<f8`` to ``<i8`` with no fill
    value) would read every stored float's bits as a huge integer. Stores written since the
    manifest records a digest of every array's metadata are checked whole by
    :func:`~gearchaos.sweep.integrity.verify_manifest`; this check also covers older ones."""
    from .variables import ORBIT_VARIABLES, SKIPPED, STEP_COUNTS
    from .verdicts import VERDICT_VARIABLES

    expected: dict[str, Any] = {name: np.float64 for name in spec.observe}
    expected.update({a.name: np.float64 for a in spec.axes})
    expected.update(final_state=np.float64, status=np.int8, section=np.int64)
    expected.update({name: np.int64 for name in (*STEP_COUNTS, SKIPPED)})
    for table in (VERDICT_VARIABLES, ORBIT_VARIABLES):
        for name, (_, dtype, _) in table.items():
            if np.dtype(dtype).kind != "U":  # a label's width is no damage
                expected[name] = np.dtype(dtype)
    for name in sorted(set(expected) & set(ds.variables)):
        dtype = ds.variables[name].dtype
        if dtype != expected[name]:
            raise _damaged(
                root,
                f"the array {name} has the element type {dtype}, but a sweep writes it as "
                f"{np.dtype(expected[name])} (the array was re-typed)",
            )


def _verify_target(root: str, attrs: Any) -> None:
    """The model's record is whole (:func:`~gearchaos.model.record.record_problem`)."""
    from ..model.record import record_problem

    problem = record_problem(attrs)
    if problem is not None:
        raise _damaged(root, problem)


def verify_progress(root: str, progress_dir: str) -> None:
    """The chunks of every finished task of an interrupted store match their marker."""
    d = os.path.join(root, progress_dir)
    if not os.path.isdir(d):
        return
    for name in sorted(os.listdir(d)):
        if not name.endswith(".done"):
            continue
        try:
            chunks = read_json(os.path.join(d, name))["chunks"]
            if not isinstance(chunks, dict):
                raise TypeError(type(chunks).__name__)
        except (OSError, ValueError, KeyError, TypeError):
            continue  # a marker torn by a kill: its task is simply not finished
        problems = verify_chunks(root, chunks)
        if problems:
            shown = "; ".join(problems[:5])
            raise _damaged(root, f"{shown} (task {name[:-5]})")


def _short(value: Any, limit: int = 60) -> str:
    r = repr(value)
    return r if len(r) <= limit else r[: limit - 3] + "..."
