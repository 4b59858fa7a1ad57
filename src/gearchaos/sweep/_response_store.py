"""Store variables of a frequency-response sweep and how to fill them (see
:mod:`gearchaos.sweep.frequency`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..model.response import (
    QUANTITIES,
    compressive_contact_forces,
    mesh_groups,
    response_quantities,
)

__all__ = ["response_extract", "response_variables"]


def response_variables(
    ref: Any, lead: tuple[str, ...], shape: tuple[int, ...], chunks: tuple[int, ...]
) -> tuple[dict[str, Any], dict[str, tuple[int, ...]]]:
    """Store variables of the response quantities (:class:`~gearchaos.sweep.run._Layout`)."""
    var: dict[str, Any] = {}
    ch: dict[str, tuple[int, ...]] = {}
    for g in mesh_groups(ref):
        npl = g.force.columns.size if g.force.per_planet else 0
        tail_dims = ("planet_all",) if npl else ()
        tail = (npl,) if npl else ()
        for q, meaning in QUANTITIES.items():
            per = tail if q != "load_factor" else ()
            dims = (*lead, *(tail_dims if per else ()))
            var[f"{q}_{g.mesh}"] = (
                dims,
                ((*shape, *per), "float64"),
                np.nan,
                {"long_name": meaning, "units": "1", "mesh": g.mesh},
            )
            ch[f"{q}_{g.mesh}"] = (*chunks, *per)
        for nm, cols, per_planet in ref.tracked_groups(contact_forces=True):
            if nm != g.force.name:
                continue
            for which in ("min", "max"):
                dims = (*lead, *(("planet_all",) if per_planet else ()))
                var[f"{nm}_{which}"] = (
                    dims,
                    ((*shape, *((cols.size,) if per_planet else ())), "float64"),
                    np.nan,
                    {"long_name": f"{which} of the contact force {nm} over the recorded window"},
                )
                ch[f"{nm}_{which}"] = (*chunks, *((cols.size,) if per_planet else ()))
    return var, ch


def response_extract(
    data: dict[str, np.ndarray],
    pos: tuple[int, ...],
    system: Any,
    obs_min: np.ndarray,
    obs_max: np.ndarray,
    observables: np.ndarray,
    *,
    ok: bool,
) -> None:
    """Fill one point's response quantities into the block arrays ``data`` (created here on
    the first call with the shape ``data["status"]`` has); NaN where the point failed."""
    bshape = data["status"].shape
    observables, obs_min, obs_max = compressive_contact_forces(
        system, observables, obs_min, obs_max
    )
    values = response_quantities(system, obs_min, obs_max, observables)
    for g in mesh_groups(system):
        cols = g.force.columns
        values[f"{g.force.name}_min"] = obs_min[cols] if g.force.per_planet else obs_min[cols[0]]
        values[f"{g.force.name}_max"] = obs_max[cols] if g.force.per_planet else obs_max[cols[0]]
    for k, v in values.items():
        arr = np.asarray(v, dtype=np.float64)
        if k not in data:
            data[k] = np.full((*bshape, *arr.shape), np.nan)
        data[k][pos] = arr if ok else np.nan
