"""The explorer's app without a browser: selecting a point fills the Poincaré plot with the
stored section at once and the worker's results arrive later; a zoom writes and shows a finer
sibling store. Every wait is bounded."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import gearchaos as gc
from gearchaos.explore import Explorer, zoom_path

WAIT_S = 300.0


def _wait(explorer: Explorer, done: object) -> None:
    deadline = time.monotonic() + WAIT_S
    while time.monotonic() < deadline:
        explorer._poll()
        if done():  # type: ignore[operator]
            return
        time.sleep(0.5)
    pytest.fail("the background job did not finish in time")


def test_a_point_shows_the_stored_section_now_and_computed_views_later(gear_store: Path) -> None:
    ds = xr.open_zarr(gear_store).load()
    app = gc.explore(gear_store)
    try:
        point = app.model.nearest(float(ds.omega.values[3]))
        app.select(point)
        stored = ds.delta_sp.isel(omega=3).sel(planet=1).values
        np.testing.assert_array_equal(app.poincare_src.data["x"], stored[np.isfinite(stored)])
        assert app.sliders[0].value == 3
        _wait(app, lambda: app.computed.object.startswith("**computed at"))
        assert f"omega = {float(ds.omega.values[3]):.6g}" in app.computed.object
        assert "λ₁ = " in app.computed.object and "λ₁ = —" not in app.computed.object
        png = app.figure_png.object
        assert isinstance(png, bytes) and png[:8] == b"\x89PNG\r\n\x1a\n"
        # the slider selects too, and a point computed once comes from the cache
        app.sliders[0].value = 5
        assert app.point is not None and app.point.index == (5,)
        app.sliders[0].value = 3
        assert app.workers.collect(app._point_key(app.point)) is not None
    finally:
        app.workers.shutdown()


def test_a_zoom_writes_and_shows_a_finer_sibling_store(gear_store: Path) -> None:
    app = gc.explore(gear_store)
    try:
        app.x_range.start, app.x_range.end = 1.25, 1.45
        app.zoom_points.value = 4
        app._zoom()
        _wait(app, lambda: app._zoom_key is None)
        expected = zoom_path(str(gear_store), {"omega": (1.25, 1.45, 4)})
        assert app.store_select.value == expected, app.zoom_note.object
        np.testing.assert_allclose(app.model.axis("omega"), np.linspace(1.25, 1.45, 4))
        assert xr.open_zarr(expected).attrs["complete"] is True
    finally:
        app.workers.shutdown()


def test_a_point_of_a_reference_systems_store_is_computed_too(linear_map_store: Path) -> None:
    """The explorer asks whether the store records a model it can build, not whether it holds
    a gear set: a point of a Duffing store is recomputed and drawn (before, the explorer said
    the store held no gear set and computed nothing)."""
    ds = xr.open_zarr(linear_map_store)
    app = gc.explore(linear_map_store)
    try:
        values = {d: float(ds[d].values[1]) for d in ds["status"].dims if d != "direction"}
        point = app.model.nearest(*values.values())
        app.select(point)
        _wait(app, lambda: app.computed.object.startswith(("**computed at", "**could not")))
        assert app.computed.object.startswith("**computed at"), app.computed.object
        png = app.figure_png.object
        assert isinstance(png, bytes) and png[:8] == b"\x89PNG\r\n\x1a\n"
    finally:
        app.workers.shutdown()
