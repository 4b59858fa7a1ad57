"""The minimal dimensionless model equals the physical 4+N-coordinate model in SI units.

Written independently here from MODEL.md §1–§5: coordinates (x_s, y_s, u_s, u_1..u_N, u_c) in
metres, time in seconds, masses m_s, m_s* = J_s/r_bs², m_p* = J_p/r_bp², m_c* = J_c/r_c² + N m_p,
the forces of §4 with dead zones and viscous damping from the ratios, the errors of §3 and the
mesh stiffness with Parker–Lin phasing. scipy's DOP853 integrates it from rest; the result is
mapped to p_i = u_s + u_i − u_c cos α_s, σ = u_s − u_c(cos α_s + cos α_r), divided by b_c, at
t = τ/ω_n, and compared with gearchaos over the first 10 mesh periods.

Both solvers run at rtol 1e-13: at contact kinks the Dormand–Prince error estimate can miss the
velocity error of a step by orders of magnitude (see tests/integrate/test_vs_scipy.py), which at
rtol 1e-11 leaves errors near 1e-7.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import gearchaos as gc
from gearchaos.integrate import integrate


def _frac(x):
    return x - np.floor(x)


def _dead_zone(x, b):
    """f(x; b) = x − b (x > b), 0 (|x| ≤ b), x + b (x < −b)."""
    return x - np.clip(x, -b, b)


class PhysicalModel:
    """MODEL.md §5 in SI units, parameters read from the gear-set fields only."""

    def __init__(self, gs, omega_bar: float):
        z, g = gs.teeth, gs.geometry
        self.N = N = g.planets
        self.a_s = math.radians(g.pressure_angle_sun)
        self.a_r = math.radians(g.pressure_angle_ring)
        r_s, r_p = g.module * z.sun / 2, g.module * z.planet / 2
        self.r_c = r_s + r_p
        self.r_bs = r_s * math.cos(self.a_s)
        r_bp = r_p * math.cos(self.a_s)
        self.m_s = gs.mass.sun
        self.ms_star = gs.inertia.sun / self.r_bs**2
        self.mp_star = gs.inertia.planet / r_bp**2
        self.mc_star = gs.inertia.carrier / self.r_c**2 + N * gs.mass.planet
        m_e = self.ms_star * self.mp_star / (self.ms_star + self.mp_star)
        st = gs.stiffness
        self.k_sp, self.ka_sp, self.kh_sp = (
            st.sun_planet_mean,
            st.sun_planet_alternating,
            st.sun_planet_harmonics,
        )
        self.k_rp, self.ka_rp, self.kh_rp = (
            st.planet_ring_mean,
            st.planet_ring_alternating,
            st.planet_ring_harmonics,
        )
        self.k_s = st.sun_bearing
        self.omega_n = math.sqrt(self.k_sp / m_e)
        d = gs.damping
        self.c_sp = 2 * d.sun_planet * math.sqrt(self.k_sp * m_e)
        self.c_rp = 2 * d.planet_ring * math.sqrt(self.k_rp * self.mp_star)
        self.c_s = 2 * d.sun_bearing * math.sqrt(self.k_s * self.m_s)
        self.b_c = bc = gs.clearance.characteristic_length
        assert gs.backlash.units == "dimensionless" and gs.clearance.units == "dimensionless"
        self.b_sp, self.b_rp = gs.backlash.sun_planet * bc, gs.backlash.planet_ring * bc
        self.b_s = gs.clearance.sun_bearing * bc
        T_D = gs.torque.input
        if gs.torque.mode == "constant_power":
            T_D = T_D * gs.torque.reference_omega / omega_bar
        self.T_D = T_D
        self.T_L = T_D * (1 + z.ring / z.sun)  # MODEL.md §2 (equal pressure angles)
        assert g.pressure_angle_sun == g.pressure_angle_ring
        self.w = omega_bar * self.omega_n  # mesh frequency [rad/s]
        self.w_sH, self.w_pH, self.w_H = self.w / z.sun, self.w / z.planet, self.w / z.ring
        self.psi = 2 * np.pi * np.arange(N) / N
        if gs.mesh_phasing.model == "parker":
            g_sp = _frac(z.sun * self.psi / (2 * np.pi))
            g_rp = _frac(-z.ring * self.psi / (2 * np.pi)) + gs.mesh_phasing.ring_sun
            self.phi_sp, self.phi_rp = -2 * np.pi * g_sp, -2 * np.pi * g_rp
        else:
            self.phi_sp = self.phi_rp = np.zeros(N)
        self.sin_pa, self.cos_pa = np.sin(self.psi - self.a_s), np.cos(self.psi - self.a_s)
        self.ca_s, self.ca_r = math.cos(self.a_s), math.cos(self.a_r)
        te, ec = gs.transmission_error, gs.eccentricity
        self.A_sp, self.A_rp = te.sun_planet, te.planet_ring
        self.te_ph_sp = math.radians(te.sun_planet_phase)
        self.te_ph_rp = math.radians(te.planet_ring_phase)
        self.E_s, self.E_p, self.E_r = ec.sun, ec.planet, ec.ring
        self.beta_s, self.beta_p, self.beta_r = (
            math.radians(v) for v in (ec.sun_phase, ec.planet_phase, ec.ring_phase)
        )

    def _stiffness(self, th, mean, alt, harmonics):
        k = mean + alt * np.cos(th)
        for h, kh in enumerate(harmonics, start=2):
            k = k + kh * np.cos(h * th)
        return k

    def meshes(self, t, y):
        """(δ_sp, δ_rp, F_sp, F_rp) [m, N] of every planet."""
        N, a_s, a_r = self.N, self.a_s, self.a_r
        n = N + 4
        x, yy, u_s, u, u_c = y[0], y[1], y[2], y[3 : 3 + N], y[3 + N]
        xd, yd, us_d, u_d, uc_d = y[n], y[n + 1], y[n + 2], y[n + 3 : n + 3 + N], y[n + 3 + N]
        w, psi = self.w, self.psi
        th_sp, th_rp = w * t + self.phi_sp, w * t + self.phi_rp
        k_sp = self._stiffness(th_sp, self.k_sp, self.ka_sp, self.kh_sp)
        k_rp = self._stiffness(th_rp, self.k_rp, self.ka_rp, self.kh_rp)
        args_sp = (
            (self.A_sp, w, th_sp + self.te_ph_sp),
            (self.E_s, self.w_sH, self.w_sH * t + self.beta_s - psi + a_s),
            (self.E_p, self.w_pH, self.w_pH * t + self.beta_p + a_s),
        )
        args_rp = (
            (self.A_rp, w, th_rp + self.te_ph_rp),
            (self.E_p, self.w_pH, self.w_pH * t + self.beta_p - a_r),
            (self.E_r, -self.w_H, -self.w_H * t + self.beta_r - psi - a_r),
        )
        e_sp = e_sp_dot = e_rp = e_rp_dot = 0.0
        for A, rate, arg in args_sp:
            if A:
                e_sp = e_sp + A * np.sin(arg)
                e_sp_dot = e_sp_dot + A * rate * np.cos(arg)
        for A, rate, arg in args_rp:
            if A:
                e_rp = e_rp + A * np.sin(arg)
                e_rp_dot = e_rp_dot + A * rate * np.cos(arg)
        s = -x * self.sin_pa + yy * self.cos_pa
        s_dot = -xd * self.sin_pa + yd * self.cos_pa
        d_sp = u_s + u - u_c * self.ca_s + s - e_sp
        d_sp_dot = us_d + u_d - uc_d * self.ca_s + s_dot - e_sp_dot
        d_rp = -u - u_c * self.ca_r - e_rp
        d_rp_dot = -u_d - uc_d * self.ca_r - e_rp_dot
        F_sp = k_sp * _dead_zone(d_sp, self.b_sp) + self.c_sp * d_sp_dot
        F_rp = k_rp * _dead_zone(d_rp, self.b_rp) + self.c_rp * d_rp_dot
        return d_sp, d_rp, F_sp, F_rp

    def rhs(self, t, y):
        N = self.N
        n = N + 4
        _, _, F_sp, F_rp = self.meshes(t, y)
        x, yy, xd, yd = y[0], y[1], y[n], y[n + 1]
        F_sx = self.k_s * _dead_zone(x, self.b_s) + self.c_s * xd
        F_sy = self.k_s * _dead_zone(yy, self.b_s) + self.c_s * yd
        acc = np.empty(n)
        acc[0] = (F_sp @ self.sin_pa - F_sx) / self.m_s
        acc[1] = (-(F_sp @ self.cos_pa) - F_sy) / self.m_s
        acc[2] = (self.T_D / self.r_bs - F_sp.sum()) / self.ms_star
        acc[3 : 3 + N] = (-F_sp + F_rp) / self.mp_star
        acc[3 + N] = (
            self.ca_s * F_sp.sum() + self.ca_r * F_rp.sum() - self.T_L / self.r_c
        ) / self.mc_star
        return np.concatenate([y[n:], acc])

    def to_minimal(self, Y):
        """Rows (x, y, u_s, u_i, u_c, velocities) → dimensionless (x̄, ȳ, p̄_i, σ̄, τ-derivatives)."""
        N = self.N
        ca_s, ca_r = math.cos(self.a_s), math.cos(self.a_r)

        def q(Z):
            x, yy, u_s, u, u_c = Z[:, 0], Z[:, 1], Z[:, 2], Z[:, 3 : 3 + N], Z[:, 3 + N]
            p = u_s[:, None] + u - (u_c * ca_s)[:, None]
            sig = u_s - u_c * (ca_s + ca_r)
            return np.column_stack([x, yy, p, sig])

        n = N + 4
        return np.hstack([q(Y[:, :n]) / self.b_c, q(Y[:, n:]) / (self.b_c * self.omega_n)])


CASES = {
    "parker": (1.5, {"mesh_phasing.model": "parker"}),
    "in_phase": (1.5, {"mesh_phasing.model": "in_phase"}),
    "eccentric": (
        1.0,
        {
            "mesh_phasing.model": "parker",
            "mesh_phasing.ring_sun": 0.25,
            "eccentricity.sun": 3e-6,
            "eccentricity.planet": 2e-6,
            "eccentricity.ring": 5e-6,
            "eccentricity.sun_phase": 30.0,
            "eccentricity.planet_phase": -60.0,
            "eccentricity.ring_phase": 120.0,
            "transmission_error.sun_planet_phase": 15.0,
            "transmission_error.planet_ring_phase": -25.0,
            "stiffness.sun_planet_harmonics": [0.04e9],
            "stiffness.planet_ring_harmonics": [0.03e9, 0.01e9],
        },
    ),
    "constant_power": (
        0.8,
        {
            "mesh_phasing.model": "parker",
            "torque.mode": "constant_power",
            "torque.reference_omega": 1.3,
            "transmission_error.sun_planet": 9e-6,
            "transmission_error.planet_ring": 9e-6,
        },
    ),
}


@pytest.mark.parametrize("case", list(CASES))
def test_minimal_model_equals_physical_si_model(case: str) -> None:
    omega, changes = CASES[case]
    gs = gc.preset("hindawi2021").evolve(changes)
    phys = PhysicalModel(gs, omega)
    N = phys.N
    system = gc.planetary_system(gs, omega)
    tr = integrate(  # exactly at rest, as the SI model's solve_ivp starts
        system,
        transient_periods=0,
        periods=10,
        samples_per_period=20,
        rtol=1e-14,
        atol=1e-16,
        perturbation=0.0,
    )
    assert tr.ok
    # the time scale of the dimensionless model is ω_n = √(k_m,sp/m_e)
    t_eval = tr.tau / phys.omega_n
    sol = solve_ivp(
        phys.rhs,
        (0.0, t_eval[-1]),
        np.zeros(2 * (N + 4)),
        method="DOP853",
        rtol=1e-13,
        atol=np.concatenate([np.full(N + 4, 1e-19), np.full(N + 4, 1e-19 * phys.omega_n)]),
        t_eval=t_eval,
    )
    assert sol.success, sol.message
    Y = sol.y.T
    assert np.abs(tr.states - phys.to_minimal(Y)).max() <= 1e-7

    # the observables in SI: deflections over b_c and forces over k_m,sp b_c
    meshes = [phys.meshes(t, y) for t, y in zip(t_eval, Y, strict=True)]
    d_sp, d_rp, F_sp, F_rp = (np.array([m[j] for m in meshes]) for j in range(4))
    force_scale = phys.k_sp * phys.b_c
    obs = tr.observables
    np.testing.assert_allclose(obs[:, :N], d_sp / phys.b_c, rtol=0, atol=1e-7)
    np.testing.assert_allclose(obs[:, N : 2 * N], d_rp / phys.b_c, rtol=0, atol=1e-7)
    f_sp, f_rp = system.observable("force_sp").columns, system.observable("force_rp").columns
    np.testing.assert_allclose(obs[:, f_sp], F_sp / force_scale, rtol=0, atol=1e-6)
    np.testing.assert_allclose(obs[:, f_rp], F_rp / force_scale, rtol=0, atol=1e-6)

    # teeth separate after the meshes first engage, so the comparison crosses the kinks
    engaged = int(np.argmax((d_sp > phys.b_sp).all(axis=1)))
    assert engaged > 0
    assert (d_sp[engaged:] < phys.b_sp).any() or (d_rp[engaged:] < phys.b_rp).any()
    if case == "in_phase":
        assert np.abs(Y[:, :2]).max() < 1e-9 * phys.b_c  # the sun's centre stays put
    else:
        assert np.abs(Y[:, :2]).max() > 0.01 * phys.b_c  # the sun's centre moves
