"""Damaged copies of the package's data files, for the tests that check they are refused."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import xarray as xr


def forge_nc(src: Path, dst: Path, **attrs: Any) -> Path:
    """A copy of the netCDF file ``src`` with its attributes changed (``None`` removes one)."""
    ds = xr.load_dataset(src, engine="h5netcdf")
    for key, value in attrs.items():
        if value is None:
            ds.attrs.pop(key, None)
        else:
            ds.attrs[key] = value
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "invalid netcdf features": as gearchaos writes them
        ds.to_netcdf(dst, engine="h5netcdf", invalid_netcdf=True)
    return dst
