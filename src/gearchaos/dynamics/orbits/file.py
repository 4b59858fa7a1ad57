"""Orbit files: a :class:`~gearchaos.dynamics.orbits.orbit.PeriodicOrbit` written to netCDF-4 and
read
back (``gearchaos orbit -o ORBIT.nc``, then ``gearchaos continue --from ORBIT.nc``).

The file is :meth:`PeriodicOrbit.to_dataset
<gearchaos.dynamics.orbits.orbit.PeriodicOrbit.to_dataset>`:
the orbit state at the section, its multipliers and monodromy, the section values, and the
provenance a new start needs (gear set TOML with the values applied, ``omega``, every
``parameter:NAME`` value, the solver settings, the package version).
"""

from __future__ import annotations

import os
from typing import Any

from ..._files import check_output_file, load_netcdf
from ..._marks import hdf5_is_marked, mark_hdf5
from ..._output import check_replaceable, write_file
from ...errors import ParameterError, StoreError

__all__ = ["ORBIT_TITLE", "is_orbit_file", "open_orbit", "save_orbit"]

#: The title every orbit file starts with.
ORBIT_TITLE = "gearchaos periodic orbit"


def save_orbit(orbit: Any, path: str | os.PathLike[str]) -> str:
    """Write ``orbit`` to a netCDF-4 file (h5netcdf); returns the path. A file there is replaced
    only when gearchaos wrote it (else :class:`~gearchaos.errors.StoreError`)."""
    # a PeriodicOrbit (checked by what it offers: orbits.py imports this module)
    if not (hasattr(orbit, "to_dataset") and hasattr(orbit, "multipliers")):
        raise ParameterError(f"orbit must be a PeriodicOrbit: got {type(orbit).__name__}")
    text = check_output_file(path, what="orbit file")
    check_replaceable(text, what="orbit file", ours=is_orbit_file)
    data = mark_hdf5(orbit.to_dataset().to_netcdf(engine="h5netcdf", invalid_netcdf=True))
    return write_file(text, data, what="orbit file")


def open_orbit(path: str | os.PathLike[str]) -> Any:
    """Open an orbit file written by :func:`save_orbit` as an :class:`xarray.Dataset`; anything
    else raises :class:`~gearchaos.errors.StoreError` naming the file."""
    name, ds = load_netcdf(path, what="orbit file")
    if not str(ds.attrs.get("title", "")).startswith(ORBIT_TITLE) or "orbit_state" not in ds:
        raise StoreError(
            f"{name!r} is not a gearchaos orbit file: its title is "
            f"{ds.attrs.get('title', '(none)')!r}"
        )
    return ds


def is_orbit_file(path: str) -> bool:
    """Whether ``path`` is a netCDF file gearchaos wrote (what a new orbit file may replace):
    its mark ``gearchaos_output`` holds the digest of its attributes
    (:func:`gearchaos._marks.hdf5_is_marked`); a file that mentions gearchaos is not."""
    return hdf5_is_marked(path)
