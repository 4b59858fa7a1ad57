"""Result of :func:`gearchaos.simulate`: a :class:`Trajectory` that converts to xarray.

Data contract of :meth:`SimulationResult.to_dataset` for the planetary model (keep these names):
dimension ``section`` (coordinate ``tau``) and ``planet`` (1..N); variables ``delta_sp``,
``delta_rp``, ``delta_sp_dot``, ``delta_rp_dot`` (section, planet), ``x_s``, ``y_s``,
``x_s_dot``, ``y_s_dot`` (section), ``delta_sp_min``, ``delta_sp_max``, ``delta_rp_min``,
``delta_rp_max`` (planet), ``contact_force_sp``, ``contact_force_rp`` (section, planet: the
mesh contact forces, 0 while the teeth are apart and where the mesh force would pull,
:func:`gearchaos.model.response.compressive_contact_forces`) with their ``_min``/``_max``
(planet) and
``load_factor_sp``, ``load_factor_rp`` (planet: max |F̄ᶜ| over T̄_D/N); attributes
``model_class`` and ``model_fields`` (the model reference: for a gear set, the gear set),
``gearset_toml`` (the gear set again, for the previous release), ``omega``, ``rtol``,
``atol``, ``transient_periods`` (the protocol's), ``extra_periods`` (periods a motion
verdict added to that transient before the record), ``periods``, ``status``, ``version``.
With ``samples_per_period > 1`` the full time history is added on dimension ``sample``
(coordinate ``tau_sample``) as ``<name>_history``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from .._files import check_output_file, load_netcdf
from .._marks import hdf5_is_marked, mark_hdf5
from .._output import check_replaceable, write_file
from .._version import provenance
from ..errors import ParameterError, StoreError
from ..model.record import model_record
from .trajectory import Trajectory

__all__ = ["SimulationResult", "open_simulation"]

#: The start of every simulation file's title: what identifies one.
SIMULATION_TITLE = "gearchaos simulation"

_DIMLESS = "1"


@dataclass(frozen=True, eq=False)
class SimulationResult(Trajectory):
    """A :class:`Trajectory` plus conversion to an :class:`xarray.Dataset` and to files."""

    @classmethod
    def from_trajectory(cls, traj: Trajectory) -> SimulationResult:
        return cls(**{f.name: getattr(traj, f.name) for f in fields(Trajectory)})

    @property
    def omega(self) -> float:
        return self.system.omega

    @property
    def gearset(self) -> Any:
        return self.system.capabilities.gearset

    # ------------------------------------------------------------------ xarray
    def _attrs(self) -> dict[str, Any]:
        attrs: dict[str, Any] = {
            "title": f"{SIMULATION_TITLE} of {self.system.name}",
            "model": self.system.name,
            "omega": self.omega,
            **self.solver.attrs(),
            "extra_periods": int(self.extra_periods),
            "status": self.status.name.lower(),
            "status_message": self.status.message,
            "steps_accepted": self.steps_accepted,
            "steps_rejected": self.steps_rejected,
            "steps_switch": self.steps_switch,
            "initial_state": self.origin
            or (
                "given"
                if self.y0 is not None
                else ("zero" if self.solver.perturbation == 0 else "rest, perturbed")
            ),
            **provenance(),
        }
        record = model_record(self.system)
        attrs["gearset_toml"] = record["gearset_toml"]
        caps = self.system.capabilities
        sc = caps.scales
        if sc is not None:
            attrs["omega_n_rad_s"] = sc.omega_n
            attrs["characteristic_length_m"] = sc.length
            attrs["mesh_frequency_rad_s"] = self.omega * sc.omega_n
        for k, v in caps.clearances.items():
            attrs[f"clearance_{k}"] = v
        if caps.period_factor != 1.0:
            attrs["period_factor"] = caps.period_factor
        # to build the model again: the reference in the same record
        attrs.update({k: record[k] for k in ("model_class", "model_fields") if k in record})
        return attrs

    def to_dataset(self) -> Any:
        """The result as an :class:`xarray.Dataset` (see the module docstring for names)."""
        writer = self.system.capabilities.result_dataset
        if writer is None:  # the generic layout: one variable per state and observable
            return self._generic_dataset()
        ds = writer(self, self._attrs(), self._series_for)  # the model's own layout
        self._history(ds)
        return ds

    def _history(self, ds: Any) -> None:
        if self.samples_per_period <= 1:
            return
        import xarray as xr

        ds.coords["tau_sample"] = xr.DataArray(
            self.tau, dims="sample", attrs={"long_name": "τ = ω_n t", "units": _DIMLESS}
        )
        for name in list(ds.data_vars):
            if "section" not in ds[name].dims:
                continue
            v = ds[name]
            full = self._series_for(name)
            if full is None:
                continue
            dims = tuple("sample" if d == "section" else d for d in v.dims)
            ds[f"{name}_history"] = xr.DataArray(full, dims=dims, attrs=v.attrs)

    def _series_for(self, name: str) -> np.ndarray | None:
        try:
            return self.series(name)
        except ParameterError:
            return None

    def _generic_dataset(self) -> Any:
        import xarray as xr

        idx = self.section_index
        ds = xr.Dataset(
            coords={"tau": xr.DataArray(self.tau[idx], dims="section", attrs={"units": _DIMLESS})},
            attrs=self._attrs(),
        )
        for name in self.system.state_names + self.system.obs_names:
            if name in ds:
                continue
            full = self._series_for(name)
            assert full is not None
            ds[name] = xr.DataArray(full[idx], dims=("section",), attrs={"units": _DIMLESS})
        for k, name in enumerate(self.system.obs_names[: self.system.n_track]):
            ds[f"{name}_min"] = float(self.obs_min[k])
            ds[f"{name}_max"] = float(self.obs_max[k])
        self._history(ds)
        return ds

    # ------------------------------------------------------------------ files
    def save(self, path: str | os.PathLike[str]) -> str:
        """Write the dataset to a netCDF-4 file (h5netcdf); returns the path.

        ``path`` must be a file path whose directory exists; an existing regular file is
        replaced, anything else there (a directory, a FIFO, a device such as ``/dev/null``)
        is refused with :class:`~gearchaos.errors.StoreError`, as is a failed write.
        """
        text = check_output_file(path, what="simulation file")
        check_replaceable(text, what="simulation file", ours=is_simulation_file)
        # serialised in memory first (HDF5 crashes on a full disk), then written under a
        # unique temporary name and renamed: never a half-written file under the final name
        data = mark_hdf5(self.to_dataset().to_netcdf(engine="h5netcdf", invalid_netcdf=True))
        return write_file(text, data, what="simulation file")


def open_simulation(path: str | os.PathLike[str]) -> Any:
    """Open a file written by :meth:`SimulationResult.save` as an :class:`xarray.Dataset`.

    A path that is not a regular file (missing, a directory, a FIFO or device) or a file that
    is not netCDF-4 raises :class:`~gearchaos.errors.StoreError` naming the file (a FIFO is
    never opened blocking); a path of the wrong type raises
    :class:`~gearchaos.errors.ParameterError`.
    """
    name, ds = load_netcdf(path, what="simulation file")
    if not str(ds.attrs.get("title", "")).startswith(SIMULATION_TITLE):
        what = "a branch (open it with open_branch)" if "parameter" in ds.attrs else "another"
        raise StoreError(
            f"{name!r} is not a gearchaos simulation file: its title is "
            f"{ds.attrs.get('title', '(none)')!r}, {what} netCDF file"
        )
    return ds


def is_simulation_file(path: str) -> bool:
    """Whether ``path`` is a netCDF file gearchaos wrote (what a new simulation file may
    replace): its mark ``gearchaos_output`` holds the digest of its attributes
    (:func:`gearchaos._marks.hdf5_is_marked`); a file that mentions gearchaos is not."""
    return hdf5_is_marked(path)
