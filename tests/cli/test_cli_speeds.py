"""The sun speed on the command line: ``--set sun_rpm=…``, ``--vary sun_rpm=…``, refusals and
the rpm beside Ω in tables. Expected Ω are computed from the gear set's numbers (MODEL.md §1,
§2, §7), not with the package's conversion."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app
from gearchaos.cli._options import DEFAULT_PRESET
from gearchaos.gearset import GearSet

SHORT = ["--transient", "2", "--periods", "2"]


@pytest.fixture(scope="module")
def runner() -> CliRunner:
    return CliRunner()


def _omega_at_rpm(gs: GearSet, rpm: float) -> float:
    m, a = gs.geometry.module, math.radians(gs.geometry.pressure_angle_sun)
    r_bs, r_bp = m * gs.teeth.sun / 2 * math.cos(a), m * gs.teeth.planet / 2 * math.cos(a)
    ms, mp = gs.inertia.sun / r_bs**2, gs.inertia.planet / r_bp**2
    omega_n = math.sqrt(gs.stiffness.sun_planet_mean / (ms * mp / (ms + mp)))
    zs, zr = gs.teeth.sun, gs.teeth.ring
    return rpm * 2 * math.pi / 60 * zs * zr / (zs + zr) / omega_n


def test_info_and_simulate_take_the_sun_speed(runner: CliRunner) -> None:
    gs = gc.preset(DEFAULT_PRESET)  # the gear set the commands run without --preset
    result = runner.invoke(app, ["info", "--set", "sun_rpm=7500", "--json"])
    assert result.exit_code == 0, result.output
    point = json.loads(result.stdout)["operating_point"]
    assert point["omega"] == pytest.approx(_omega_at_rpm(gs, 7500.0), rel=1e-12)
    assert point["sun_speed_rpm"] == pytest.approx(7500.0, rel=1e-12)
    # with another stiffness set beside it, the speed converts through the changed gear set
    result = runner.invoke(
        app, ["info", "--set", "stiffness.sun_planet_mean=4e8", "--set", "sun_rpm=7500", "--json"]
    )
    changed = gs.evolve({"stiffness.sun_planet_mean": 4e8})
    assert json.loads(result.stdout)["operating_point"]["omega"] == pytest.approx(
        _omega_at_rpm(changed, 7500.0), rel=1e-12
    )
    result = runner.invoke(app, ["simulate", *SHORT, "--set", "sun_rpm=7500", "--no-verdict"])
    assert result.exit_code == 0, result.output
    om = _omega_at_rpm(gs, 7500.0)
    assert f"at Ω = {om:g} (n_s = 7500 rpm" in " ".join(result.stdout.split())


def test_info_tables_show_the_sun_speed_of_every_resonance(runner: CliRunner) -> None:
    result = runner.invoke(app, ["info", "--json"])
    gs = gc.preset(DEFAULT_PRESET)  # the gear set the commands run without --preset
    for row in json.loads(result.stdout)["omega_at_resonances"]:
        rpm = row["sun_speed_rpm"]
        assert _omega_at_rpm(gs, rpm) == pytest.approx(row["omega"], rel=1e-12)


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        (["simulate", "--set", "omega=7000"], ["got 7000", "sun_rpm=7000"]),
        (["simulate", "--set", "omega=0"], ["omega"]),
        (["info", "--set", "omega=1.5", "--set", "sun_rpm=7500"], ["each set Ω"]),
        (["bifurcation", "--vary", "sun_rpm=1000:2000:2", "--set", "omega=1.5", "-o", "x.zarr"],
         ["--set omega and --vary sun_rpm each set Ω"]),
        (["simulate", "--set", "rpm=7500"], ["did you mean 'sun_rpm'"]),
        (["simulate", "--model", "examples/kahraman_singh_1991.py:KahramanSingh1991", "--set",
          "sun_rpm=1000"], ["sun_rpm sets Ω through a gear set", "give omega"]),
    ],
)  # fmt: skip
def test_refusals_name_the_value_and_the_way_out(
    runner: CliRunner,
    args: list[str],
    needles: list[str],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    root = Path(__file__).resolve().parents[2]
    args = [str(root / a) if a.startswith("examples/") else a for a in args]
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, args)
    assert result.exit_code == 2, result.output
    text = " ".join(result.stderr.split())
    for needle in needles:
        assert needle in text


def test_bifurcation_over_sun_rpm_stores_omega_and_prints_both(
    runner: CliRunner, tmp_path: Path
) -> None:
    store = tmp_path / "rpm.zarr"
    result = runner.invoke(
        app,
        ["bifurcation", "--vary", "sun_rpm=2000:8000:3", *SHORT, "--no-verdicts", "-o",
         str(store)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    gs = gc.preset(DEFAULT_PRESET)  # the gear set the commands run without --preset
    ds = xr.open_zarr(store)
    expected = [_omega_at_rpm(gs, r) for r in (2000.0, 5000.0, 8000.0)]
    np.testing.assert_allclose(ds["omega"].values, expected, rtol=1e-12)
    np.testing.assert_allclose(ds["sun_rpm"].values, [2000.0, 5000.0, 8000.0], rtol=1e-12)
    text = " ".join(result.stdout.split())
    assert f"{expected[0]:.6g} … {expected[-1]:.6g} (2000 … 8000 rpm)" in text


def test_a_clearance_in_metres_on_a_gear_set_in_b_c_is_warned_about(runner: CliRunner) -> None:
    result = runner.invoke(
        app, ["info", "--preset", "sheng2016-v1", "--set", "backlash.sun_planet=60e-6"]
    )
    assert result.exit_code == 0, result.output
    text = " ".join(result.stderr.split())
    assert "backlash.sun_planet = 6e-05 is in units of b_c" in text
    assert "a value in metres given for a parameter in units of b_c" in text
