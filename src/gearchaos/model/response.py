"""Dynamic mesh forces and transmission errors of one run: the numbers of a frequency response.

For every mesh type of a model (``sp`` and ``rp`` of the planetary model, one per planet;
``mesh`` of the backlash oscillator) this module turns the kernel's outputs into

* the **contact force** F̄ᶜ: the mesh force F̄ = κ(τ) f(δ̄; b̄) + c̄ δ̄' of MODEL.md §4 while the
  teeth touch (|δ̄| > b̄) and it presses them together (F̄ δ̄ > 0: F̄ > 0 on the drive flank,
  F̄ < 0 on the back flank), else exactly 0 (:func:`compressive_contact_forces`). Two parts
  of the model's mesh force are not a contact force: the damping c̄ δ̄' that MODEL.md §4
  applies inside the clearance too (it keeps the vector field continuous, but no force passes
  through a gap), and the *tension* of the viscous term just before the teeth release, where
  c̄ δ̄' < 0 outweighs κ f(δ̄; b̄) → 0 (a Kelvin–Voigt contact pulls; real flanks cannot — on
  ``sheng2016`` at Ω = 1.5 the sun–planet mesh force reaches −0.018 against a peak of 0.25).
  The equations of motion keep that force as MODEL.md writes it; only what is *reported* as a
  contact force leaves it out;
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

__all__ = [
    "MeshGroup",
    "compressive_contact_forces",
    "mesh_contacts",
    "mesh_groups",
    "peak_contact_forces",
    "response_quantities",
    "static_mesh_force",
    "transmission_error",
]

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
    out = []
    for label, force, deflection in system.force_groups:
        d = system.observable(deflection)
        if d.source == "state" and deflection in system.obs_names:
            # a deflection that is both a state and an observable: the observable, read
            # beside its force (the same values)
            d = Observable(deflection, "obs", np.array([system.obs_names.index(deflection)]), False)
        out.append(MeshGroup(label, system.observable(force), d))
    return out


def mesh_contacts(system: System) -> dict[str, tuple[str, ...]]:
    """The names of the contacts of each mesh type, by its label, in member order: the
    model's :attr:`~gearchaos.model.contract.Capabilities.contacts` judged on the columns of
    the type's deflection (``sp`` → ``sun_planet_1 … sun_planet_N``, the backlash
    oscillator's ``mesh`` → ``mesh``). A member that no contact is judged on is named by its
    deflection variable (``delta_sp_2``), so every mesh type names each of its members."""
    caps = system.capabilities
    by_column = {c.column: c.name for c in caps.contacts}
    out: dict[str, tuple[str, ...]] = {}
    for g in mesh_groups(system):
        d = g.deflection
        names = system.obs_names if d.source == "obs" else system.state_names
        out[g.mesh] = tuple(
            by_column.get(int(col), names[int(col)]) if d.source == "obs" else names[int(col)]
            for col in d.columns
        )
    return out


def compressive_contact_forces(
    system: System,
    observables: np.ndarray,
    obs_min: np.ndarray,
    obs_max: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The kernel's outputs with every contact force reduced to what the flanks carry.

    The kernel tracks, as ``contact_force_*``, the mesh force F̄ = κ f(δ̄; b̄) + c̄ δ̄' while
    |δ̄| > b̄ and 0 in the gap. Teeth can only push, so the contact force is

        F̄ᶜ = F̄ where F̄ δ̄ > 0 (compression on the flank in contact), else 0,

    and this function applies that to the samples and to the tracked extrema (copies; the
    other columns unchanged; applying it twice changes nothing). The equations of motion are
    not affected: they use MODEL.md §4's mesh force, tension included.

    The extrema are exact when the window touched one flank only (the usual case: then every
    negative value on the drive flank is tension, so F̄ᶜ_min = max(F̄_min, 0) and
    F̄ᶜ_max = max(F̄_max, 0); the back flank alike, mirrored): which flanks touched comes from
    the tracked extrema of δ̄ against ±b̄. Where both flanks touched, the tracked extrema
    cannot tell the tension of one flank from the compression of the other; they are kept
    (with 0 inside [F̄ᶜ_min, F̄ᶜ_max], which a passage through the gap reaches) and are exact
    unless a tension exceeded the opposite flank's largest compression.

    Parameters
    ----------
    system
        The system that ran (no contact forces: the arrays come back unchanged).
    observables
        (..., n_obs) observables at the samples.
    obs_min, obs_max
        (..., n_track) extrema of the tracked observables over the window.

    Returns
    -------
    tuple of numpy.ndarray
        ``observables``, ``obs_min``, ``obs_max`` with the contact-force columns replaced.
    """
    groups = mesh_groups(system)
    if not groups:
        return observables, obs_min, obs_max
    obs = np.array(observables, dtype=np.float64, copy=True)
    lo = np.array(obs_min, dtype=np.float64, copy=True)
    hi = np.array(obs_max, dtype=np.float64, copy=True)
    widths = system.switch_widths
    for g in groups:
        fc, dc = g.force.columns, g.deflection.columns
        f = obs[..., fc]
        obs[..., fc] = np.where(f * obs[..., dc] > 0.0, f, 0.0)
        drive = hi[..., dc] > widths[dc]
        back = lo[..., dc] < -widths[dc]
        flo, fhi = lo[..., fc], hi[..., fc]
        lo[..., fc] = np.where(back, np.minimum(flo, 0.0), np.maximum(flo, 0.0))
        hi[..., fc] = np.where(drive, np.maximum(fhi, 0.0), np.minimum(fhi, 0.0))
        none = ~drive & ~back
        lo[..., fc] = np.where(none, 0.0, lo[..., fc])
        hi[..., fc] = np.where(none, 0.0, hi[..., fc])
    return obs, lo, hi


def peak_contact_forces(
    system: System, obs_min: np.ndarray, obs_max: np.ndarray
) -> dict[str, np.ndarray]:
    """The peak contact force max |F̄ᶜ| of each mesh type from the tracked extrema, by
    ``force_peak_<mesh>``: the extrema reduced to what the flanks carry
    (:func:`compressive_contact_forces`), then max(|F̄ᶜ_min|, |F̄ᶜ_max|).

    ``obs_min``, ``obs_max`` are (..., n_track): over a recorded window (a sweep point) or over
    an orbit (a branch point), any leading dimensions. Each value has the leading shape, with
    a last axis of planets for per-planet meshes."""
    empty = np.zeros((0, system.n_obs))
    _, lo, hi = compressive_contact_forces(system, empty, obs_min, obs_max)
    out: dict[str, np.ndarray] = {}
    for g in mesh_groups(system):
        cols = g.force.columns
        peak = np.maximum(np.abs(lo[..., cols]), np.abs(hi[..., cols]))
        out[f"force_peak_{g.mesh}"] = peak if g.force.per_planet else peak[..., 0]
    return out


def transmission_error(deflection: np.ndarray) -> np.ndarray:
    """The RMS dynamic transmission error √⟨(δ̄ − ⟨δ̄⟩)²⟩ of mesh deflections sampled along
    the first axis (uniform over whole forcing periods): the RMS of their fluctuating part."""
    d = np.asarray(deflection, dtype=np.float64)
    return np.sqrt(np.mean((d - d.mean(axis=0)) ** 2, axis=0))


def static_mesh_force(system: System) -> float:
    """F̄_static: T̄_D/N (planetary, MODEL.md §10.1, at this Ω) or F_m (oscillator); NaN when
    the model has no static load."""
    static = system.capabilities.static_mesh_force
    return float(static(system.omega)) if static is not None else float("nan")


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
        The contact forces are taken as :func:`compressive_contact_forces` gives them.

    Returns
    -------
    dict
        ``force_rms_m``, ``force_peak_m``, ``dte_rms_m`` with one value per planet (planetary)
        or shape () (oscillator), and ``load_factor_m`` = max over the planets of
        ``force_peak_m`` / F̄_static (shape ()).
        With F̄ᶜ the contact force and δ̄ the mesh deflection:
        force_rms = √⟨F̄ᶜ²⟩, force_peak = max |F̄ᶜ|, dte_rms = √⟨(δ̄ − ⟨δ̄⟩)²⟩.
    """
    observables, obs_min, obs_max = compressive_contact_forces(
        system, observables, obs_min, obs_max
    )
    static = static_mesh_force(system)
    peaks = peak_contact_forces(system, obs_min, obs_max)
    out: dict[str, np.ndarray] = {}
    for g in mesh_groups(system):
        cols = g.force.columns
        peak = peaks[f"force_peak_{g.mesh}"]
        f = observables[:, cols]
        d = observables[:, g.deflection.columns]
        rms = np.sqrt(np.mean(f * f, axis=0))
        dte = transmission_error(d)
        shape: Any = slice(None) if g.force.per_planet else 0
        out[f"force_rms_{g.mesh}"] = rms[shape]
        out[f"force_peak_{g.mesh}"] = peak
        out[f"dte_rms_{g.mesh}"] = dte[shape]
        lf = float(np.max(peak)) / static if static > 0 else float("nan")
        out[f"load_factor_{g.mesh}"] = np.asarray(lf)
    return out
