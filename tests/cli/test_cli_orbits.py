"""``gearchaos orbit`` and ``gearchaos continue`` from the command line: the JSON the issue fixes,
multipliers consistent with their definition, refusals that name the option, and a branch
file whose events sit where its multipliers cross the unit circle."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from gearchaos.cli import app

KEYS = {
    "period",
    "minimal_period",
    "converged",
    "residual",
    "stable",
    "stability_margin",
    "max_multiplier",
    "multipliers",
    "section_variable",
    "section",
    "contact",
    "message",
}


@pytest.fixture(scope="module")
def runner() -> CliRunner:
    return CliRunner()


def test_orbit_json_has_exactly_the_documented_keys(runner: CliRunner) -> None:
    result = runner.invoke(app, ["orbit", "--set", "omega=1.5", "--set", "xi=0.03", "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert set(out) == KEYS
    assert out["period"] == 1 and out["converged"] is True
    assert out["residual"] < 1e-6
    mus = out["multipliers"]
    assert len(mus) == 16  # one per state of the N = 5 planetary model
    for mu in mus:
        assert mu["abs"] == pytest.approx(math.hypot(mu["re"], mu["im"]), rel=1e-12)
    absolute = [mu["abs"] for mu in mus]
    # sorted by modulus, largest first (a conjugate pair's moduli differ by rounding only)
    assert all(a >= b - 1e-12 for a, b in itertools.pairwise(absolute))
    # one stability criterion with its margin stated (10⁻⁴, as documented): five planets
    # leave no multiplier structural, so stable means every |μ| < 1 − margin
    assert out["stability_margin"] == 1e-4
    assert out["stable"] is (max(absolute) < 1.0 - out["stability_margin"])
    # complex multipliers of a real monodromy matrix come in conjugate pairs
    z = np.array([complex(mu["re"], mu["im"]) for mu in mus])
    assert np.sort_complex(z) == pytest.approx(np.sort_complex(np.conj(z)), abs=1e-9)
    # a period-1 orbit has one section value per planet at the section
    assert len(out["section"]) == 1


@pytest.mark.parametrize("period", ["0", "65"])
def test_orbit_period_out_of_range_is_refused(runner: CliRunner, period: str) -> None:
    result = runner.invoke(app, ["orbit", "--period", period])
    assert result.exit_code != 0
    assert "--period" in result.output and period in result.output


def test_continue_requires_vary_and_a_known_suffix(runner: CliRunner, tmp_path: Path) -> None:
    result = runner.invoke(app, ["continue", "-o", str(tmp_path / "b.nc")])
    assert result.exit_code != 0 and "--vary" in result.output
    result = runner.invoke(app, ["continue", "--vary", "omega=1:2", "-o", str(tmp_path / "b.txt")])
    assert result.exit_code != 0 and ".nc or .zarr" in result.output


def test_continue_writes_a_branch_whose_events_bracket_stability_changes(
    runner: CliRunner, tmp_path: Path
) -> None:
    path = tmp_path / "branch.nc"
    result = runner.invoke(
        app,
        [
            "continue",
            "--vary",
            "omega=1.47:1.56",
            "--set",
            "xi=0.03",
            "--max-points",
            "60",
            "-o",
            str(path),
            "--json",
        ],
    )
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert summary["points"] > 2 and path.exists()
    with xr.open_dataset(path) as ds:
        stable = ds["stable"].values.astype(bool)
        mx = ds["max_multiplier"].values
        # the stored flag is the definition: every |μ| < 1
        assert np.array_equal(stable, mx < 1.0)
        lam = ds[ds.attrs["parameter"]].values
        points = list(ds["event_point"].values) if "event" in ds.dims else []
        # every change of stability along the branch is explained by a detected event there
        flips = np.flatnonzero(stable[1:] != stable[:-1])
        for k in flips:
            near = [p for p in points if abs(int(p) - int(k)) <= 1]
            assert near, f"stability changes after point {k} (Ω = {lam[k]:.4f}) with no event"
