"""Each plotting function returns labelled Axes with the clearance lines where they belong."""

from __future__ import annotations

import math

import numpy as np
import pytest
from matplotlib.axes import Axes
from matplotlib.patches import Rectangle

import gearchaos as gc
from gearchaos.errors import ParameterError
from gearchaos.plot import (
    amplitude_spectrum,
    phase_portrait,
    poincare_map,
    spectrum,
    sun_orbit,
    time_history,
)


def clearance_values(ax: Axes, axis: str) -> list[float]:
    """Positions of the ±b̄ lines (horizontal: y, vertical: x), sorted."""
    out = []
    for line in ax.get_lines():
        if line.get_gid() != "clearance":
            continue
        data = line.get_ydata() if axis == "y" else line.get_xdata()
        assert data[0] == data[1]
        out.append(float(data[0]))
    return sorted(out)


def test_time_history_planetary(planetary: gc.SimulationResult) -> None:
    ax = time_history(planetary)
    assert isinstance(ax, Axes)
    assert r"\bar{X}_{sp1}" in ax.get_ylabel() and r"\delta_{sp1}/b_c" in ax.get_ylabel()
    assert "mesh periods" in ax.get_xlabel()
    b_sp = planetary.system.model.parameters.b_sp
    assert clearance_values(ax, "y") == [-b_sp, b_sp]
    # x axis in mesh periods: τΩ/2π spans transient .. transient + recorded periods
    t = ax.get_lines()[0].get_xdata()
    assert t[0] == pytest.approx(20.0)
    assert t[-1] == pytest.approx(40.0 - 1 / 32)


def test_time_history_other_variables(planetary: gc.SimulationResult) -> None:
    ax = time_history(planetary, "delta_rp", planet=2, periods=3)
    assert r"\bar{X}_{rp2}" in ax.get_ylabel()
    b_rp = planetary.system.model.parameters.b_rp
    assert clearance_values(ax, "y") == [-b_rp, b_rp]
    t = ax.get_lines()[0].get_xdata()
    assert t[-1] - t[0] == pytest.approx(3 - 1 / 32)
    ax = time_history(planetary, "force_sp")
    assert r"\bar{F}_{sp1}" in ax.get_ylabel()
    assert clearance_values(ax, "y") == []
    # the contact force (the mesh force's compressive part) has the force axis in N opposite,
    # the scale k_m,sp b_c of the model: 1 on the dimensionless axis is that many newtons
    for var in ("force_sp", "contact_force_sp"):
        ax = time_history(planetary, var)
        (sec,) = [c for c in ax.child_axes if "[N]" in c.get_ylabel()]
        ax.figure.canvas.draw()
        lo, hi = ax.get_ylim()
        scale = planetary.system.model.scales.force
        assert sec.get_ylim() == pytest.approx((lo * scale, hi * scale))
    with pytest.raises(ParameterError, match="var"):
        time_history(planetary, "nonsense")
    with pytest.raises(ParameterError, match="planet"):
        time_history(planetary, planet=0)


def test_time_history_on_given_axes(planetary: gc.SimulationResult) -> None:
    import matplotlib.pyplot as plt

    _, ax = plt.subplots()
    assert time_history(planetary, ax=ax) is ax


def test_reference_system_plots(oscillator: gc.SimulationResult) -> None:
    ax = time_history(oscillator, "x")
    assert "x" in ax.get_ylabel()
    assert "forcing periods" in ax.get_xlabel()
    assert clearance_values(ax, "y") == [-1.0, 1.0]
    ax = phase_portrait(oscillator, "x")
    assert "x" in ax.get_xlabel() and "x'" in ax.get_ylabel()
    assert clearance_values(ax, "x") == [-1.0, 1.0]
    ax = poincare_map(oscillator, var="x")
    assert "x" in ax.get_xlabel()
    assert clearance_values(ax, "x") == [-1.0, 1.0]
    with pytest.raises(ParameterError, match="sun coordinates x_s, y_s"):
        sun_orbit(oscillator)


def test_phase_portrait(planetary: gc.SimulationResult) -> None:
    ax = phase_portrait(planetary)
    assert r"\bar{X}_{sp1}" in ax.get_xlabel()
    assert r"\bar{X}_{sp1}'" in ax.get_ylabel()
    b_sp = planetary.system.model.parameters.b_sp
    assert clearance_values(ax, "x") == [-b_sp, b_sp]
    orbit, sections = ax.get_lines()[:2]
    np.testing.assert_array_equal(orbit.get_xdata(), planetary.series("delta_sp_1"))
    np.testing.assert_array_equal(sections.get_ydata(), planetary.section("delta_sp_dot_1"))


def test_poincare_map(planetary: gc.SimulationResult) -> None:
    ax = poincare_map(planetary)
    assert r"\bar{X}_{sp1}" in ax.get_xlabel()
    assert r"\bar{X}_{sp1}'" in ax.get_ylabel()
    (scatter,) = ax.collections
    assert scatter.get_rasterized()
    offsets = np.asarray(scatter.get_offsets())
    np.testing.assert_array_equal(offsets[:, 0], planetary.section("delta_sp_1"))
    b_sp = planetary.system.model.parameters.b_sp
    assert clearance_values(ax, "x") == [-b_sp, b_sp]


def test_sun_orbit(planetary: gc.SimulationResult) -> None:
    ax = sun_orbit(planetary)
    assert r"\bar{x}_s" in ax.get_xlabel() and r"\bar{y}_s" in ax.get_ylabel()
    (square,) = [p for p in ax.patches if isinstance(p, Rectangle)]
    b_s = planetary.system.model.parameters.b_s
    assert square.get_xy() == (-b_s, -b_s)
    assert square.get_width() == square.get_height() == 2 * b_s
    assert ax.get_aspect() == 1.0


def test_spectrum_peak_of_a_1T_response(planetary: gc.SimulationResult) -> None:
    ax = spectrum(planetary)
    assert "mesh frequency" in ax.get_xlabel()
    assert r"\bar{X}_{sp1}" in ax.get_ylabel()
    assert ax.get_yscale() == "log"
    ratio, amp = ax.get_lines()[0].get_data()
    assert ratio[np.argmax(amp)] == pytest.approx(1.0)
    # a periodic response has lines only at the mesh harmonics
    r, a = amplitude_spectrum(planetary)
    off = np.abs(r - np.round(r)) > 1e-9
    assert a[off].max() < 1e-2 * a.max()


def test_spectrum_amplitude_of_a_linear_oscillator() -> None:
    # x'' + 2ζx' + x = F cos Ωτ: steady amplitude F|H(Ω)|, exactly in the bin ω/Ω = 1
    zeta, omega, force = 0.1, 0.5, 1.0
    r = gc.simulate(
        gc.linear_oscillator(omega, zeta=zeta, force=force),
        transient_periods=40,
        periods=10,
        samples_per_period=16,
    )
    ratio, amp = amplitude_spectrum(r, "y_0")
    exact = force / abs(1 - omega**2 + 2j * zeta * omega)
    k = int(np.argmax(amp))
    assert ratio[k] == 1.0
    assert amp[k] == pytest.approx(exact, rel=1e-6)
    _, amp_hann = amplitude_spectrum(r, "y_0", window="hann")
    assert amp_hann.max() == pytest.approx(exact, rel=1e-6)


def test_spectrum_needs_samples() -> None:
    r = gc.simulate(
        gc.preset("hindawi2021"), omega=0.5, transient_periods=5, periods=5, samples_per_period=1
    )
    with pytest.raises(ParameterError, match="samples_per_period"):
        spectrum(r)
    # the other plots still work with one sample per period
    ax = time_history(r)
    assert len(ax.get_lines()[0].get_xdata()) == 5
    assert not math.isnan(phase_portrait(r).get_lines()[0].get_xdata()[0])


def test_periodic_poincare_point_is_not_blown_up(oscillator: gc.SimulationResult) -> None:
    # a 1T orbit: the section points agree to ~1e-9; the axes must not zoom onto that noise
    ax = poincare_map(oscillator, var="x")
    lo, hi = ax.get_ylim()
    assert hi - lo > 0.05 * abs(oscillator.section("x_dot")[0])
    assert ax.yaxis.get_major_formatter().get_useOffset() is False


def test_spectrum_labels_mesh_harmonics_in_hertz(planetary: gc.SimulationResult) -> None:
    """The h-th mesh harmonic is labelled h f_m in Hz with f_m = Ω ω_n/2π, ω_n = √(k_m,sp/m_e)
    from the gear set's own numbers (MODEL.md §7)."""
    import re

    from gearchaos.plot.timeseries import HARMONIC_GID

    gs = planetary.system.model.gearset
    alpha = math.radians(gs.geometry.pressure_angle_sun)
    r_bs = 0.5 * gs.geometry.module * gs.teeth.sun * math.cos(alpha)
    r_bp = 0.5 * gs.geometry.module * gs.teeth.planet * math.cos(alpha)
    m_s, m_p = gs.inertia.sun / r_bs**2, gs.inertia.planet / r_bp**2
    omega_n = math.sqrt(gs.stiffness.sun_planet_mean * (m_s + m_p) / (m_s * m_p))
    f_m = 0.5 * omega_n / (2.0 * math.pi)  # Ω = 0.5
    ax = gc.plot.spectrum(planetary, max_harmonic=5.0)
    labels = [t.get_text() for t in ax.texts if t.get_gid() == HARMONIC_GID]
    assert len(labels) == 5
    for h, text in enumerate(labels, start=1):
        hz = float(re.search(r"= (\d+) Hz", text).group(1))
        assert hz == pytest.approx(h * f_m, abs=0.5)
