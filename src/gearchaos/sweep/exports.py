"""Export of results to the formats other tools read: a tidy CSV table and a MATLAB file.

:func:`export` takes a sweep store (``RUN.zarr``), a simulation file (``simulation.nc``) or an
open :class:`xarray.Dataset` of either kind and writes

* ``csv`` — one row per point and section sample (a tidy table): the swept parameters, the
  section index (and ``tau`` for a simulation), the planet where a variable is per planet, then
  one column per variable; per-point variables (``status``, ``motion``, ``lle`` …) repeat on the
  rows of their point, and those over every planet or state get one column per planet or state
  (``contact_sp_p1`` … ``contact_sp_p5``, ``delta_sp_min_p1``, ``final_state_x_s``). A
  header of ``#`` lines carries the provenance (gear set name, settings, versions), which
  ``pandas.read_csv(..., comment="#")`` skips.
* ``mat`` — every variable and coordinate as a MATLAB array (``scipy.io.savemat``, format 5),
  names with ``.`` turned into ``_`` (``backlash.sun_planet`` → ``backlash_sun_planet``), the
  dimension names of each variable in ``dims_<name>`` and the attributes in the struct
  ``attrs``; label arrays become cell arrays of strings.

The write is atomic (a temporary file renamed into place).
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import numpy as np

from .._files import check_output_file, check_path
from .._output import check_replaceable, file_has_mark, staged_file
from .._version import __version__
from ..errors import ParameterError, StoreError

__all__ = ["FORMATS", "export", "open_result", "table"]

#: The formats :func:`export` writes.
FORMATS = ("csv", "mat")

#: Attributes written into the CSV header (when present).
_HEADER_ATTRS = (
    "title",
    "model",
    "omega",
    "transient_periods",
    "periods",
    "samples_per_period",
    "rtol",
    "atol",
    "initial_conditions",
    "status",
    "version",
    "numba_version",
    "numpy_version",
)


def open_result(source: Any) -> Any:
    """A dataset from a sweep store, a simulation file or a dataset (returned as it is)."""
    import xarray as xr

    if isinstance(source, xr.Dataset):
        return source
    if hasattr(source, "to_dataset"):  # a SimulationResult, or a SweepResult's dataset
        return source.to_dataset()
    if hasattr(source, "ds") and isinstance(source.ds, xr.Dataset):
        return source.ds
    path = check_path(
        source, f"source must be a sweep store, a simulation file or a Dataset: got {source!r}"
    )
    if os.path.isdir(path):
        from .store import open_sweep

        return open_sweep(path).load()
    if not os.path.exists(path):
        raise StoreError(f"no result at {path!r} (no such file or directory)")
    from ..integrate.result import open_simulation

    try:
        return open_simulation(path)
    except StoreError as exc:
        if "open_branch" in str(exc):  # a branch file of `gearchaos continue`
            raise StoreError(
                f"{path!r} is a branch of `gearchaos continue`, not a sweep store or a "
                "simulation file: draw it with `gearchaos plot STORE --branch` or read it with "
                "gearchaos.dynamics.open_branch"
            ) from None
        raise StoreError(
            f"{path!r} is neither a sweep store nor a simulation file: {exc}"
        ) from None
    except Exception as exc:  # h5netcdf / h5py raise many types for a file that is no netCDF
        raise StoreError(
            f"{path!r} is neither a sweep store nor a simulation file ({type(exc).__name__})"
        ) from None


def _provenance_lines(ds: Any, columns: list[str]) -> list[str]:
    """The header lines that make a CSV stand alone: the legend of every coded column
    (``status``, ``verdict``, ``record``, ``orbit_status`` …: code = meaning, from the
    variable's ``flag_values``/``flag_meanings``), then the whole gear set and sweep
    specification as TOML — every parameter value, the changed ones too."""
    lines = []
    for name in columns:
        if name not in ds.variables:
            continue
        attrs = ds[name].attrs
        values, meanings = attrs.get("flag_values"), attrs.get("flag_meanings")
        if values is None or not isinstance(meanings, str):
            continue
        pairs = ", ".join(
            f"{int(v)} = {m}" for v, m in zip(np.ravel(values), meanings.split(), strict=False)
        )
        lines.append(f"# {name}: {pairs}")
    for key, title in (("gearset_toml", "gear set"), ("sweep_toml", "sweep")):
        text = ds.attrs.get(key)
        if isinstance(text, str) and text.strip():
            lines.append(f"# {title} (TOML, every value):")
            lines += [f"#   {ln}" if ln else "#" for ln in text.strip().splitlines()]
    return lines


def _is_sweep(ds: Any) -> bool:
    return "status" in ds.data_vars and "section" in ds.dims and "tau" not in ds.coords


def table(source: Any) -> Any:
    """The tidy table of a result as a :class:`pandas.DataFrame` (see the module docstring)."""
    ds = open_result(source)
    if "section" not in ds.dims:
        raise StoreError("the result has no section dimension: nothing to tabulate")
    lead = [str(d) for d in ds["status"].dims] if _is_sweep(ds) else []
    keep_dims = {*lead, "section", "planet"}
    names = [
        str(n)
        for n, v in ds.data_vars.items()
        if set(v.dims) <= keep_dims and (set(v.dims) & ({"section"} | set(lead)))
    ]
    if not names:
        raise StoreError("the result has no variables over its points and sections")
    sub = ds[names]
    df = sub.to_dataframe().reset_index()
    order = [*lead, "section", *(["tau"] if "tau" in df.columns else [])]
    order += [c for c in ("planet",) if c in df.columns]
    df = df[[*order, *(c for c in df.columns if c not in order)]]
    wide = _wide_columns(ds, lead, names)
    if wide:
        import pandas as pd

        extra = pd.DataFrame(wide)
        if lead:  # per point: repeated on the rows of the point, matched by its coordinates
            keys = {d: np.asarray(ds[d].values) for d in lead}
            grid = np.meshgrid(*keys.values(), indexing="ij")
            for d, g in zip(keys, grid, strict=True):
                extra[d] = g.reshape(-1)
            df = df.merge(extra, on=lead, how="left", sort=False)
        else:
            for col, values in wide.items():
                df[col] = values[0]
    return df


#: Dimensions spread over one column per value (planets, state components).
_WIDE_DIMS = ("planet_all", "planet", "state")


def _wide_columns(ds: Any, lead: list[str], skip: list[str]) -> dict[str, np.ndarray]:
    """The per-point variables over one more dimension (the extrema and contact regimes of every
    planet over ``planet_all``, the final state over ``state``) as one column per value of that
    dimension: ``contact_sp_p3``, ``delta_sp_min_p1``, ``final_state_x_s``; values flattened in
    the order of the lead dimensions."""
    out: dict[str, np.ndarray] = {}
    for name, var in ds.data_vars.items():
        if name in skip or "section" in var.dims:
            continue
        extra = [d for d in var.dims if d not in lead]
        if len(extra) != 1 or [d for d in var.dims if d in lead] != lead:
            continue
        (dim,) = extra
        if dim not in _WIDE_DIMS:  # e.g. the time samples of a simulation: not one per column
            continue
        values = var.transpose(*lead, dim).values.reshape(-1, var.sizes[dim])
        prefix = "p" if dim in ("planet_all", "planet") else ""
        for k, label in enumerate(np.asarray(ds[dim].values)):
            out[f"{name}_{prefix}{label}"] = values[:, k]
    return out


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


def export(source: Any, path: str | os.PathLike[str], *, to: str | None = None) -> Path:
    """Write a result as CSV or MATLAB ``.mat`` (see the module docstring); returns the path.

    Parameters
    ----------
    source
        A sweep store path, a simulation file path (``simulation.nc``) or a dataset of either.
    path
        The file to write.
    to
        ``csv`` or ``mat``; default: from the suffix of ``path``.
    """
    if isinstance(path, str | os.PathLike) and os.path.isdir(path):
        raise ParameterError(f"the output must be a file: {os.fspath(path)!r} is a directory")
    out = Path(check_output_file(path, what="the output"))
    fmt = to if to is not None else out.suffix.lower().lstrip(".")
    if fmt not in FORMATS:
        raise ParameterError(
            f"the export format must be one of {', '.join(FORMATS)} (or a path ending in "
            f".csv or .mat): got {to if to is not None else out.name!r}"
        )
    if out.is_dir():
        raise ParameterError(f"the output must be a file: {str(out)!r} is a directory")
    ds = open_result(source)
    out.parent.mkdir(parents=True, exist_ok=True)
    # an existing export is replaced only if gearchaos wrote it (its header, the .mat's text)
    check_replaceable(str(out), what="export", ours=file_has_mark)
    with staged_file(str(out), what="export") as staged:
        tmp = Path(staged)
        if fmt == "csv":
            df = table(ds)
            header = [f"# {k} = {ds.attrs[k]}" for k in _HEADER_ATTRS if k in ds.attrs]
            if ds.attrs.get("gearset_toml"):
                name = re.search(r'^name = "(.*)"', str(ds.attrs["gearset_toml"]), re.M)
                if name:
                    header.insert(0, f"# gearset = {name.group(1)}")
            header.insert(0, f"# gearchaos {__version__} export of {os.fspath(source)}")
            header += _provenance_lines(ds, [*map(str, df.columns), *map(str, ds.data_vars)])
            with open(tmp, "w", encoding="utf-8", newline="") as f:
                f.write("\n".join(header) + ("\n" if header else ""))
                df.to_csv(f, index=False)  # floats as repr: the shortest exact text
        else:
            _write_mat(ds, os.fspath(tmp))
    return out
