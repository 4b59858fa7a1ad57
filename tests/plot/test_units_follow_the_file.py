"""Figures speak the gear set's units: a clearance the gear-set file gives in metres is drawn
and titled in µm beside b̄, and a fixed Ω is titled with the sun speed. Expected numbers come
from the gear set's own values (b = b̄ b_c; MODEL.md §2, §7 for the speed), not from the
package's conversions."""

from __future__ import annotations

import math

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.gearset import GearSet
from gearchaos.plot import bifurcation_figure, sweep_figure
from gearchaos.plot._common import given_values

TINY = {"transient_periods": 2, "periods": 2, "verdicts": False, "progress": False}


@pytest.fixture(scope="module")
def metric() -> GearSet:
    """sheng2016 with its clearances in metres (the issue's user: backlash.units = "m")."""
    gs = gc.preset("sheng2016-v1")
    b_c = gs.clearance.characteristic_length
    return gs.evolve(
        {
            "name": "metric",
            "backlash.units": "m",
            "backlash.sun_planet": 100e-6,
            "backlash.planet_ring": 72e-6,
            "clearance.units": "m",
            "clearance.sun_bearing": 2.0 * b_c,
        }
    )


def _rpm(gs: GearSet, omega: float) -> float:
    """Sun speed at Ω (MODEL.md §2, §7)."""
    m, a = gs.geometry.module, math.radians(gs.geometry.pressure_angle_sun)
    r_bs, r_bp = m * gs.teeth.sun / 2 * math.cos(a), m * gs.teeth.planet / 2 * math.cos(a)
    ms, mp = gs.inertia.sun / r_bs**2, gs.inertia.planet / r_bp**2
    omega_n = math.sqrt(gs.stiffness.sun_planet_mean / (ms * mp / (ms + mp)))
    zs, zr = gs.teeth.sun, gs.teeth.ring
    return omega * omega_n * (zs + zr) / (zs * zr) * 60 / (2 * math.pi)


def test_titles_write_clearances_in_um_beside_b_bar_and_the_sun_speed(metric: GearSet) -> None:
    b_c = metric.clearance.characteristic_length
    got = given_values({}, fixed={"omega": 1.5}, gearset=metric)
    assert got[0] == rf"$\Omega$ = 1.5 ({_rpm(metric, 1.5):.5g} rpm)"
    assert got[1] == rf"$\bar b_{{sp}}$ = {100e-6 / b_c:.6g} (100 µm)"
    assert got[2] == rf"$\bar b_{{rp}}$ = {72e-6 / b_c:.6g} (72 µm)"
    # a fixed clearance in metres is the gear set's: written once, as b̄ and µm, never as b̄ = 1e-4
    changed = metric.evolve({"backlash.sun_planet": 50e-6})
    got = given_values({}, fixed={"backlash.sun_planet": 50e-6}, gearset=changed)
    assert rf"$\bar b_{{sp}}$ = {50e-6 / b_c:.6g} (50 µm)" in got
    assert not any("5e" in g for g in got)
    # a gear set in units of b_c: b̄ alone, as before
    sheng = gc.preset("sheng2016-v1")
    assert given_values({}, fixed={}, gearset=sheng)[0] == r"$\bar b_{sp}$ = 3"


def test_a_swept_clearance_in_metres_is_drawn_in_um_with_b_bar_opposite(metric: GearSet) -> None:
    b_c = metric.clearance.characteristic_length
    ds = gc.bifurcation(metric, "backlash.sun_planet=50e-6:150e-6:3", sun_rpm=7500.0, **TINY)
    fig = bifurcation_figure(ds)
    fig.canvas.draw()
    labels = [ax.get_xlabel() for ax in fig.axes if ax.get_xlabel()]
    assert r"$b_{sp}$ [µm]" in labels and r"$\bar b_{sp}$" not in labels
    band = next(ax for ax in fig.axes if ax.get_xlabel() == r"$b_{sp}$ [µm]")
    ticks = {t.get_position()[0]: t.get_text() for t in band.get_xticklabels() if t.get_text()}
    for value, text in ticks.items():  # tick labels are the metres times 10⁶
        assert float(text.replace("\N{MINUS SIGN}", "-")) == pytest.approx(value * 1e6, abs=1e-6)
    top = [c for ax in fig.axes for c in ax.child_axes if c.get_xlabel() == r"$\bar b_{sp}$"]
    assert len(top) == 1
    forward = top[0]._functions[0]  # the opposite axis: b̄ = b/b_c
    assert float(forward(np.array(100e-6))) == pytest.approx(100e-6 / b_c, rel=1e-12)
    title = fig._suptitle.get_text()
    assert f"({_rpm(metric, float(ds.attrs['omega_fixed'])):.5g} rpm)" in title
    assert f"({72:.4g} µm)" in title and "0.0001" not in title


def test_a_map_over_speed_and_a_clearance_in_metres(metric: GearSet) -> None:
    ds = gc.bifurcation(metric, ["sun_rpm=5000,9000", "backlash.sun_planet=50e-6,150e-6"], **TINY)
    fig = sweep_figure(ds)
    fig.canvas.draw()
    (ax,) = [a for a in fig.axes if a.get_ylabel() == r"$b_{sp}$ [µm]"]
    right = [c for c in ax.child_axes if c.get_ylabel() == r"$\bar b_{sp}$"]
    top = [c for c in ax.child_axes if "rpm" in c.get_xlabel()]
    assert len(right) == 1 and len(top) == 1
    rpm = top[0]._functions[0](np.array(ds["omega"].values))
    np.testing.assert_allclose(rpm, [5000.0, 9000.0], rtol=1e-9)
