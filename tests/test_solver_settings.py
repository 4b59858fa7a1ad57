"""Invalid solver settings are refused the same way at every entry point (issue 9): the Python
front doors (simulate, bifurcation, the sweep specification, Poincaré galleries, the
calibration) and the commands (simulate, bifurcation, poincare), each message naming the
setting, the rule and the value — before anything is computed or written."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app
from gearchaos.errors import ParameterError
from gearchaos.integrate import SolverSettings
from gearchaos.paper.calibrate import SweepSettings
from gearchaos.paper.galleries import run_gallery
from gearchaos.sweep import SweepSpec

#: (setting, invalid value, the words the message must contain)
INVALID = [
    ("rtol", -1.0, "rtol must be a finite number >= 1e-14: got -1.0"),
    ("rtol", 0.0, "rtol must be a finite number >= 1e-14: got 0.0"),
    ("rtol", math.nan, "rtol must be a finite number in [1e-14, 0.1]: got nan"),
    ("rtol", 2.0, "rtol must be a finite number <= 0.1: got 2.0"),
    # issue 23: 0.5 ran and flipped the contact regime; the docstring's limit is 0.1
    ("rtol", 0.5, "rtol must be a finite number <= 0.1: got 0.5"),
    ("rtol", "1e-8", "rtol must be a finite number in [1e-14, 0.1]: got '1e-8' (str)"),
    ("atol", math.nan, "atol must be a finite number in (0, 1]: got nan"),
    ("atol", 0.0, "atol must be a finite number > 0: got 0.0"),
    ("atol", -1.0, "atol must be a finite number > 0: got -1.0"),
    ("atol", math.inf, "atol must be a finite number in (0, 1]: got inf"),
    ("periods", 0, "periods must be an integer >= 1: got 0"),
    ("periods", True, "periods must be an integer in [1, 1000000000]: got True (bool)"),
    ("transient_periods", -1.0, "transient_periods must be a finite number >= 0: got -1.0"),
    ("transient_periods", 1e308, "transient_periods must be a finite number <= 1e+09: got 1e+308"),
]
IDS = [f"{name}={value!r}" for name, value, _ in INVALID]


@pytest.fixture(scope="module")
def gs() -> gc.GearSet:
    return gc.preset("hindawi2021")


@pytest.mark.parametrize(("name", "value", "message"), INVALID, ids=IDS)
def test_python_entry_points_refuse_identically(
    gs: gc.GearSet, tmp_path: Path, name: str, value: object, message: str
) -> None:
    calls = {
        "SolverSettings": lambda: SolverSettings(**{name: value}),
        "simulate": lambda: gc.simulate(gs, omega=1.5, **{name: value}),
        "bifurcation": lambda: gc.bifurcation(
            gs, "omega=1,2", store=tmp_path / "x.zarr", progress=False, **{name: value}
        ),
        "SweepSpec.build": lambda: SweepSpec.build("omega=1:2:3", **{name: value}),
        "lyapunov_spectrum": lambda: gc.dynamics.lyapunov_spectrum(
            gc.planetary_system(gs, 1.5), **{name: value}
        ),
        "calibrate settings": lambda: SweepSettings(**{name: value}),
    }
    calls["run_gallery"] = lambda: run_gallery(gs, "omega", [1.5], progress=False, **{name: value})
    for where, call in calls.items():
        with pytest.raises(ParameterError) as info:
            call()
        assert message in str(info.value), where
    assert not (tmp_path / "x.zarr").exists()


CLI_INVALID = [
    ("--rtol", "-1", "--rtol: rtol must be a finite number >= 1e-14: got -1.0"),
    ("--rtol", "nan", "--rtol: rtol must be a finite number in [1e-14, 0.1]: got nan"),
    ("--rtol", "0", "--rtol: rtol must be a finite number >= 1e-14: got 0.0"),
    ("--atol", "nan", "--atol: atol must be a finite number in (0, 1]: got nan"),
    ("--atol", "-1", "--atol: atol must be a finite number > 0: got -1.0"),
    ("--periods", "0", "--periods: periods must be an integer >= 1: got 0"),
    ("--transient", "-2", "--transient: transient_periods must be a finite number >= 0: got -2.0"),
]


@pytest.mark.parametrize(("option", "value", "message"), CLI_INVALID, ids=lambda x: str(x))
def test_commands_refuse_identically(tmp_path: Path, option: str, value: str, message: str) -> None:
    runner = CliRunner()
    commands = {
        "simulate": ["simulate", "--json"],
        "bifurcation": ["bifurcation", "--vary", "omega=1,2", "-o", str(tmp_path / "b.zarr")],
        "poincare": ["poincare", "--vary", "omega=1,2", "-o", str(tmp_path / "g.png")],
    }
    for name, args in commands.items():
        result = runner.invoke(app, [*args, option, value])
        assert result.exit_code == 2, (name, result.output)
        assert message in result.stderr, name
        assert "Traceback" not in result.output
    assert list(tmp_path.iterdir()) == []
