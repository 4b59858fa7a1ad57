"""The files of a CSV export: the point table, the section table and their sidecar.

An export to ``run.csv`` writes

* ``run.csv`` — the point table (:mod:`.export_table`): a header row of column names, then
  one row per point; nothing else, so ``pandas.read_csv(path)`` and a spreadsheet read it as
  it is;
* ``run.sections.csv`` — the section table, when the result records section samples;
* ``run.csv.json`` — the sidecar: the provenance (package versions of the run and of the
  export, the gear set or model, the sweep or basin specification, the solver settings and
  the protocol, the physical scales) and, for every column of both tables, its unit, its
  meaning and the values a coded column takes.

Every field of both tables is written by the :mod:`csv` module (quoted where it holds a
comma or a quote): a name or a label can never start a row of its own, and text from the
result has passed :func:`~gearchaos._text.escape_text` before it gets here.

**Ownership.** The sidecar carries gearchaos's mark (:mod:`gearchaos._marks`:
``gearchaos_output:sha256:…``, the digest of the sidecar itself) and records the SHA-256 digest
of each table it describes (:data:`MARK`). A file at an export's path is replaced only when it
is gearchaos's: a sidecar whose mark holds, and a table whose digest the sidecar beside it
records. A file that merely mentions gearchaos, or a table edited since (saved from a
spreadsheet), is the user's and is refused. The sidecar is written first and also records the
digests of the tables it is about to replace, so an export interrupted between its files
leaves every file recognised by the next run.
"""

from __future__ import annotations

import contextlib
import csv
import hashlib
import io
import json
import math
import os
from typing import Any

import numpy as np

from .._files import open_regular_nofollow, read_nofollow
from .._marks import MARK_KEY, MAX_MARKED_BYTES, file_is_marked, fill_mark, placeholder
from .._output import check_replaceable, write_file
from .._version import __version__
from ..gearset import GearSet, preset_of
from .export_table import Column, ExportTables

__all__ = ["MARK", "sections_path", "sidecar_path", "write_csv_export"]

#: The key of the sidecar's record of the export: the kind and the digests of its tables.
MARK = "gearchaos_export"

#: Attributes grouped in the sidecar (the rest go under ``attributes``).
_SETTINGS = ("rtol", "atol", "perturbation")
_PROTOCOL = (
    "initial_conditions",
    "direction",
    "transient_periods",
    "extra_periods",
    "periods",
    "samples_per_period",
)
_SPECIFICATION = (
    "model",
    "gearset_toml",
    "sweep_toml",
    "basin_spec",
    "model_parameters",
    "model_class",
    "model_fields",
)
_SCALES = (
    "omega_n_rad_s",
    "characteristic_length_m",
    "mesh_frequency_rad_s",
    "clearance_sun_planet",
    "clearance_planet_ring",
    "clearance_sun_bearing",
)
_VERSIONS = {
    "version": "gearchaos",
    "numba_version": "numba",
    "numpy_version": "numpy",
    "scipy_version": "scipy",
}
_JSON_TEXT = ("regime_table", "attractors", "tracks", "basin_spec", "model_fields")


def sections_path(path: str) -> str:
    """The section table beside the point table ``path``: ``run.csv`` → ``run.sections.csv``."""
    root, ext = os.path.splitext(path)
    return f"{root}.sections{ext}"


def sidecar_path(path: str) -> str:
    """The sidecar of the point table ``path``: ``run.csv`` → ``run.csv.json``."""
    return f"{path}.json"


# ---------------------------------------------------------------------------- tables
def _cells(values: np.ndarray) -> list[str]:
    """The text of each value: floats as their shortest exact form (``repr``), NaN as an
    empty cell (what a spreadsheet and pandas read as missing), booleans as True/False."""
    arr = np.asarray(values)
    if arr.dtype == object:
        return [v if isinstance(v, str) else str(v) for v in arr.tolist()]
    if arr.dtype.kind == "b":
        return ["True" if v else "False" for v in arr.tolist()]
    if arr.dtype.kind in "iu":
        return [str(v) for v in arr.tolist()]
    out = []
    for v in arr.astype(np.float64).tolist():
        out.append(repr(v) if math.isfinite(v) else ("" if math.isnan(v) else str(v)))
    return out


def render(columns: tuple[Column, ...]) -> bytes:
    """A table as CSV bytes (UTF-8, header row, one line per row, ``\\n`` line ends)."""
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow([c.name for c in columns])
    writer.writerows(zip(*(_cells(c.values) for c in columns), strict=True))
    return buf.getvalue().encode("utf-8")


# ---------------------------------------------------------------------------- ownership
def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def file_digest(path: str) -> str | None:
    """The SHA-256 digest of the regular file ``path`` (``None``: none there, a link, a FIFO)."""
    try:
        fd = open_regular_nofollow(path)
    except OSError:
        return None
    h = hashlib.sha256()
    try:
        while block := os.read(fd, 1 << 20):
            h.update(block)
    except OSError:
        return None
    finally:
        os.close(fd)
    return h.hexdigest()


def read_sidecar(path: str) -> dict[str, Any] | None:
    """The sidecar at ``path`` if gearchaos wrote it and nobody edited it since (it carries
    :data:`~gearchaos._marks.MARK_KEY` with the digest of what it holds,
    :func:`~gearchaos._marks.file_is_marked`), else ``None``."""
    if not file_is_marked(path):
        return None
    try:
        record = json.loads(read_nofollow(path, MAX_MARKED_BYTES).decode("utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        return None
    if not isinstance(record, dict) or not isinstance(record.get(MARK), dict):
        return None
    return record


def _owned(record: dict[str, Any] | None) -> set[str]:
    """The table digests a sidecar vouches for."""
    if record is None:
        return set()
    mark = record[MARK]
    files = mark.get("files")
    found = set(files.values()) if isinstance(files, dict) else set()
    previous = mark.get("previous")
    if isinstance(previous, list):
        found |= set(previous)
    return {d for d in found if isinstance(d, str)}


# ---------------------------------------------------------------------------- sidecar
def _jsonable(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return [_jsonable(v) for v in value.tolist()]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None if math.isnan(value) else str(value)
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    if value is None or isinstance(value, bool | int | float | str):
        return value
    return str(value)


def _attr(attrs: dict[str, Any], key: str) -> Any:
    value = attrs[key]
    if key in _JSON_TEXT and isinstance(value, str):
        with contextlib.suppress(ValueError):
            return _jsonable(json.loads(value))
    return _jsonable(value)


def _gearset_names(gearset: GearSet | None) -> dict[str, str | None]:
    """The ``gearset`` and ``preset`` a sidecar names (``None`` for a model's result)."""
    if gearset is None:  # gear-set switch: a sidecar names only a gear set and its preset
        return {"gearset": None, "preset": None}
    return {"gearset": gearset.name, "preset": preset_of(gearset)}


def _provenance(
    attrs: dict[str, Any], source: str | None, gearset: GearSet | None
) -> dict[str, Any]:
    attrs = dict(attrs)
    placed: set[str] = set()

    def group(keys: Any) -> dict[str, Any]:
        found = {k: _attr(attrs, k) for k in keys if k in attrs}
        placed.update(found)
        return found

    out: dict[str, Any] = {
        "source": source,
        "title": _attr(attrs, "title") if "title" in attrs else None,
        **_gearset_names(gearset),
    }
    placed.add("title")
    out["specification"] = group(_SPECIFICATION)
    out["settings"] = group(_SETTINGS)
    out["protocol"] = group(_PROTOCOL)
    out["scales"] = group(_SCALES)
    out["versions"] = {
        "run": {name: _attr(attrs, k) for k, name in _VERSIONS.items() if k in attrs},
        "export": {"gearchaos": __version__},
    }
    placed.update(_VERSIONS)
    out["attributes"] = {k: _attr(attrs, k) for k in attrs if k not in placed}
    return out


def _table_record(name: str, columns: tuple[Column, ...]) -> dict[str, Any]:
    rows = len(columns[0].values) if columns else 0
    return {"file": name, "rows": rows, "columns": {c.name: c.record() for c in columns}}


# ---------------------------------------------------------------------------- writing
def write_csv_export(
    tables: ExportTables,
    path: str,
    *,
    attrs: dict[str, Any],
    source: str | None,
    gearset: Any,
) -> list[str]:
    """Write the point table at ``path``, the section table beside it (when there is one) and
    the sidecar; returns the paths written. Each file that exists is replaced only if it is
    gearchaos's (see the module docstring); the sidecar is written first."""
    sections = sections_path(path)
    side = sidecar_path(path)
    old = read_sidecar(side)
    own = _owned(old)
    check_replaceable(side, what="export", ours=lambda p: old is not None)
    tables_out = [(path, tables.points)]
    if tables.sections:
        tables_out.append((sections, tables.sections))
    for p, _ in tables_out:
        check_replaceable(p, what="export", ours=lambda q: file_digest(q) in own)
    previous = sorted(d for p in (path, sections) if (d := file_digest(p)) is not None and d in own)
    data = {p: render(cols) for p, cols in tables_out}
    record: dict[str, Any] = {
        MARK_KEY: placeholder(),  # filled in with the digest of the sidecar (fill_mark)
        MARK: {
            "version": __version__,
            "kind": tables.kind,
            "files": {os.path.basename(p): _sha256(b) for p, b in data.items()},
            "previous": previous,
        },
        **_provenance(attrs, source, gearset),
        "tables": {
            "points": _table_record(os.path.basename(path), tables.points),
            **(
                {"sections": _table_record(os.path.basename(sections), tables.sections)}
                if tables.sections
                else {}
            ),
        },
    }
    text = json.dumps(record, indent=2, ensure_ascii=True) + "\n"
    write_file(side, fill_mark(text.encode("ascii")), what="export")
    for p, b in data.items():
        write_file(p, b, what="export")
    if not tables.sections and file_digest(sections) in own:  # a stale table of ours
        with contextlib.suppress(OSError):
            os.remove(sections)
    return [path, *(p for p, _ in tables_out[1:]), side]
