"""Continuation of periodic orbits and its events, checked against closed forms and against
brute-force sweeps (:func:`gearchaos.bifurcation`) of the same systems.

* Backlash oscillator (MODEL.md §10.5): while the teeth stay in contact the orbit is the linear
  oscillator's, x = b + F_m + F_a Ω²|H| cos(Ωτ − arg(1 − Ω² + 2iζΩ)); it grazes (min x = b)
  where F_a Ω²|H(Ω)| = F_m, i.e. Ω² = 1/(2 − 4ζ²) for F_a = F_m. The grazing event must sit
  there, and the multipliers before it are exp((−ζ ± i√(1 − ζ²))T).
* The same oscillator has a period-doubling cascade near Ω ≈ 1.95 → 1.85 → 1.82: the period
  doubling located on the continued 1T branch lies within one grid step of the 1T → 2T change
  of a brute-force sweep (continuation initial conditions, long transients, periods by
  :func:`~gearchaos.analysis.periodicity.periods_of`), and the branch started there (and the
  4T branch started at its own period doubling) coincide with the brute-force section points
  to 1e-6.
* A hardening Duffing oscillator has two folds; they lie within one grid step of the jumps
  of the up and down continuation sweeps (hysteresis).
* Varying a clearance of a planetary gear set whose teeth never separate only shifts the
  deflections: δ_sp − b̄_sp and the multipliers stay constant along the branch.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.analysis.periodicity import periods_of
from gearchaos.dynamics.continuation.arclength import parse_vary
from gearchaos.dynamics.continuation.events import Event, events

TIGHT = {"rtol": 1e-10, "atol": 1e-12}


def backlash(**kw: float) -> gc.System:
    return gc.backlash_oscillator(1.0, zeta=0.05, f_alt=0.1, f_mean=0.1, **kw)


# ----------------------------------------------------------------------------------- grazing
def test_grazing_of_the_backlash_oscillator_at_the_closed_form() -> None:
    zeta = 0.05
    ds = gc.continuation(backlash(), "omega=0.6:0.72", max_step=0.005, **TIGHT)
    assert ds.attrs["stop_reason"].startswith("reached the range stop")
    found = events(ds)
    assert [e.kind for e in found] == ["grazing"]
    (graze,) = found
    assert graze.detail == "mesh: none → single_sided"
    omega_g = 1.0 / math.sqrt(2.0 - 4.0 * zeta**2)
    assert graze.value == pytest.approx(omega_g, abs=1e-6)
    # before grazing: the linear oscillator's orbit and multipliers
    before = ds.where(ds.omega < omega_g - 1e-3, drop=True)
    assert before.sizes["point"] > 5
    for k in range(before.sizes["point"]):
        om = float(before.omega[k])
        den = 1 - om**2 + 2j * zeta * om
        amp = 0.1 * om**2 / abs(den)
        x0 = 1.0 + 0.1 + amp * math.cos(-np.angle(den))
        assert float(before.x[k, 0]) == pytest.approx(x0, abs=1e-8)
        mu = before.multiplier_re[k].values + 1j * before.multiplier_im[k].values
        wd = math.sqrt(1 - zeta**2)
        expected = np.exp((-zeta + 1j * wd) * 2 * math.pi / om)
        pair = np.array([expected, expected.conjugate()])
        assert np.max(np.abs(np.sort_complex(mu) - np.sort_complex(pair))) < 1e-8
    assert set(before.contact_regime.values.ravel()) == {"none"}
    after = ds.where(ds.omega > omega_g + 1e-3, drop=True)
    assert set(after.contact_regime.values.ravel()) == {"single_sided"}
    # the orbit at the event touches the clearance edge: a simulation from its state says so
    res = gc.simulate(
        backlash().at(graze.value), y0=graze.state, transient_periods=0, periods=1, **TIGHT
    )
    assert res.obs_min[0] == pytest.approx(1.0, abs=1e-6)


# ------------------------------------------------------------------------------ period doubling
def brute_periods(sweep) -> np.ndarray:
    return periods_of(np.stack([sweep.x.values, sweep.x_dot.values], axis=-1))


def test_period_doubling_cascade_matches_the_brute_force_sweep() -> None:
    """1T → 2T → 4T: each period doubling lies within one grid step of the period change of a
    brute-force sweep (down, continuation initial conditions), and the 2T and 4T branches
    started there pass through the brute-force section points (landed on the same grid)."""
    system = backlash()
    grid = np.round(np.arange(1.80, 2.1001, 0.01), 10)
    one = gc.continuation(system, "omega=2.1:1.8", grid=grid, **TIGHT)
    pd1 = next(e for e in events(one) if e.kind == "period_doubling")
    two = gc.continuation(system, "omega=2.1:1.8", start=pd1, grid=grid, **TIGHT)
    pd2 = next(e for e in events(two) if e.kind == "period_doubling")
    four = gc.continuation(system, "omega=2.1:1.8", start=pd2, grid=grid, **TIGHT)
    sweep = gc.bifurcation(
        system, "omega=1.8:2.1:31", initial_conditions="continuation", direction="down",
        transient_periods=1500, periods=16, progress=False, **TIGHT,
        verdicts=False,  # the brute-force reference: the protocol's own records
    )  # fmt: skip
    om = sweep.omega.values
    per = brute_periods(sweep)
    step = om[1] - om[0]
    assert isinstance(pd1, Event) and isinstance(pd2, Event)
    assert pd1.period == 1 and pd2.period == 2
    for event, (n_low, n_high) in ((pd1, (2, 1)), (pd2, (4, 2))):
        # brute force: the grid interval where the period changes from n_high (above) to n_low
        changes = [
            (om[k], om[k + 1]) for k in range(om.size - 1)
            if per[k] == n_low and per[k + 1] == n_high
        ]  # fmt: skip
        assert len(changes) == 1, (event, list(zip(om, per, strict=True)))
        lo, hi = changes[0]
        assert lo - step <= event.value <= hi + step
        assert event.multiplier.real == pytest.approx(-1.0, abs=1e-3)
        assert abs(event.multiplier.imag) < 1e-9
    # the 4T branch goes on doubling: its first event is the next period doubling
    found = events(four)
    assert [e.kind for e in found][:1] == ["period_doubling"]
    assert found[0].value < pd2.value

    x = sweep.x.values
    for ds, n, least in ((two, 2, 8), (four, 4, 2)):
        assert ds.attrs["period"] == n
        # every orbit of the branch but the first (the bifurcation point) has n distinct points
        assert np.all(np.ptp(ds.x.values[1:], axis=1) > 1e-6)
        assert ds.minimal_period.values[0] == n // 2
        assert np.all(ds.minimal_period.values[1:] == n)
        on = ds.where(ds.on_grid == 1, drop=True)
        compared = 0
        for i, w in enumerate(on.omega.values):
            k = int(np.argmin(np.abs(om - w)))
            assert abs(om[k] - w) < 1e-12
            if per[k] != n:
                continue
            # the brute-force points have converged onto their orbit ...
            assert np.max(np.abs(x[k, n:] - x[k, :-n])) < 1e-8
            # ... and it is the continued one (the same n section values, in some order)
            assert np.sort(on.x.values[i]) == pytest.approx(np.sort(x[k, -n:]), abs=1e-6)
            compared += 1
        assert compared >= least


# ----------------------------------------------------------------------------------- folds
def test_folds_match_the_jumps_of_up_and_down_sweeps() -> None:
    system = gc.duffing(1.0)  # x'' + 0.1x' + x + x³ = 0.5 cos Ωτ: hardening
    ds = gc.continuation(system, "omega=1.2:2.5", max_step=0.1, **TIGHT)
    folds = [e for e in events(ds) if e.kind == "fold"]
    assert len(folds) == 2, events(ds)
    upper, lower = sorted(folds, key=lambda e: -e.value)
    for e in folds:
        assert e.multiplier.real == pytest.approx(1.0, abs=1e-3)
    # the branch turns back at each fold
    turns = np.flatnonzero(np.diff(np.sign(ds.dparameter_ds.values)))
    assert turns.size == 2
    sweep = gc.bifurcation(
        system, "omega=1.2:2.5:66", initial_conditions="continuation", direction="both",
        transient_periods=300, periods=4, progress=False, **TIGHT,
    )  # fmt: skip
    om = sweep.omega.values
    step = om[1] - om[0]
    for direction, fold in (("up", upper), ("down", lower)):
        amp = sweep.x_max.sel(direction=direction).values
        k = int(np.argmax(np.abs(np.diff(amp))))
        assert abs(amp[k + 1] - amp[k]) > 0.5  # a jump between the two stable branches
        assert om[k] - step <= fold.value <= om[k + 1] + step, (direction, om[k], fold)
    # between the folds three orbits coexist: the middle one is the unstable one
    middle = ds.where((ds.omega > lower.value + 0.05) & (ds.omega < upper.value - 0.05), drop=True)
    assert {0.0, 1.0} <= set(np.unique(middle.stable.values))


# ----------------------------------------------------------------------------------- gear sets
def test_clearance_branch_without_separation_only_shifts_the_deflections() -> None:
    gs = gc.preset("sheng2016-v1")
    ds = gc.continuation(gs, "backlash.sun_planet=2:4", omega=0.5, max_step=0.1)
    assert ds.attrs["parameter"] == "backlash.sun_planet"
    assert ds.attrs["stop_reason"].startswith("reached the range stop")
    b = ds["backlash.sun_planet"].values
    assert b[0] == 2.0 and b[-1] == 4.0
    shifted = ds.delta_sp.values[:, 0, :] - b[:, None]
    assert np.ptp(shifted) < 1e-6
    assert np.ptp(ds.multiplier_abs.values, axis=0).max() < 1e-6
    assert set(ds.contact_regime.sel(contact="sun_planet_1").values) == {"none"}
    assert ds.sizes["event"] == 0


@pytest.fixture(scope="module")
def planetary_branch(tmp_path_factory) -> object:
    gs = gc.preset("sheng2016-v1")
    return gc.continuation(gs, "omega=3.3:3.45", max_step=0.01)


def test_branch_dataset_layout_and_provenance(planetary_branch) -> None:
    ds = planetary_branch
    gs = gc.preset("sheng2016-v1")
    assert ds.attrs["gearset_toml"] == gs.to_toml()
    for key in ("version", "numba_version", "rtol", "atol", "parameter", "period", "fixed"):
        assert key in ds.attrs
    assert ds.omega.dims == ("point",)
    assert ds.orbit_state.dims == ("point", "state")
    assert ds.delta_sp.dims == ("point", "section", "planet")
    assert ds.delta_sp_min.dims == ("point", "planet_all")
    assert ds.contact_regime.dims == ("point", "contact")
    assert ds.multiplier_abs.dims == ("point", "multiplier")
    assert np.all(np.diff(ds.multiplier_abs.values, axis=1) <= 1e-12)
    assert np.all(ds.residual.values <= ds.attrs["tol"])
    stable = ds.max_multiplier.values < 1
    assert np.array_equal(ds.stable.values == 1, stable)
    # the period doubling of the sheng2016 1T branch near Ω = 3.39 (the sweep labels 2T there)
    found = events(ds)
    pds = [e for e in found if e.kind == "period_doubling"]
    assert len(pds) == 1 and 3.3 < pds[0].value < 3.45
    k = pds[0].point
    assert ds.stable.values[k] != ds.stable.values[k + 1]


@pytest.mark.parametrize("suffix", [".nc", ".zarr"])
def test_branch_files_round_trip(planetary_branch, tmp_path, suffix) -> None:
    from gearchaos.dynamics.continuation.branch import open_branch, save_branch

    ds = planetary_branch
    path = tmp_path / f"branch{suffix}"
    save_branch(ds, path)
    back = open_branch(path)
    assert back.attrs["gearset_toml"] == ds.attrs["gearset_toml"]
    assert np.array_equal(back.orbit_state.values, ds.orbit_state.values)
    assert [(e.kind, e.value) for e in events(back)] == [(e.kind, e.value) for e in events(ds)]
    with pytest.raises(gc.StoreError, match="exists"):
        save_branch(ds, path)
    save_branch(ds, path, overwrite=True)


def test_store_argument_and_start_from_an_orbit(tmp_path) -> None:
    system = backlash()
    orbit = gc.periodic_orbit(system, omega=0.65, **TIGHT)
    path = tmp_path / "b.nc"
    ds = gc.continuation(system, "omega=0.6:0.7", start=orbit, store=path, **TIGHT)
    assert float(ds.omega[0]) == 0.65
    assert np.max(np.abs(ds.orbit_state.values[0] - orbit.state)) < 1e-9
    assert ds.attrs["start"] == "periodic_orbit"
    assert path.exists()


def test_stops_cleanly_with_the_reason() -> None:
    ds = gc.continuation(backlash(), "omega=0.6:0.7", max_points=3, **TIGHT)
    assert ds.sizes["point"] == 3
    assert "max_points" in ds.attrs["stop_reason"]
    # a corrector that may take two map evaluations cannot converge: the reason is kept
    # (min_step <= step <= max_step is required since issue 23)
    ds = gc.continuation(
        backlash(),
        "omega=0.6:0.7",
        max_corrector=2,
        step=0.05,
        min_step=0.02,
        max_step=0.05,
        **TIGHT,
    )
    assert ds.attrs["stop_reason"].startswith("stopped at omega=0.6")
    assert ds.sizes["point"] == 1


def test_invalid_arguments_are_named() -> None:
    system = backlash()
    for bad in ("omega", "omega=1", "omega=a:b", "=1:2", "omega=1:1"):
        with pytest.raises(gc.ParameterError, match="vary"):
            parse_vary(bad)
    assert parse_vary(("zeta", 0.1, 0.2)) == ("zeta", 0.1, 0.2)
    assert parse_vary({"zeta": (0.1, 0.2)}) == ("zeta", 0.1, 0.2)
    with pytest.raises(gc.ParameterError, match="cannot also be fixed"):
        gc.continuation(system, "zeta=0.05:0.1", zeta=0.07)
    with pytest.raises(gc.ParameterError, match="outside the range"):
        gc.continuation(system, "omega=0.6:0.7", start=gc.periodic_orbit(system, omega=0.8))
    with pytest.raises(gc.ParameterError, match="unknown parameter"):
        gc.continuation(system, "zetta=0.05:0.1")
    with pytest.raises(gc.ParameterError, match="max_step"):
        gc.continuation(system, "omega=0.6:0.7", max_step=-1.0)
    with pytest.raises(gc.ParameterError, match=r"\.nc or \.zarr"):
        gc.continuation(system, "omega=0.6:0.61", store="branch.txt")


def test_sun_bearing_grazing_where_the_free_orbit_reaches_the_clearance() -> None:
    """With sequential (Parker) mesh phasing the sun centre moves. While |x̄_s|, |ȳ_s| ≤ b̄_s
    the bearing exerts no stiffness force (its damping acts everywhere), so the orbit does not
    depend on b̄_s; shrinking b̄_s, the bearing first touches where b̄_s equals the largest
    excursion of the free orbit, on the positive sides of ȳ_s and x̄_s."""
    gs = gc.preset("sheng2016-v1").evolve({"mesh_phasing.model": "parker"})
    ds = gc.continuation(gs, "clearance.sun_bearing=0.0025:0.0015", omega=0.5, max_step=1e-4)
    free = gc.periodic_orbit(gs, omega=0.5, **TIGHT)  # b̄_s = 2: never touches
    res = gc.simulate(
        free.system, y0=free.state, transient_periods=0, periods=1, samples_per_period=4000,
        **TIGHT,
    )  # fmt: skip
    reach_x, reach_y = float(np.max(res.series("x_s"))), float(np.max(res.series("y_s")))
    assert 0.0015 < min(reach_x, reach_y) and max(reach_x, reach_y) < 0.0025
    found = events(ds)
    assert all(e.kind == "grazing" for e in found)
    first = sorted(found, key=lambda e: -e.value)[:2]
    expected = sorted(
        [(reach_x, "sun_bearing_x: free → single_sided"),
         (reach_y, "sun_bearing_y: free → single_sided")],
        reverse=True,
    )  # fmt: skip
    tols = (1e-8, 1e-7)
    for e, (value, detail), tol in zip(first, expected, tols, strict=True):
        # the second contact happens on an orbit the first one has (slightly) changed
        assert e.detail == detail
        assert e.value == pytest.approx(value, abs=tol)
    # before the first contact the orbit is the same at every b̄_s
    before = ds.where(ds["clearance.sun_bearing"] > max(reach_x, reach_y), drop=True)
    assert before.sizes["point"] >= 3
    assert np.ptp(before.orbit_state.values, axis=0).max() < 1e-9
    assert np.max(np.abs(before.orbit_state.values[0] - free.state)) < 1e-8
    last = ds.contact_regime.isel(point=-1)
    assert list(last.sel(contact=["sun_bearing_x", "sun_bearing_y"]).values) == [
        "double_sided", "double_sided",
    ]  # fmt: skip


def test_neimark_sacker_of_the_duffing_oscillator_where_the_damping_vanishes() -> None:
    """x'' + δx' + x + x³ = γ cos Ωτ: the divergence of the vector field is −δ, so
    det M = exp(−δT) (Liouville) and a complex pair of multipliers has |μ|² = exp(−δT).
    Continuing in δ through 0, the pair leaves the unit circle exactly at δ = 0."""
    omega = 1.2
    system = gc.duffing(omega, delta=0.1, gamma=0.1)
    ds = gc.continuation(system, "delta=0.1:-0.1", max_step=0.01, **TIGHT)
    (ns,) = events(ds)
    assert ns.kind == "neimark_sacker"
    assert ns.value == pytest.approx(0.0, abs=1e-6)
    assert abs(ns.multiplier) == pytest.approx(1.0, abs=1e-6)
    assert ns.multiplier.imag > 0.1
    period = 2 * math.pi / omega
    expected = np.exp(-ds.delta.values * period / 2)
    assert np.max(np.abs(ds.multiplier_abs.values - expected[:, None])) < 1e-9
    assert np.array_equal(ds.stable.values == 1, ds.delta.values > 0)


def test_branch_summary_is_json_and_segments_cover_the_branch(planetary_branch) -> None:
    import json

    from gearchaos.dynamics.continuation.branch import branch_summary

    summary = branch_summary(planetary_branch)
    json.dumps(summary)
    assert summary["parameter"] == "omega" and summary["period"] == 1
    assert sum(seg["points"] for seg in summary["segments"]) == summary["points"]
    # stability alternates from one segment to the next, and changes only at events
    flags = [seg["stable"] for seg in summary["segments"]]
    assert all(a != b for a, b in itertools.pairwise(flags))
    kinds = {e["kind"] for e in summary["events"]}
    assert len(summary["segments"]) - 1 <= len(summary["events"])
    assert "period_doubling" in kinds
