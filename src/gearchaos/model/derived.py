"""Derived quantities of a gear set, as one JSON-ready dictionary (``gearchaos info``).

:func:`gearset_info` gathers what a user wants to know about a gear set before simulating it:
radii, equivalent masses, the time scale ω_n, damping coefficients, the dimensionless parameters
of MODEL.md §7, the static mesh load and deflection (MODEL.md §10.1), the mesh phasing class,
the linear natural frequencies (MODEL.md §10.3) and the mesh frequencies at which a mesh
harmonic meets one of them.
"""

from __future__ import annotations

import math
from typing import Any

from ..gearset import GearSet
from .modal import natural_frequencies
from .planetary import nondimensionalise

__all__ = ["RESONANCE_HARMONICS", "gearset_info"]

#: Mesh-frequency harmonics h listed in ``omega_at_resonances``.
RESONANCE_HARMONICS: tuple[int, ...] = (1, 2, 3)


def gearset_info(gs: GearSet) -> dict[str, Any]:
    """Derived quantities of a gear set as a JSON-serialisable dictionary.

    Parameters
    ----------
    gs : GearSet
        The gear set (SI).

    Returns
    -------
    dict
        Plain ``float``/``int``/``str``/``list``/``dict`` values only, so ``json.dumps`` works:

        - ``name``, ``description``, ``planets`` (N), ``teeth`` {sun, planet, ring};
        - ``radii_m``: pitch radii r = m z/2, carrier r_c = r_s + r_p, base radii
          r_bs = r_s cos α_s and r_bp = r_p cos α_s;
        - ``equivalent_masses_kg``: m_s* = J_s/r_bs², m_p* = J_p/r_bp²,
          m_c* = J_c/r_c² + N m_p and the mesh mass m_e = m_s* m_p*/(m_s* + m_p*);
        - ``omega_n_rad_s`` = √(k_m,sp/m_e) and ``omega_n_hz`` = ω_n/2π;
        - ``damping_coefficients_N_s_per_m``: c_sp = 2ξ_sp √(k_m,sp m_e),
          c_rp = 2ξ_rp √(k_m,rp m_p*), c_s = 2ξ_s √(k_s m_s);
        - ``dimensionless``: the parameters of MODEL.md §7 from
          :func:`gearchaos.model.nondimensionalise` (μ's, ε_sp, κ's, c̄ = c/(m_e ω_n),
          b̄'s, T̄_D, T̄_L, Ā's, stiffness harmonics);
        - ``output_torque_N_m`` (T_L), ``torque_ratio`` (T_L/T_D = r_c (cos α_s + cos α_r)/r_bs,
          = 1 + z_r/z_s for α_s = α_r; defined also for T_D = 0), ``load_mode`` and
          ``reference_omega`` (Ω_ref of constant power);
        - ``mesh_phasing``: {"model", "class", "k"} with k = z_r mod N;
        - ``static_mesh_force_N``: F = T_D/(N r_bs), the load of every mesh in static
          equilibrium (MODEL.md §10.1);
        - ``static_deflection``: F/k_m of each mesh in metres and in units of b_c
          (``*_m`` and ``*_bar``), the elastic part of δ = b + F/k_m;
        - ``clearances_um``: the half clearances b_sp, b_rp, b_s in µm (b̄ b_c, whatever units
          the gear set gives them in), beside their b̄ among ``dimensionless``;
        - ``natural_frequencies``: :func:`gearchaos.model.modal.modes_table` rows;
        - ``omega_at_resonances``: for every non-zero mode and h in
          :data:`RESONANCE_HARMONICS`, ``{"mode_ratio", "kind", "harmonic", "omega",
          "sun_speed_rpm"}`` with Ω = ratio/h, the dimensionless mesh frequency at which h Ω
          meets the mode, and the sun speed there; sorted by Ω.
    """
    par, scales = nondimensionalise(gs)
    n = gs.n_planets
    z = gs.teeth
    modes = natural_frequencies(gs)
    table = [m.as_dict() for m in modes]

    force = gs.torque.input / (n * gs.base_radius_sun)
    bc = gs.clearance.characteristic_length
    defl_sp = force / gs.stiffness.sun_planet_mean
    defl_rp = force / gs.stiffness.planet_ring_mean

    resonances = [
        {
            "mode_ratio": float(m.ratio),
            "kind": m.kind,
            "harmonic": h,
            "omega": float(m.ratio / h),
            "sun_speed_rpm": gs.sun_speed_rpm(float(m.ratio / h)),
        }
        for m in modes
        if m.ratio > 0.0
        for h in RESONANCE_HARMONICS
    ]
    resonances.sort(key=lambda r: (r["omega"], r["harmonic"]))

    dimensionless: dict[str, float | list[float]] = {
        "mu_s": float(par.mu_s),
        "mu_s_star": float(par.mu_s_star),
        "mu_p_star": float(par.mu_p_star),
        "mu_c_star": float(par.mu_c_star),
        "eps_sp": float(par.eps_sp),
        "kappa_rp_mean": float(par.kappa_rp_mean),
        "kappa_rp_alt": float(par.kappa_rp_alt),
        "kappa_b": float(par.kappa_b),
        "damping_sun_planet": float(par.damping_sun_planet),
        "damping_planet_ring": float(par.damping_planet_ring),
        "damping_sun_bearing": float(par.damping_sun_bearing),
        "b_sp": float(par.b_sp),
        "b_rp": float(par.b_rp),
        "b_s": float(par.b_s),
        "torque_input": float(par.torque_input),
        "torque_output": float(par.torque_output),
        "te_sp": float(par.te_sp),
        "te_rp": float(par.te_rp),
        "harmonics_sp": [float(h) for h in par.harmonics_sp],
        "harmonics_rp": [float(h) for h in par.harmonics_rp],
    }

    return {
        "name": gs.name,
        "description": gs.description,
        "planets": int(n),
        "teeth": {"sun": int(z.sun), "planet": int(z.planet), "ring": int(z.ring)},
        "radii_m": {
            "sun": float(gs.radius_sun),
            "planet": float(gs.radius_planet),
            "ring": float(gs.radius_ring),
            "carrier": float(gs.radius_carrier),
            "base_sun": float(gs.base_radius_sun),
            "base_planet": float(gs.base_radius_planet),
        },
        "equivalent_masses_kg": {
            "sun": float(gs.equivalent_mass_sun),
            "planet": float(gs.equivalent_mass_planet),
            "carrier": float(gs.equivalent_mass_carrier),
            "mesh": float(gs.equivalent_mass_mesh),
        },
        "omega_n_rad_s": float(scales.omega_n),
        "omega_n_hz": float(scales.omega_n / (2.0 * math.pi)),
        "damping_coefficients_N_s_per_m": {
            "sun_planet": float(gs.damping_sun_planet),
            "planet_ring": float(gs.damping_planet_ring),
            "sun_bearing": float(gs.damping_sun_bearing),
        },
        "dimensionless": dimensionless,
        "output_torque_N_m": float(gs.output_torque),
        "torque_ratio": float(
            gs.radius_carrier * (math.cos(gs.alpha_s) + math.cos(gs.alpha_r)) / gs.base_radius_sun
        ),
        "load_mode": gs.torque.mode,
        "reference_omega": float(gs.torque.reference_omega),
        "mesh_phasing": {
            "model": gs.mesh_phasing.model,
            "class": gs.phasing_class,
            "k": int(z.ring % n),
        },
        "static_mesh_force_N": float(force),
        "static_deflection": {
            "sun_planet_m": float(defl_sp),
            "sun_planet_bar": float(defl_sp / bc),
            "planet_ring_m": float(defl_rp),
            "planet_ring_bar": float(defl_rp / bc),
        },
        "clearances_um": {
            "sun_planet": float(par.b_sp * bc * 1e6),
            "planet_ring": float(par.b_rp * bc * 1e6),
            "sun_bearing": float(par.b_s * bc * 1e6),
        },
        "natural_frequencies": table,
        "omega_at_resonances": resonances,
    }
