"""The store of a basin computation (:mod:`gearchaos.sweep.basins`): a sweep store's machinery
(:class:`~gearchaos.sweep.store.SweepStore`: Zarr format 2, chunk by chunk, task markers,
chunk manifest, lock) with its own identity and reader.

Layout: ``kind`` ``basins`` (dims: the two state coordinates of the slice, ``y`` then ``x``)
or ``basin_fractions`` (dims: the parameter, ``start``); per start ``attractor`` (int code:
an index into the attractor legend, −1 not run, −2 failed), ``label`` (its motion label),
``status``, ``steps_accepted``, ``final_state`` (…, ``state``), and for fractions
``initial_state``. While the store is written, the attractor catalogue of every operating
point lives in ``_attractors.json`` (rewritten atomically as it grows, so a resumed run
continues with the same attractor codes); when every task is done it moves into the attribute
``attractors`` (JSON: one catalogue per operating point), with ``tracks`` for fractions.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import warnings
from typing import Any

import numpy as np

from .._files import check_path
from .._output import check_replaceable, is_own_zarr
from ..errors import StoreError
from .integrity import (
    MANIFEST,
    check_store_tree,
    read_json,
    verify_manifest,
    write_json_atomic,
)
from .store import PROGRESS, SweepStore, consolidate, set_attributes
from .storecheck import verify_metadata, verify_progress

__all__ = ["CATALOGUE", "KINDS", "BasinStore", "is_basin_store", "open_basins"]

#: The file of the attractor catalogues while a basin store is written.
CATALOGUE = "_attractors.json"
#: Values of the attribute ``kind`` of basin stores.
KINDS = ("basins", "basin_fractions")


def is_basin_store(path: str) -> bool:
    """Whether ``path`` is a basin store gearchaos wrote and nothing else."""
    return is_own_zarr(
        path,
        keys=("basin_spec", "version"),
        files=frozenset({MANIFEST, CATALOGUE}),
        markers=PROGRESS,
    )


def open_basins(path: str | os.PathLike[str], *, verify: bool = True) -> Any:
    """Open a basin store as an :class:`xarray.Dataset` (a missing or foreign path, damaged
    metadata or chunks raise :class:`~gearchaos.errors.StoreError` naming it)."""
    import xarray as xr

    root = check_path(
        path, f"a basin store path must be a non-empty path: got {path!r}", StoreError
    )
    if not os.path.isdir(root) or not os.path.exists(os.path.join(root, ".zgroup")):
        raise StoreError(
            f"no basin store at {root!r} (not a Zarr directory written by gearchaos basins)"
        )
    check_store_tree(root, "the basin computation")  # nothing for Zarr to block on
    if verify:
        verify_metadata(root)
        verify_manifest(root)
    try:
        ds = xr.open_zarr(root, chunks=None, consolidated=True)
    except Exception as exc:  # zarr and xarray raise many types for damaged metadata
        raise StoreError(f"{root!r} is not a readable basin store ({exc})") from None
    if ds.attrs.get("kind") not in KINDS or "attractor" not in ds.data_vars:
        raise StoreError(
            f"{root!r} is not a basin store (kind {ds.attrs.get('kind')!r}; a sweep store is "
            "drawn by gearchaos plot as a bifurcation diagram)"
        )
    if ds.attrs.get("complete") is not True:
        if verify:
            verify_progress(root, PROGRESS)
        left = int(np.sum(np.asarray(ds["status"].values) == 4))
        warnings.warn(
            f"{root!r} is an interrupted basin computation: {left} starts are not computed yet "
            "(attractor code -1); run the same command again to resume it",
            UserWarning,
            stacklevel=2,
        )
    return ds


class BasinStore(SweepStore):
    """A :class:`~gearchaos.sweep.store.SweepStore` with the basin store's identity, reader
    and attractor catalogue file."""

    def remove(self) -> None:
        if self.path is not None and os.path.lexists(self.path):
            check_replaceable(self.path, what="basin store", ours=is_basin_store)
            shutil.rmtree(self.path)

    def open(self) -> Any:
        if self.path is not None:
            return open_basins(self.path)
        import xarray as xr

        return xr.open_zarr(self.zarr_store, chunks=None, consolidated=True)

    def read_catalogues(self) -> dict[str, Any]:
        """The catalogue records written so far, by operating point (``{}`` when none)."""
        if self.path is None:
            return {}
        try:
            data = read_json(os.path.join(self.path, CATALOGUE))
        except FileNotFoundError:
            return {}
        except (OSError, ValueError):
            raise StoreError(
                f"{self.path} is damaged: its attractor catalogue {CATALOGUE} is not readable; "
                "run again with --overwrite (overwrite=True)"
            ) from None
        return dict(data) if isinstance(data, dict) else {}

    def write_catalogues(self, records: dict[str, Any]) -> None:
        if self.path is not None:
            write_json_atomic(os.path.join(self.path, CATALOGUE), records)

    def finish_with(self, attrs: dict[str, Any]) -> None:
        """Set the final attributes (the attractor legends), drop the catalogue file and
        finish the store (:meth:`~gearchaos.sweep.store.SweepStore.finish`)."""
        if self.path is not None:
            set_attributes(self.path, attrs)
            consolidate(self.path)
        else:
            import zarr

            g = zarr.open_group(self.zarr_store, mode="a", use_consolidated=False)
            g.attrs.update(attrs)
        self.finish()
        if self.path is not None:
            with contextlib.suppress(FileNotFoundError):
                os.remove(os.path.join(self.path, CATALOGUE))
