"""The dataset of a continued branch, and its files (netCDF-4 via h5netcdf, or Zarr).

Layout of :func:`branch_dataset` (keep these names; plots and the CLI read them):

dimensions
    ``point`` (branch points in arclength order), ``state`` (state names), ``multiplier``
    (0 … n_state−1, by modulus, descending), ``section`` (0 … n−1), ``planet`` (observed
    per-planet variables), ``planet_all`` (tracked per-planet extrema), ``contact`` (meshes
    and bearing axes), ``event``.
coordinates
    the parameter by its dotted name (point) and ``arclength`` (point).
per point
    ``orbit_state`` (point, state): y* at the section; ``multiplier_re``, ``multiplier_im``,
    ``multiplier_abs`` (point, multiplier); ``max_multiplier``, ``unstable`` (number of
    |μ| > 1), ``stable`` (int8), ``residual``, ``iterations`` (map evaluations of the
    corrector), ``jacobians`` (of them, with tangents), ``newton_steps`` (corrections),
    ``dparameter_ds`` (dλ/ds of the unit tangent: changes sign at folds), ``minimal_period``
    (the smallest d | n after which the section points repeat), ``on_grid`` (int8: landed on
    a value of ``grid``);
    the observed variables at the n section points (``delta_sp`` (point, section, planet),
    ``delta_sp_dot`` …, as sweeps store them); extrema over the orbit of the tracked
    observables (``delta_sp_min`` (point, planet_all) …); ``contact_regime`` (point, contact);
    for models with mesh contact forces, ``force_peak_<mesh>`` (point[, planet_all]): the
    peak contact force max |F̄ᶜ| over the orbit, from the extrema the integrator tracked
    while shooting (:func:`gearchaos.model.response.peak_contact_forces`, the definition a
    response sweep stores under the same name; attributes ``mesh`` and ``deflection``).
events
    ``event_kind``, ``event_value`` (parameter value), ``event_point`` (index of the point
    before it), ``event_arclength``, ``event_multiplier_re``, ``event_multiplier_im``,
    ``event_state`` (event, state), ``event_vector`` (event, state), ``event_detail``,
    ``event_located`` (int8), ``event_uncertainty`` (the location uncertainty in the
    parameter, :mod:`gearchaos.dynamics.continuation.locate`).
attributes
    ``parameter``, ``period``, ``range_start``, ``range_stop``, ``vary``, ``fixed`` (JSON of the
    fixed values), ``stop_reason``, ``start`` (how the branch started), ``tol``, the step
    settings, the solver settings, the model's provenance (``model``, ``model_class``,
    ``model_fields``, ``gearset_toml``, ``model_parameters``, scales, clearances) and the
    versions (``version``, ``numba_version`` …), as sweeps carry them.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..._checks import check_bool
from ..._files import check_path, check_regular_file, irregular_entry, read_nofollow
from ..._marks import MARK_KEY, hdf5_is_marked, mark_hdf5, zarr_mark
from ..._output import check_replaceable, is_own_zarr, staged_dir, write_file
from ..._version import provenance
from ...errors import ParameterError, StoreError
from ...model.response import mesh_groups, peak_contact_forces
from ..orbits.orbit import (
    PeriodicOrbit,
    minimal_period,
    model_attrs,
    orbit_contacts,
)

__all__ = [
    "branch_dataset",
    "branch_multipliers",
    "branch_summary",
    "check_observe",
    "check_store",
    "fixed_json",
    "open_branch",
    "save_branch",
]


def _default_observe(system: Any) -> tuple[str, ...]:
    var, dot = system.default_observables
    return (var, dot) if dot != var else (var,)


def check_observe(system: Any, observe: Any) -> tuple[str, ...]:
    """The variables a branch stores at its section points: ``observe`` (a name or a list of
    distinct names of ``system``'s variables) or the default; refused before any run."""
    if observe is None:
        return _default_observe(system)
    names = (observe,) if isinstance(observe, str) else observe
    if (
        not isinstance(names, tuple | list)
        or not names
        or not all(isinstance(nm, str) and nm for nm in names)
        or len(set(names)) != len(names)
    ):
        raise ParameterError(f"observe must be distinct variable names: got {observe!r}")
    for nm in names:
        system.observable(nm)  # an unknown name is refused by name
    return tuple(names)


def _start_text(start: Any) -> str:
    if start is None:
        return "simulation"
    if isinstance(start, PeriodicOrbit):
        return "periodic_orbit"
    if hasattr(start, "kind") and hasattr(start, "value"):
        return f"{start.kind} at {start.parameter}={start.value:.10g} (period {start.period})"
    return "state"


def branch_dataset(
    br: Any,
    pts: list[Any],
    events: list[Any],
    reason: str,
    rng: tuple[float, float],
    observe: Any,
    start: Any,
) -> Any:
    """The :class:`xarray.Dataset` of a branch (layout in the module docstring)."""
    import xarray as xr

    ref = br.system(pts[0].lam)
    names = list(ref.state_names)
    m, n = len(names), br.n
    P = len(pts)
    observed = [ref.observable(nm) for nm in check_observe(ref, observe)]
    tracked = ref.tracked_groups()
    levels = br.levels
    n_planets = ref.group_size
    coords: dict[str, Any] = {
        br.name: ("point", np.array([p.lam for p in pts])),
        "arclength": ("point", np.array([p.s for p in pts])),
        "point": ("point", np.arange(P)),
        "state": ("state", np.array(names, dtype="U16")),
        "multiplier": ("multiplier", np.arange(m)),
        "section": ("section", np.arange(n)),
    }
    if any(ob.per_planet for ob in observed):
        coords["planet"] = ("planet", np.arange(1, n_planets + 1))
    groups = mesh_groups(ref)
    if any(per for *_, per in tracked) or any(g.force.per_planet for g in groups):
        coords["planet_all"] = ("planet_all", np.arange(1, n_planets + 1))
    if levels:
        coords["contact"] = ("contact", np.array([lv[0] for lv in levels], dtype="U16"))
    mu = np.array([p.mu for p in pts])
    cfg = br.cfg
    st = br.steps
    attrs = {
        "title": f"gearchaos branch of period-{n} orbits of {ref.name}",
        **model_attrs(ref),
        "parameter": br.name,
        "period": int(n),
        "range_start": float(rng[0]),
        "range_stop": float(rng[1]),
        "vary": f"{br.name}={rng[0]:.10g}:{rng[1]:.10g}",
        "fixed": fixed_json(br.fixed),
        "stop_reason": reason,
        "start": _start_text(start),
        "n_points": int(P),
        "map_evaluations": int(br.evals),
        "jacobian_evaluations": int(br.jacobians),
        "tol": float(br.tol),
        "step": st.initial,
        "min_step": st.minimum,
        "max_step": st.maximum,
        "max_points": st.max_points,
        "event_tol": st.event_tol,
        **cfg.attrs(),
        **provenance(),
    }
    ds = xr.Dataset(coords=coords, attrs=attrs)
    ds[br.name].attrs["long_name"] = f"continued parameter {br.name}"
    ds["arclength"].attrs["long_name"] = "pseudo-arclength s (parameter units)"
    ds["orbit_state"] = (("point", "state"), np.array([p.y for p in pts]))
    ds["orbit_state"].attrs["long_name"] = "orbit state y* at the section"
    ds["multiplier_re"] = (("point", "multiplier"), mu.real)
    ds["multiplier_im"] = (("point", "multiplier"), mu.imag)
    ds["multiplier_abs"] = (("point", "multiplier"), np.abs(mu))
    ds["max_multiplier"] = ("point", np.abs(mu).max(axis=1))
    ds["unstable"] = ("point", (np.abs(mu) > 1.0).sum(axis=1).astype(np.int64))
    ds["stable"] = ("point", (np.abs(mu).max(axis=1) < 1.0).astype(np.int8))
    ds["residual"] = ("point", np.array([p.residual for p in pts]))
    ds["iterations"] = ("point", np.array([p.evals for p in pts], dtype=np.int64))
    ds["iterations"].attrs["long_name"] = "map evaluations of the corrector"
    ds["newton_steps"] = ("point", np.array([p.corrections for p in pts], dtype=np.int64))
    ds["newton_steps"].attrs["long_name"] = "Newton corrections of the corrector"
    ds["jacobians"] = ("point", np.array([p.jacobians for p in pts], dtype=np.int64))
    ds["jacobians"].attrs["long_name"] = "map evaluations with tangents (monodromy matrices)"
    ds["dparameter_ds"] = ("point", np.array([float(p.tangent[-1]) for p in pts]))
    ds["minimal_period"] = (
        "point",
        np.array([minimal_period(p.shot.sections[0], br.tol) for p in pts], dtype=np.int64),
    )
    ds["minimal_period"].attrs["long_name"] = (
        "smallest d | n after which the section points repeat (d < n: a period-d orbit)"
    )
    ds["on_grid"] = ("point", np.array([p.landed for p in pts], dtype=np.int8))
    ds["on_grid"].attrs["long_name"] = "1 where the point was landed on a value of grid"
    for ob in observed:
        vals = np.array([ob.take(p.shot.sections[0], p.shot.section_obs[0]) for p in pts])
        dims = ("point", "section", "planet") if ob.per_planet else ("point", "section")
        ds[ob.name] = (dims, vals, {"long_name": f"{ob.name} at the section"})
    for nm, cols, per in tracked:
        for which in ("min", "max"):
            arr = np.array([getattr(p.shot, f"obs_{which}")[0][cols] for p in pts])
            if per:
                ds[f"{nm}_{which}"] = (("point", "planet_all"), arr)
            else:
                ds[f"{nm}_{which}"] = ("point", arr[:, 0])
            ds[f"{nm}_{which}"].attrs["long_name"] = f"{which} of {nm} over the orbit"
    if levels:
        # against the clearances of each point (the continued parameter may be one)
        reg = [
            list(orbit_contacts(br.system(p.lam), p.shot.obs_min[0], p.shot.obs_max[0]).values())
            for p in pts
        ]
        ds["contact_regime"] = (("point", "contact"), np.array(reg, dtype="U16"))
    _put_force_peaks(ds, br, pts, groups)
    _put_events(ds, events, m)
    return ds


def _put_force_peaks(ds: Any, br: Any, pts: list[Any], groups: list[Any]) -> None:
    """``force_peak_<mesh>``: max |F̄ᶜ| over each point's orbit, from the shot's tracked
    extrema against that point's clearances (the continued parameter may be one)."""
    if not groups:
        return
    peaks = [
        peak_contact_forces(br.system(p.lam), p.shot.obs_min[0], p.shot.obs_max[0]) for p in pts
    ]
    for g in groups:
        key = f"force_peak_{g.mesh}"
        dims = ("point", "planet_all") if g.force.per_planet else ("point",)
        ds[key] = (dims, np.array([pk[key] for pk in peaks], dtype=np.float64))
        ds[key].attrs.update(
            long_name="peak contact force max |F̄ᶜ| over the orbit (tracked in the integrator)",
            units="1",
            mesh=g.mesh,
            deflection=g.deflection.name,
        )


def _put_events(ds: Any, events: list[Any], m: int) -> None:
    E = len(events)
    ds.coords["event"] = ("event", np.arange(E))
    ds["event_kind"] = ("event", np.array([e.kind for e in events], dtype="U16"))
    ds["event_value"] = ("event", np.array([e.value for e in events], dtype=float))
    ds["event_point"] = ("event", np.array([e.point for e in events], dtype=np.int64))
    ds["event_arclength"] = ("event", np.array([e.arclength for e in events], dtype=float))
    mu = np.array([e.multiplier for e in events], dtype=complex)
    ds["event_multiplier_re"] = ("event", mu.real)
    ds["event_multiplier_im"] = ("event", mu.imag)
    ds["event_state"] = (("event", "state"), np.array([e.state for e in events]).reshape(E, m))
    ds["event_vector"] = (("event", "state"), np.array([e.vector for e in events]).reshape(E, m))
    width = max([len(e.detail) for e in events] + [1])
    ds["event_detail"] = ("event", np.array([e.detail for e in events], dtype=f"U{width}"))
    ds["event_located"] = ("event", np.array([e.located for e in events], dtype=np.int8))
    ds["event_uncertainty"] = ("event", np.array([e.uncertainty for e in events], dtype=float))
    ds["event_uncertainty"].attrs["long_name"] = (
        "location uncertainty of event_value: the final bracket's half-width plus the shift "
        "the integrator's error of the test function causes (its rtol/100 check)"
    )


def fixed_json(values: Mapping[str, Any]) -> str:
    """The fixed parameter values as JSON (numbers and strings; anything else by repr)."""
    out = {k: v if isinstance(v, int | float | str) else repr(v) for k, v in values.items()}
    return json.dumps(out, sort_keys=True)


def branch_summary(ds: Any) -> dict[str, Any]:
    """A JSON-serialisable summary of a branch: ``parameter``, ``period``, ``range``,
    ``points``, ``stop_reason``, ``segments`` (maximal runs of consecutive points of equal
    stability: ``from``/``to`` parameter values, ``stable``, ``points``) and ``events``
    (``kind``, ``value``, ``uncertainty`` (of ``value``; None for files without it),
    ``point``, ``multiplier`` {re, im, abs} or None for grazing, ``detail``, ``located``),
    in arclength order."""
    name = str(ds.attrs["parameter"])
    lam = np.asarray(ds[name].values, dtype=float)
    stable = np.asarray(ds["stable"].values, dtype=bool)
    segments = []
    start = 0
    for k in range(1, lam.size + 1):
        if k == lam.size or stable[k] != stable[start]:
            segments.append(
                {
                    "from": float(lam[start]),
                    "to": float(lam[k - 1]),
                    "stable": bool(stable[start]),
                    "points": int(k - start),
                }
            )
            start = k
    events = []
    for k in range(ds.sizes.get("event", 0)):
        re, im = float(ds.event_multiplier_re[k]), float(ds.event_multiplier_im[k])
        kind = str(ds.event_kind.values[k])
        unc = float(ds.event_uncertainty[k]) if "event_uncertainty" in ds else math.nan
        events.append(
            {
                "kind": kind,
                "value": float(ds.event_value[k]),
                "uncertainty": unc if math.isfinite(unc) else None,
                "point": int(ds.event_point[k]),
                "multiplier": None
                if kind == "grazing"
                else {"re": re, "im": im, "abs": float(np.hypot(re, im))},
                "detail": str(ds.event_detail.values[k]),
                "located": bool(int(ds.event_located[k])),
            }
        )
    return {
        "parameter": name,
        "period": int(ds.attrs["period"]),
        "range": [float(ds.attrs["range_start"]), float(ds.attrs["range_stop"])],
        "points": int(lam.size),
        "stop_reason": str(ds.attrs["stop_reason"]),
        "segments": segments,
        "events": events,
    }


def branch_multipliers(ds: Any) -> np.ndarray:
    """The complex multipliers (point, multiplier) of a branch dataset."""
    return np.asarray(ds["multiplier_re"].values) + 1j * np.asarray(ds["multiplier_im"].values)


def check_store(path: str | os.PathLike[str], overwrite: bool = False) -> str:
    """The kind of a branch file (``zarr`` or ``netcdf``) from its suffix; refuses other
    suffixes and, unless ``overwrite``, existing paths (before any computation)."""
    path = check_path(path, f"store must be a path ending in .nc or .zarr: got {path!r}")
    check_bool("overwrite", overwrite)
    if path.endswith(".zarr"):
        kind = "zarr"
    elif path.endswith((".nc", ".nc4", ".h5")):
        kind = "netcdf"
    else:
        raise ParameterError(f"store must end in .nc or .zarr: got {path!r}")
    if os.path.lexists(path) and not overwrite:
        raise StoreError(f"{path} exists; choose another path or pass overwrite=True")
    # overwrite replaces a branch gearchaos wrote, never anything else
    check_replaceable(path, what=f"{kind} branch file", ours=is_branch_file)
    up = os.path.dirname(os.path.abspath(path))
    while not os.path.exists(up) and os.path.dirname(up) != up:
        up = os.path.dirname(up)
    if not os.path.isdir(up):  # checked before any computation
        raise StoreError(f"cannot write {path}: {up} is not a directory")
    return kind


def save_branch(ds: Any, path: str | os.PathLike[str], *, overwrite: bool = False) -> str:
    """Write a branch to ``path``: ``*.nc`` as netCDF-4 (h5netcdf), ``*.zarr`` as a Zarr store.

    An existing path is refused unless ``overwrite``; the file appears under its name only
    when complete. Only a branch (a dataset of :func:`~gearchaos.continuation`, with its
    ``parameter`` attribute and multipliers) is written.
    """
    import xarray as xr

    if not isinstance(ds, xr.Dataset):
        raise ParameterError(
            f"save_branch needs a branch dataset (from continuation): got {type(ds).__name__}"
        )
    if "parameter" not in ds.attrs or "multiplier_re" not in ds:
        raise ParameterError(
            "save_branch needs a branch dataset (from continuation): this dataset has no "
            "'parameter' attribute or no 'multiplier_re' variable"
        )
    kind = check_store(path, overwrite)
    path = os.fspath(path)
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    if kind == "zarr":
        ds = ds.copy()  # the caller's dataset keeps its attributes
        ds.attrs[MARK_KEY] = zarr_mark(ds.attrs)
        with staged_dir(path, what="branch store") as tmp:
            # every chunk written (none skipped as all fill values) and its digest kept
            ds.to_zarr(tmp, mode="w", consolidated=True, zarr_format=2, write_empty_chunks=True)
            keys = _chunk_files(tmp) + _metadata_files(tmp)
            digests = {key: _digest(os.path.join(tmp, key)) for key in keys}
            with open(os.path.join(tmp, MANIFEST), "w", encoding="utf-8") as f:
                json.dump(digests, f)
    else:  # HDF5 Fletcher-32 checksums: a damaged chunk is an error when read, never data
        encoding = {
            name: {"fletcher32": True}
            for name, var in ds.variables.items()
            if var.ndim and var.size and var.dtype.kind in "biuf"
        }
        # serialised in memory first: HDF5 crashes on a full disk, a plain write fails cleanly
        data = mark_hdf5(ds.to_netcdf(engine="h5netcdf", encoding=encoding))
        write_file(path, data, what="branch file")
    return path


def is_branch_file(path: str) -> bool:
    """Whether ``path`` is a branch gearchaos wrote (what ``overwrite`` may replace): a Zarr
    branch holding only its arrays and manifest, or a netCDF file, each with gearchaos's mark
    of its attributes (:mod:`gearchaos._marks`); a file that mentions gearchaos is not."""
    if os.path.isdir(path):
        return is_own_zarr(path, keys=("parameter",), files=frozenset({MANIFEST}))
    return hdf5_is_marked(path)


def open_branch(path: str | os.PathLike[str]) -> Any:
    """Open a branch written by :func:`save_branch` (loaded into memory)."""
    import xarray as xr

    path = check_path(path, f"branch must be a path (BRANCH.nc or BRANCH.zarr): got {path!r}")
    if not os.path.lexists(path):
        raise StoreError(f"branch {path} does not exist")
    try:
        if os.path.isdir(path):
            _check_chunks(path)
            ds = xr.open_zarr(path, consolidated=True).load()
        else:
            ds = xr.load_dataset(check_regular_file(path, what="branch file"), engine="h5netcdf")
    except (StoreError, ParameterError):
        raise
    except Exception as exc:  # zarr, h5py and blosc raise many types for damaged files
        raise StoreError(
            f"branch {path} is damaged or no branch file ({type(exc).__name__})"
        ) from None
    if "parameter" not in ds.attrs or "multiplier_re" not in ds:
        title = str(ds.attrs.get("title", ""))
        what = (
            "a simulation file: gearchaos simulate -o DIR draws its figure"
            if title.startswith("gearchaos simulation")
            else "an orbit file: start a branch from it with gearchaos continue --from"
            if title.startswith("gearchaos periodic orbit")
            else "no branch file (no 'parameter' attribute)"
        )
        raise StoreError(f"{path} is not a gearchaos branch: it is {what}")
    ds.encoding["source"] = path  # figures name a branch by its file
    return ds


#: The digests of a Zarr branch's chunks, written last by :func:`save_branch`.
MANIFEST = ".gearchaos_chunks.json"


def _chunk_files(root: str) -> list[str]:
    """The chunk files of a Zarr store (every file not starting with a dot), sorted."""
    found = []
    for d, dirs, files in os.walk(root):
        dirs[:] = sorted(x for x in dirs if not x.startswith("."))
        found += [os.path.relpath(os.path.join(d, f), root) for f in files if f[0] != "."]
    return sorted(found)


def _metadata_files(root: str) -> list[str]:
    """The Zarr metadata files of a branch store (``.zmetadata``, which readers use, and every
    ``.zgroup``, ``.zattrs`` and ``.zarray``), sorted."""
    found = []
    for d, dirs, files in os.walk(root):
        dirs[:] = sorted(x for x in dirs if not x.startswith("."))
        found += [
            os.path.relpath(os.path.join(d, f), root).replace(os.sep, "/")
            for f in files
            if f in (".zmetadata", ".zgroup", ".zattrs", ".zarray")
        ]
    return sorted(found)


def _digest(path: str) -> str:
    """SHA-256 of a chunk file itself (never through a link, never blocking on a FIFO, at
    most 4 GiB: a chunk of a branch is far smaller)."""
    import hashlib

    return hashlib.sha256(read_nofollow(path, 1 << 32)).hexdigest()


def _check_chunks(path: str) -> None:
    """Every chunk of a Zarr branch is the one :func:`save_branch` wrote (its manifest of
    SHA-256 digests): a deleted, emptied or overwritten chunk, or one added, is reported by
    name instead of being read as data (fill values, junk)."""
    found = irregular_entry(path)
    if found is not None:  # Zarr opens its files plainly: it would block on a FIFO
        raise StoreError(
            f"branch {path} is damaged: {found[0]} is {found[1]}, not a regular file "
            "(gearchaos writes only files and directories in a branch store)"
        )
    try:
        manifest = json.loads(read_nofollow(os.path.join(path, MANIFEST), 1 << 30))
        if not isinstance(manifest, dict) or not all(
            isinstance(k, str) and isinstance(v, str) for k, v in manifest.items()
        ):
            raise ValueError(manifest)
    except (OSError, ValueError, UnicodeDecodeError):
        raise StoreError(
            f"branch {path} is damaged: its chunk manifest is missing or unreadable"
        ) from None
    on_disk = set(_chunk_files(path))
    # branches written since the manifest holds the metadata's digests have them checked too
    # (an array re-typed in .zarray and .zmetadata would be read as other numbers)
    metadata = {k for k in manifest if k.rsplit("/", 1)[-1].startswith(".")}
    on_disk |= set(_metadata_files(path)) if metadata else set()
    for key in sorted(set(manifest) | on_disk):
        what = "metadata file" if key.rsplit("/", 1)[-1].startswith(".") else "chunk"
        if key not in manifest:
            raise StoreError(f"branch {path} is damaged: {what} {key} is not in its manifest")
        try:
            same = key in on_disk and _digest(os.path.join(path, key)) == manifest[key]
        except OSError:
            same = False
        if not same:
            raise StoreError(f"branch {path} is damaged: {what} {key} is missing or altered")
