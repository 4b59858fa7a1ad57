"""Periodic orbits by shooting: what :func:`gearchaos.periodic_orbit` promises, checked against
theory and against computations done here independently of the shooting code.

* Linear systems y' = A y + f cos Ωτ + g sin Ωτ: the multipliers of the period-n orbit are the
  eigenvalues of e^{A nT} (``scipy.linalg.expm``), and the orbit is the closed-form steady
  state y(τ) = Re[(iΩ − A)⁻¹ (f − i g) e^{iΩτ}].
* The backlash oscillator that never separates is the linear oscillator (MODEL.md §10.5): its
  orbit is b + F_m + F_a|H| cos(Ωτ − arg(1 − Ω² + 2iζΩ)) and its multipliers are
  exp((−ζ ± i√(1 − ζ²)) T).
* Planetary orbits (N = 3 and 5, with and without tooth separation): the monodromy matrix and
  the multipliers equal those of a central finite-difference Jacobian of the stroboscopic map,
  computed here with :func:`gearchaos.simulate` from perturbed states; whether the teeth
  separate is checked on a finely sampled simulation of the orbit.
* Liouville: the product of the multipliers is exp(−tr(M⁻¹C)/ω_n · nT), with the damping
  matrix C built here from the gear set (``gear_reference.damping_trace``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg
from scipy.optimize import linear_sum_assignment

import gearchaos as gc
from gear_reference import damping_trace
from gearchaos.dynamics.orbits.orbit import PeriodicOrbit

TIGHT = {"rtol": 1e-12, "atol": 1e-14}


# ----------------------------------------------------------------------------------- helpers
def max_mismatch(a: np.ndarray, b: np.ndarray) -> float:
    """Largest distance between two multisets of complex numbers, optimally paired."""
    cost = np.abs(np.asarray(a)[:, None] - np.asarray(b)[None, :])
    rows, cols = linear_sum_assignment(cost)
    return float(cost[rows, cols].max())


def flow_map(system: gc.System, y: np.ndarray) -> np.ndarray:
    """P(y): one forcing period from the section τ = 0, by :func:`gearchaos.simulate`."""
    res = gc.simulate(system, y0=y, transient_periods=0, periods=1, **TIGHT)
    return np.asarray(res.final_state)


def fd_jacobian(system: gc.System, y: np.ndarray, h: float = 1e-4) -> np.ndarray:
    """Central (five-point) finite-difference Jacobian of the stroboscopic map at y."""
    n = y.size
    jac = np.empty((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = h * max(1.0, abs(y[j]))
        jac[:, j] = (
            -flow_map(system, y + 2 * e)
            + 8 * flow_map(system, y + e)
            - 8 * flow_map(system, y - e)
            + flow_map(system, y - 2 * e)
        ) / (12 * e[j])
    return jac


@pytest.fixture(scope="module")
def sheng() -> gc.GearSet:
    return gc.preset("sheng2016-v1")


def three_planets(gs: gc.GearSet) -> gc.GearSet:
    """The gear set with N = 3: (z_s + z_r)/3 an integer, z_r = z_s + 2 z_p (z_p = 32 kept)."""
    return gs.evolve({"geometry.planets": 3, "teeth.sun": 34, "teeth.ring": 98})


# ----------------------------------------------------------------------------------- linear
A3 = np.array([[-0.1, 1.0, 0.0], [-1.0, -0.1, 0.3], [0.2, 0.0, -0.5]])
F3 = np.array([0.0, 1.0, 0.2])
G3 = np.array([0.3, 0.0, -0.1])


@pytest.mark.parametrize("n", [1, 2])
def test_linear_multipliers_are_eigenvalues_of_expm(n: int) -> None:
    omega = 1.3
    system = gc.linear_system(A3, omega, cos_forcing=F3, sin_forcing=G3)
    orbit = gc.periodic_orbit(system, period=n, guess=np.zeros(3), **TIGHT)
    assert orbit.converged, orbit.message
    expected = np.linalg.eigvals(scipy.linalg.expm(A3 * n * 2 * math.pi / omega))
    assert max_mismatch(orbit.multipliers, expected) < 1e-9
    # sorted by modulus, descending
    mods = np.abs(orbit.multipliers)
    assert np.all(np.diff(mods) <= 1e-15)
    # the orbit is the closed-form steady state, sampled at τ = 0 and T
    amp = np.linalg.solve(1j * omega * np.eye(3) - A3, F3 - 1j * G3)
    assert np.max(np.abs(orbit.state - amp.real)) < 1e-9
    assert orbit.minimal_period == 1
    assert orbit.stable
    assert orbit.residual <= orbit.tol


def test_unstable_linear_orbit_is_found_and_called_unstable() -> None:
    """Shooting finds periodic orbits a simulation cannot reach: y' = A y + f with an
    eigenvalue of A in the right half-plane still has a unique T-periodic solution."""
    a = np.array([[0.05, 1.0], [-1.0, 0.05]])
    omega = 0.7
    system = gc.linear_system(a, omega, cos_forcing=[0.0, 1.0])
    orbit = gc.periodic_orbit(system, guess=[0.0, 0.0], **TIGHT)
    assert orbit.converged
    assert not orbit.stable
    expected = np.linalg.eigvals(scipy.linalg.expm(a * 2 * math.pi / omega))
    assert max_mismatch(orbit.multipliers, expected) < 1e-9
    amp = np.linalg.solve(1j * omega * np.eye(2) - a, np.array([0.0, 1.0]))
    assert np.max(np.abs(orbit.state - amp.real)) < 1e-9


def test_backlash_oscillator_without_separation_is_the_linear_oscillator() -> None:
    zeta, fm, fa, omega = 0.05, 0.5, 0.1, 0.8
    system = gc.backlash_oscillator(omega, zeta=zeta, f_mean=fm, f_alt=fa, omega_power=0)
    orbit = gc.periodic_orbit(system, **TIGHT)
    assert orbit.converged
    period = 2 * math.pi / omega
    wd = math.sqrt(1 - zeta**2)
    expected = np.exp(np.array([-zeta + 1j * wd, -zeta - 1j * wd]) * period)
    assert max_mismatch(orbit.multipliers, expected) < 1e-9
    den = 1 - omega**2 + 2j * zeta * omega
    h = 1 / den
    x0 = 1.0 + fm + fa * abs(h) * math.cos(-np.angle(den))
    v0 = -fa * abs(h) * omega * math.sin(-np.angle(den))
    assert orbit.state == pytest.approx([x0, v0], abs=1e-9)
    assert orbit.contact == {"mesh": "none"}


# ----------------------------------------------------------------------------------- planetary
CASES = [
    # (planets, Ω, teeth separate?)
    (3, 0.5, False),
    (3, 1.5, True),
    (5, 0.5, False),
    (5, 1.5, True),
]


@pytest.mark.parametrize(("planets", "omega", "separates"), CASES)
def test_planetary_multipliers_match_finite_differences(
    sheng: gc.GearSet, planets: int, omega: float, separates: bool
) -> None:
    gs = sheng if planets == 5 else three_planets(sheng)
    orbit = gc.periodic_orbit(gs, omega=omega, **TIGHT)
    assert orbit.converged, orbit.message
    assert orbit.system.model.n_planets == planets
    # whether the teeth separate, from a finely sampled simulation of one period of the orbit
    res = gc.simulate(
        orbit.system, y0=orbit.state, transient_periods=0, periods=1, samples_per_period=4000,
        **TIGHT,
    )  # fmt: skip
    b_sp, b_rp = gs.backlash_bar()
    gap = min(
        float(np.min(res.series("delta_sp"))) - b_sp,
        float(np.min(res.series("delta_rp"))) - b_rp,
    )
    assert (gap < 0) == separates
    # ... and the orbit closes on itself
    assert np.max(np.abs(res.final_state - orbit.state)) < 1e-8
    jac = fd_jacobian(orbit.system, orbit.state)
    scale = float(np.max(np.abs(jac)))
    assert np.max(np.abs(orbit.monodromy - jac)) < 1e-6 * scale
    assert max_mismatch(orbit.multipliers, np.linalg.eigvals(jac)) < 1e-6
    # the regimes PeriodicOrbit reports agree with the simulation
    regimes = set(orbit.contact.values())
    assert ("single_sided" in regimes) == separates


@pytest.mark.parametrize(("planets", "omega", "period"), [(5, 1.5, 1), (3, 1.5, 1), (5, 0.5, 2)])
def test_liouville_product_of_multipliers(
    sheng: gc.GearSet, planets: int, omega: float, period: int
) -> None:
    """Π μ = det M = exp(∫ tr J dτ) = exp(−tr(M⁻¹C)/ω_n · nT): the damping acts inside the
    clearances too, so the trace is the same in every contact state."""
    gs = sheng if planets == 5 else three_planets(sheng)
    orbit = gc.periodic_orbit(gs, omega=omega, period=period, **TIGHT)
    assert orbit.converged
    expected = math.exp(damping_trace(gs) * period * 2 * math.pi / omega)
    product = np.prod(orbit.multipliers)
    assert abs(product.imag) < 1e-12
    assert product.real == pytest.approx(expected, rel=1e-9)


# ----------------------------------------------------------------------------------- the API
def test_orbit_api_section_values_contacts_and_summary(sheng: gc.GearSet) -> None:
    orbit = gc.periodic_orbit(sheng, omega=1.5)
    assert isinstance(orbit, PeriodicOrbit)
    assert orbit.converged and orbit.period == 1 and orbit.iterations >= 1
    assert orbit.omega == 1.5
    x = orbit.section("delta_sp")
    assert x.shape == (1, 5)
    assert orbit.section("delta_sp", planets=[1]).shape == (1, 1)
    assert orbit.section("x_s").shape == (1,)
    assert set(orbit.contact) == {
        *(f"sun_planet_{i}" for i in range(1, 6)),
        *(f"planet_ring_{i}" for i in range(1, 6)),
        "sun_bearing_x",
        "sun_bearing_y",
    }
    summary = orbit.summary()
    assert list(summary) == [
        "period", "minimal_period", "converged", "max_multiplier", "residual", "stable",
        "stability_margin", "multipliers", "section_variable", "section", "contact", "message",
    ]  # fmt: skip
    assert summary["minimal_period"] == 1  # issue 24: the JSON says the orbit's own period
    # the stated criterion (issue 32: one margin, 10⁻⁴ as documented): with five planets no
    # multiplier is structural, so stable means every |μ| < 1 − margin
    assert summary["stability_margin"] == 1e-4
    assert summary["stable"] == all(
        m["abs"] < 1 - summary["stability_margin"] for m in summary["multipliers"]
    )
    assert summary["max_multiplier"] == pytest.approx(max(m["abs"] for m in summary["multipliers"]))
    assert summary["section_variable"] == "delta_sp_1"
    assert summary["section"] == pytest.approx([float(x[0, 0])])
    assert len(summary["multipliers"]) == 16
    m0 = summary["multipliers"][0]
    assert m0["abs"] == pytest.approx(math.hypot(m0["re"], m0["im"]))
    import json

    json.dumps(summary)


def test_orbit_dataset_carries_provenance(sheng: gc.GearSet, tmp_path) -> None:
    orbit = gc.periodic_orbit(sheng, omega=1.5, period=2)
    ds = orbit.to_dataset()
    assert ds.attrs["gearset_toml"] == sheng.to_toml()
    for key in ("version", "numba_version", "rtol", "atol", "transient_periods", "omega"):
        assert key in ds.attrs
    assert ds.sizes["section"] == 2 and ds.sizes["state"] == 16
    assert ds["delta_sp"].dims == ("section", "planet")
    mu = ds["multiplier_re"].values + 1j * ds["multiplier_im"].values
    assert np.allclose(mu, orbit.multipliers)
    path = tmp_path / "orbit.nc"
    ds.to_netcdf(path, engine="h5netcdf")


def test_period_two_guess_from_a_simulation_and_minimal_period(sheng: gc.GearSet) -> None:
    """A 1T orbit solves P²(y) = y too: the orbit says its minimal period is 1."""
    sim = gc.simulate(sheng, omega=0.5, transient_periods=50, periods=8)
    orbit = gc.periodic_orbit(sheng, omega=0.5, period=2, guess=sim)
    assert orbit.converged
    assert orbit.minimal_period == 1
    one = gc.periodic_orbit(sheng, omega=0.5, guess=orbit)
    assert np.max(np.abs(one.state - orbit.state)) < 1e-6
    # the multipliers of the period-2 map are the squares of the period-1 ones
    assert max_mismatch(orbit.multipliers, one.multipliers**2) < 1e-6


def test_failure_is_reported_not_raised() -> None:
    system = gc.linear_system([[0.0, 1.0], [-1.0, 0.0]], 1.0, cos_forcing=[0.0, 1.0])
    # resonant undamped forcing: no periodic orbit, Newton cannot converge
    orbit = gc.periodic_orbit(system, guess=[0.0, 0.0], max_iterations=6)
    assert not orbit.converged
    assert not orbit.stable
    assert orbit.message


def test_invalid_arguments_are_named(sheng: gc.GearSet) -> None:
    with pytest.raises(gc.ParameterError, match="period"):
        gc.periodic_orbit(sheng, omega=1.5, period=0)
    with pytest.raises(gc.ParameterError, match="omega is required"):
        gc.periodic_orbit(sheng)
    with pytest.raises(gc.ParameterError, match=r"'omgea'; did you mean 'omega'"):
        gc.periodic_orbit(gc.duffing(1.0), omgea=1.2)
    with pytest.raises(gc.ParameterError, match="guess"):
        gc.periodic_orbit(sheng, omega=1.5, guess=[1.0, 2.0])
    with pytest.raises(gc.ParameterError, match="tol"):
        gc.periodic_orbit(sheng, omega=1.5, tol=0.0)
    with pytest.raises(gc.ParameterError, match="rtol"):
        gc.periodic_orbit(sheng, omega=1.5, rtol=0.0)
    with pytest.raises(gc.ParameterError, match="twice"):
        gc.periodic_orbit(gc.duffing(1.0), delta=0.2, params={"delta": 0.3})


def test_dotted_parameters_by_params(sheng: gc.GearSet) -> None:
    """``params`` takes dotted names; the orbit equals the one of the evolved gear set."""
    a = gc.periodic_orbit(sheng, omega=0.5, params={"backlash.sun_planet": 2.5})
    b = gc.periodic_orbit(sheng.evolve({"backlash.sun_planet": 2.5}), omega=0.5)
    assert a.converged and b.converged
    assert np.max(np.abs(a.state - b.state)) < 1e-7
    # no separation at Ω = 0.5: the mean deflection of a mesh is b̄ + F̄; b̄ shifts it by −0.5
    c = gc.periodic_orbit(sheng, omega=0.5)
    shift = a.section("delta_sp")[0, 0] - c.section("delta_sp")[0, 0]
    assert shift == pytest.approx(-0.5, abs=1e-6)


# ----------------------------------------------------------------------------------- batches
def test_batched_orbits_confirm_the_points_of_a_sweep(sheng: gc.GearSet) -> None:
    """The sweep's final states (at a section time) are the guesses; the batched Newton finds
    the orbits the sweep converged to, and each is what periodic_orbit finds alone."""
    from gearchaos.analysis.periodicity import periods_of
    from gearchaos.dynamics.orbits.batch import periodic_orbits

    sweep = gc.bifurcation(
        sheng, "omega=2.9:3.1:5", progress=False, transient_periods=600, periods=16
    )
    settings = gc.integrate.SolverSettings(transient_periods=600, periods=16)
    labels = periods_of(
        np.stack([sweep.delta_sp.values[..., 0], sweep.delta_sp_dot.values[..., 0]], axis=-1)
    )
    one = np.flatnonzero(labels == 1)  # the points the sweep labels 1T
    assert one.size >= 3
    points = [{"omega": float(sweep.omega.values[k])} for k in one]
    guesses = sweep.final_state.values[one]
    orbits = periodic_orbits(sheng, points, guesses=guesses, settings=settings)
    for k, orbit in zip(one, orbits, strict=True):
        assert orbit.converged, orbit.message
        assert orbit.minimal_period == 1
        assert orbit.stable
        # the orbit is the one the sweep's run converges to: continued 1500 periods by
        # simulate (|μ| ≈ 0.975 leaves 0.975^1500 ≈ 3e-17 of any transient), the run's section
        # point is the orbit's; the sweep's own last one may still carry a slowly decaying
        # transient (a point that left a chaotic transient late: 3e-4 off after 616 periods)
        cont = gc.simulate(
            sheng, omega=orbit.omega, y0=sweep.final_state.values[k], transient_periods=1500,
            periods=1, samples_per_period=1,
        )  # fmt: skip
        x_cont = float(np.asarray(cont.series("delta_sp_1"))[cont.section_index][-1])
        assert orbit.section("delta_sp")[0, 0] == pytest.approx(x_cont, abs=1e-8)
        assert orbit.section("delta_sp")[0, 0] == pytest.approx(
            float(sweep.delta_sp.values[k, -1, 0]), abs=1e-3
        )
        alone = gc.periodic_orbit(
            sheng, guess=sweep.final_state.values[k], settings=settings, omega=orbit.omega
        )
        assert np.max(np.abs(alone.state - orbit.state)) < 1e-7
        assert max_mismatch(alone.multipliers, orbit.multipliers) < 1e-6
    # the chord iteration (the verdict's) finds the same orbits and the multipliers of the
    # orbit's own state, with fewer evaluations in all
    chord = periodic_orbits(sheng, points, guesses=guesses, settings=settings, chord=True)
    for a, b in zip(orbits, chord, strict=True):
        assert b.converged, b.message
        assert np.max(np.abs(a.state - b.state)) < 1e-7
        assert max_mismatch(a.multipliers, b.multipliers) < 1e-6
    assert sum(b.iterations for b in chord) <= sum(a.iterations for a in orbits)
    with pytest.raises(gc.ParameterError, match="guesses"):
        periodic_orbits(sheng, points, guesses=np.zeros((2, 16)))
    with pytest.raises(gc.ParameterError, match="systems must hold one system per point"):
        periodic_orbits(sheng, points, guesses=guesses, systems=[])
    with pytest.raises(gc.ParameterError, match="contraction"):
        periodic_orbits(sheng, points, guesses=guesses, contraction=2.0)
    assert periodic_orbits(sheng, []) == []
