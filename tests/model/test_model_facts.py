"""The facts of MODEL.md §10 that a correct planetary model satisfies (1, 2, 4, 5, 6).

Every expected number is computed here from the gear-set fields and the equations of MODEL.md,
never copied from the code's output.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.integrate import integrate

NO_EXCITATION = {
    "stiffness.sun_planet_alternating": 0.0,
    "stiffness.planet_ring_alternating": 0.0,
    "transmission_error.sun_planet": 0.0,
    "transmission_error.planet_ring": 0.0,
}


def _cols(system, *groups: str) -> np.ndarray:
    """Observable columns by name (e.g. "force_sp" → force_sp_1..N), independent of layout."""
    return np.concatenate([system.observable(g).columns for g in groups])


def _geometry(gs):
    """Radii and equivalent masses from the gear-set fields (MODEL.md §1)."""
    z, g = gs.teeth, gs.geometry
    a_s, a_r = math.radians(g.pressure_angle_sun), math.radians(g.pressure_angle_ring)
    r_s, r_p = g.module * z.sun / 2, g.module * z.planet / 2
    r_bs, r_bp, r_c = r_s * math.cos(a_s), r_p * math.cos(a_s), r_s + r_p
    ms_star = gs.inertia.sun / r_bs**2
    mp_star = gs.inertia.planet / r_bp**2
    mc_star = gs.inertia.carrier / r_c**2 + g.planets * gs.mass.planet
    m_e = ms_star * mp_star / (ms_star + mp_star)
    return {
        "alpha_s": a_s,
        "alpha_r": a_r,
        "r_bs": r_bs,
        "r_c": r_c,
        "ms_star": ms_star,
        "mp_star": mp_star,
        "mc_star": mc_star,
        "m_s": gs.mass.sun,
        "m_e": m_e,
        "omega_n": math.sqrt(gs.stiffness.sun_planet_mean / m_e),
    }


# ------------------------------------------------------------------------------- fact 1
def _static_expectation(gs):
    geo = _geometry(gs)
    N = gs.geometry.planets
    F = gs.torque.input / (N * geo["r_bs"])  # [N], each mesh
    force_scale = gs.stiffness.sun_planet_mean * gs.clearance.characteristic_length
    F_bar = F / force_scale
    d_sp = gs.backlash.sun_planet + F / force_scale  # b̄ + F/(k_m,sp b_c)
    d_rp = gs.backlash.planet_ring + F / (
        gs.stiffness.planet_ring_mean * gs.clearance.characteristic_length
    )
    return F_bar, d_sp, d_rp


@pytest.mark.parametrize("phasing", ["in_phase", "parker"])
def test_static_equilibrium_is_a_rest_point(phasing: str) -> None:
    gs = gc.preset("hindawi2021").evolve(NO_EXCITATION, mesh_phasing__model=phasing)
    F_bar, d_sp, d_rp = _static_expectation(gs)
    N = gs.n_planets
    system = gc.planetary_system(gs, 1.3)
    # q* = (0, 0, p_i = δ_sp, σ = p + δ_rp), zero velocity
    y = np.zeros(system.n_state)
    y[2 : 2 + N] = d_sp
    y[2 + N] = d_sp + d_rp
    for tau in (0.0, 1.234, 17.0):
        np.testing.assert_allclose(system.derivative(tau, y), 0.0, atol=1e-12)
    obs = system.observe(np.array([0.7]), y)[0]
    np.testing.assert_allclose(obs[_cols(system, "force_sp", "force_rp")], F_bar, rtol=1e-12)


def test_static_equilibrium_is_the_long_time_solution() -> None:
    gs = gc.preset("hindawi2021").evolve(NO_EXCITATION, xi=0.05)
    F_bar, d_sp, d_rp = _static_expectation(gs)
    N = gs.n_planets
    system = gc.planetary_system(gs, 1.0)
    tr = integrate(system, transient_periods=150, periods=2, rtol=1e-10, atol=1e-12)
    assert tr.ok
    obs = tr.observables[-1]
    force_scale = gs.stiffness.sun_planet_mean * gs.clearance.characteristic_length
    # in SI: F_spi = F_rpi = T_D/(N r_bs)
    F_si = gs.torque.input / (N * _geometry(gs)["r_bs"])
    forces = obs[_cols(system, "force_sp", "force_rp")]
    np.testing.assert_allclose(forces * force_scale, F_si, rtol=1e-8)
    np.testing.assert_allclose(obs[:N], d_sp, rtol=1e-9)
    np.testing.assert_allclose(obs[N : 2 * N], d_rp, rtol=1e-9)
    np.testing.assert_allclose(tr.states[-1, :2], 0.0, atol=1e-9)  # x_s = y_s = 0
    np.testing.assert_allclose(tr.states[-1, N + 3 :], 0.0, atol=1e-8)  # at rest
    # teeth in contact: the static deflection exceeds the clearance
    assert F_bar > 0 and np.all(obs[:N] > gs.backlash.sun_planet)


# ------------------------------------------------------------------------------- fact 2
def test_kinematics_and_torque_balance() -> None:
    gs = gc.preset("hindawi2021")
    z = gs.teeth
    rpm = 1500.0
    w_s = rpm * 2 * math.pi / 60
    # Willis with a fixed ring: (ω_s − ω_H)/(0 − ω_H) = −z_r/z_s
    w_H = w_s * z.sun / (z.sun + z.ring)
    w_mesh = z.sun * (w_s - w_H)  # sun teeth passing a planet, relative to the carrier
    assert gs.mesh_frequency(rpm) == pytest.approx(w_mesh, rel=1e-13)
    assert w_mesh == pytest.approx(z.ring * w_H, rel=1e-13)  # ring teeth passing the carrier
    # the planet spins relative to the carrier at ω_pH with z_p ω_pH = ω
    w_pH = z.sun * (w_s - w_H) / z.planet
    assert w_pH == pytest.approx(w_mesh / z.planet, rel=1e-13)
    # round trip through the dimensionless mesh frequency
    omega_n = _geometry(gs)["omega_n"]
    assert gs.sun_speed_rpm(w_mesh / omega_n) == pytest.approx(rpm, rel=1e-12)
    # loss-free power balance T_L ω_H = T_D ω_s
    assert gs.output_torque == pytest.approx(gs.torque.input * w_s / w_H, rel=1e-12)
    assert gs.output_torque / gs.torque.input == pytest.approx(1 + z.ring / z.sun, rel=1e-12)


ECCENTRIC = {
    "sun": ("eccentricity.sun", "teeth.sun"),
    "planet": ("eccentricity.planet", "teeth.planet"),
    "ring": ("eccentricity.ring", "teeth.ring"),
}


def _only_eccentricity(member: str):
    changes = dict(NO_EXCITATION)
    changes[ECCENTRIC[member][0]] = 4e-6
    changes["eccentricity.sun_phase"] = 25.0
    changes["eccentricity.planet_phase"] = -40.0
    changes["eccentricity.ring_phase"] = 70.0
    changes["mesh_phasing.model"] = "parker"
    return gc.preset("hindawi2021").evolve(changes)


@pytest.mark.parametrize("member", list(ECCENTRIC))
def test_eccentricity_excitation_has_the_member_period(member: str) -> None:
    gs = _only_eccentricity(member)
    omega = 1.3
    system = gc.planetary_system(gs, omega)
    T = system.period
    z = {"sun": gs.teeth.sun, "planet": gs.teeth.planet, "ring": gs.teeth.ring}[member]
    rng = np.random.default_rng(3)
    y = rng.normal(scale=3.0, size=system.n_state)
    for tau in (0.3, 5.0, 40.0):
        f0 = system.derivative(tau, y)
        # period z T = 2π z/Ω of the member's rotation relative to the carrier
        np.testing.assert_allclose(system.derivative(tau + z * T, y), f0, rtol=1e-9, atol=1e-9)
        # and not the mesh period
        assert np.abs(system.derivative(tau + T, y) - f0).max() > 1e-3


@pytest.mark.parametrize("member", list(ECCENTRIC))
def test_eccentricity_terms_match_model_md(member: str) -> None:
    """At the zero state δ_sp = −e_sp and δ_rp = −e_rp (MODEL.md §3)."""
    gs = _only_eccentricity(member)
    omega = 1.3
    system = gc.planetary_system(gs, omega)
    N = gs.n_planets
    geo = _geometry(gs)
    a_s, a_r = geo["alpha_s"], geo["alpha_r"]
    bc = gs.clearance.characteristic_length
    ec = gs.eccentricity
    Es, Ep, Er = ec.sun / bc, ec.planet / bc, ec.ring / bc
    bs, bp, br = (math.radians(v) for v in (ec.sun_phase, ec.planet_phase, ec.ring_phase))
    psi = 2 * np.pi * np.arange(N) / N
    z = gs.teeth
    tau = np.linspace(0.0, 80.0, 37)
    obs = system.observe(tau, np.zeros((tau.size, system.n_state)))
    for k, t in enumerate(tau):
        wt = omega * t
        e_sp = Es * np.sin(wt / z.sun + bs - psi + a_s) + Ep * np.sin(wt / z.planet + bp + a_s)
        e_rp = Ep * np.sin(wt / z.planet + bp - a_r) + Er * np.sin(-wt / z.ring + br - psi - a_r)
        e_sp_d = omega * (
            Es / z.sun * np.cos(wt / z.sun + bs - psi + a_s)
            + Ep / z.planet * np.cos(wt / z.planet + bp + a_s)
        )
        e_rp_d = omega * (
            Ep / z.planet * np.cos(wt / z.planet + bp - a_r)
            - Er / z.ring * np.cos(-wt / z.ring + br - psi - a_r)
        )
        np.testing.assert_allclose(obs[k, :N], -e_sp, atol=1e-13)
        np.testing.assert_allclose(obs[k, N : 2 * N], -e_rp, atol=1e-13)
        np.testing.assert_allclose(obs[k, _cols(system, "delta_sp_dot")], -e_sp_d, atol=1e-13)
        np.testing.assert_allclose(obs[k, _cols(system, "delta_rp_dot")], -e_rp_d, atol=1e-13)


# ------------------------------------------------------------------------------- fact 4
def _clearance_case(**changes):
    # a large transmission error makes the meshes separate (clearances active)
    base = {"transmission_error.sun_planet": 8e-6, "transmission_error.planet_ring": 8e-6}
    base.update(changes)
    return gc.preset("hindawi2021").evolve(base)


def test_in_phase_symmetry_keeps_sun_centred_and_planets_equal() -> None:
    gs = _clearance_case(**{"mesh_phasing.model": "in_phase"})
    N = gs.n_planets
    tr = integrate(
        gc.planetary_system(gs, 1.5),
        transient_periods=0,
        periods=15,
        samples_per_period=8,
        rtol=1e-10,
        atol=1e-12,
        perturbation=0.0,  # the exact symmetric start: the property is about that manifold
    )
    assert tr.ok
    # the meshes separate (δ_sp < b_sp at times), so the dead zones are exercised
    assert tr.obs_min[:N].min() < gs.backlash.sun_planet
    assert np.abs(tr.states[:, [0, 1, N + 3, N + 4]]).max() <= 1e-9
    p = tr.states[:, 2 : 2 + N]
    assert np.abs(p - p[:, :1]).max() <= 1e-9 * np.abs(p).max()
    assert np.abs(p).max() > 1.0
    # consequently the sun bearing clearance and stiffness play no part (MODEL.md §9); the two
    # runs differ only by integration error (step sequences differ), hence the tight rtol
    gs2 = gs.evolve({"clearance.sun_bearing": 0.0, "stiffness.sun_bearing": 1e9})
    kw = {"transient_periods": 0, "periods": 15, "samples_per_period": 8, "atol": 1e-14}
    kw["perturbation"] = 0.0  # on the symmetric manifold, as above
    a = integrate(gc.planetary_system(gs, 1.5), rtol=1e-12, **kw)
    b = integrate(gc.planetary_system(gs2, 1.5), rtol=1e-12, **kw)
    assert np.abs(a.states[:, 2:] - b.states[:, 2:]).max() <= 1e-6 * np.abs(p).max()


def test_parker_phasing_moves_the_sun() -> None:
    gs = _clearance_case(**{"mesh_phasing.model": "parker"})
    assert gs.phasing_class == "sequential"  # z_r mod N = 96 mod 5 = 1
    tr = integrate(
        gc.planetary_system(gs, 1.5),
        transient_periods=0,
        periods=15,
        samples_per_period=8,
        rtol=1e-10,
        atol=1e-12,
    )
    assert tr.ok
    assert np.abs(tr.states[:, 0]).max() > 0.1
    assert np.abs(tr.states[:, 1]).max() > 0.1


# ------------------------------------------------------------------------------- fact 5
def _linear_steady_state(omega, zeta, b, f_mean, amp):
    D = 1 - omega**2 + 2j * zeta * omega
    H = 1 / D
    phase = np.angle(D)
    return lambda tau: b + f_mean + amp * abs(H) * np.cos(omega * tau - phase), amp * abs(H)


@pytest.mark.parametrize(
    ("omega", "zeta", "b", "f_mean", "f_alt", "power"),
    [
        (1.5, 0.1, 1.0, 1.0, 0.5, 0),
        (0.9, 0.08, 0.5, 0.6, 0.12, 0),  # near resonance, |H| ≈ 4.1
        (0.8, 0.1, 1.0, 1.0, 0.3, 2),  # transmission-error forcing, amplitude F_a Ω²
        (2.3, 0.05, 2.0, 0.3, 0.2, 2),
    ],
)
def test_backlash_oscillator_exact_steady_state(omega, zeta, b, f_mean, f_alt, power) -> None:
    amp = f_alt * omega**power
    x_exact, a = _linear_steady_state(omega, zeta, b, f_mean, amp)
    assert f_mean > a  # never reaches the clearance: x > b always
    system = gc.backlash_oscillator(
        omega, zeta=zeta, eps=0.0, b=b, f_mean=f_mean, f_alt=f_alt, omega_power=power
    )
    transient = math.ceil(30 * omega / (2 * math.pi * zeta))  # e^(−ζτ) < 1e-13
    tr = integrate(
        system, transient_periods=transient, periods=6, samples_per_period=7, rtol=1e-11, atol=1e-13
    )
    assert tr.ok
    np.testing.assert_allclose(tr.series("x"), x_exact(tr.tau), atol=1e-7)
    v_exact = (x_exact(tr.tau + 1e-6) - x_exact(tr.tau - 1e-6)) / 2e-6
    np.testing.assert_allclose(tr.series("x_dot"), v_exact, atol=1e-6)
    lo, hi = tr.extrema("x")
    assert lo == pytest.approx(b + f_mean - a, abs=1e-7)
    assert hi == pytest.approx(b + f_mean + a, abs=1e-7)


# ------------------------------------------------------------------------------- fact 6
CONSERVATIVE = {
    **NO_EXCITATION,
    "xi": 0.0,
    "torque.input": 0.0,
    "mesh_phasing.model": "parker",
}


def _energy_model(gs):
    """Masses, stiffnesses, clearances (dimensionless) and the rigid mode, from the fields."""
    geo = _geometry(gs)
    me = geo["m_e"]
    k = gs.stiffness.sun_planet_mean
    N = gs.geometry.planets
    ca_s, ca_r = math.cos(geo["alpha_s"]), math.cos(geo["alpha_r"])
    mass = np.array([geo["ms_star"], *([geo["mp_star"]] * N), geo["mc_star"]]) / me
    phi = np.array([ca_s + ca_r, *([-ca_r] * N), 1.0])  # rigid rotation (u_s, u_i, u_c)
    # rows: p_i' = u_s' + u_i' − cos α_s u_c';  σ' = u_s' − (cos α_s + cos α_r) u_c';  P
    M = np.zeros((N + 2, N + 2))
    for i in range(N):
        M[i, 0], M[i, 1 + i], M[i, N + 1] = 1.0, 1.0, -ca_s
    M[N, 0], M[N, N + 1] = 1.0, -(ca_s + ca_r)
    M[N + 1] = mass * phi
    return {
        "N": N,
        "mu_s": gs.mass.sun / me,
        "mass": mass,
        "phi": phi,
        "M": M,
        "k_rp": gs.stiffness.planet_ring_mean / k,
        "k_b": gs.stiffness.sun_bearing / k,
        "b_sp": gs.backlash.sun_planet,
        "b_rp": gs.backlash.planet_ring,
        "b_s": gs.clearance.sun_bearing,
        "psi": 2 * np.pi * np.arange(N) / N,
        "alpha_s": geo["alpha_s"],
    }


def _rotational_velocities(em, p_dot, sig_dot, momentum=0.0):
    rhs = np.concatenate([p_dot, [sig_dot, momentum]])
    return np.linalg.solve(em["M"], rhs)


def _energy(em, y):
    """(kinetic, potential) energy in units of k_m,sp b_c²."""
    N = em["N"]
    n = N + 3
    x, yy, p, sig = y[0], y[1], y[2 : 2 + N], y[2 + N]
    xd, yd, pd, sigd = y[n], y[n + 1], y[n + 2 : n + 2 + N], y[n + 2 + N]
    u_dot = _rotational_velocities(em, pd, sigd)
    kinetic = 0.5 * em["mu_s"] * (xd**2 + yd**2) + 0.5 * np.sum(em["mass"] * u_dot**2)
    a = em["psi"] - em["alpha_s"]
    d_sp = p - x * np.sin(a) + yy * np.cos(a)
    d_rp = sig - p

    def gap(d, b):
        return np.maximum(np.abs(d) - b, 0.0) ** 2

    potential = 0.5 * np.sum(gap(d_sp, em["b_sp"])) + 0.5 * em["k_rp"] * np.sum(
        gap(d_rp, em["b_rp"])
    )
    potential += 0.5 * em["k_b"] * (gap(x, em["b_s"]) + gap(yy, em["b_s"]))
    return kinetic, potential


def test_rigid_mode_and_velocity_reconstruction() -> None:
    em = _energy_model(gc.preset("hindawi2021").evolve(CONSERVATIVE))
    N = em["N"]
    # the rigid rotation leaves every p_i and σ unchanged ...
    np.testing.assert_allclose(em["M"][: N + 1] @ em["phi"], 0.0, atol=1e-15)
    # ... and is what the momentum row picks out: P = a φᵀMφ gives u' = a φ
    P = 2.5 * np.sum(em["mass"] * em["phi"] ** 2)
    np.testing.assert_allclose(
        _rotational_velocities(em, np.zeros(N), 0.0, P), 2.5 * em["phi"], rtol=1e-13
    )
    # a relative motion is reproduced exactly
    rng = np.random.default_rng(0)
    pd, sd = rng.normal(size=N), 0.7
    u = _rotational_velocities(em, pd, sd)
    np.testing.assert_allclose(em["M"] @ u, [*pd, sd, 0.0], atol=1e-13)


@pytest.mark.parametrize("omega", [0.9, 2.2])
def test_energy_is_conserved_with_impacts(omega: float) -> None:
    gs = gc.preset("hindawi2021").evolve(CONSERVATIVE)
    em = _energy_model(gs)
    N = em["N"]
    system = gc.planetary_system(gs, omega)
    rng = np.random.default_rng(42)
    y0 = np.zeros(system.n_state)
    y0[:2] = rng.uniform(-1, 1, 2)
    y0[2 : N + 3] = rng.uniform(-2, 2, N + 1)
    y0[N + 3 :] = rng.normal(scale=3.0, size=N + 3)
    tr = integrate(
        system,
        y0=y0,
        transient_periods=0,
        periods=6,
        samples_per_period=25,
        rtol=1e-12,
        atol=1e-14,
    )
    assert tr.ok
    E0 = sum(_energy(em, y0))
    KV = np.array([_energy(em, y) for y in tr.states])
    E = KV.sum(axis=1)
    assert np.abs(E / E0 - 1).max() <= 1e-8
    # impacts on both flanks of both meshes, and the sun hits its bearing clearance
    d = tr.observables
    assert d[:, :N].max() > em["b_sp"] and d[:, :N].min() < -em["b_sp"]
    assert d[:, N : 2 * N].max() > em["b_rp"] and d[:, N : 2 * N].min() < -em["b_rp"]
    assert np.abs(tr.states[:, :2]).max() > em["b_s"]
    # energy is exchanged between kinetic and potential (the check is not vacuous)
    assert np.ptp(KV[:, 0] / E0) > 0.05
