"""The sweep result store: Zarr, written chunk by chunk, resumable after any interruption.

Layout (Zarr format 2): one array per variable with xarray's ``_ARRAY_DIMENSIONS``,
leading dimensions ``spec.dims``, then ``section`` / ``planet`` / ``planet_all`` / ``state``
as the variable needs. Each task writes only its own Zarr chunks, then drops a marker file
``_progress/<task>.done``. A task without a marker is (re)computed on resume, so a chunk half
written when the process was killed (even with SIGKILL) is simply written again; results are
deterministic, so the final store equals an uninterrupted run's. When every task is done the
markers are removed and the attribute ``complete`` becomes true.

Every store carries its provenance: the gear set (``gearset_toml``), the sweep specification
(``sweep_toml``), the solver settings and the versions of gearchaos, numba and numpy.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import warnings
from collections.abc import Iterable, Iterator, Sequence
from typing import Any

import numpy as np

from .._files import check_path, read_nofollow
from .._marks import MARK_KEY, zarr_mark
from .._output import check_replaceable, is_own_zarr, write_error, write_file
from ..errors import Status, StoreError
from ..gearset.mapping import flatten
from .integrity import (
    MANIFEST,
    METADATA_MAX_BYTES,
    check_store_tree,
    chunk_keys,
    digest_chunks,
    manifest_record,
    read_json,
    verify_chunks,
    verify_manifest,
    write_json_atomic,
)
from .storecheck import verify_attributes, verify_metadata, verify_progress

__all__ = ["SweepStore", "open_sweep"]

PROGRESS = "_progress"


def is_sweep_store(path: str) -> bool:
    """Whether ``path`` is a directory gearchaos wrote as a sweep store and nothing else
    (:func:`~gearchaos._output.is_own_zarr`: its attributes name the sweep and the package
    version; it holds only Zarr metadata, the manifest, the task markers and arrays of chunks —
    a file a user put inside makes it no longer only a store, so ``overwrite`` refuses it)."""
    return is_own_zarr(
        path, keys=("sweep_toml", "version"), files=frozenset({MANIFEST}), markers=PROGRESS
    )


@contextlib.contextmanager
def foreign_files_ignored() -> Iterator[None]:
    """Silence Zarr's warning about the files of a store that are no Zarr nodes (the task
    markers and the chunk manifest), which it meets when it lists the store."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*not recognized as a component")
        yield


def set_attributes(root: str, updates: dict[str, Any]) -> None:
    """Update the root attributes (``.zattrs``) of an on-disk store in one atomic write (Zarr
    rewrites the file in place: a kill or a full disk would leave it torn)."""
    path = os.path.join(root, ".zattrs")
    attrs = read_json(path)
    attrs.update(updates)
    write_file(path, json.dumps(attrs, indent=4).encode("utf-8"), what="store attributes")


def consolidate(store: Any) -> None:
    """Consolidate a store's metadata. On disk the ``.zmetadata`` file is built from the
    metadata files and written in one atomic step (Zarr's own writer truncates it first, so a
    full disk or a kill would leave a store that no longer opens)."""
    import zarr

    if not isinstance(store, str):
        with foreign_files_ignored():
            zarr.consolidate_metadata(store)
        return
    meta: dict[str, Any] = {}
    for dirpath, dirnames, files in os.walk(store):
        dirnames[:] = sorted(d for d in dirnames if d != PROGRESS)
        rel = os.path.relpath(dirpath, store).replace(os.sep, "/")
        for name in (".zgroup", ".zattrs", ".zarray"):
            if name in files:
                meta[name if rel == "." else f"{rel}/{name}"] = read_json(
                    os.path.join(dirpath, name)
                )
    text = json.dumps({"metadata": meta, "zarr_consolidated_format": 1}, indent=4)
    write_file(os.path.join(store, ".zmetadata"), text.encode("utf-8"), what="store metadata")


def open_sweep(path: str | os.PathLike[str], *, verify: bool = True) -> Any:
    """Open a sweep store as an :class:`xarray.Dataset` (lazy, no dask needed).

    A path that is no sweep store (missing, a file, an empty or foreign directory, unreadable
    metadata) raises :class:`~gearchaos.errors.StoreError`; with ``verify`` (the default) every
    chunk of a complete store is checked against its manifest first, so a deleted, truncated or
    overwritten chunk is reported by name instead of being read as data.
    """
    import xarray as xr

    root = check_path(
        path, f"a sweep store path must be a non-empty path: got {path!r}", StoreError
    )
    if not os.path.exists(root):
        raise StoreError(f"no sweep store at {root!r} (no such file or directory)")
    if not os.path.isdir(root):
        raise StoreError(
            f"{root!r} is not a readable sweep store: it is a file, not a directory such as "
            "run.zarr"
        )
    if not os.path.lexists(os.path.join(root, ".zgroup")):
        raise StoreError(f"{root!r} is not a readable sweep store (no Zarr group metadata .zgroup)")
    check_store_tree(root)  # no FIFO or device for Zarr to block on, even unverified
    if verify:  # the metadata first, as before a resume: then its digests and the chunks
        verify_metadata(root)
        verify_manifest(root)
    consolidated = os.path.exists(os.path.join(root, ".zmetadata"))
    try:
        ds = xr.open_zarr(root, chunks=None, consolidated=consolidated)
    except Exception as exc:  # zarr and xarray raise many types for damaged metadata
        raise StoreError(
            f"{root!r} is not a readable sweep store ({type(exc).__name__}: {exc})"
        ) from None
    if "status" not in ds.data_vars:
        raise StoreError(f"{root!r} is not a gearchaos sweep store (no 'status' variable)")
    if verify:
        verify_attributes(root, ds)
        if ds.attrs.get("complete") is not True:
            verify_progress(root, PROGRESS)
    if ds.attrs.get("complete") is not True:
        status = np.asarray(ds["status"].values)
        left = int(np.sum(status == int(Status.NOT_RUN)))
        if left:
            warnings.warn(
                f"{root!r} is an interrupted sweep: {left} of {status.size} points are not "
                "computed yet (shown as 'not run'); run the same command again to resume it",
                UserWarning,
                stacklevel=2,
            )
    return ds


class SweepStore:
    """Creates, checks and fills a sweep store."""

    def __init__(self, path: str | os.PathLike[str] | None):
        self.path = None if path is None else os.fspath(path)
        self._memory: Any = None
        self._arrays: dict[str, Any] | None = None

    # ------------------------------------------------------------------ identity
    @property
    def zarr_store(self) -> Any:
        if self.path is not None:
            return self.path
        if self._memory is None:
            import zarr

            self._memory = zarr.storage.MemoryStore()
        return self._memory

    def exists(self) -> bool:
        return self.path is not None and os.path.exists(os.path.join(self.path, ".zgroup"))

    def attrs(self) -> dict[str, Any]:
        import zarr

        return dict(zarr.open_group(self.zarr_store, mode="r").attrs)

    def verify(self) -> None:
        """The checks of :func:`open_sweep` before a store is resumed: its metadata (every
        file equal to its consolidated copy, every array of the schema gearchaos writes)
        and, when complete, every chunk against the manifest."""
        if self.path is not None:
            check_store_tree(self.path)
            verify_metadata(self.path)
            verify_manifest(self.path)

    def check_same(self, identity: dict[str, Any]) -> None:
        """Refuse to resume a store made with other settings (name what differs)."""
        old = self.attrs()
        diffs = []
        for k, v in identity.items():
            if k == "sweep_toml" and isinstance(old.get(k), str):
                # the same sweep, whatever the version that wrote its text
                stored = _spec_text(old[k])
                if stored != v:
                    diffs.append(_toml_diff(stored, v, "sweep"))
            elif old.get(k) != v:
                if k == "gearset_toml" and isinstance(old.get(k), str):
                    diffs.append(_toml_diff(old[k], v, "gear set"))
                else:
                    diffs.append(f"{k}: store has {_short(old.get(k))}, now {_short(v)}")
        if diffs:
            raise StoreError(
                f"{self.path} holds a sweep with other settings ("
                + "; ".join(diffs)
                + "). Use another output path, or overwrite=True (--overwrite) to replace it."
            )

    def check_resumable(self, variables: Iterable[str]) -> None:
        """Refuse to resume an interrupted store that lacks ``variables`` this version writes
        (one written before every sweep stored its verdicts), naming them."""
        import zarr

        g = zarr.open_group(self.zarr_store, mode="r", use_consolidated=False)
        missing = sorted(set(variables) - {name for name, _ in g.arrays()})
        if missing:
            raise StoreError(
                f"{self.path} is an interrupted sweep written by an earlier version, without "
                f"the variables {', '.join(missing)} that every sweep now stores: it cannot "
                "be resumed; run the sweep again with --overwrite (overwrite=True)"
            )

    def remove(self) -> None:
        """Delete the store (``overwrite``): only a gearchaos sweep store that holds nothing
        else (:func:`is_sweep_store`); any other path is refused with its name."""
        if self.path is not None and os.path.lexists(self.path):
            check_replaceable(self.path, what="sweep store", ours=is_sweep_store)
            shutil.rmtree(self.path)

    # ------------------------------------------------------------------ creation
    def create(
        self,
        coords: dict[str, tuple[tuple[str, ...], np.ndarray]],
        variables: dict[str, tuple[tuple[str, ...], Any, Any, dict[str, Any]]],
        chunks: dict[str, tuple[int, ...]],
        attrs: dict[str, Any],
    ) -> None:
        """Coordinates are written whole; float variables are created empty (NaN fill value);
        integer and string variables are written with their "not run" value and carry no fill
        value, so xarray keeps their type.

        On disk the store is built under a temporary name and renamed into place, so a store
        path either holds a complete, resumable layout or nothing (a kill during creation
        leaves only a ``*.creating-*`` directory, removed by the next run).
        """
        import xarray as xr
        import zarr

        target: Any = self.zarr_store
        tmp = None
        if self.path is not None:
            parent = os.path.dirname(os.path.abspath(self.path))
            os.makedirs(parent, exist_ok=True)
            base = os.path.basename(self.path)
            for stale in os.listdir(parent):
                if stale.startswith(base + ".creating-"):
                    shutil.rmtree(os.path.join(parent, stale), ignore_errors=True)
            tmp = f"{self.path}.creating-{os.getpid()}"
            target = tmp
        try:
            ds = xr.Dataset(coords={k: (d, v) for k, (d, v) in coords.items()})
            ds.attrs.update(attrs)
            ds.attrs["complete"] = False
            ds.attrs[MARK_KEY] = zarr_mark(ds.attrs)  # gearchaos's mark: what overwrite replaces
            # Zarr format 2: consolidated metadata and string coordinates are part of its
            # specification (format 3 still flags both as unstable)
            ds.to_zarr(target, mode="w", consolidated=False, zarr_format=2)
            g = zarr.open_group(target, mode="a", zarr_format=2)
            for name, (dims, shape_dtype, fill, vattrs) in variables.items():
                shape, dtype = shape_dtype
                # integers, flags and strings (labels) carry no fill value, so xarray keeps
                # their type
                written = np.dtype(dtype).kind in "iubU"
                arr = g.create_array(
                    name,
                    shape=shape,
                    chunks=chunks[name],
                    dtype=dtype,
                    fill_value=None if written else fill,
                    attributes={**vattrs, "_ARRAY_DIMENSIONS": list(dims)},
                )
                if written:
                    arr[...] = np.full(shape, fill, dtype=dtype)
            consolidate(target)
            if tmp is not None and self.path is not None:
                os.makedirs(os.path.join(tmp, PROGRESS), exist_ok=True)
                os.rename(tmp, self.path)
        except BaseException as exc:  # a full disk or an interrupt: no half-built store left
            if tmp is not None:
                shutil.rmtree(tmp, ignore_errors=True)
            if isinstance(exc, OSError) and self.path is not None:
                raise write_error(exc, "sweep store", self.path) from None
            raise

    # ------------------------------------------------------------------ progress
    def done_tasks(self) -> set[int]:
        """Tasks whose chunks are written and intact: a marker whose recorded chunks are
        missing or damaged is dropped, so the task is computed again."""
        if self.path is None:
            return set()
        d = os.path.join(self.path, PROGRESS)
        if not os.path.isdir(d):
            return set()
        out = set()
        for name in os.listdir(d):
            if not name.endswith(".done"):
                continue
            try:
                index = int(name[:-5])
                text = read_nofollow(os.path.join(d, name), METADATA_MAX_BYTES)
                chunks = json.loads(text)["chunks"] if text.strip() else {}
            except (ValueError, KeyError, TypeError, OSError):
                continue  # a marker torn by a kill: the task is computed again
            if not verify_chunks(self.path, chunks):
                out.add(index)
        return out

    def write(self, task_index: int, block: tuple[slice, ...], data: dict[str, np.ndarray]) -> None:
        """Write a task's block of every variable, then mark the task done."""
        self.write_tasks([(task_index, block, data)])

    def write_tasks(self, tasks: Sequence[TaskData]) -> None:
        """Write the blocks of several tasks (index, block, data), then mark each done.

        Tasks whose blocks follow each other along the last dimension (a sweep's tasks in
        order) are written by one assignment per variable: each costs about a millisecond
        whatever its size. The markers come after all the data, so a kill in between leaves
        tasks without markers, which a resume computes again."""
        import zarr

        if not tasks:
            return
        if self._arrays is None:  # open once: reopening costs tens of ms per task
            g = zarr.open_group(self.zarr_store, mode="a", use_consolidated=False)
            self._arrays = {}
            for name in tasks[0][2]:
                arr = g[name]
                assert isinstance(arr, zarr.Array)
                self._arrays[name] = arr
        keys: dict[int, list[str]] = {index: [] for index, _, _ in tasks}
        try:
            for run in _contiguous(tasks):
                block = (*run[0][1][:-1], slice(run[0][1][-1].start, run[-1][1][-1].stop))
                # status last: a point whose status says it ran has every other variable
                for name in sorted(run[0][2], key=lambda n: n == "status"):
                    arr = self._arrays[name]
                    parts = [data[name] for _, _, data in run]
                    whole = parts[0] if len(parts) == 1 else np.concatenate(parts, len(block) - 1)
                    arr[block + (slice(None),) * (arr.ndim - len(block))] = whole
                    for index, b, _ in run:
                        keys[index] += chunk_keys(name, arr.shape, arr.chunks, b)
        except OSError as exc:  # the tasks have no markers: a resume computes them again
            raise write_error(exc, "sweep store", str(self.path)) from None
        if self.path is not None:
            d = os.path.join(self.path, PROGRESS)
            os.makedirs(d, exist_ok=True)
            # the marker records what was written: a later damage is found on resume
            for index, task_keys in keys.items():
                write_json_atomic(
                    os.path.join(d, f"{index}.done"),
                    {"chunks": digest_chunks(self.path, task_keys)},
                )

    def clear_stale_progress(self) -> None:
        """Remove task markers left by a kill after a store was completed."""
        if self.path is not None:
            shutil.rmtree(os.path.join(self.path, PROGRESS), ignore_errors=True)

    def refresh_manifest(self) -> None:
        """Rewrite the chunk manifest of a complete store after a legitimate change (the
        classifier relabelling its points)."""
        if self.path is not None and os.path.exists(os.path.join(self.path, MANIFEST)):
            write_json_atomic(os.path.join(self.path, MANIFEST), manifest_record(self.path))

    def finish(self) -> None:
        """Mark the store complete: write the chunk manifest, set ``complete``, consolidate the
        metadata, then remove the task markers. A kill at any moment leaves a store that the
        next run finishes (markers present: nothing is recomputed) or a complete one."""
        import zarr

        if self.path is not None:
            write_json_atomic(os.path.join(self.path, MANIFEST), manifest_record(self.path))
        if self.path is not None:
            set_attributes(self.path, {"complete": True})
        else:
            g = zarr.open_group(self.zarr_store, mode="a", use_consolidated=False)
            g.attrs["complete"] = True
        consolidate(self.zarr_store)
        if self.path is not None:
            shutil.rmtree(os.path.join(self.path, PROGRESS), ignore_errors=True)

    def open(self) -> Any:
        if self.path is not None:
            return open_sweep(self.path)
        import xarray as xr

        return xr.open_zarr(self.zarr_store, chunks=None, consolidated=True)


def _short(v: Any, limit: int = 80) -> str:
    r = repr(v)
    return r if len(r) <= limit else r[: limit - 3] + "..."


def _spec_text(text: str) -> str:
    """A stored sweep specification as this version writes it (the text itself when it is not
    readable: then it differs)."""
    from .spec import SweepSpec

    try:
        return SweepSpec.from_toml(text).to_toml()
    except StoreError:
        return text


def _toml_diff(old: str, new: str, what: str) -> str:
    import tomllib

    try:
        a, b = flatten(tomllib.loads(old)), flatten(tomllib.loads(new))
    except Exception:
        return f"{what} differs (the stored text is not readable TOML)"
    keys = sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))
    shown = []
    for k in keys[:4]:
        va, vb = a.get(k), b.get(k)
        head, dot, field = k.rpartition(".")
        if dot and (head.startswith("vary[") or head == "family"):
            axis = b.get(f"{head}.name") or a.get(f"{head}.name")
            k = f"{head.split('[')[0]} axis {axis!r} {field}"
        if isinstance(va, list) and len(va) > 6:
            va = f"[{len(va)} values {va[0]}..{va[-1]}]"
        if isinstance(vb, list) and len(vb) > 6:
            vb = f"[{len(vb)} values {vb[0]}..{vb[-1]}]"
        shown.append(f"{k}: store has {va!r}, now {vb!r}")
    more = f" (+{len(keys) - 4} more)" if len(keys) > 4 else ""
    return f"{what} differs: " + ", ".join(shown) + more


#: A finished task for the store: its index, its block (slices over the sweep's dimensions)
#: and its block of every variable.
TaskData = tuple[int, tuple[slice, ...], dict[str, np.ndarray]]


def _contiguous(tasks: Sequence[TaskData]) -> Iterator[list[TaskData]]:
    """Runs of consecutive tasks whose blocks follow each other along the last dimension
    (equal in the others) and that carry the same variables."""
    run = [tasks[0]]
    for task in tasks[1:]:
        prev, block = run[-1][1], task[1]
        if (
            len(block) == len(prev)
            and block[:-1] == prev[:-1]
            and block[-1].start == prev[-1].stop
            and task[2].keys() == run[0][2].keys()
        ):
            run.append(task)
        else:
            yield run
            run = [task]
    yield run
