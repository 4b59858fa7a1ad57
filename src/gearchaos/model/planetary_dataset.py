"""The simulation dataset of a planetary result: variables named per planet (the layout of
:meth:`gearchaos.integrate.result.SimulationResult.to_dataset` for the planetary model).

Section values ``delta_sp``, ``delta_rp`` … over (section, planet), their extrema over the
recorded window, the contact-force extrema and the dynamic load factor, with long names and
units; the model hands it to the result (:meth:`PlanetaryModel.result_dataset`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

_DIMLESS = "1"


def planetary_dataset(
    model: Any, result: Any, attrs: dict[str, Any], series: Callable[[str], np.ndarray | None]
) -> Any:
    import xarray as xr

    N = model.n_planets
    idx = result.section_index
    tau = result.tau[idx]
    coords = {
        "tau": xr.DataArray(
            tau,
            dims="section",
            attrs={"long_name": "τ = ω_n t at the section", "units": _DIMLESS},
        ),
        "planet": xr.DataArray(np.arange(1, N + 1), dims="planet", attrs={"long_name": "planet i"}),
    }
    ds = xr.Dataset(coords=coords, attrs=attrs)
    b_sp, b_rp = model.parameters.b_sp, model.parameters.b_rp

    def put(
        name: str, dims: tuple[str, ...], long_name: str, units: str = "b_c", **extra: Any
    ) -> None:
        full = series(name)
        assert full is not None
        ds[name] = xr.DataArray(
            full[idx], dims=dims, attrs={"long_name": long_name, "units": units, **extra}
        )

    lu = {"units_note": "dimensionless, in units of the characteristic length b_c"}
    put(
        "delta_sp",
        ("section", "planet"),
        "X̄_sp = δ_sp/b_c, sun–planet mesh deflection",
        _DIMLESS,
        backlash=b_sp,
        **lu,
    )
    put(
        "delta_rp",
        ("section", "planet"),
        "X̄_rp = δ_rp/b_c, planet–ring mesh deflection",
        _DIMLESS,
        backlash=b_rp,
        **lu,
    )
    put("delta_sp_dot", ("section", "planet"), "X̄'_sp = dX̄_sp/dτ", _DIMLESS)
    put("delta_rp_dot", ("section", "planet"), "X̄'_rp = dX̄_rp/dτ", _DIMLESS)
    put(
        "force_sp",
        ("section", "planet"),
        "F̄_sp = F_sp/(k_m,sp b_c), sun–planet mesh force",
        _DIMLESS,
    )
    put(
        "force_rp",
        ("section", "planet"),
        "F̄_rp = F_rp/(k_m,sp b_c), planet–ring mesh force",
        _DIMLESS,
    )
    for mesh, what in (("sp", "sun–planet"), ("rp", "planet–ring")):
        put(
            f"contact_force_{mesh}",
            ("section", "planet"),
            f"F̄ᶜ_{mesh}, {what} contact force: κ f(X̄; b̄) + c̄ X̄' where it presses the "
            "flanks in contact together, 0 while apart or pulling",
            _DIMLESS,
        )
    put("x_s", ("section",), "x̄_s, sun centre displacement", _DIMLESS, **lu)
    put("y_s", ("section",), "ȳ_s, sun centre displacement", _DIMLESS, **lu)
    put("x_s_dot", ("section",), "x̄'_s", _DIMLESS)
    put("y_s_dot", ("section",), "ȳ'_s", _DIMLESS)
    put("p", ("section", "planet"), "p̄_i = (u_s + u_i − u_c cos α_s)/b_c", _DIMLESS)
    put("sigma", ("section",), "σ̄ = (u_s − u_c (cos α_s + cos α_r))/b_c", _DIMLESS)
    put("p_dot", ("section", "planet"), "p̄'_i", _DIMLESS)
    put("sigma_dot", ("section",), "σ̄'", _DIMLESS)
    for mesh, off in (("sp", 0), ("rp", N)):
        for which, arr in (("min", result.obs_min), ("max", result.obs_max)):
            ds[f"delta_{mesh}_{which}"] = xr.DataArray(
                arr[off : off + N],
                dims=("planet",),
                attrs={
                    "long_name": f"{which} of X̄_{mesh} over the recorded window",
                    "units": _DIMLESS,
                },
            )
    for k, coord in ((2 * N, "x_s"), (2 * N + 1, "y_s")):
        for which, arr in (("min", result.obs_min), ("max", result.obs_max)):
            ds[f"{coord}_{which}"] = xr.DataArray(
                arr[k],
                attrs={
                    "long_name": f"{which} of {coord} over the recorded window",
                    "units": _DIMLESS,
                },
            )
    # contact-force extrema tracked in the integrator, and the dynamic load factor
    # max |F̄ᶜ| over the static mesh force T̄_D/N (MODEL.md §10.1)
    td, _ = model.parameters.loads(result.omega)
    static = td / N
    for mesh in ("sp", "rp"):
        cols = result.system.observable(f"contact_force_{mesh}").columns
        for which, arr in (("min", result.obs_min), ("max", result.obs_max)):
            ds[f"contact_force_{mesh}_{which}"] = xr.DataArray(
                arr[cols],
                dims=("planet",),
                attrs={
                    "long_name": f"{which} of F̄ᶜ_{mesh} over the recorded window",
                    "units": _DIMLESS,
                },
            )
        if static > 0:
            peak = np.maximum(np.abs(result.obs_min[cols]), np.abs(result.obs_max[cols]))
            ds[f"load_factor_{mesh}"] = xr.DataArray(
                peak / static,
                dims=("planet",),
                attrs={
                    "long_name": f"dynamic load factor max |F_{mesh}ᶜ|/(T_D/(N r_bs))",
                    "units": _DIMLESS,
                    "note": "contact force (0 while the teeth are apart or the damping would "
                    "pull), extrema tracked "
                    "inside every integration step: independent of the sampling",
                },
            )
    return ds
