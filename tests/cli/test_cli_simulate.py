"""``gearchaos simulate``: JSON contract, agreement with the Python API, files, errors."""

from __future__ import annotations

import importlib
import json
import math
import re

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app
from gearchaos.dynamics.verdict.point import analyse_point
from gearchaos.errors import IntegrationError
from gearchaos.gearset import GearSet, preset
from gearchaos.integrate.settings import SolverSettings

#: The JSON contract of ``simulate --json`` (gearchaos.analysis.summary.summarize), in order.
CONTRACT = [
    "omega",
    "omega_n_rad_s",
    "distinct_section_points",
    "motion",
    "record_label",
    "section_min",
    "section_max",
    "contact",
    "status",
    "steps_accepted",
    "steps_rejected",
]
REGIMES = {"none", "single_sided", "double_sided"}
SHORT = ["--transient", "20", "--periods", "20"]


@pytest.fixture(scope="module")
def runner() -> CliRunner:
    return CliRunner()


def run_json(runner: CliRunner, *args: str) -> dict:
    result = runner.invoke(app, ["simulate", *SHORT, "--json", *args])
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)  # stdout holds the JSON document and nothing else


def test_json_keys_and_values_match_the_python_api(runner: CliRunner) -> None:
    out = run_json(runner, "--set", "omega=1.5", "--samples-per-period", "8")
    assert list(out)[: len(CONTRACT)] == CONTRACT

    gs = preset("sheng2016")  # the CLI's default
    # the CLI is analyse_point: the simulation, then the verdict (which may show the
    # finished record: the run continued by the verdict, never the orbit's own points)
    cfg = SolverSettings(transient_periods=20, periods=20, samples_per_period=8)
    point = analyse_point(gs, {"omega": 1.5}, cfg)
    res = point.result
    assert out["motion"] == point.summary["motion"] and out["evidence"] == "floquet"
    ds = res.to_dataset()
    x = ds.delta_sp.sel(planet=1).values
    assert out["omega"] == 1.5
    assert out["section_min"] == pytest.approx(float(x.min()), rel=1e-12)
    assert out["section_max"] == pytest.approx(float(x.max()), rel=1e-12)
    assert out["steps_accepted"] == res.steps_accepted
    assert out["steps_rejected"] == res.steps_rejected
    assert out["status"] == "ok"

    # physical consistency, recomputed here from the gear set's definition (MODEL.md §2, §7)
    z, geo = gs.teeth, gs.geometry
    cos_a = math.cos(math.radians(geo.pressure_angle_sun))
    ms = gs.inertia.sun / (geo.module * z.sun / 2 * cos_a) ** 2
    mp = gs.inertia.planet / (geo.module * z.planet / 2 * cos_a) ** 2
    me = ms * mp / (ms + mp)
    omega_n = math.sqrt(gs.stiffness.sun_planet_mean / me)
    assert out["omega_n_rad_s"] == pytest.approx(omega_n, rel=1e-12)
    sun_rad_s = 1.5 * omega_n * (z.sun + z.ring) / (z.sun * z.ring)
    assert out["sun_speed_rpm"] == pytest.approx(sun_rad_s * 60 / (2 * math.pi), rel=1e-12)
    assert 1 <= out["distinct_section_points"] <= 20 + 1
    assert isinstance(out["motion"], str) and out["motion"]
    assert out["steps_accepted"] > 0 and out["steps_rejected"] >= 0
    # section values lie within the extrema tracked at every step
    assert float(ds.delta_sp_min.sel(planet=1)) <= out["section_min"]
    assert out["section_min"] <= out["section_max"]
    assert out["section_max"] <= float(ds.delta_sp_max.sel(planet=1))
    n = gs.n_planets
    assert len(out["contact"]) == 2 * n
    assert all(set(c) == {"mesh", "regime", "separation_fraction"} for c in out["contact"])
    assert len({c["mesh"] for c in out["contact"]}) == 2 * n
    assert {c["regime"] for c in out["contact"]} <= REGIMES


def test_default_omega_is_documented_value(runner: CliRunner) -> None:
    out = run_json(runner, "--samples-per-period", "1")
    assert out["omega"] == 1.5


def test_set_changes_the_gear_set_and_files_are_written(runner: CliRunner, tmp_path) -> None:
    outdir = tmp_path / "run"
    result = runner.invoke(
        app,
        [
            "simulate",
            *SHORT,
            "--set",
            "omega=1.2",
            "--set",
            "xi=0.05",
            "--set",
            "backlash.sun_planet=2.5",
            "-o",
            str(outdir),
        ],
    )
    assert result.exit_code == 0, result.output
    assert "simulation.nc" in result.stdout and "simulation.png" in result.stdout
    nc, png = outdir / "simulation.nc", outdir / "simulation.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with xr.open_dataset(nc, engine="h5netcdf") as ds:
        assert ds.attrs["omega"] == 1.2
        assert ds.attrs["version"] == gc.__version__
        gs = GearSet.from_toml_string(ds.attrs["gearset_toml"])
        assert "delta_sp" in ds and ds.delta_sp.sizes["section"] == 20
        assert np.all(np.isfinite(ds.delta_sp.sel(planet=1).values))
    # every value as set, and a name that says the gear set is not plain sheng2016 (issue 24)
    expected = preset("sheng2016").evolve(
        {
            "xi": 0.05,
            "backlash.sun_planet": 2.5,
            "name": "sheng2016 (modified: xi, backlash.sun_planet)",
        }
    )
    assert gs == expected


def test_json_with_output_keeps_stdout_pure(runner: CliRunner, tmp_path) -> None:
    out = run_json(runner, "--samples-per-period", "4", "-o", str(tmp_path), "--no-plot")
    assert out["status"] == "ok"
    assert (tmp_path / "simulation.nc").exists()
    assert not (tmp_path / "simulation.png").exists()


@pytest.mark.parametrize(
    ("setting", "message"),
    [
        ("backlash.sun_planit=3", "did you mean 'backlash.sun_planet'"),
        ("sun_planet=3", "did you mean one of"),
        ("omga=1.5", "did you mean 'omega'"),
        ("teeth.sun=abc", "teeth.sun must be an integer"),
        ("backlash.sun_planet=-1", "backlash.sun_planet must be >= 0"),
        ("omega=-1", "omega must be a finite number > 0"),
        ("omega", "--set expects NAME=VALUE"),
        ("backlash=3", "backlash is a table"),
    ],
)
def test_invalid_set_exits_2_without_traceback(
    runner: CliRunner, setting: str, message: str
) -> None:
    result = runner.invoke(app, ["simulate", *SHORT, "--set", setting])
    assert result.exit_code == 2
    assert message in result.stderr
    assert "Traceback" not in result.output
    assert result.stdout == ""


def test_invalid_solver_setting_exits_2(runner: CliRunner) -> None:
    result = runner.invoke(app, ["simulate", "--periods", "0", "--json"])
    assert result.exit_code == 2
    assert "periods must be an integer >= 1" in result.stderr


def test_preset_and_gearset_are_exclusive(runner: CliRunner, tmp_path) -> None:
    f = tmp_path / "g.toml"
    f.write_text(gc.preset("sheng2016-v1").to_toml(), encoding="utf-8")
    result = runner.invoke(app, ["simulate", "--preset", "sheng2016-v1", "--gearset", str(f)])
    assert result.exit_code == 2
    assert "mutually exclusive" in result.stderr


def test_unknown_preset_and_missing_file_exit_2(runner: CliRunner, tmp_path) -> None:
    result = runner.invoke(app, ["simulate", "--preset", "sheng2061"])
    assert result.exit_code == 2
    assert "did you mean 'sheng2016'" in result.stderr
    result = runner.invoke(app, ["simulate", "--gearset", str(tmp_path / "none.toml")])
    assert result.exit_code == 2
    assert "not found" in result.stderr


def test_integration_failure_exits_1(runner: CliRunner, monkeypatch) -> None:
    def fail(*args: object, **kwargs: object) -> None:
        raise IntegrationError("simulation at omega=1.5 stopped at tau=3: NON_FINITE: diverged")

    # the CLI simulates through gearchaos.dynamics.verdict.point.analyse_point, which runs the
    # integration with run_simulation
    monkeypatch.setattr(
        importlib.import_module("gearchaos.dynamics.verdict.point"), "run_simulation", fail
    )
    result = runner.invoke(app, ["simulate", "--json"])
    assert result.exit_code == 1
    assert "NON_FINITE" in result.stderr
    assert result.stdout == ""
    assert "Traceback" not in result.output


def test_human_output_names_the_summary(runner: CliRunner) -> None:
    result = runner.invoke(app, ["simulate", *SHORT, "--samples-per-period", "1"])
    assert result.exit_code == 0, result.output
    for text in ("sheng2016", "Ω", "ω_n", "sun speed", "X̄_sp1", "contact", "status"):
        assert text in result.stdout


def test_a_user_models_output_speaks_its_own_words(runner: CliRunner) -> None:
    """Issue 36: ``simulate --model`` of a model of one's own (tests/two_frequency_train.py: two
    stages meshing at Ω and 3Ω/5, T = 5·2π/Ω) prints its section variable by its symbol, its
    contacts and its periods, and neither its JSON nor its table names the planetary model."""
    from pathlib import Path

    from gearchaos.model import System
    from two_frequency_train import TwoFrequencyTrain

    model = f"{Path(__file__).parents[1] / 'two_frequency_train.py'}:TwoFrequencyTrain"
    args = ["--model", model, "--set", "omega=1.2", "--no-verdict"]
    out = run_json(runner, *args)
    old = {"x_sp1_section_min", "x_sp1_section_max", "sun_speed_rpm", "dte_sp1_rms"}
    assert not old & set(out) and "load_factor_sp_max" not in out
    assert out["section_variable"] == "x_1" and out["dte_contact"] == "stage1"
    # the range of the model's own section points (one per T = 5·2π/Ω), from its record
    ref = gc.simulate(System(TwoFrequencyTrain(), 1.2), transient_periods=20, periods=20)
    x = ref.section("x_1")
    assert (out["section_min"], out["section_max"]) == (float(x.min()), float(x.max()))
    result = runner.invoke(app, ["simulate", *SHORT, *args])
    assert result.exit_code == 0, result.output
    text = result.stdout
    assert "q̄_1 section min" in text and "contact stage2" in text
    assert "20 recorded train periods" in text
    words = re.compile(r"planet|sun|ring|sp1|X̄|mesh|b_c|gear set", re.IGNORECASE)
    assert not words.search(text), text
