"""Helpers of the sweep tests: short protocols and exact store comparison."""

from __future__ import annotations

import os

import numpy as np
import xarray as xr

#: Short protocol for the planetary sweeps (a few ms per point).
SHORT = {"transient_periods": 20, "periods": 16}

#: Attributes that describe how or where a sweep ran rather than what it computed. None of the
#: engine's attributes is execution-related today; keep the set here so that adding one (an
#: executor name, a wall time) is a deliberate decision of the tests.
EXECUTION_ATTRS: frozenset[str] = frozenset()


def open_store(path: str | os.PathLike[str]) -> xr.Dataset:
    """The store as the user opens it, fully loaded."""
    return xr.open_zarr(os.fspath(path)).load()


def assert_bitwise_equal(
    a: xr.Dataset, b: xr.Dataset, *, ignore_attrs: frozenset[str] = EXECUTION_ATTRS
) -> None:
    """Same variables, dims, coords, dtypes and bytes (NaN positions included), same attrs."""
    assert set(a.data_vars) == set(b.data_vars)
    assert set(a.coords) == set(b.coords)
    assert dict(a.sizes) == dict(b.sizes)
    for name in [*a.coords, *a.data_vars]:
        va, vb = a[name], b[name]
        assert va.dims == vb.dims, name
        x, y = np.asarray(va.values), np.asarray(vb.values)
        assert x.dtype == y.dtype, (name, x.dtype, y.dtype)
        if x.dtype.kind == "f":
            same_nan = np.array_equal(np.isnan(x), np.isnan(y))
            assert same_nan, f"{name}: NaN at different points"
            assert np.array_equal(x, y, equal_nan=True), (
                f"{name}: {np.sum(x != y)} values differ, max |diff| = {np.nanmax(np.abs(x - y))}"
            )
            assert x.tobytes() == y.tobytes(), f"{name}: not bitwise equal (signed zeros?)"
        else:
            assert np.array_equal(x, y), f"{name} differs"
    keys_a = set(a.attrs) - ignore_attrs
    keys_b = set(b.attrs) - ignore_attrs
    assert keys_a == keys_b
    for k in keys_a:
        assert a.attrs[k] == b.attrs[k], k


def file_snapshot(path: str | os.PathLike[str]) -> dict[str, tuple[int, bytes]]:
    """Modification time and content of every file under a store."""
    out: dict[str, tuple[int, bytes]] = {}
    root = os.fspath(path)
    for d, _, files in os.walk(root):
        for f in files:
            p = os.path.join(d, f)
            with open(p, "rb") as fh:
                out[os.path.relpath(p, root)] = (os.stat(p).st_mtime_ns, fh.read())
    return out
