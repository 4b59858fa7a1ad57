"""``gearchaos orbit`` and ``gearchaos attractors`` in the model's own words (issue 36): the
section values are keyed ``section`` with the model's ``section_variable`` in the JSON, and the
tables name that variable by the model's symbol: X̄_sp1 for the planetary gear set, q̄_1 for the
two-frequency train of ``tests/two_frequency_train.py`` (stages meshing at Ω and 3Ω/5,
T = 5·2π/Ω), whose output names nothing planetary."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app
from gearchaos.model import System
from two_frequency_train import TwoFrequencyTrain

MODEL = f"{Path(__file__).parents[1] / 'two_frequency_train.py'}:TwoFrequencyTrain"
#: Words and symbols of the planetary model that the train's output must not show.
PLANETARY = re.compile(r"planet|sun|ring|sp1|X̄|x_sp|mesh|b_c|gear set", re.IGNORECASE)
#: A short attractor search: the start at rest and one random start.
SHORT = ["--starts", "2", "--transient", "20", "--periods", "20"]


@pytest.fixture(scope="module")
def runner() -> CliRunner:
    return CliRunner()


def _run(runner: CliRunner, *args: str) -> str:
    result = runner.invoke(app, list(args), env={"COLUMNS": "200"})  # no wrapped headers
    assert result.exit_code == 0, result.output
    return result.stdout


@pytest.fixture(scope="module")
def settled() -> list[float]:
    """The train's section values of x_1 at Ω = 0.5 from a long simulation from rest: its
    stable orbit (largest |μ| ≈ 0.09) one point per period T, reached to rounding."""
    res = gc.simulate(System(TwoFrequencyTrain(), 0.5), transient_periods=40, periods=4)
    x = res.section("x_1")
    assert max(x) - min(x) < 1e-10  # one point: the motion has the period T = 5·2π/Ω
    return [float(v) for v in x]


def test_a_user_models_orbit_is_keyed_and_labelled_by_its_own_variable(
    runner: CliRunner, settled: list[float]
) -> None:
    out = json.loads(_run(runner, "orbit", "--model", MODEL, "--set", "omega=0.5", "--json"))
    assert "x_sp1" not in out
    assert out["converged"] and out["section_variable"] == "x_1"
    # the orbit's section value is where a simulation from rest settles (x_1 is the state y_0)
    assert out["section"] == pytest.approx(settled[:1], abs=1e-8)
    ref = gc.periodic_orbit(System(TwoFrequencyTrain(), 0.5), period=1)
    assert out["section"] == pytest.approx([float(ref.state[0])], abs=1e-8)
    assert not PLANETARY.search(json.dumps(out))
    table = _run(runner, "orbit", "--model", MODEL, "--set", "omega=0.5")
    assert "q̄_1 at the section" in table and f"{settled[0]:.6g}" in table
    assert "contact stage1" in table and "contact stage2" in table
    assert not PLANETARY.search(table), table
    # an orbit that settles longer says so in the model's periods (not "mesh periods")
    table = _run(runner, "orbit", "--model", MODEL, "--set", "omega=1.2")
    assert "q̄_1 at the section" in table and "train periods from rest" in table
    assert not PLANETARY.search(table), table


def test_a_user_models_attractors_are_keyed_and_labelled_by_its_own_variable(
    runner: CliRunner, settled: list[float]
) -> None:
    args = ["attractors", "--model", MODEL, "--set", "omega=0.5", *SHORT]
    found = json.loads(_run(runner, *args, "--json"))
    assert [a["label"] for a in found] == ["1T"]  # both starts settle on the stable orbit
    (item,) = found
    assert "x_sp1" not in item and item["section_variable"] == "x_1"
    assert item["section"] == pytest.approx(settled[:1], abs=1e-6)  # rounded to 6 decimals
    assert not PLANETARY.search(json.dumps(found))
    table = _run(runner, *args)
    assert "q̄_1 at the section" in table
    assert not PLANETARY.search(table), table


def test_the_planetary_orbit_keeps_its_symbol_and_its_section_values(runner: CliRunner) -> None:
    args = ["orbit", "--set", "omega=1.5", "--set", "xi=0.03"]
    out = json.loads(_run(runner, *args, "--json"))
    assert out["section_variable"] == "delta_sp_1"
    # the orbit's own X̄_sp1, planet 1 of its (n, N) section values of the group delta_sp
    ref = gc.periodic_orbit(gc.preset("sheng2016"), period=1, params={"omega": 1.5, "xi": 0.03})
    assert ref.converged
    assert out["section"] == pytest.approx(list(ref.section("delta_sp")[:, 0]), abs=1e-8)
    table = _run(runner, *args)
    assert "X̄_sp1 at the section" in table
    assert f"{out['section'][0]:.6g}" in table


def test_the_planetary_attractors_keep_their_symbol(runner: CliRunner) -> None:
    args = ["attractors", "--set", "omega=0.5", *SHORT, "--confirm-periods", "50"]
    found = json.loads(_run(runner, *args, "--json"))
    assert found and all(a["section_variable"] == "delta_sp_1" for a in found)
    table = _run(runner, *args)
    assert "X̄_sp1 at the section" in table


def test_a_user_models_bifurcation_counts_its_own_periods(
    runner: CliRunner, tmp_path: Path
) -> None:
    """The bifurcation table's protocol line counts the train's periods T = 5·2π/Ω ("train
    periods"), not a gear set's mesh periods, and names nothing planetary; the store holds two
    points, each with the protocol's 20 section points."""
    store = tmp_path / "train.zarr"
    text = _run(
        runner, "bifurcation", "--model", MODEL, "--vary", "omega=0.5:0.6:2",
        "--transient", "20", "--periods", "20", "--no-verdicts", "-o", str(store),
    )  # fmt: skip
    assert "20 transient + 20 recorded train periods" in text
    assert not PLANETARY.search(text), text
    ds = gc.open_sweep(store)
    assert ds.sizes["omega"] == 2 and ds["x"].sizes["section"] == 20
    # its tables name the members stages (x_stage1), not planets (x_p1)
    assert ds.attrs["member_name"] == "stage"
    _run(runner, "export", str(store), "-o", str(tmp_path / "train.csv"))
    header = (tmp_path / "train.csv").read_text().splitlines()[0].split(",")
    assert "x_max_stage1" in header and "x_min_stage2" in header
    assert not [c for c in header if c.endswith(("_p1", "_p2"))], header
    sections = (tmp_path / "train.sections.csv").read_text().splitlines()[0].split(",")
    assert "x_stage1" in sections and "x_p1" not in sections
