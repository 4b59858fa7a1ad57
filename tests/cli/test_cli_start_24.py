"""Issue 24 (continuation): ``orbit`` and ``continue`` start where the user says — from a longer
settle, a sweep store point, a branch point or an orbit file — and the Python front doors take a
gear set with values by name.

Each test runs the command that failed or misled before: ``continue --vary
backlash.sun_planet=1:6 --set omega=1.5`` failed ("pass a better start", with no option to
pass one), and ``orbit --period 2 --set omega=3.5`` returned the unstable 1T orbit.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app

#: the gear set these tests were written against: its stable 1T orbit at Ω = 1.5 and its 2T
#: orbit at Ω = 3.5 (the recalibrated default has a 2T orbit at 1.5 and a 1T at 3.5)
V1 = ["--preset", "sheng2016-v1"]


@pytest.fixture(scope="module")
def runner() -> CliRunner:
    return CliRunner()


def _ok(runner: CliRunner, args: list[str]) -> str:
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    return result.stdout


def _refused(runner: CliRunner, args: list[str], *needles: str) -> str:
    result = runner.invoke(app, args)
    assert result.exit_code != 0, result.output
    for needle in needles:
        assert needle in result.output, result.output
    return result.output


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory, runner: CliRunner) -> Path:
    """A three-point Ω sweep whose middle point (Ω = 1.5) ends on the stable 1T orbit."""
    path = tmp_path_factory.mktemp("start") / "w.zarr"
    _ok(runner, ["bifurcation", *V1, "--vary", "omega=1.4:1.6:3", "-o", str(path), "--quiet"])
    return path


# ------------------------------------------------------------------ a longer settle
def test_orbit_period_two_at_3_5_settles_to_the_stable_2t_orbit(runner: CliRunner) -> None:
    out = json.loads(_ok(runner, ["orbit", *V1, "--period", "2", "--set", "omega=3.5", "--json"]))
    assert out["converged"] and out["stable"], out["message"]
    assert out["minimal_period"] == 2
    # the attractor a long simulation from rest ends on is this orbit: its section points
    # alternate between the orbit's two X̄_sp1 values (|μ| ≈ 0.97: settled after 800 periods)
    sim = gc.simulate(gc.preset("sheng2016-v1"), omega=3.5, transient_periods=800, periods=8)
    x = sim.section("delta_sp")[:, 0]
    orbit_x = np.array(out["section"])
    for k, value in enumerate(x):
        assert np.min(np.abs(orbit_x - value)) < 1e-5, (k, value, orbit_x)
    assert abs(x[0] - x[1]) > 1e-2  # truly period 2 at the section


def test_without_the_settle_the_same_shooting_ends_on_the_unstable_1t_orbit() -> None:
    """What the command returned before: the 50-period guess lies near the unstable 1T orbit
    (so the test above exercises the settle, not a lucky guess)."""
    gs = gc.preset("sheng2016-v1")
    once = gc.periodic_orbit(gs, period=2, omega=3.5, settle=50)
    assert once.converged and not once.stable and once.minimal_period == 1
    settled = gc.periodic_orbit(gs, period=2, omega=3.5)
    assert settled.stable and settled.settings.transient_periods > 50
    assert "mesh periods from rest" in settled.message


def test_settle_is_checked_and_only_for_a_guess_from_rest() -> None:
    gs = gc.preset("sheng2016-v1")
    with pytest.raises(gc.ParameterError, match="settle"):
        gc.periodic_orbit(gs, omega=1.5, settle=10)  # shorter than transient_periods = 50
    orbit = gc.periodic_orbit(gs, omega=1.5)
    with pytest.raises(gc.ParameterError, match="settle applies to guess=None"):
        gc.periodic_orbit(gs, omega=1.5, guess=orbit, settle=400)


def test_continue_in_backlash_at_1_5_starts_without_a_given_start(
    runner: CliRunner, tmp_path: Path
) -> None:
    path = tmp_path / "b.nc"
    args = ["continue", *V1, "--vary", "backlash.sun_planet=1:6", "--set", "omega=1.5"]
    out = json.loads(_ok(runner, [*args, "-o", str(path), "--json"]))
    ds = gc.open_branch(path)
    lam = ds["backlash.sun_planet"].values
    assert lam[0] == pytest.approx(1.0) and lam.max() == pytest.approx(6.0)
    assert out["points"] == lam.size
    assert json.loads(ds.attrs["fixed"])["omega"] == 1.5
    # the start is the orbit at b̄_sp = 1 itself: shooting again from its state at that value
    # moves it by no more than the tolerance
    again = gc.periodic_orbit(
        gc.preset("sheng2016-v1"),
        omega=1.5,
        params={"backlash.sun_planet": 1.0},
        guess=ds["orbit_state"].values[0],
    )
    assert again.converged
    np.testing.assert_allclose(again.state, ds["orbit_state"].values[0], atol=1e-7)


# ------------------------------------------------------------------ --from / --at
def test_orbit_from_a_store_point_is_the_orbit_at_that_point(
    runner: CliRunner, store: Path
) -> None:
    here = json.loads(_ok(runner, ["orbit", "--from", str(store), "--at", "omega=1.5", "--json"]))
    rest = json.loads(_ok(runner, ["orbit", *V1, "--set", "omega=1.5", "--json"]))
    assert here["converged"] and rest["converged"]
    # the same orbit, reached from two different guesses
    np.testing.assert_allclose(here["section"], rest["section"], atol=1e-8)
    assert here["max_multiplier"] == pytest.approx(rest["max_multiplier"], abs=1e-6)


def test_orbit_file_round_trip_starts_a_branch_on_that_orbit(
    runner: CliRunner, store: Path, tmp_path: Path
) -> None:
    orbit_file = tmp_path / "o.nc"
    first = json.loads(
        _ok(
            runner,
            ["orbit", "--from", str(store), "--at", "omega=1.5", "-o", str(orbit_file), "--json"],
        )
    )
    saved = gc.dynamics.orbits.file.open_orbit(orbit_file)
    assert saved.attrs["omega"] == 1.5 and saved.attrs["period"] == 1
    branch = tmp_path / "c.nc"
    _ok(runner, ["continue", "--from", str(orbit_file), "--vary", "omega=1.5:1.55",
                 "-o", str(branch), "--quiet"])  # fmt: skip
    ds = gc.open_branch(branch)
    assert float(ds["omega"].values[0]) == pytest.approx(1.5)
    np.testing.assert_allclose(ds["orbit_state"].values[0], saved["orbit_state"].values, atol=1e-8)
    np.testing.assert_allclose(ds["delta_sp"].values[0, 0, 0], first["section"][0], atol=1e-8)


def test_orbit_from_a_branch_point(runner: CliRunner, tmp_path: Path) -> None:
    branch = tmp_path / "b.nc"
    _ok(runner, ["continue", "--vary", "omega=1.45:1.5", "-o", str(branch), "--quiet"])
    ds = gc.open_branch(branch)
    k = ds.sizes["point"] // 2
    value = float(ds["omega"].values[k])
    out = json.loads(
        _ok(runner, ["orbit", "--from", str(branch), "--at", f"omega={value!r}", "--json"])
    )
    assert out["converged"]
    np.testing.assert_allclose(out["section"][0], ds["delta_sp"].values[k, 0, 0], atol=1e-7)


def test_continue_from_a_store_point_in_another_parameter(
    runner: CliRunner, store: Path, tmp_path: Path
) -> None:
    """The branch starts at the point's own value of the continued parameter (b̄_sp = 3 of the
    stored gear set) with Ω = 1.5 from the point, and heads to STOP."""
    branch = tmp_path / "bsp.nc"
    _ok(runner, ["continue", "--from", str(store), "--at", "omega=1.5",
                 "--vary", "backlash.sun_planet=3:3.2", "-o", str(branch), "--quiet"])  # fmt: skip
    ds = gc.open_branch(branch)
    lam = ds["backlash.sun_planet"].values
    assert lam[0] == pytest.approx(3.0) and lam[-1] == pytest.approx(3.2)
    assert json.loads(ds.attrs["fixed"])["omega"] == 1.5


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        (["--at", "omega=1.5"], ["--at", "--from"]),
        (["--from", "{store}"], ["--at must name omega", "1.4 … 1.6"]),
        (["--from", "{store}", "--at", "omega=1.55"], ["omega=1.55", "nearest", "1.5, 1.6"]),
        (["--from", "{store}", "--at", "xi=0.05"], ["xi", "does not sweep", "omega"]),
        (["--from", "{store}", "--at", "omega"], ["NAME=VALUE"]),
        (["--from", "{store}", "--at", "omega=1.5", "--preset", "sheng2016-v1"], ["--preset"]),
        (["--from", "{missing}", "--at", "omega=1.5"], ["no such file"]),
    ],
)
def test_bad_starts_are_refused_naming_the_option(
    runner: CliRunner, store: Path, tmp_path: Path, args: list[str], needles: list[str]
) -> None:
    filled = [a.format(store=store, missing=tmp_path / "nope.zarr") for a in args]
    _refused(runner, ["orbit", *filled], *needles)


def test_orbit_output_must_be_netcdf(runner: CliRunner, tmp_path: Path) -> None:
    _refused(runner, ["orbit", "--set", "omega=1.5", "-o", str(tmp_path / "o.txt")], ".nc")


# ------------------------------------------------------------------ the Python front doors
def test_lyapunov_takes_a_gear_set_and_values_by_name() -> None:
    gs = gc.preset("sheng2016-v1")
    by_name = gc.max_lyapunov(gs, omega=1.7, periods=60, transient_periods=20)
    system = gc.planetary_system(gs, 1.7)
    direct = gc.max_lyapunov(system, periods=60, transient_periods=20)
    assert by_name == direct  # the same system, so the same computation
    changed = gc.lyapunov_spectrum(
        gs, omega=1.7, params={"backlash.sun_planet": 2.5}, periods=60, transient_periods=20,
        n_exponents=1,
    )  # fmt: skip
    other = gc.max_lyapunov(
        gc.planetary_system(gs.evolve({"backlash.sun_planet": 2.5}), 1.7),
        periods=60,
        transient_periods=20,
    )
    assert changed.largest == other
    with pytest.raises(gc.ParameterError, match="omega is required"):
        gc.max_lyapunov(gs)


def test_top_level_has_the_orbit_branch_and_lyapunov_doors() -> None:
    for name in ("max_lyapunov", "lyapunov_spectrum", "periodic_orbit", "periodic_orbits",
                 "continuation", "open_branch", "save_branch", "Event", "attractors"):  # fmt: skip
        assert name in gc.__all__ and callable(getattr(gc, name)), name


def test_gear_set_getter_by_dotted_name() -> None:
    gs = gc.preset("sheng2016-v1")
    assert gs["backlash.sun_planet"] == gs.backlash.sun_planet
    assert gs["geometry.planets"] == gs.geometry.planets
    assert gs["xi"] == gs.damping.sun_planet
    changed = gs.evolve({"backlash.planet_ring": 2.0})
    assert changed["backlash.planet_ring"] == 2.0
    with pytest.raises(gc.ParameterError, match=r"backlash\.sun_planet"):
        gs["backlash.sunplanet"]
