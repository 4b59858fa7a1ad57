"""Impact maps and amplitude–frequency curves (issue 26, item 5).

* The impact map's cells are the stored contact codes (read back from the image array), their
  colours the palette's, and the codes are what the contact regime means: from the stored
  minimum deflection and the swept clearance b̄_sp, no impact where δ_min > b̄, single-sided
  where −b̄ ≤ δ_min ≤ b̄, double-sided below.
* The amplitude curve of a continued branch is max − min of the deflection of the orbit
  simulated independently (gc.simulate from the orbit state) at a few points, and the stable
  branch passes through the brute-force up sweep's periodic points.
* With ``quantity="force_peak"`` the branch's lines are its stored ``force_peak_mesh`` (solid
  where stable, dashed where not) and the sweep points the store's; a branch file without the
  variable (written before branches stored it) still draws its amplitude and is refused by the
  variable's name for the force.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from matplotlib.colors import to_rgba

import gearchaos as gc
from gearchaos.plot.amplitude import amplitude_figure
from gearchaos.plot.branch import branch_figure
from gearchaos.plot.impact import IMPACT_COLOURS, IMPACT_GID, impact_figure, impact_map

TIGHT = {"rtol": 1e-10, "atol": 1e-12}


@pytest.fixture(scope="module")
def impact_store(tmp_path_factory: pytest.TempPathFactory):
    path = tmp_path_factory.mktemp("impact") / "map.zarr"
    return gc.bifurcation(
        gc.preset("sheng2016-v1"), ["omega=0.6:2.4:7", "backlash.sun_planet=0.5:4:4"],
        params={"xi": 0.05}, transient_periods=40, periods=16, progress=False, store=path,
    )  # fmt: skip


@pytest.mark.parametrize(("mesh", "planet"), [("sun_planet", 1), ("rp", 2)])
def test_impact_map_cells_are_the_stored_contact_codes(impact_store, mesh, planet) -> None:
    ax = impact_map(impact_store, mesh=mesh, planet=planet)
    (quad,) = [c for c in ax.collections if c.get_gid() == IMPACT_GID]
    key = "sp" if mesh == "sun_planet" else "rp"
    stored = impact_store[f"contact_{key}"].sel(planet_all=planet)
    want = stored.transpose("backlash.sun_planet", "omega").values
    got = np.asarray(quad.get_array()).reshape(want.shape)
    np.testing.assert_array_equal(got, want)
    rgba = quad.to_rgba(quad.get_array()).reshape(*want.shape, 4)
    for code in np.unique(want):
        assert np.allclose(rgba[want == code], to_rgba(IMPACT_COLOURS[int(code)]))


def test_impact_codes_mean_the_contact_regime_of_the_swept_clearance(impact_store) -> None:
    """Independent of the classifier: δ_sp,min against the swept b̄_sp of each point."""
    dmin = impact_store.delta_sp_min.sel(planet_all=1)
    b = impact_store["backlash.sun_planet"]
    expected = xr_where(dmin > b, 0, xr_where(dmin >= -b, 1, 2))
    np.testing.assert_array_equal(
        impact_store.contact_sp.sel(planet_all=1).transpose(*expected.dims).values,
        expected.values,
    )
    assert len(np.unique(expected.values)) >= 2  # the map shows a boundary


def xr_where(cond, a, b):
    import xarray as xr

    return xr.where(cond, a, b)


def test_impact_figure_has_physical_axes_and_refuses_unknown_meshes(impact_store) -> None:
    fig = impact_figure(impact_store, mesh="sp")
    ax = fig.axes[0]
    labels = [c.get_xlabel() for c in ax.child_axes] + [c.get_ylabel() for c in ax.child_axes]
    assert any("rpm" in t for t in labels) and any("µm" in t for t in labels)
    from figure_checks import assert_legends_clear_of_titles

    assert_legends_clear_of_titles(fig)  # under the panels, as the regime maps'
    with pytest.raises(gc.ParameterError, match="mesh must be one of"):
        impact_figure(impact_store, mesh="sun_ring")
    with pytest.raises(gc.ParameterError, match="planet must be one of"):
        impact_map(impact_store, planet=9)


def _physical_labels(fig) -> list[str]:
    """The labels of the secondary (physical) axes of a figure's first panel."""
    ax = fig.axes[0]
    return sorted(t for c in ax.child_axes for t in (c.get_xlabel(), c.get_ylabel()) if t)


def test_regime_map_has_the_physical_axes_of_the_impact_map(impact_store) -> None:
    """The 2-D regime map (``gearchaos plot MAP.zarr``) has the physical axes of the impact
    map and the stability chart over the same store (one helper): the sun speed in rpm
    opposite Ω, µm opposite b̄_sp; the distinct-point map too."""
    from gearchaos.plot.maps import sweep_figure

    fig = sweep_figure(impact_store)
    regime = _physical_labels(fig)
    assert regime == _physical_labels(impact_figure(impact_store))
    assert regime == ["$b_{sp}$ [µm]", "sun speed [rpm]"]
    assert _physical_labels(sweep_figure(impact_store, regimes=False)) == regime
    fig.draw_without_rendering()  # secondary axes take their limits when drawn
    ax = fig.axes[0]
    (top,) = [c for c in ax.child_axes if c.get_xlabel()]
    (right,) = [c for c in ax.child_axes if c.get_ylabel()]
    gs = gc.preset("sheng2016-v1")
    np.testing.assert_allclose(top.get_xlim(), np.multiply(ax.get_xlim(), gs.sun_speed_rpm(1.0)))
    um = gs.clearance.characteristic_length * 1e6
    np.testing.assert_allclose(right.get_ylim(), np.multiply(ax.get_ylim(), um))


@pytest.fixture(scope="module")
def oscillator_response():
    system = gc.backlash_oscillator(1.0, zeta=0.05, f_alt=0.1, f_mean=0.1)
    res = gc.response(system, "omega=0.8:1.2:9", progress=False)
    branch = gc.continuation(system, "omega=0.75:1.25", **TIGHT)
    return system, res, branch


def _stable_line(fig):
    ax = fig.axes[0]
    (line,) = [ln for ln in ax.lines if ln.get_gid() == "amplitude:branch:stable"]
    return np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)


def test_branch_amplitude_is_the_simulated_orbits_peak_to_peak(oscillator_response) -> None:
    system, res, branch = oscillator_response
    fig = amplitude_figure(res, [branch], var="x")
    xs, ys = _stable_line(fig)
    stable = np.flatnonzero(branch.stable.values == 1)
    for k in (stable[0], stable[stable.size // 2], stable[-1]):
        lam = float(branch.omega[k])
        sim = gc.simulate(
            system.at(lam), y0=branch.orbit_state.values[k], transient_periods=0, periods=1,
            samples_per_period=4096, **TIGHT,
        )  # fmt: skip
        x = sim.series("x") if callable(getattr(sim, "series", None)) else sim.states[:, 0]
        amp = float(np.max(x) - np.min(x))
        assert xs[k] == lam
        assert ys[k] == pytest.approx(amp, rel=1e-5)


def test_stable_branch_passes_through_the_up_sweeps_periodic_points(oscillator_response) -> None:
    _, res, branch = oscillator_response
    fig = amplitude_figure(res, [branch])
    xs, ys = _stable_line(fig)
    ok = ~np.isnan(ys)
    order = np.argsort(xs[ok])
    up = res.sel(direction="up")
    amp = (up.x_max - up.x_min).values
    assert set(up.motion.values.astype(str)) == {"1T"}
    on_branch = np.interp(up.omega.values, xs[ok][order], ys[ok][order])
    np.testing.assert_allclose(amp, on_branch, rtol=2e-3)
    assert [ln for ln in fig.axes[0].lines if ln.get_gid() == "amplitude:sweep:up"]


def _branch_lines(fig):
    return {
        ln.get_gid().rsplit(":", 1)[1]: ln
        for ln in fig.axes[0].lines
        if str(ln.get_gid()).startswith("amplitude:branch:")
    }


def test_force_figure_draws_the_stored_peak_force_dashed_where_unstable(
    oscillator_response,
) -> None:
    _, res, branch = oscillator_response
    fig = amplitude_figure(res, [branch], quantity="force_peak")
    lines = _branch_lines(fig)
    assert set(lines) == {"stable", "unstable"}
    stored = branch.force_peak_mesh.values
    stable = branch.stable.values == 1
    for which, mask in (("stable", stable), ("unstable", ~stable)):
        ln = lines[which]
        np.testing.assert_array_equal(np.asarray(ln.get_xdata(), float), branch.omega.values)
        y = np.asarray(ln.get_ydata(), float)
        shown = ~np.isnan(y)
        assert np.all(shown[mask]) and shown.sum() <= mask.sum() + 2  # + the joins
        np.testing.assert_array_equal(y[shown], stored[shown])  # the stored values, unchanged
    assert lines["stable"].get_linestyle() == "-"
    assert lines["unstable"].get_linestyle() == "--"
    (up,) = [ln for ln in fig.axes[0].lines if ln.get_gid() == "amplitude:sweep:up"]
    np.testing.assert_array_equal(
        np.asarray(up.get_ydata(), float), res.force_peak_mesh.sel(direction="up").values
    )
    assert "contact force" in fig.axes[0].get_ylabel()
    assert any(t.get_text() == "PD" for t in fig.axes[0].texts)  # the event is marked


def test_old_branch_without_peak_force_draws_amplitude_and_names_the_variable(
    oscillator_response, tmp_path
) -> None:
    _, res, branch = oscillator_response
    path = tmp_path / "old.nc"
    gc.save_branch(branch.drop_vars("force_peak_mesh"), path)
    old = gc.open_branch(path)
    assert _branch_lines(amplitude_figure(res, [old], var="x"))
    with pytest.raises(gc.ParameterError, match=r"old\.nc has no variable force_peak_mesh"):
        amplitude_figure(res, [old], quantity="force_peak")
    with pytest.raises(gc.ParameterError, match="quantity must be one of amplitude, force_peak"):
        amplitude_figure(res, [branch], quantity="force")
    with pytest.raises(gc.ParameterError, match=r"deflection of a mesh .*\(x\): got 'y'"):
        amplitude_figure(res, [branch], quantity="force_peak", var="y")


def test_event_names_sit_beside_the_curve_not_on_it(oscillator_response) -> None:
    """An event's name goes to the side of its marker that the curves leave free: written
    above it, "graze" sat on the steep branch (docs/howto/force.png)."""
    from figure_checks import labels_on_curves, steep_branch

    _, res, branch = oscillator_response
    steep = steep_branch(branch, "x", (0.85, 1.15), 0.45, 0.7)
    for quantity in ("amplitude", "force_peak"):
        if quantity == "force_peak":
            steep["force_peak_mesh"] = steep["x_max"]
        fig = amplitude_figure(res, [steep], quantity=quantity)
        assert [t.get_text() for t in fig.axes[0].texts if t.get_text() == "graze"] == ["graze"]
        assert labels_on_curves(fig, "amplitude:") == []


def test_amplitude_figure_is_titled_by_the_shared_helper(oscillator_response) -> None:
    """The title names the model (or gear set) and the figure as the other sweep figures do
    (bifurcation.suptitle), not the store's "gearchaos … of …" record."""
    from gearchaos.model.record import target_record

    _, res, branch = oscillator_response
    title = amplitude_figure(res, [branch]).get_suptitle().splitlines()
    assert title[0] == "backlash_oscillator: amplitude–frequency curves"
    # a reference system's parameters, as the branch figure writes them (one helper)
    given = r"at $\zeta$ = 0.05, $\varepsilon$ = 0, $b$ = 1, $F_m$ = 0.1, $F_a$ = 0.1"
    assert title[1] == given
    assert title[2] == "100 transient + 50 recorded periods, continuation initial conditions"
    assert title[3] == "continued branches (rtol 1e−10) beside the brute-force sweeps"
    assert branch_figure([branch]).get_suptitle().splitlines()[1] == given
    force = amplitude_figure(res, [branch], quantity="force_peak").get_suptitle()
    assert force.startswith(f"backlash_oscillator: peak contact force curves\n{given}\n")
    geared = res.copy()  # the record of a gear set: its model reference and its TOML
    geared.attrs.update(target_record(gc.preset("sheng2016-v1")))
    title = amplitude_figure(geared, [branch]).get_suptitle().splitlines()
    assert title[0] == "sheng2016-v1: amplitude–frequency curves"
    assert title[1].startswith(r"at $\bar b_{sp}$ = ")


def test_no_physical_axis_where_a_swept_parameter_changes_its_scale(
    tmp_path: Path, impact_store
) -> None:
    """The sun speed in rpm per unit Ω is ω_n-dependent: over (Ω, mesh stiffness) one rpm
    axis opposite Ω would be right on one row only, so the map draws none (and no force in
    N, k_m,sp b_c); b_c does not depend on the stiffness, so lengths keep their µm. Over
    (Ω, b̄_sp) nothing changes the scales and the rpm axis stays (the impact store)."""
    from gearchaos.plot.maps import sweep_figure
    from gearchaos.plot.units import PhysicalScales
    from gearchaos.sweep.result import SweepResult

    gs = gc.preset("sheng2016-v1")
    k = gs.stiffness.sun_planet_mean
    res = gc.bifurcation(
        gs, ["omega=1:2:3", f"stiffness.sun_planet_mean={k}:{2 * k}:2"],
        transient_periods=2, periods=2, progress=False, store=tmp_path / "k.zarr",
    )  # fmt: skip
    scales = PhysicalScales.of_sweep(SweepResult.of(res))
    assert scales.rpm_per_omega is None and scales.omega_n is None and scales.force_n is None
    assert scales.length_m == pytest.approx(gs.clearance.characteristic_length)
    assert "sun speed [rpm]" not in _physical_labels(sweep_figure(res))
    kept = PhysicalScales.of_sweep(SweepResult.of(impact_store))
    assert kept.rpm_per_omega == pytest.approx(gs.sun_speed_rpm(1.0))
    # the same rule for a boundary curve drawn alone (its two parameters' ranges)
    assert PhysicalScales.over(gs, {"stiffness.sun_planet_mean": [k, 2 * k]}).omega_n is None
    assert PhysicalScales.over(gs, {"xi": [0.01, 0.05], "omega": [1, 3]}) == PhysicalScales.over(
        gs, {}
    )
