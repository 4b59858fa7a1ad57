"""The compiled integrator and the compiled planetary right-hand side against scipy.

1. scipy's DOP853 (rtol = atol = 1e-13) on the compiled RHS (``System.derivative``) — checks the
   integrator: same vector field, independent solver.
2. scipy's DOP853 on an independent numpy implementation of MODEL.md §7 written in this file from
   the equations (dimensionless minimal form, parameters from ``nondimensionalise`` only) —
   checks the compiled vector field.
Both must agree with gearchaos to 1e-7 in the state at the section times τ_k = 2πk/Ω.

Tolerances are 1e-13, not 1e-12: the contact kinks (dead zone) defeat both solvers' error
estimators in isolated steps. For DOPRI5 the velocity error estimate of a step whose kink lies at
θ ≈ 0.42 of the step vanishes (e_1 θ + e_3 (θ − 0.3) = 0) while the true error is ~1e-3 J h²;
at rtol = 1e-12 one such step (five planet–ring meshes separating at once, Ω = 0.5) leaves a
7.8e-8 error, and scipy's DOP853 shows 6e-8 at Ω = 2.5. At 1e-13 both stay below 1e-9.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import gearchaos as gc
from gearchaos.integrate import integrate


def _dead_zone(x, b):
    return np.where(x > b, x - b, np.where(x < -b, x + b, 0.0))


def model_md_rhs(par, omega: float):
    """Right-hand side of MODEL.md §7 (minimal dimensionless form), written from the text.

    State (x̄_s, ȳ_s, p̄_1..p̄_N, σ̄, then τ-derivatives).
    """
    N = par.n_planets
    psi = np.asarray(par.psi)
    phs = np.asarray(par.phi_sp)
    phr = np.asarray(par.phi_rp)
    a_s, a_r = par.alpha_s, par.alpha_r
    ca_s, ca_r = math.cos(a_s), math.cos(a_r)
    sin_pa = np.sin(psi - a_s)
    cos_pa = np.cos(psi - a_s)
    om_sH, om_pH, om_rH = omega / par.teeth_sun, omega / par.teeth_planet, omega / par.teeth_ring
    if par.load_mode == "constant_power":
        td = par.torque_input * par.omega_ref / omega
        tl = par.torque_output * par.omega_ref / omega
    else:
        td, tl = par.torque_input, par.torque_output

    def stiffness(theta, mean, alt, harmonics):
        k = mean + alt * np.cos(theta)
        for h, kh in enumerate(harmonics, start=2):
            k = k + kh * np.cos(h * theta)
        return k

    def meshes(t, y):
        """(δ_sp, δ_rp, δ'_sp, δ'_rp, F_sp, F_rp), each of length N."""
        q, v = y[: N + 3], y[N + 3 :]
        x, yy, p, sig = q[0], q[1], q[2 : 2 + N], q[2 + N]
        xd, yd, pd, sigd = v[0], v[1], v[2 : 2 + N], v[2 + N]
        th_sp = omega * t + phs
        th_rp = omega * t + phr
        k_sp = stiffness(th_sp, 1.0, par.eps_sp, par.harmonics_sp)
        k_rp = stiffness(th_rp, par.kappa_rp_mean, par.kappa_rp_alt, par.harmonics_rp)
        # transmission errors e and de/dτ (MODEL.md §3, with the TE phase offsets)
        a1 = th_sp + par.te_sp_phase
        a2 = om_sH * t + par.beta_s - psi + a_s
        a3 = om_pH * t + par.beta_p + a_s
        e_sp = par.te_sp * np.sin(a1) + par.ecc_sun * np.sin(a2) + par.ecc_planet * np.sin(a3)
        e_sp_d = (
            par.te_sp * omega * np.cos(a1)
            + par.ecc_sun * om_sH * np.cos(a2)
            + par.ecc_planet * om_pH * np.cos(a3)
        )
        b1 = th_rp + par.te_rp_phase
        b2 = om_pH * t + par.beta_p - a_r
        b3 = -om_rH * t + par.beta_r - psi - a_r
        e_rp = par.te_rp * np.sin(b1) + par.ecc_planet * np.sin(b2) + par.ecc_ring * np.sin(b3)
        e_rp_d = (
            par.te_rp * omega * np.cos(b1)
            + par.ecc_planet * om_pH * np.cos(b2)
            - par.ecc_ring * om_rH * np.cos(b3)
        )
        s = -x * sin_pa + yy * cos_pa
        sd = -xd * sin_pa + yd * cos_pa
        d_sp = p + s - e_sp
        d_sp_d = pd + sd - e_sp_d
        d_rp = sig - p - e_rp
        d_rp_d = sigd - pd - e_rp_d
        F_sp = k_sp * _dead_zone(d_sp, par.b_sp) + par.damping_sun_planet * d_sp_d
        F_rp = k_rp * _dead_zone(d_rp, par.b_rp) + par.damping_planet_ring * d_rp_d
        return d_sp, d_rp, d_sp_d, d_rp_d, F_sp, F_rp

    def rhs(t, y):
        q, v = y[: N + 3], y[N + 3 :]
        x, yy, xd, yd = q[0], q[1], v[0], v[1]
        *_, F_sp, F_rp = meshes(t, y)
        cb = par.damping_sun_bearing
        xdd = (np.sum(F_sp * sin_pa) - cb * xd - par.kappa_b * _dead_zone(x, par.b_s)) / par.mu_s
        ydd = (-np.sum(F_sp * cos_pa) - cb * yd - par.kappa_b * _dead_zone(yy, par.b_s)) / par.mu_s
        Qs = td - F_sp.sum()
        Qc = np.sum(F_sp * ca_s + F_rp * ca_r) - tl
        pdd = Qs / par.mu_s_star + (F_rp - F_sp) / par.mu_p_star - ca_s * Qc / par.mu_c_star
        sdd = Qs / par.mu_s_star - (ca_s + ca_r) * Qc / par.mu_c_star
        return np.concatenate([v, [xdd, ydd], pdd, [sdd]])

    rhs.meshes = meshes
    return rhs


def _scipy(fun, n_state: int, t_eval: np.ndarray, y0=None) -> np.ndarray:
    y0 = np.zeros(n_state) if y0 is None else y0
    sol = solve_ivp(
        fun, (0.0, t_eval[-1]), y0, method="DOP853", rtol=1e-13, atol=1e-13, t_eval=t_eval
    )
    assert sol.success, sol.message
    return sol.y.T


def _gearchaos(system, periods: int):
    # exactly at rest, as the reference solution starts (no perturbation of the start)
    tr = integrate(
        system, transient_periods=0, periods=periods, rtol=1e-13, atol=1e-15, perturbation=0.0
    )
    assert tr.ok
    return tr


# (Ω, periods, changes): a 1T regime, a rougher one, and one with every optional term switched on
CASES = {
    "omega0.5": (0.5, 4, {}),
    "omega2.5": (2.5, 6, {}),
    "parker_ecc_harm_power": (
        1.5,
        5,
        {
            "mesh_phasing.model": "parker",
            "mesh_phasing.ring_sun": 0.3,
            "eccentricity.sun": 2e-6,
            "eccentricity.planet": 3e-6,
            "eccentricity.ring": 4e-6,
            "eccentricity.sun_phase": 20.0,
            "eccentricity.planet_phase": 50.0,
            "eccentricity.ring_phase": -70.0,
            "transmission_error.sun_planet_phase": 30.0,
            "transmission_error.planet_ring_phase": -45.0,
            "stiffness.sun_planet_harmonics": [0.03e9, 0.01e9],
            "stiffness.planet_ring_harmonics": [0.02e9],
            "torque.mode": "constant_power",
            "torque.reference_omega": 1.1,
        },
    ),
}


@pytest.mark.parametrize("case", ["omega0.5", "omega2.5"])
def test_integrator_matches_scipy_on_compiled_rhs(case: str) -> None:
    omega, periods, changes = CASES[case]
    gs = gc.preset("hindawi2021").evolve(changes)
    system = gc.planetary_system(gs, omega)
    tr = _gearchaos(system, periods)
    ref = _scipy(system.derivative, system.n_state, tr.tau)
    assert np.abs(tr.states - ref).max() < 1e-7
    # the comparison is not trivial: the state moved far from zero
    assert np.abs(ref).max() > 1.0


@pytest.mark.parametrize("case", list(CASES))
def test_compiled_rhs_matches_independent_model_md(case: str) -> None:
    omega, periods, changes = CASES[case]
    gs = gc.preset("hindawi2021").evolve(changes)
    par, _ = gc.nondimensionalise(gs)
    system = gc.planetary_system(gs, omega)
    fun = model_md_rhs(par, omega)
    # pointwise: the vector fields agree at random states and times
    rng = np.random.default_rng(1)
    for _ in range(20):
        y = rng.normal(scale=4.0, size=system.n_state)
        t = rng.uniform(0, 200)
        np.testing.assert_allclose(system.derivative(t, y), fun(t, y), rtol=1e-12, atol=1e-12)
    tr = _gearchaos(system, periods)
    ref = _scipy(fun, system.n_state, tr.tau)
    assert np.abs(tr.states - ref).max() < 1e-7
    # the observables (δ_sp, δ_rp, δ'_sp, δ'_rp, F_sp, F_rp) at the samples, from the text
    groups = ("delta_sp", "delta_rp", "delta_sp_dot", "delta_rp_dot", "force_sp", "force_rp")
    cols = np.concatenate([system.observable(g).columns for g in groups])
    assert cols.size == 6 * par.n_planets
    for tau, y, obs in zip(tr.tau, tr.states, tr.observables[:, cols], strict=True):
        np.testing.assert_allclose(obs, np.concatenate(fun.meshes(tau, y)), rtol=1e-12, atol=1e-12)
