"""Sweeps over the sun speed: ``sun_rpm`` and ``mesh_hz`` axes and fixed values run as Ω.

The stored Ω are compared with Ω computed here from the gear set's numbers (MODEL.md §1, §2,
§7: ω_n = √(k_m,sp/m_e), ω = ω_s z_s z_r/(z_s + z_r), Ω = ω/ω_n), not with the package's own
conversion.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import zarr

import gearchaos as gc
from gearchaos.gearset import GearSet

TINY = {"transient_periods": 2, "periods": 2, "verdicts": False, "progress": False}


def _omega_n(gs: GearSet) -> float:
    m, a = gs.geometry.module, math.radians(gs.geometry.pressure_angle_sun)
    r_bs = m * gs.teeth.sun / 2 * math.cos(a)
    r_bp = m * gs.teeth.planet / 2 * math.cos(a)
    ms, mp = gs.inertia.sun / r_bs**2, gs.inertia.planet / r_bp**2
    return math.sqrt(gs.stiffness.sun_planet_mean / (ms * mp / (ms + mp)))


def _omega_at_rpm(gs: GearSet, rpm: np.ndarray) -> np.ndarray:
    zs, zr = gs.teeth.sun, gs.teeth.ring
    return np.asarray(rpm) * 2 * math.pi / 60 * zs * zr / (zs + zr) / _omega_n(gs)


def test_a_sweep_over_sun_rpm_stores_the_converted_omega_and_the_speeds(
    sheng: GearSet, tmp_path: Path
) -> None:
    rpm = np.linspace(1000.0, 20000.0, 5)
    store = tmp_path / "rpm.zarr"
    ds = gc.bifurcation(sheng, "sun_rpm=1000:20000:5", store=str(store), **TINY)
    assert ds["omega"].dims == ("omega",)  # Ω is the coordinate, the speeds ride along it
    np.testing.assert_allclose(ds["omega"].values, _omega_at_rpm(sheng, rpm), rtol=1e-12)
    np.testing.assert_allclose(ds["sun_rpm"].values, rpm, rtol=1e-12)
    assert ds["sun_rpm"].dims == ds["mesh_hz"].dims == ("omega",)
    np.testing.assert_allclose(
        ds["mesh_hz"].values, ds["omega"].values * _omega_n(sheng) / (2 * math.pi), rtol=1e-12
    )
    # the same command resumes the store (the stored specification is the converted one)
    again = gc.bifurcation(sheng, "sun_rpm=1000:20000:5", store=str(store), **TINY)
    np.testing.assert_array_equal(again["omega"].values, ds["omega"].values)
    # the export's own rpm column (through the stored gear set) agrees
    table = tmp_path / "rpm.csv"
    gc.export(str(store), table)
    np.testing.assert_allclose(pd.read_csv(table)["sun_rpm"], rpm, rtol=1e-12)


def test_a_fixed_sun_rpm_is_stored_as_omega_with_the_speeds_beside_it(
    sheng: GearSet, tmp_path: Path
) -> None:
    store = tmp_path / "xi.zarr"
    gc.bifurcation(sheng, "xi=0.03,0.05", sun_rpm=7500.0, store=str(store), **TINY)
    attrs = dict(zarr.open_group(str(store), mode="r").attrs)
    expected = float(_omega_at_rpm(sheng, np.array(7500.0)))
    assert attrs["omega_fixed"] == pytest.approx(expected, rel=1e-12)
    assert attrs["sun_rpm_fixed"] == pytest.approx(7500.0, rel=1e-12)
    assert 'omega" = ' in attrs["sweep_toml"] and "sun_rpm" not in attrs["sweep_toml"]


def test_a_sweep_over_mesh_hz_and_a_family_over_sun_rpm(sheng: GearSet) -> None:
    ds = gc.bifurcation(sheng, "mesh_hz=1000,2000", **TINY)
    np.testing.assert_allclose(
        ds["omega"].values, 2 * math.pi * np.array([1000.0, 2000.0]) / _omega_n(sheng), 1e-12
    )
    ds = gc.bifurcation(sheng, "xi=0.05", family={"sun_rpm": [3000.0, 6000.0]}, **TINY)
    np.testing.assert_allclose(
        ds["omega"].values, _omega_at_rpm(sheng, np.array([3000.0, 6000.0])), rtol=1e-12
    )


def test_a_sweep_given_in_omega_stores_omega_alone(sheng: GearSet) -> None:
    ds = gc.bifurcation(sheng, "omega=1:2:2", **TINY)
    assert "sun_rpm" not in ds.coords and "sun_rpm_fixed" not in ds.attrs


def test_sweep_refusals_name_the_speed(sheng: GearSet) -> None:
    # one sun speed is another Ω at every mesh stiffness: refused, not silently mixed
    with pytest.raises(gc.ParameterError, match="sun_rpm cannot be given while stiffness"):
        gc.bifurcation(sheng, ["sun_rpm=1000:2000:2", "stiffness.sun_planet_mean=5e8,6e8"], **TINY)
    with pytest.raises(gc.ParameterError, match="each set Ω"):
        gc.bifurcation(sheng, "sun_rpm=1000:2000:2", omega=1.5, **TINY)
    with pytest.raises(gc.ParameterError, match="not built from a gear set"):
        gc.bifurcation(gc.backlash_oscillator(1.0), "sun_rpm=1000:2000:2", **TINY)
    with pytest.raises(gc.ParameterError, match="plausible range"):
        gc.bifurcation(sheng, "omega=1,7000", **TINY)
