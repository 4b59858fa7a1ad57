"""The explorer's model without a browser: a click selects the nearest swept value, and what
it shows for a point is what the store holds (read here independently with xarray), and for a
linear oscillator what theory says."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import gearchaos as gc
from gearchaos.errors import ParameterError, StoreError
from gearchaos.explore import ExploreModel, zoom_path
from gearchaos.sweep.result import open_result


def _store(path: Path) -> xr.Dataset:
    return xr.open_zarr(path).load()


def test_a_click_selects_the_nearest_swept_value(gear_store: Path) -> None:
    ds = _store(gear_store)
    omegas = np.asarray(ds.omega.values)
    model = ExploreModel(open_result(gear_store))
    rng = np.random.default_rng(7)
    for x in [*rng.uniform(omegas[0] - 0.3, omegas[-1] + 0.3, 40), *omegas]:
        point = model.nearest(float(x))
        expected = int(np.argmin(np.abs(omegas - x)))
        assert point.index == (expected,)
        assert point.values == {"omega": float(omegas[expected])}
    with pytest.raises(ParameterError, match="finite"):
        model.nearest(math.nan)


def test_a_point_shows_its_stored_section_label_and_count(gear_store: Path) -> None:
    ds = _store(gear_store)
    model = ExploreModel(open_result(gear_store))
    for i, omega in enumerate(ds.omega.values):
        point = model.nearest(float(omega))
        x, y, xlabel, ylabel = model.section(point)
        stored_x = ds.delta_sp.isel(omega=i).sel(planet=1).values
        stored_y = ds.delta_sp_dot.isel(omega=i).sel(planet=1).values
        ok = np.isfinite(stored_x) & np.isfinite(stored_y)
        assert x.size == int(ok.sum()) == ds.sizes["section"]  # short protocol: every point ran
        np.testing.assert_array_equal(x, stored_x[ok])
        np.testing.assert_array_equal(y, stored_y[ok])
        assert xlabel.startswith("X̄ₛₚ₁") and ylabel.startswith("X̄′ₛₚ₁")
        assert model.label(point) == str(ds.motion.values[i])
        assert model.status(point) == "ok"


def test_the_diagram_holds_every_stored_section_value(gear_store: Path) -> None:
    ds = _store(gear_store)
    model = ExploreModel(open_result(gear_store))
    data = model.diagram()
    stored = ds.delta_sp.sel(planet=1).values
    assert data["y"].size == int(np.isfinite(stored).sum())
    np.testing.assert_array_equal(np.sort(data["y"]), np.sort(stored[np.isfinite(stored)]))
    np.testing.assert_array_equal(np.unique(data["x"]), np.asarray(ds.omega.values))
    band = model.band()
    assert band["label"] == [str(m) for m in ds.motion.values]
    # the band's cells tile the swept range without gaps
    left = np.asarray(band["x"]) - np.asarray(band["width"]) / 2
    right = np.asarray(band["x"]) + np.asarray(band["width"]) / 2
    np.testing.assert_allclose(left[1:], right[:-1])


def test_a_linear_oscillator_map_shows_1T_points_on_the_analytic_orbit(
    linear_map_store: Path, linear_parameters: dict[str, float]
) -> None:
    """x'' + δx' + αx = γ cos Ωτ has the one periodic response x = Re[γ e^{iΩτ}/(α − Ω² + iδΩ)]:
    every cell of the map is 1T, and the section at τ_k = 2πk/Ω is that response at phase 0."""
    model = ExploreModel(open_result(linear_map_store), var="x")
    assert model.is_map
    band = model.band()
    assert len(band["label"]) == 15
    assert set(band["label"]) == {"1T"}
    point = model.nearest(1.12, 0.27)  # nearest of Ω ∈ {0.6, 0.85, 1.1, 1.35, 1.6}, γ ∈ {.., .3}
    assert point.values == pytest.approx({"omega": 1.1, "gamma": 0.3})
    omega, gamma = point.values["omega"], point.values["gamma"]
    z = gamma / (linear_parameters["alpha"] - omega**2 + 1j * linear_parameters["delta"] * omega)
    x, y, _, _ = model.section(point)
    assert x.size == 8
    np.testing.assert_allclose(x, z.real, rtol=0, atol=1e-5)
    np.testing.assert_allclose(y, (1j * omega * z).real, rtol=0, atol=1e-5)
    assert model.label(point) == "1T"


def test_bad_choices_are_refused_by_name(gear_store: Path, tmp_path: Path) -> None:
    res = open_result(gear_store)
    with pytest.raises(ParameterError, match="var must be a section variable"):
        ExploreModel(res, var="nope")
    with pytest.raises(ParameterError, match="planet must be one of"):
        ExploreModel(res, planet=2)
    with pytest.raises(ParameterError, match="store not found"):
        gc.explore(tmp_path / "missing.zarr")
    (tmp_path / "empty.zarr").mkdir()
    with pytest.raises(StoreError, match="not a readable sweep store"):
        gc.explore(tmp_path / "empty.zarr")


def test_a_zoom_is_a_sibling_store_named_by_its_range(tmp_path: Path) -> None:
    path = zoom_path(str(tmp_path / "run.zarr"), {"omega": (1.25, 1.5, 40)})
    assert Path(path).parent == tmp_path / "run.zoom"
    assert Path(path).name == "omega_1.25_1.5_40.zarr"


def test_a_finer_sweep_covers_the_range_with_the_stores_settings(gear_store: Path) -> None:
    from gearchaos.explore import run_zoom

    path = run_zoom(str(gear_store), {"omega": (1.3, 1.4, 3)})
    assert path == zoom_path(str(gear_store), {"omega": (1.3, 1.4, 3)})
    finer, coarse = _store(Path(path)), _store(gear_store)
    np.testing.assert_allclose(finer.omega.values, [1.3, 1.35, 1.4])
    assert finer.sizes["section"] == coarse.sizes["section"]
    for key in ("gearset_toml", "transient_periods", "periods", "rtol", "atol"):
        assert finer.attrs[key] == coarse.attrs[key]
    assert finer.attrs["complete"] is True
    with pytest.raises(ParameterError, match="zoom range of omega"):
        run_zoom(str(gear_store), {"omega": (1.4, 1.3, 3)})


def test_the_default_variable_is_the_stores_first_observed_one(linear_map_store: Path) -> None:
    assert ExploreModel(open_result(linear_map_store)).var == "x"


def test_poincare_limits_hold_the_points_and_stay_readable() -> None:
    from gearchaos.explore.app import readable_range

    one = 1.3956 + np.array([0.0, 2e-10, -1e-10])  # a 1T section: equal to the ninth digit
    lo, hi = readable_range(one)
    assert lo < one.min() and hi > one.max()
    assert hi - lo == pytest.approx(1e-3 * 1.3956)
    cloud = np.array([-0.4, 0.1, 0.3])
    lo, hi = readable_range(cloud)
    assert (lo, hi) == pytest.approx((-0.4 - 0.035, 0.3 + 0.035))
