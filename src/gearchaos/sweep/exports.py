"""Export of results to the formats other tools read: CSV tables and a MATLAB file.

:func:`export` takes a sweep store (``RUN.zarr`` of ``gearchaos bifurcation``), a response
store (``gearchaos response``), a basin or basin-fraction store (``gearchaos basins``,
``basin-fractions``), a simulation file (``simulation.nc``) or an open
:class:`xarray.Dataset` of one of these, and writes

* ``csv`` — a table a spreadsheet and ``pandas.read_csv(path)`` open as they are: one row
  per point with the units in the column names (``omega``, ``sun_rpm``, ``mesh_hz``,
  ``motion``, ``lle``, ``load_factor_sp``, ``contact_sp_p1`` …; :mod:`.export_table`), the
  section samples in a separate long table ``RUN.sections.csv`` (one row per point and
  sample), and the provenance and the meaning and unit of every column in the sidecar
  ``RUN.csv.json`` (:mod:`.export_files`);
* ``mat`` — every variable and coordinate as a MATLAB array (``scipy.io.savemat``, format 5),
  names with ``.`` turned into ``_`` (``backlash.sun_planet`` → ``backlash_sun_planet``), the
  dimension names of each variable in ``dims_<name>`` and the attributes in the struct
  ``attrs``; label arrays become cell arrays of strings.

Branch files of ``gearchaos continue``, boundary curves and orbit files are refused, naming
what they are and the kinds :func:`export` writes. Every write is atomic (a temporary file
renamed into place); an existing file is replaced only when gearchaos wrote it.
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path
from typing import Any

import numpy as np

from .._files import check_output_file, check_path, load_netcdf
from .._marks import mark_file, placeholder
from .._output import check_replaceable, file_has_mark, staged_file
from .._text import escape_path
from ..errors import ParameterError, StoreError
from .export_files import sections_path, sidecar_path, write_csv_export
from .export_table import ExportTables, export_tables

__all__ = ["FORMATS", "KINDS", "export", "open_result", "result_kind", "table", "write_export"]

#: The formats :func:`export` writes.
FORMATS = ("csv", "mat")

#: The kinds of results :func:`export` writes, with the command that makes each.
KINDS = {
    "sweep": "sweep stores (gearchaos bifurcation)",
    "response": "response stores (gearchaos response)",
    "basins": "basin stores (gearchaos basins)",
    "basin_fractions": "basin-fraction stores (gearchaos basin-fractions)",
    "simulation": "simulation files (gearchaos simulate -o DIR)",
}

_EXPORTS = (
    "export writes sweep stores (gearchaos bifurcation), response stores (gearchaos response), "
    "basin stores (gearchaos basins, basin-fractions) and simulation files (gearchaos "
    "simulate -o DIR)"
)


def _refuse(path: str, what: str, hint: str) -> StoreError:
    return StoreError(f"'{escape_path(path)}' is {what}: {_EXPORTS}; {hint}")


def result_kind(ds: Any) -> str:
    """The kind of a result dataset (a key of :data:`KINDS`); a branch, a boundary curve, an
    orbit or anything else raises :class:`~gearchaos.errors.StoreError` saying what it is."""
    from ..dynamics.orbits.file import ORBIT_TITLE
    from ..integrate.result import SIMULATION_TITLE
    from ._basin_store import KINDS as BASIN_KINDS

    attrs = ds.attrs
    kind = attrs.get("kind")
    title = str(attrs.get("title", ""))
    if kind in BASIN_KINDS and "attractor" in ds.data_vars:
        return str(kind)
    if title.startswith(SIMULATION_TITLE):
        return "simulation"
    if "status" in ds.data_vars and isinstance(attrs.get("sweep_toml"), str):
        return "response" if kind == "response" else "sweep"
    name = "the dataset"
    if kind == "boundary_curve":
        raise _refuse(name, "a boundary curve of gearchaos boundary", _CURVE_HINT)
    if "parameter" in attrs:
        raise _refuse(name, "a branch of gearchaos continue", _BRANCH_HINT)
    if title.startswith(ORBIT_TITLE):
        raise _refuse(name, "an orbit file of gearchaos orbit", _ORBIT_HINT)
    raise _refuse(name, "no result gearchaos exports", "check the path")


_BRANCH_HINT = (
    "draw it with gearchaos plot BRANCH, or read it in Python with "
    "gearchaos.dynamics.open_branch (an xarray.Dataset)"
)
_CURVE_HINT = "draw it with gearchaos plot CURVE, or read it with gearchaos.dynamics.open_branch"
_ORBIT_HINT = (
    "read it with gearchaos.dynamics.open_orbit, or continue it with gearchaos continue --from"
)


def _store_kind(path: str) -> str | None:
    """The ``kind`` attribute of a Zarr directory's root (``None`` when unreadable or absent;
    the store's own reader then reports what is wrong)."""
    from .integrity import read_json

    try:
        attrs = read_json(os.path.join(path, ".zattrs"))
    except (OSError, ValueError):
        return None
    if not isinstance(attrs, dict):
        return None
    if "parameter" in attrs:
        return "boundary_curve" if attrs.get("kind") == "boundary_curve" else "branch"
    kind = attrs.get("kind")
    return kind if isinstance(kind, str) else None


def _open_store(path: str) -> Any:
    from ._basin_store import KINDS as BASIN_KINDS, open_basins
    from .store import open_sweep

    kind = _store_kind(path)
    if kind in BASIN_KINDS:
        return open_basins(path).load()
    if kind == "branch":
        raise _refuse(path, "a branch store of gearchaos continue", _BRANCH_HINT)
    if kind == "boundary_curve":
        raise _refuse(path, "a boundary curve of gearchaos boundary", _CURVE_HINT)
    return open_sweep(path).load()


def _open_file(path: str) -> Any:
    from ..dynamics.orbits.file import ORBIT_TITLE
    from ..integrate.result import SIMULATION_TITLE

    name, ds = load_netcdf(path, what="result file")
    title = str(ds.attrs.get("title", ""))
    if title.startswith(SIMULATION_TITLE):
        return ds
    if ds.attrs.get("kind") == "boundary_curve":
        raise _refuse(name, "a boundary curve of gearchaos boundary", _CURVE_HINT)
    if "parameter" in ds.attrs:
        raise _refuse(name, "a branch of gearchaos continue", _BRANCH_HINT)
    if title.startswith(ORBIT_TITLE):
        raise _refuse(name, "an orbit file of gearchaos orbit", _ORBIT_HINT)
    raise _refuse(name, "a netCDF file gearchaos did not write as a result", "check the path")


def open_result(source: Any) -> Any:
    """A result dataset from a store or file path, a result object or a dataset (returned
    as it is); see the module docstring for the kinds."""
    import xarray as xr

    if isinstance(source, xr.Dataset):
        return source
    if hasattr(source, "to_dataset"):  # a SimulationResult, or a SweepResult's dataset
        return source.to_dataset()
    if hasattr(source, "ds") and isinstance(source.ds, xr.Dataset):
        return source.ds
    path = check_path(
        source, f"source must be a result store or file, or a Dataset: got {source!r}"
    )
    if os.path.isdir(path):
        return _open_store(path)
    if not os.path.lexists(path):
        raise StoreError(f"no result at '{escape_path(path)}' (no such file or directory)")
    return _open_file(path)


def _gearset_of(ds: Any, kind: str) -> tuple[Any, dict[str, Any]]:
    """(the result's gear set with its fixed values applied, or ``None`` for a model's
    result; the fixed values of a sweep)."""
    from ..gearset.schema import OMEGA
    from ..model.record import recorded_gearset
    from .result import SweepResult

    if kind in ("sweep", "response"):
        res = SweepResult(ds)
        return res.gearset, res.fixed
    try:  # the one reader of records: a damaged one is refused (ParameterError)
        gs = recorded_gearset(ds.attrs, where="the result")
        changes: dict[str, Any] = {}
        if kind in ("basins", "basin_fractions"):
            spec = json.loads(str(ds.attrs.get("basin_spec", "{}")))
            values = spec.get("values", {}) if isinstance(spec, dict) else {}
            changes = {k: v for k, v in dict(values).items() if k != OMEGA}
        # gear-set switch: a model's basin values are its fields, not the gear set's
        if changes and gs is not None:
            gs = gs.evolve(changes)
    except (ValueError, TypeError) as exc:  # ParameterError is a ValueError
        raise StoreError(str(exc)) from None
    return gs, {}


def tables(source: Any) -> ExportTables:
    """The point and section tables of a result (:mod:`.export_table`)."""
    ds = open_result(source)
    kind = result_kind(ds)
    gs, fixed = _gearset_of(ds, kind)
    return export_tables(ds, kind, gearset=gs, fixed=fixed)


def table(source: Any, *, sections: bool = False) -> Any:
    """The point table of a result (or with ``sections`` its section table) as a
    :class:`pandas.DataFrame`, with the columns of the CSV export."""
    import pandas as pd

    t = tables(source)
    cols = t.sections if sections else t.points
    return pd.DataFrame({c.name: c.values for c in cols})


def _mat_name(name: str) -> str:
    out = re.sub(r"[^A-Za-z0-9_]", "_", name)
    return out if out[:1].isalpha() else f"v_{out}"


def _mat_value(values: np.ndarray) -> Any:
    if values.dtype.kind in "US":
        return np.array(values.astype(str), dtype=object)
    if values.dtype.kind == "b":
        return values.astype(np.uint8)
    return values


def _write_mat(ds: Any, path: str) -> None:
    from scipy.io import savemat

    data: dict[str, Any] = {}
    for name in [*ds.coords, *ds.data_vars]:
        v = ds[name]
        key = _mat_name(str(name))
        data[key] = _mat_value(np.asarray(v.values))
        data[f"dims_{key}"] = np.array([str(d) for d in v.dims], dtype=object)
    attrs = {}
    for k, v in ds.attrs.items():
        if isinstance(v, bool | int | float | str | np.number):
            attrs[_mat_name(str(k))] = v
        else:
            attrs[_mat_name(str(k))] = str(v)
    data["attrs"] = attrs
    savemat(path, data, do_compression=True, oned_as="column", appendmat=False)
    # the 116 bytes of descriptive text of a MAT 5 file hold gearchaos's mark: the digest of
    # the file (what a new export may replace)
    text = f"MATLAB 5.0 MAT-file, {placeholder()}".encode("ascii").ljust(116)
    with open(path, "r+b") as f:
        f.write(text)
    mark_file(path)


def export(source: Any, path: str | os.PathLike[str], *, to: str | None = None) -> Path:
    """Write a result as CSV tables or a MATLAB ``.mat`` file (see the module docstring).

    Parameters
    ----------
    source
        A sweep, response, basin or basin-fraction store path, a simulation file path
        (``simulation.nc``) or a dataset of one of these.
    path
        The file to write: the point table of a CSV export (its section table and sidecar
        are written beside it: ``RUN.sections.csv``, ``RUN.csv.json``), or the ``.mat`` file.
    to
        ``csv`` or ``mat``; default: from the suffix of ``path``.

    Returns
    -------
    Path
        ``path`` (the point table of a CSV export); :func:`write_export` returns every file.
    """
    return write_export(source, path, to=to)[0]


def write_export(source: Any, path: str | os.PathLike[str], *, to: str | None = None) -> list[Path]:
    """:func:`export`, returning every file written (the point table, the section table when
    the result has sections, the sidecar; or the ``.mat`` file)."""
    if isinstance(path, str | os.PathLike) and os.path.isdir(path):
        raise ParameterError(f"the output must be a file: '{escape_path(path)}' is a directory")
    out = Path(check_output_file(path, what="the output"))
    fmt = to if to is not None else out.suffix.lower().lstrip(".")
    if fmt not in FORMATS:
        raise ParameterError(
            f"the export format must be one of {', '.join(FORMATS)} (or a path ending in "
            f".csv or .mat): got {to if to is not None else out.name!r}"
        )
    ds = open_result(source)
    kind = result_kind(ds)
    out.parent.mkdir(parents=True, exist_ok=True)
    if fmt == "csv":
        gs, fixed = _gearset_of(ds, kind)
        for extra in (sections_path(str(out)), sidecar_path(str(out))):
            check_output_file(extra, what="the output")
        written = write_csv_export(
            export_tables(ds, kind, gearset=gs, fixed=fixed),
            str(out),
            attrs=dict(ds.attrs),
            source=os.fsdecode(source) if isinstance(source, str | bytes | os.PathLike) else None,
            gearset=gs,
        )
        return [Path(p) for p in written]
    # an existing .mat is replaced only if gearchaos wrote it
    check_replaceable(str(out), what="export", ours=file_has_mark)
    with staged_file(str(out), what="export") as staged:
        _write_mat(ds, os.fspath(staged))
    return [out]
