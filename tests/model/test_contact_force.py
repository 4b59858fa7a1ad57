"""Mesh contact forces (issue 12): the closed-form linear response, exactly zero while the teeth
are apart, peaks tracked by the integrator independently of the sampling, one sampling default.

The closed forms are MODEL.md §10.5: without separation the backlash oscillator
x'' + 2ζx' + f(x; b) = F_m + F_a cos Ωτ is linear, x = b + F_m + F_a|H| cos(Ωτ − φ),
H = 1/(1 − Ω² + 2iζΩ), so its contact force Fᶜ = (x − b) + 2ζx' is
F_m + F_a|H| √(1 + 4ζ²Ω²) cos(Ωτ − φ + atan 2ζΩ): peak F_m + A and RMS √(F_m² + A²/2) with
A = F_a|H|√(1 + 4ζ²Ω²).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app
from gearchaos.dynamics.verdict.point import analyse_point
from gearchaos.integrate.settings import SolverSettings
from gearchaos.model.response import response_quantities

ZETA, FM, FA, B = 0.1, 1.0, 0.3, 1.0


def _linear_amplitude(omega: float, zeta: float, fa: float) -> float:
    h = 1.0 / complex(1.0 - omega**2, 2.0 * zeta * omega)
    return fa * abs(h) * math.sqrt(1.0 + 4.0 * zeta**2 * omega**2)


@pytest.mark.parametrize("omega", [0.5, 1.6])
def test_contact_force_without_separation_is_the_closed_form_linear_response(
    omega: float,
) -> None:
    # force amplitude (omega_power=0); F_a|H| < F_m: the teeth never separate
    sys_ = gc.backlash_oscillator(omega, zeta=ZETA, b=B, f_mean=FM, f_alt=FA, omega_power=0)
    assert FA / abs(complex(1 - omega**2, 2 * ZETA * omega)) < FM
    res = gc.simulate(
        sys_, transient_periods=80, periods=10, samples_per_period=16, rtol=1e-11, atol=1e-13
    )
    amp = _linear_amplitude(omega, ZETA, FA)
    rq = response_quantities(res.system, res.obs_min, res.obs_max, res.observables)
    assert float(rq["force_peak_mesh"]) == pytest.approx(FM + amp, abs=1e-6)
    assert float(rq["force_rms_mesh"]) == pytest.approx(math.sqrt(FM**2 + amp**2 / 2), abs=1e-6)
    lo, hi = res.extrema("contact_force")
    assert lo == pytest.approx(FM - amp, abs=1e-6)
    assert hi == pytest.approx(FM + amp, abs=1e-6)
    assert float(rq["load_factor_mesh"]) == pytest.approx((FM + amp) / FM, abs=1e-6)
    # DTE: the deflection's fluctuating part, F_a|H| cos(…), RMS F_a|H|/√2
    fah = FA / abs(complex(1 - omega**2, 2 * ZETA * omega))
    assert float(rq["dte_rms_mesh"]) == pytest.approx(fah / math.sqrt(2), abs=1e-6)


def _impacting() -> gc.System:
    """Transmission-error forcing strong enough to open the backlash every period."""
    return gc.backlash_oscillator(1.0, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.2)


def test_contact_force_is_exactly_zero_while_the_teeth_are_apart() -> None:
    res = gc.simulate(_impacting(), transient_periods=60, periods=8, samples_per_period=512)
    x = res.series("x")
    v = res.series("x_dot")
    fc = res.series("contact_force")
    apart = np.abs(x) <= 1.0
    assert 0.05 < apart.mean() < 0.95  # the run does separate
    assert np.all(fc[apart] == 0.0)
    # in contact: the mesh force κ f(x; b) + 2ζx' (ε = 0, recomputed here) where it presses
    # the flanks together, 0 where the damping would pull them just before release
    touch = ~apart
    mesh = (x - np.sign(x) * 1.0) + 2 * 0.05 * v
    assert np.any(mesh[touch] * x[touch] < 0)  # the run has such tension: the case tested
    expected = np.where(mesh * x > 0, mesh, 0.0)
    np.testing.assert_allclose(fc[touch], expected[touch], rtol=1e-13, atol=1e-15)
    assert np.all(fc * x >= 0)  # never pulls, on either flank
    # the tracked extrema bound the samples and are reached by them to the sampling
    # resolution (512 samples per period)
    lo, hi = res.extrema("contact_force")
    assert lo <= fc.min() + 1e-12 and hi >= fc.max() - 1e-12
    assert hi - fc.max() < 1e-4 * hi
    assert fc.min() - lo < 1e-2 * hi


@pytest.mark.parametrize("target", ["oscillator", "planetary"])
def test_load_factors_do_not_depend_on_samples_per_period(target: str) -> None:
    if target == "oscillator":
        sys_ = _impacting()
        kw = {"transient_periods": 60, "periods": 6}
    else:
        sys_ = gc.model.target.resolve(gc.preset("hindawi2021"), {"omega": 0.8})
        kw = {"transient_periods": 40, "periods": 4}
    factors = []
    for spp in (1, 5, 64):
        res = gc.simulate(sys_, samples_per_period=spp, rtol=1e-10, atol=1e-12, **kw)
        rq = response_quantities(res.system, res.obs_min, res.obs_max, res.observables)
        factors.append({k: float(v) for k, v in rq.items() if k.startswith("load_factor")})
    for k in factors[0]:
        vals = [f[k] for f in factors]
        assert max(vals) - min(vals) <= 1e-6 * max(vals), (k, vals)
        assert vals[0] > 1.0  # a dynamic load factor exceeds the static one


def test_python_and_cli_give_identical_summaries() -> None:
    args = ["--preset", "hindawi2021", "--set", "omega=1.2", "--transient", "10"]
    out = CliRunner().invoke(app, ["simulate", *args, "--periods", "12", "--json"])
    assert out.exit_code == 0, out.output
    cli = json.loads(out.stdout)
    # the CLI's Python twin: the simulation and its verdict
    cfg = SolverSettings(transient_periods=10, periods=12, samples_per_period=64)
    py = json.loads(
        json.dumps(analyse_point(gc.preset("hindawi2021"), {"omega": 1.2}, cfg).summary)
    )
    assert cli == py
    assert cli["samples_per_period"] == 64
    assert cli["load_factor_sp_max"] is not None and cli["load_factor_sp_max"] > 0


def test_quick_start_contact_forces_are_the_compressive_mesh_forces_of_model_md() -> None:
    """The quick start (``gearchaos simulate --preset sheng2016 --set omega=1.5``) drew a
    sun–planet contact force of −0.0066 just before the teeth release: the viscous term c̄ δ̄'
    of MODEL.md §4's mesh force outweighs κ f(δ̄; b̄) there, and teeth cannot pull. Here the
    mesh forces are recomputed from the state with MODEL.md §3, §4 and §7 alone (numpy, gear
    set values), and what is reported and plotted as the contact force must be exactly their
    compressive part: ≥ 0 on the drive flank, 0 while apart or pulling."""
    from gearchaos.plot.timeseries import mesh_force_history

    gs = gc.preset("sheng2016-v1")
    omega = 1.5
    res = gc.simulate(gs, omega=omega, transient_periods=100, periods=20, samples_per_period=64)
    # MODEL.md §1, §7: equivalent masses, ω_n, the dimensionless damping and stiffness
    z, geo = gs.teeth, gs.geometry
    alpha = math.radians(geo.pressure_angle_sun)
    ms = gs.inertia.sun / (geo.module * z.sun / 2 * math.cos(alpha)) ** 2
    mp = gs.inertia.planet / (geo.module * z.planet / 2 * math.cos(alpha)) ** 2
    me = ms * mp / (ms + mp)
    k = gs.stiffness
    c_sp = 2 * gs.damping.sun_planet  # c_sp/(m_e ω_n) with c_sp = 2ξ √(k_sp m_e)
    ratio = k.planet_ring_mean * mp / (k.sun_planet_mean * me)
    c_rp = 2 * gs.damping.planet_ring * math.sqrt(ratio)  # c_rp = 2ξ √(k_rp m_p*)
    b_sp, b_rp = gs.backlash.sun_planet, gs.backlash.planet_ring  # already in b_c
    amp = gs.transmission_error.sun_planet / gs.clearance.characteristic_length
    assert gs.mesh_phasing.model == "in_phase" and gs.transmission_error.sun_planet_phase == 0
    th = omega * res.tau
    kappa_sp = 1 + k.sun_planet_alternating / k.sun_planet_mean * np.cos(th)
    kappa_rp = (k.planet_ring_mean + k.planet_ring_alternating * np.cos(th)) / k.sun_planet_mean
    e, e_d = amp * np.sin(th), amp * omega * np.cos(th)
    st = {n: res.series(n) for n in ("x_s", "y_s", "p_1", "sigma")}
    st_d = {n: res.series(n + "_dot") for n in ("x_s", "y_s", "p_1", "sigma")}

    def s1(v: dict[str, np.ndarray]) -> np.ndarray:  # ψ_1 = 0 (MODEL.md §3)
        return -v["x_s"] * math.sin(-alpha) + v["y_s"] * math.cos(-alpha)

    # MODEL.md §3 (planet 1, ring fixed) and §6: δ_sp = p + s − e, δ_rp = σ − p − e
    d_sp = st["p_1"] + s1(st) - e
    d_sp_d = st_d["p_1"] + s1(st_d) - e_d
    d_rp = st["sigma"] - st["p_1"] - e
    d_rp_d = st_d["sigma"] - st_d["p_1"] - e_d

    def dead(x: np.ndarray, b: float) -> np.ndarray:
        return np.where(x > b, x - b, np.where(x < -b, x + b, 0.0))

    ax = mesh_force_history(res, physical=False, periods=20)
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    for mesh, d, dd, kap, c, b in (
        ("sp", d_sp, d_sp_d, kappa_sp, c_sp, b_sp),
        ("rp", d_rp, d_rp_d, kappa_rp, c_rp, b_rp),
    ):
        force = kap * dead(d, b) + c * dd  # MODEL.md §4 mesh force
        assert np.all(d > -b), mesh  # drive flank only in this run
        touch = d > b
        assert np.any(touch & (force < 0)), mesh  # the model's force pulls before release
        expected = np.where(touch & (force > 0), force, 0.0)
        reported = res.series(f"contact_force_{mesh}_1")
        np.testing.assert_allclose(reported, expected, rtol=1e-7, atol=1e-9 * force.max())
        lo, hi = res.extrema(f"contact_force_{mesh}_1")
        assert lo >= 0.0 and hi >= reported.max() - 1e-12, mesh
        drawn = next(ln for key, ln in lines.items() if f"{mesh}1" in key)
        ydata = np.asarray(drawn.get_ydata(), dtype=float)
        assert ydata.min() >= 0.0, mesh
        np.testing.assert_allclose(ydata, expected[-ydata.size :], atol=1e-9 * force.max())
    ds = res.to_dataset()
    assert float(ds["contact_force_sp_min"].min()) >= 0.0
    assert float(ds["contact_force_rp_min"].min()) >= 0.0
