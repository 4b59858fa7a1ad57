"""Dynamic mesh forces and transmission errors of one run: the numbers of a frequency response.

For every mesh type of a model (``sp`` and ``rp`` of the planetary model, one per planet;
``mesh`` of the backlash oscillator) this module turns the kernel's outputs into

* the **contact force** F̄ᶜ = κ(τ) f(δ̄; b̄) + c̄ δ̄' while the teeth touch (|δ̄| > b̄) and
  exactly 0 while they are apart (MODEL.md §4 applies the damping c̄ δ̄' inside the clearance
  too, so the vector field is continuous, but no force is transmitted through a gap);
* its **peak** max_τ |F̄ᶜ(τ)| over the recorded window, from the running extrema that the
  integrator tracks inside every step (so it does not depend on the sampling rate);
* its **RMS** √(⟨F̄ᶜ²⟩), the mean over the recorded samples (uniform over whole forcing
  periods: the trapezoidal rule of a periodic signal);
* the **dynamic load factor** peak / F̄_static with the static mesh force
  F̄_static = T̄_D/N of MODEL.md §10.1 (planetary: the same for both mesh types) or F_m (the
  oscillator's mean force);
* the RMS **dynamic transmission error** √⟨(δ̄ − ⟨δ̄⟩)²⟩: the fluctuating part of the mesh
  deflection δ̄ along the line of action (MODEL.md §3), in units of b_c.

Every quantity is dimensionless like the kernel (forces in k_m,sp b_c, deflections in b_c).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .system import Observable, System

__all__ = ["MeshGroup", "mesh_groups", "response_quantities", "static_mesh_force"]

#: Names of the response quantities per mesh type ``m`` (``sp``, ``rp`` or ``mesh``).
QUANTITIES = {
    "force_rms": "RMS contact force √⟨F̄ᶜ²⟩ over the recorded window",
    "force_peak": "peak contact force max |F̄ᶜ| over the recorded window (tracked in the "
    "integrator)",
    "load_factor": "dynamic load factor max |F̄ᶜ| / F̄_static",
    "dte_rms": "RMS dynamic transmission error √⟨(δ̄ − ⟨δ̄⟩)²⟩ of the mesh deflection",
}


@dataclass(frozen=True)
class MeshGroup:
    """One mesh type: its short name, contact-force and deflection observables."""

    mesh: str
    force: Observable
    deflection: Observable


def mesh_groups(system: System) -> list[MeshGroup]:
    """The mesh types of ``system`` whose contact forces the kernel tracks (empty for smooth
    reference systems)."""
    if system.n_contact_forces == 0:
        return []
    if hasattr(system.model, "n_planets"):
        return [
            MeshGroup(m, system.observable(f"contact_force_{m}"), system.observable(f"delta_{m}"))
            for m in ("sp", "rp")
        ]
    return [MeshGroup("mesh", system.observable("contact_force"), system.observable("x"))]


def static_mesh_force(system: System) -> float:
    """F̄_static: T̄_D/N (planetary, MODEL.md §10.1, at this Ω) or F_m (oscillator); NaN when
    the model has no static load."""
    model = system.model
    if hasattr(model, "n_planets"):
        td, _ = model.parameters.loads(system.omega)
        return float(td) / int(model.n_planets)
    fm = getattr(model, "f_mean", None)
    return float(fm) if fm is not None else float("nan")


def response_quantities(
    system: System,
    obs_min: np.ndarray,
    obs_max: np.ndarray,
    observables: np.ndarray,
) -> dict[str, np.ndarray]:
    """Response quantities of one run, by ``<quantity>_<mesh>`` (module docstring).

    Parameters
    ----------
    system
        The system that ran.
    obs_min, obs_max
        (n_track,) running extrema of the tracked observables over the recorded window.
    observables
        (s, n_obs) observables at the recorded samples (uniform over whole forcing periods).

    Returns
    -------
    dict
        ``force_rms_m``, ``force_peak_m``, ``dte_rms_m`` with one value per planet (planetary)
        or shape () (oscillator), and ``load_factor_m`` = max over the planets of
        ``force_peak_m`` / F̄_static (shape ()).
        With F̄ᶜ the contact force and δ̄ the mesh deflection:
        force_rms = √⟨F̄ᶜ²⟩, force_peak = max |F̄ᶜ|, dte_rms = √⟨(δ̄ − ⟨δ̄⟩)²⟩.
    """
    static = static_mesh_force(system)
    out: dict[str, np.ndarray] = {}
    for g in mesh_groups(system):
        cols = g.force.columns
        peak = np.maximum(np.abs(obs_min[cols]), np.abs(obs_max[cols]))
        f = observables[:, cols]
        d = observables[:, g.deflection.columns]
        rms = np.sqrt(np.mean(f * f, axis=0))
        dte = np.sqrt(np.mean((d - d.mean(axis=0)) ** 2, axis=0))
        shape: Any = slice(None) if g.force.per_planet else 0
        out[f"force_rms_{g.mesh}"] = rms[shape]
        out[f"force_peak_{g.mesh}"] = peak[shape]
        out[f"dte_rms_{g.mesh}"] = dte[shape]
        lf = float(np.max(peak)) / static if static > 0 else float("nan")
        out[f"load_factor_{g.mesh}"] = np.asarray(lf)
    return out
