"""The store as users open it: dimensions, coordinates, provenance, and failed points."""

from __future__ import annotations

import functools
import warnings

import numba
import numpy as np
import pytest
import xarray as xr

import gearchaos as gc
from gearchaos.sweep import SweepSpec

#: sweeps record one sample per period: compare with simulations that do too
_simulate = functools.partial(gc.simulate, samples_per_period=1)

#: 2 × 3 × 4 grid (family, Ω, b̄_sp): unequal sizes, so a swapped axis cannot go unnoticed.
FAMILY = {"xi": [0.03, 0.09]}
VARY = {"omega": "0.8,1.6,2.4", "backlash.sun_planet": "2:5:4"}
FIXED = {"clearance.sun_bearing": 1.5}
#: the record of the protocol run at every point (a verdict would replace the unfinished
#: ones): these tests compare stored points with single simulations
SETTINGS = {
    "verdicts": False,
    "observe": ("delta_sp", "delta_rp", "x_s"),
    "planets": (1, 3),
    "transient_periods": 10,
    "periods": 8,
    "rtol": 1e-7,
    "atol": 1e-9,
}
LEAD = ("xi", "omega", "backlash.sun_planet")


@pytest.fixture(scope="module")
def target():
    return gc.preset("hindawi2021").evolve({"backlash.planet_ring": 4.0})


@pytest.fixture(scope="module")
def store(target, tmp_path_factory):
    path = tmp_path_factory.mktemp("store") / "map.zarr"
    gc.bifurcation(
        target, VARY, family=FAMILY, params=FIXED, store=path, progress=False, **SETTINGS
    )
    return xr.open_zarr(path)  # plain xarray, default arguments


def test_dimensions_and_coordinates(store, target):
    n = SETTINGS["periods"]
    assert store.delta_sp.dims == (*LEAD, "section", "planet")
    assert store.delta_sp.shape == (2, 3, 4, n, 2)
    assert store.delta_rp.dims == (*LEAD, "section", "planet")
    assert store.x_s.dims == (*LEAD, "section")
    np.testing.assert_array_equal(store.xi.values, FAMILY["xi"])
    np.testing.assert_array_equal(store.omega.values, [0.8, 1.6, 2.4])
    np.testing.assert_array_equal(store["backlash.sun_planet"].values, [2.0, 3.0, 4.0, 5.0])
    np.testing.assert_array_equal(store.planet.values, [1, 3])
    assert store.sizes["section"] == n
    for name in ("delta_sp_min", "delta_sp_max", "delta_rp_min", "delta_rp_max"):
        assert store[name].dims == (*LEAD, "planet_all")
        assert store.sizes["planet_all"] == target.geometry.planets
    for name in ("x_s_min", "x_s_max", "status", "steps_accepted", "steps_rejected"):
        assert store[name].dims == LEAD
    system = gc.planetary_system(target, 1.0)
    assert store.final_state.dims == (*LEAD, "state")
    assert list(store.state.values) == list(system.state_names)


def test_per_point_variables_have_integer_types(store):
    assert store.status.dtype == np.int8
    assert np.issubdtype(store.steps_accepted.dtype, np.integer)
    assert np.issubdtype(store.steps_rejected.dtype, np.integer)
    assert np.all(store.status.values == 0)
    assert np.all(store.steps_accepted.values > 0)


def test_provenance_attributes(store, target):
    a = store.attrs
    assert gc.GearSet.from_toml_string(a["gearset_toml"]) == target
    spec = SweepSpec.from_toml(a["sweep_toml"])
    assert spec == SweepSpec.build(VARY, family=FAMILY, params=FIXED, **SETTINGS)
    assert a["rtol"] == SETTINGS["rtol"] and a["atol"] == SETTINGS["atol"]
    assert a["transient_periods"] == SETTINGS["transient_periods"]
    assert a["periods"] == SETTINGS["periods"]
    assert a["initial_conditions"] == "fresh" and a["direction"] == "up"
    assert a["version"] == gc.__version__
    assert a["numba_version"] == numba.__version__
    assert a["numpy_version"] == np.__version__
    assert a["complete"] is True


@pytest.mark.parametrize("index", [(0, 0, 0), (1, 2, 3), (0, 1, 3), (1, 2, 0)])
def test_points_carry_their_own_parameters(store, target, index):
    """Each point equals `simulate` of the gear set with that point's family, axes and --set."""
    pt = store.isel(dict(zip(LEAD, index, strict=True))).load()
    gs = target.evolve(
        {"xi": float(pt.xi), "backlash.sun_planet": float(pt["backlash.sun_planet"]), **FIXED}
    )
    res = _simulate(
        gs,
        omega=float(pt.omega),
        transient_periods=SETTINGS["transient_periods"],
        periods=SETTINGS["periods"],
        rtol=SETTINGS["rtol"],
        atol=SETTINGS["atol"],
    ).to_dataset()
    for name in ("delta_sp", "delta_rp"):
        np.testing.assert_array_equal(pt[name].values, res[name].sel(planet=[1, 3]).values)
    np.testing.assert_array_equal(pt.x_s.values, res.x_s.values)
    np.testing.assert_array_equal(pt.delta_sp_max.values, res.delta_sp_max.values)
    assert int(pt.steps_accepted) == res.attrs["steps_accepted"]


def test_reference_system_store_uses_state_names(tmp_path):
    system = gc.backlash_oscillator(1.0, zeta=0.1, b=1.0, f_mean=0.1, f_alt=0.3, omega_power=0)
    gc.bifurcation(
        system,
        {"omega": "0.5:1.5:5"},
        family={"zeta": [0.05, 0.1]},
        observe=("x", "x_dot"),
        transient_periods=10,
        periods=8,
        store=tmp_path / "bo.zarr",
        progress=False,
        verdicts=False,  # the protocol's record, compared with a single simulation below
    )
    ds = xr.open_zarr(tmp_path / "bo.zarr")
    assert ds.x.dims == ("zeta", "omega", "section")
    assert ds.x_min.dims == ds.x_max.dims == ("zeta", "omega")
    assert list(ds.state.values) == ["x", "x_dot"]
    assert np.all(ds.x_min.values <= ds.x.min("section").values)
    assert np.all(ds.x_max.values >= ds.x.max("section").values)
    pt = ds.sel(zeta=0.05, omega=1.25)
    res = _simulate(
        gc.backlash_oscillator(1.25, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.3, omega_power=0),
        transient_periods=10,
        periods=8,
    )
    np.testing.assert_array_equal(pt.x.values, res.states[:, 0])


# --------------------------------------------------------------------------- failed points

#: Duffing oscillator with a softening cubic: x'' + 0.1x' + x − x³ = γ cos t. A small forcing
#: keeps the orbit in the potential well |x| < 1; a large one throws it over the barrier and
#: x runs to infinity in finite time, so that point cannot be integrated.
WELL = {"delta": 0.1, "alpha": 1.0, "beta": -1.0}
GAMMAS = [0.05, 0.3, 0.1, 1.0, 0.08]


def escape_sweep(tmp_path, **kw):
    """The protocol's record at every point (no verdict replaces the unfinished ones): the
    tests compare points with single runs."""
    kw.setdefault("verdicts", False)
    path = tmp_path / "escape.zarr"
    gc.bifurcation(
        gc.duffing(1.0, gamma=0.05, **WELL),
        {"gamma": GAMMAS},
        observe=("x", "x_dot"),
        transient_periods=10,
        periods=8,
        store=path,
        progress=False,
        **kw,
    )
    return xr.open_zarr(path).load()


def single(gamma: float) -> gc.SimulationResult:
    """One zero-start run; a failed one warns (RuntimeWarning) instead of raising."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        system = gc.duffing(1.0, gamma=gamma, **WELL)
        return _simulate(system, transient_periods=10, periods=8, check=False)


def test_failed_points_are_stored_with_their_status_and_the_sweep_goes_on(tmp_path):
    ds = escape_sweep(tmp_path)
    assert ds.attrs["complete"] is True
    for k, gamma in enumerate(GAMMAS):
        res = single(gamma)
        pt = ds.isel(gamma=k)
        assert int(pt.status) == int(res.status), gamma
        np.testing.assert_array_equal(pt.x.values, res.states[:, 0])  # NaN where unreached
        assert int(pt.steps_accepted) == res.steps_accepted
    failed = ds.status.values != 0
    assert list(failed) == [False, True, False, True, False]
    assert set(ds.status.values[failed]) <= {int(s) for s in gc.Status if not s.ok}
    assert np.all(np.isnan(ds.x.values[failed]))
    assert np.all(np.isfinite(ds.x.values[~failed]))


def test_continuation_restarts_from_zero_after_a_failed_point(tmp_path):
    ds = escape_sweep(tmp_path, initial_conditions="continuation")
    assert list(ds.status.values != 0) == [False, True, False, True, False]
    first = single(GAMMAS[0])
    np.testing.assert_array_equal(ds.x.values[0], first.states[:, 0])
    after_failure = single(GAMMAS[2])  # zero start, not the diverged state
    np.testing.assert_array_equal(ds.x.values[2], after_failure.states[:, 0])
    np.testing.assert_array_equal(ds.x.values[4], single(GAMMAS[4]).states[:, 0])
