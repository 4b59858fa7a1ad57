"""Motion labels and contact regimes of real simulations whose answer is known independently.

* The single-mesh backlash oscillator with F_m > F_a|H(Ω)| never separates; its steady state is
  x = b + F_m + F_a|H| cos(Ωτ − arg(1 − Ω² + 2iζΩ)) (MODEL.md §10.5): one section point (1T),
  contact regime ``none``, exponents −ζ.
* An undamped linear oscillator forced at Ω with 1/Ω irrational has two frequencies: its section
  points fill an ellipse (quasi-periodic), and both exponents are 0 (Re eig = 0).
* The Lorenz attractor is chaotic (λ_1 = 0.9056 > 0).
* Back-flank contact (δ < −b) is *proved* from a dense time history: between two samples
  Δτ apart, δ cannot move by more than max|δ'| Δτ, so sample values bound the true extrema.
"""

from __future__ import annotations

import cmath
import math

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.analysis.contact import contact_fractions, contact_regimes
from gearchaos.analysis.summary import summarize
from gearchaos.dynamics.lyapunov import max_lyapunov

SAMPLES = 256  # per forcing period, for the dense time histories


def _bounds(result: gc.SimulationResult, name: str, rate: str) -> tuple[float, float]:
    """Interval [lo, hi] holding the true minimum of ``name`` over the recorded window:
    hi = sample minimum, lo = hi − max|rate| Δτ (``rate`` is d(name)/dτ, its sampled maximum
    standing in for the true one)."""
    x = result.series(name)
    xd = result.series(rate)
    dt = float(np.diff(result.tau).max())
    return float(x.min() - np.abs(xd).max() * dt), float(x.min())


# ----------------------------------------------------------------- no separation: 1T, none
@pytest.mark.parametrize(("omega", "zeta"), [(0.8, 0.05), (1.3, 0.1)])
def test_oscillator_without_separation_is_1T_with_no_separation(omega: float, zeta: float) -> None:
    f_mean, f_alt, b = 2.0, 0.3, 1.0
    system = gc.backlash_oscillator(
        omega, zeta=zeta, eps=0.0, b=b, f_mean=f_mean, f_alt=f_alt, omega_power=0
    )
    kw = {"transient_periods": 200, "periods": 100}
    result = gc.simulate(system, samples_per_period=16, **kw)
    # exact steady state (MODEL.md §10.5): x_min = b + F_m − F_a|H| > b
    h = 1.0 / (1.0 - omega**2 + 2j * zeta * omega)
    x_min = b + f_mean - f_alt * abs(h)
    assert x_min > b + 0.5
    assert result.obs_min[0] == pytest.approx(x_min, rel=1e-6)
    x_exact = b + f_mean + f_alt * abs(h) * np.cos(omega * result.tau + cmath.phase(h))
    np.testing.assert_allclose(result.series("x"), x_exact, rtol=0, atol=1e-6)

    lle = max_lyapunov(system, **kw)
    s = summarize(result, lle=lle)
    assert s["motion"] is None and s["record_label"] == "1T"
    assert s["distinct_section_points"] == 1
    assert s["contact"] == [{"mesh": "mesh", "regime": "none", "separation_fraction": 0.0}]
    assert s["lle"] == pytest.approx(-zeta, abs=1e-3)
    assert s["indicators_agree"] is True
    assert contact_fractions(result)["mesh"] == {"drive": 1.0, "gap": 0.0, "back": 0.0}


# ------------------------------------------------------------------- quasi-periodic, chaos
def test_two_frequency_linear_oscillator_is_quasi_periodic() -> None:
    omega = 0.7 * (1.0 + math.sqrt(5.0)) / 2.0  # 1/Ω irrational: the section is a rotation
    system = gc.linear_oscillator(omega, zeta=0.0, force=1.0)
    kw = {"transient_periods": 0, "periods": 500, "y0": np.array([1.0, 0.0])}
    lle = max_lyapunov(system, **kw)
    assert abs(lle) < 1e-6  # Re eig = 0
    s = summarize(gc.simulate(system, **kw), lle=lle)
    assert s["motion"] is None and s["record_label"] == "QP"
    assert s["indicators_agree"] is True
    assert s["k01"] < 0.2


def test_lorenz_is_chaotic() -> None:
    system = gc.lorenz(sample_interval=1.0)
    kw = {"transient_periods": 20, "periods": 500, "y0": np.array([1.0, 1.0, 1.0])}
    lle = max_lyapunov(system, **kw)
    s = summarize(gc.simulate(system, **kw), lle=lle)
    assert s["motion"] is None and s["record_label"] == "chaos"
    assert s["lle"] == pytest.approx(0.9056, rel=0.1)
    assert s["contact"] == []


# ------------------------------------------------------------------------ contact regimes
def test_oscillator_with_back_flank_contact_is_double_sided() -> None:
    """F_m = 0.1, F_a = 3 well below resonance: the quasi-static force changes sign, so the
    mesh crosses the whole gap to the back flank every period."""
    b = 1.0
    system = gc.backlash_oscillator(0.5, zeta=0.05, b=b, f_mean=0.1, f_alt=3.0, omega_power=0)
    result = gc.simulate(system, transient_periods=200, periods=20, samples_per_period=SAMPLES)
    lo, hi = _bounds(result, "x", "x_dot")
    assert hi < -b - 1.0  # proved: δ < −b occurs
    assert lo <= result.obs_min[0] <= hi  # the tracked minimum lies in the proved interval
    assert contact_regimes(result) == {"mesh": "double_sided"}
    s = summarize(result)
    assert [(c["mesh"], c["regime"]) for c in s["contact"]] == [("mesh", "double_sided")]
    assert 0.0 < s["contact"][0]["separation_fraction"] < 1.0
    x = result.series("x")
    assert contact_fractions(result)["mesh"]["back"] == pytest.approx(np.mean(x < -b))
    assert 0.0 < contact_fractions(result)["mesh"]["back"] < 1.0


def test_oscillator_with_separation_only_is_single_sided() -> None:
    """Teeth leave the drive flank (δ < b) but provably never reach the back flank."""
    b = 1.0
    system = gc.backlash_oscillator(1.0, zeta=0.05, b=b, f_mean=0.3, f_alt=0.3, omega_power=0)
    result = gc.simulate(system, transient_periods=200, periods=20, samples_per_period=SAMPLES)
    lo, hi = _bounds(result, "x", "x_dot")
    assert hi < b and lo > -b  # δ enters the gap; the true minimum is above −b
    assert contact_regimes(result) == {"mesh": "single_sided"}
    assert contact_fractions(result)["mesh"]["back"] == 0.0
    assert contact_fractions(result)["mesh"]["gap"] > 0.0


def test_planetary_with_back_flank_contact_is_double_sided() -> None:
    """Light load and small clearances: every planet–ring mesh reaches its back flank."""
    gs = gc.preset("hindawi2021").evolve(
        {"torque.input": 50.0, "backlash.sun_planet": 0.1, "backlash.planet_ring": 0.1}
    )
    result = gc.simulate(gs, omega=0.5, transient_periods=100, periods=20, samples_per_period=128)
    regimes = contact_regimes(result)
    s = summarize(result)
    assert [c["regime"] for c in s["contact"]] == list(regimes.values())
    b = {"sun_planet": 0.1, "planet_ring": 0.1}
    proved_back = 0
    for mesh, regime in regimes.items():
        kind, i = mesh.rsplit("_", 1)
        m = "sp" if kind == "sun_planet" else "rp"
        lo, hi = _bounds(result, f"delta_{m}_{i}", f"delta_{m}_dot_{i}")
        k = list(regimes).index(mesh)
        assert lo <= result.obs_min[k] <= hi + 1e-12
        if hi < -b[kind]:  # the samples prove back-flank contact
            assert regime == "double_sided", mesh
            proved_back += 1
        elif lo > -b[kind] and hi <= b[kind]:  # proved separation without back contact
            assert regime == "single_sided", mesh
        elif lo > b[kind]:  # proved: never separates
            assert regime == "none", mesh
    assert proved_back >= 5  # at least the five planet–ring meshes


# ------------------------------------------------------------------------------- sweeps
def test_sweep_labels_no_separation_oscillator_1T_with_lle_minus_zeta() -> None:
    zeta = 0.05
    system = gc.backlash_oscillator(
        0.5, zeta=zeta, eps=0.0, b=1.0, f_mean=2.0, f_alt=0.3, omega_power=0
    )
    ds = gc.bifurcation(
        system,
        "omega=0.3,0.5,0.8,1.3,2.0",
        lyapunov=True,
        transient_periods=200,
        periods=100,
        progress=False,
    )
    assert ds["motion"].values.tolist() == ["1T"] * 5
    np.testing.assert_allclose(ds["lle"].values, -zeta, rtol=0, atol=2e-3)
    assert np.all(ds["indicators_agree"].values)
