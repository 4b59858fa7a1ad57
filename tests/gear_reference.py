"""Reference quantities of the planetary model computed here from the gear set, independently of
the package's model code: shared by the Lyapunov and periodic-orbit tests."""

from __future__ import annotations

import math

import numpy as np

import gearchaos as gc
from gearchaos.model.modal import mass_stiffness


def damping_trace(gs: gc.GearSet) -> float:
    """−tr(M⁻¹C)/ω_n: the sum of the Lyapunov exponents per unit τ (MODEL.md §10.7).

    C is built from MODEL.md §4 along the lines of action, like K in
    :func:`~gearchaos.model.modal.mass_stiffness`:
    C = c_sp Σ a_i a_iᵀ + c_rp Σ r_i r_iᵀ + c_s (e_x e_xᵀ + e_y e_yᵀ) in the physical
    coordinates (x_s, y_s, u_s, u_1..u_N, u_c). The rigid rotation is undamped (C has it as a
    null vector), so the minimal coordinates of the model carry the whole trace.
    """
    m, _, _ = mass_stiffness(gs)
    n = gs.n_planets
    dof = 4 + n
    c = np.zeros((dof, dof))
    k_sp = gs.stiffness.sun_planet_mean
    m_e = gs.equivalent_mass_sun * gs.equivalent_mass_planet
    m_e /= gs.equivalent_mass_sun + gs.equivalent_mass_planet
    c_sp = 2.0 * gs.damping.sun_planet * math.sqrt(k_sp * m_e)
    c_rp = (
        2.0
        * gs.damping.planet_ring
        * math.sqrt(gs.stiffness.planet_ring_mean * gs.equivalent_mass_planet)
    )
    c_s = 2.0 * gs.damping.sun_bearing * math.sqrt(gs.stiffness.sun_bearing * gs.mass.sun)
    for i, psi in enumerate(2.0 * math.pi * np.arange(n) / n):
        a = np.zeros(dof)
        a[[0, 1, 2, 3 + i, 3 + n]] = [
            -math.sin(psi - gs.alpha_s),
            math.cos(psi - gs.alpha_s),
            1.0,
            1.0,
            -math.cos(gs.alpha_s),
        ]
        r = np.zeros(dof)
        r[[3 + i, 3 + n]] = [-1.0, -math.cos(gs.alpha_r)]
        c += c_sp * np.outer(a, a) + c_rp * np.outer(r, r)
    c[0, 0] += c_s
    c[1, 1] += c_s
    omega_n = math.sqrt(k_sp / m_e)
    return -float(np.trace(np.linalg.solve(m, c))) / omega_n
