"""Dynamic mesh loads of a candidate gear set: is it a gear set that could run?

The calibration (issue 34) looks for the regime where the seed's clearances act: meshes that
reach their back flanks. Its first study found that regime only at dynamic mesh forces tens to
hundreds of times the static load (``paper/confirmation.json``): gear sets whose teeth would
break at the speeds the seed sweeps. A stand-in for the seed's lost Table 1
must be a gear set that could run, so the calibration measures the **peak dynamic load factor**

    LF = max over Ω ∈ :data:`LOAD_OMEGAS` and over every mesh of max |F_meshᶜ| / (T_D/(N r_bs)),

the largest contact force of the recorded window (the tracked extrema, not samples) over the
static load of one mesh (MODEL.md §10.1; under constant power T_D at that Ω), of runs of the
gear set as built (its own damping, the seed's clearances b̄_sp = 3, b̄_rp = 3.5, b̄_s = 2) from the
report's perturbed start after :data:`TRANSIENT` periods over :data:`RECORD` periods.

A candidate is **plausible in its loads** when its peak mesh force F_peak = LF · T_D/(N r_bs)
stays within the tooth-root bending strength of its sun–planet mesh (ISO 6336-3):

    F_allow = σ_FP b m / Y_FS,   b = k_m,sp / c_γ,   σ_FP = σ_Flim Y_ST / S_F,min

with the face width b that the gear set's own mesh stiffness implies (ISO 6336-1's mean mesh
stiffness per unit face width of spur gears, c_γ = :data:`C_GAMMA` = 20 N/(mm·µm)), the module m,
the combined tooth-form and stress-correction factor of a standard external tooth of about 30
teeth Y_FS = :data:`Y_FS` = 4.2, and case-carburised steel σ_Flim = 500 MPa, Y_ST = 2 with
S_F,min = 1 (σ_FP = 1000 MPa: the strength itself, no safety margin). For the seed's sets
(k_m,sp = 0.62e9 N/m, m = 4 mm) that is b = 31 mm and F_allow ≈ 30 kN, many times the static
load of the previous default and of the MODEL.md §9 set: a bound on gear sets whose teeth
break, not on lively ones. A run that fails counts as LF = ∞
(with its status).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = [
    "C_GAMMA",
    "LOAD_OMEGAS",
    "RECORD",
    "SIGMA_FP",
    "TRANSIENT",
    "Y_FS",
    "allowable_mesh_force",
    "load_factors",
]

#: Mesh frequencies of the load check: the seed's Ω range (Figs. 4, 5 sweep Ω ≤ 4).
LOAD_OMEGAS = (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5)
#: ISO 6336-1 mean mesh stiffness per unit face width of spur gears, N/m per m (20 N/(mm·µm)).
C_GAMMA = 20e9
#: Combined tooth-form and stress-correction factor Y_F·Y_S of a standard tooth (z ≈ 30, x = 0).
Y_FS = 4.2
#: Tooth-root strength σ_Flim·Y_ST/S_F,min of case-carburised steel with S_F,min = 1, Pa.
SIGMA_FP = 500e6 * 2.0 / 1.0
#: Protocol of the load check: periods discarded, then recorded.
TRANSIENT = 100
RECORD = 50


def allowable_mesh_force(gs: Any) -> float:
    """F_allow = σ_FP b m / Y_FS of the sun–planet mesh, in N (see the module docstring)."""
    width = gs.stiffness.sun_planet_mean / C_GAMMA
    return SIGMA_FP * width * gs.geometry.module / Y_FS


def load_factors(gs: Any, omegas: Sequence[float] = LOAD_OMEGAS) -> dict[str, Any]:
    """The peak dynamic loads of gear set ``gs`` over ``omegas``: ``{"max": LF, "omega": where,
    "per_omega": [LF at each Ω], "omegas", "status": [status at each Ω], "peak_force_N":
    F_peak, "allowable_force_N": F_allow, "plausible": F_peak ≤ F_allow}`` (LF = ∞ at an Ω
    whose run failed)."""
    from ..integrate.simulate import simulate

    per: list[float] = []
    status: list[str] = []
    for om in omegas:
        res = simulate(gs, omega=float(om), transient_periods=TRANSIENT, periods=RECORD)
        status.append(str(res.status))
        if not res.ok:
            per.append(math.inf)
            continue
        ds = res.to_dataset()
        peak = max(float(np.max(ds[f"load_factor_{m}"].values)) for m in ("sp", "rp"))
        per.append(peak if math.isfinite(peak) else math.inf)
    forces = [
        lf * _static_force(gs, float(om)) if math.isfinite(lf) else math.inf
        for lf, om in zip(per, omegas, strict=True)
    ]
    i = int(np.argmax(per))
    allow = allowable_mesh_force(gs)
    peak_force = float(max(forces))
    return {
        "peak_force_N": peak_force,
        "allowable_force_N": float(allow),
        "plausible": bool(peak_force <= allow),
        "max": float(per[i]),
        "omega": float(omegas[i]),
        "per_omega": [float(x) for x in per],
        "omegas": [float(x) for x in omegas],
        "status": status,
    }


def _static_force(gs: Any, omega: float) -> float:
    """T_D/(N r_bs) at Ω, in N (constant power: T_D Ω_ref/Ω)."""
    torque = gs.torque.input
    if gs.torque.mode == "constant_power":
        torque = torque * gs.torque.reference_omega / omega
    return torque / (gs.n_planets * gs.base_radius_sun)
