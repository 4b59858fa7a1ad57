"""``gearchaos --version | presets | init-gearset | info`` and the ``--set`` parser."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app, parse_sets
from gearchaos.errors import ParameterError
from gearchaos.gearset import GearSet, preset


@pytest.fixture(scope="module")
def runner() -> CliRunner:
    return CliRunner()


def test_python_m_gearchaos_version() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "gearchaos", "--version"],
        capture_output=True,
        text=True,
        timeout=120,
        stdin=subprocess.DEVNULL,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == f"gearchaos {gc.__version__}"


def test_version_option(runner: CliRunner) -> None:
    result = runner.invoke(app, ["--version"])
    assert result.exit_code == 0
    assert gc.__version__ in result.stdout


def test_presets_lists_sheng2016(runner: CliRunner) -> None:
    result = runner.invoke(app, ["presets"])
    assert result.exit_code == 0
    assert "sheng2016" in result.stdout


def test_init_gearset_writes_the_values_of_preset(runner: CliRunner, tmp_path) -> None:
    """``--preset NAME`` writes that preset's values (the how-tos pin the previous default)."""
    f = tmp_path / "v1.toml"
    result = runner.invoke(app, ["init-gearset", str(f), "--preset", "sheng2016-v1"])
    assert result.exit_code == 0, result.output
    gs = GearSet.from_toml(f)
    ref = preset("sheng2016-v1")
    assert gs.evolve({"name": ref.name, "description": ref.description}) == ref
    assert gs.teeth != preset("sheng2016").teeth  # not the default's values
    assert "the sheng2016-v1 preset" in f.read_text(encoding="utf-8")
    # an unknown preset is refused by name, and no file is written
    g = tmp_path / "none.toml"
    result = runner.invoke(app, ["init-gearset", str(g), "--preset", "nope"])
    assert result.exit_code == 2
    assert "unknown preset 'nope'" in result.stderr and "sheng2016-v1" in result.stderr
    assert not g.exists()


def test_init_gearset_round_trip(runner: CliRunner, tmp_path) -> None:
    f = tmp_path / "my.toml"
    result = runner.invoke(app, ["init-gearset", str(f)])
    assert result.exit_code == 0, result.output
    gs = GearSet.from_toml(f)
    ref = preset("sheng2016")  # the default gear set of every command
    assert gs.evolve({"name": ref.name, "description": ref.description}) == ref

    # refuses to overwrite without --force, and leaves the file alone
    result = runner.invoke(app, ["init-gearset", str(f)])
    assert result.exit_code == 1
    assert "--force" in result.stderr
    # --force replaces the file it wrote, as it wrote it
    written = f.read_bytes()
    result = runner.invoke(app, ["init-gearset", str(f), "--force"])
    assert result.exit_code == 0, result.output
    assert f.read_bytes() == written
    # an edited file is the user's (issue 33): --force refuses it and leaves it whole
    f.write_text("# edited\n" + f.read_text(encoding="utf-8"), encoding="utf-8")
    result = runner.invoke(app, ["init-gearset", str(f), "--force"])
    assert result.exit_code == 2
    assert "not a gear-set file gearchaos wrote" in result.stderr
    assert f.read_text(encoding="utf-8").startswith("# edited")

    # the written file drives a simulation
    result = runner.invoke(
        app,
        ["simulate", "--gearset", str(f), "--transient", "5", "--periods", "5", "--json"],
    )
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["gearset"] == "my_gearset"


def test_info_json(runner: CliRunner) -> None:
    result = runner.invoke(app, ["info", "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    gs = preset("sheng2016")  # the default gear set
    assert data["omega_n_rad_s"] == pytest.approx(gs.omega_n, rel=1e-12)
    freqs = data["natural_frequencies"]
    hz = [f["hz"] for f in freqs]
    assert min(hz) == pytest.approx(0.0, abs=1e-6 * max(hz))  # the rigid-body rotation
    assert all({"hz", "kind", "multiplicity"} <= set(f) for f in freqs)
    assert "operating_point" not in data


def test_info_with_set_and_omega(runner: CliRunner) -> None:
    result = runner.invoke(
        app, ["info", "--set", "omega=2", "--set", "stiffness.sun_planet_mean=7e8", "--json"]
    )
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    gs = preset("sheng2016").evolve({"stiffness.sun_planet_mean": 7e8})  # the default's
    assert data["omega_n_rad_s"] == pytest.approx(gs.omega_n, rel=1e-12)
    assert data["operating_point"]["omega"] == 2.0
    assert data["operating_point"]["sun_speed_rpm"] == pytest.approx(gs.sun_speed_rpm(2.0))


def test_info_human_tables(runner: CliRunner) -> None:
    result = runner.invoke(app, ["info"])
    assert result.exit_code == 0, result.output
    assert "sheng2016" in result.stdout
    assert "Natural frequencies" in result.stdout


def test_info_unknown_key(runner: CliRunner) -> None:
    result = runner.invoke(app, ["info", "--set", "damping.sun_planit=0.1"])
    assert result.exit_code == 2
    assert "did you mean 'damping.sun_planet'" in result.stderr


def test_parse_sets_kinds() -> None:
    omega, changes = parse_sets(
        [
            "omega=1.25",
            "teeth.sun=34",
            "geometry.planets=5.0",
            "xi=0.05",
            "torque.mode=constant_power",
            "backlash.units='m'",
            "stiffness.sun_planet_harmonics=[1e7, -2e6]",
            "stiffness.planet_ring_harmonics=",
            "backlash.sun_planet=3",
            "backlash.sun_planet=4",
        ]
    )
    assert omega == 1.25
    assert changes == {
        "teeth.sun": 34,
        "geometry.planets": 5,
        "xi": 0.05,
        "torque.mode": "constant_power",
        "backlash.units": "m",
        "stiffness.sun_planet_harmonics": (1e7, -2e6),
        "stiffness.planet_ring_harmonics": (),
        "backlash.sun_planet": 4.0,
    }
    assert type(changes["teeth.sun"]) is int
    assert parse_sets([]) == (None, {})


@pytest.mark.parametrize(
    "item", ["teeth.sun=34.5", "xi=much", "omega=nan", "omega=0", "=3", "stiffness.sun_bearing"]
)
def test_parse_sets_rejects(item: str) -> None:
    with pytest.raises(ParameterError):
        parse_sets([item])
