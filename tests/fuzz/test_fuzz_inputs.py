"""Fuzzing what the newer commands take in (issue 33): sizes and time spans checked before
anything is allocated or integrated, a user's model file that fails to load, and refusals that
name the option.

* **Time spans** beyond the floating-point resolution of the time variable: a run of
  ``transient_periods + periods`` forcing periods ends at τ = span·T, where the integrator's
  finest step is 16 ε τ (its ``STEP_UNDERFLOW`` bound); once that exceeds
  :data:`~gearchaos.integrate.settings.TIME_RESOLUTION` of a period the run is refused up front
  naming the setting (``--transient``), instead of failing at τ = 0 with ``STEP_UNDERFLOW``.
* **A model's parameters**: a field set to NaN is refused by its name; a ``pack`` that returns
  text is refused naming ``pack``.
* **A failed integration** names options the command line has (``--rtol``), not only the
  Python keyword ``max_steps``.
* **Grids of starts** (``basins``, ``basin-fractions``) whose starts would not fit in memory
  are refused before anything is allocated, naming ``--x`` or ``--starts``.

Every case is a test with its expected class (see :mod:`fuzz_helpers`): a refusal (exit 2, one
``error:`` line naming the culprit) or a failure (exit 1); never a traceback, never accepted.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from fuzz_helpers import cli_refused, inside, refused

import gearchaos as gc
from gearchaos.integrate.settings import MAX_SPAN_PERIODS, TIME_RESOLUTION, SolverSettings

BASE = gc.preset("hindawi2021")
DUFFING = "gearchaos.model.library:Duffing"

#: A user model (the forced Duffing oscillator) as a file; ``{pack}`` is its pack's body.
MODEL = """
import math
from dataclasses import dataclass

import numba
import numpy as np

from gearchaos.model.contract import UserModel


@numba.njit(cache=True)
def rhs(t, y, p, dydt, obs, level):
    dydt[0] = y[1]
    dydt[1] = p[4] * math.cos(p[0] * t) - p[1] * y[1] - p[2] * y[0] - p[3] * y[0] ** 3
    obs[0] = y[0]
    obs[1] = y[1]


@dataclass(frozen=True)
class Oscillator(UserModel):
    delta: float = 0.3
    alpha: float = -1.0
    beta: float = 1.0
    gamma: float = 0.5
    name = "oscillator"
    state_names = ("x", "x_dot")
    obs_names = ("x", "x_dot")
    n_track = 1
    rhs = rhs

    def pack(self, omega):
        {pack}
"""
GOOD_PACK = "return np.array([omega, self.delta, self.alpha, self.beta, self.gamma])"


_SERIAL = itertools.count()


def model_file(folder: Path, stem: str, text: str) -> str:
    """``--model`` of a new model file holding ``text`` in ``folder``, named ``stem`` and a
    serial number (a file is imported as a module of its name, once per process)."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{stem}_{next(_SERIAL)}.py"
    path.write_text(text, encoding="utf-8")
    return f"{path}:Oscillator"


# ----------------------------------------------------------------------------- time spans
def test_the_span_bound_is_the_time_resolution() -> None:
    """16 ε · span = TIME_RESOLUTION at the bound (ε of float64, the kernel's 16 ε τ)."""
    eps = float(np.finfo(np.float64).eps)
    assert math.isclose(16 * eps * MAX_SPAN_PERIODS, TIME_RESOLUTION, rel_tol=1e-12)
    SolverSettings(transient_periods=MAX_SPAN_PERIODS - 300, periods=200).check_span()
    with pytest.raises(gc.ParameterError, match="transient_periods"):
        SolverSettings(transient_periods=MAX_SPAN_PERIODS, periods=200).check_span()
    with pytest.raises(gc.ParameterError, match="section_phase"):
        SolverSettings(section_phase=4 * math.pi * MAX_SPAN_PERIODS).check_span()


@pytest.mark.filterwarnings("ignore:MAX_STEPS")
def test_a_span_within_the_bound_integrates() -> None:
    """At 99 % of the bound the time variable still resolves the first steps from rest: the run
    goes on until its step budget ends (MAX_STEPS), never STEP_UNDERFLOW at τ = 0 (as 3e8
    periods did)."""
    res = gc.simulate(
        BASE, omega=1.5, transient_periods=0.99 * MAX_SPAN_PERIODS, periods=1, max_steps=2000,
        check=False,
    )  # fmt: skip
    assert res.status is gc.Status.MAX_STEPS


#: Doors that take a time span; each refuses one beyond the bound naming the setting.
SPAN_DOORS = {
    "SolverSettings.check_span": lambda kw: SolverSettings(**kw).check_span(),
    "simulate": lambda kw: gc.simulate(BASE, omega=1.5, **kw),
    "simulate (reference system)": lambda kw: gc.simulate(gc.duffing(1.2), **kw),
    "max_lyapunov": lambda kw: gc.max_lyapunov(gc.duffing(1.2), **kw),
    "bifurcation": lambda kw: gc.bifurcation(BASE, "omega=1:2:2", progress=False, **kw),
}


@pytest.mark.parametrize("door", sorted(SPAN_DOORS))
@pytest.mark.parametrize(
    ("setting", "value"),
    [("transient_periods", 1e9), ("transient_periods", 3e6), ("periods", 3 * 10**6)],
)
def test_a_span_beyond_the_time_resolution_is_refused(
    door: str, setting: str, value: float, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    kw = {"transient_periods": 1, "periods": 2, "samples_per_period": 1, setting: value}
    refused(door, lambda: SPAN_DOORS[door](kw), setting)
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (["simulate", "--set", "omega=1.5", "--transient", "1e9"], "--transient"),
        (["simulate", "--set", "omega=1.5", "--transient", "3e6"], "--transient"),
        (
            ["simulate", "--set", "omega=1.5", "--periods", "3000000", "--samples-per-period", "1"],
            "--periods",
        ),
        (["bifurcation", "-v", "omega=1:2:2", "-o", "b.zarr", "--transient", "1e9"], "--transient"),
        (["orbit", "--set", "omega=1.5", "--transient", "1e9"], "--transient"),
    ],
)
def test_cli_refuses_a_span_beyond_the_time_resolution(
    args: list[str], option: str, tmp_path: Path
) -> None:
    """``simulate --transient 1e9`` stopped with "STEP_UNDERFLOW … at tau=0"."""
    with inside(tmp_path):
        text = cli_refused(f"CLI {args[0]}", args, option)
    assert option in text and "resolves" in text


# ----------------------------------------------------------------------------- failed runs
def test_a_run_out_of_steps_names_options_the_cli_has(tmp_path: Path) -> None:
    """A stiff oscillator (ω₀ = 10⁶ per unit time: steps of ~10⁻⁶ against a period of 4.2)
    exhausts the step budget; the message names --rtol/--atol, which simulate has, not only
    ``max_steps``, which it has not."""
    gc.simulate(gc.duffing(1.5), transient_periods=0, periods=1)  # compiled before the clock
    args = ["simulate", "--model", DUFFING, "--set", "alpha=1e12", "--transient", "0",
            "--periods", "1", "--no-verdict"]  # fmt: skip
    with inside(tmp_path):
        text = cli_refused("CLI simulate", args, "--rtol", codes=(1,))
    assert "MAX_STEPS" in text and "--atol" in text


def test_samples_do_not_exhaust_the_step_budget(tmp_path: Path) -> None:
    """``simulate --samples-per-period 100000`` stopped after 47 s with "MAX_STEPS … raise
    max_steps": every sample ended a step, and 100 000 samples a period outran the budget of
    50 000 steps a period. 200 000 samples of one period (budget 150 000 steps) complete, on
    the same steps as one sample a period."""
    from typer.testing import CliRunner

    from gearchaos.cli import app

    one = gc.simulate(gc.duffing(1.2), transient_periods=0, periods=1, samples_per_period=1)
    many = gc.simulate(gc.duffing(1.2), transient_periods=0, periods=1, samples_per_period=200_000)
    assert many.status is gc.Status.OK and many.steps_accepted == one.steps_accepted
    args = ["simulate", "--model", DUFFING, "--set", "omega=1.2", "--transient", "0",
            "--periods", "1", "--samples-per-period", "200000", "--no-verdict",
            "--json"]  # fmt: skip
    with inside(tmp_path):
        result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output


# ----------------------------------------------------------------------------- model parameters
@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_a_model_parameter_that_is_not_finite_is_named(value: str, tmp_path: Path) -> None:
    """The refusal named no parameter ("packed parameters contain NaN or inf")."""
    spec = model_file(tmp_path / "m", "c33_nan_model", MODEL.format(pack=GOOD_PACK))
    with inside(tmp_path / "run"):
        cli_refused("CLI simulate", ["simulate", "--model", spec, "--set", f"gamma={value}"],
                    "gamma")  # fmt: skip
    from gearchaos.model import load_model_class

    cls = load_model_class(spec)
    refused("System", lambda: gc.System(cls(gamma=float(value)), 1.2), "gamma")


@pytest.mark.parametrize(
    "pack",
    [
        'return np.array(["a", "b"])',
        'return "omega"',
        "return None",
        "return np.zeros((2, 2))",
        'return [omega, "0.3", self.alpha, self.beta, self.gamma]',
    ],
)
def test_a_pack_that_gives_no_vector_of_numbers_is_refused(pack: str, tmp_path: Path) -> None:
    spec = model_file(tmp_path / "m", "c33_pack_model", MODEL.format(pack=pack))
    with inside(tmp_path / "run"):
        text = cli_refused("CLI simulate", ["simulate", "--model", spec, "--json"], "pack")
    assert "Oscillator.pack(omega) must return a vector of numbers" in text


# ----------------------------------------------------------------------------- grids of starts
#: A basin image and basin fractions of 10¹² starts or more: no machine holds their starts
#: (36 bytes a start of the Duffing oscillator), so each is refused before anything is made.
HUGE_GRIDS = {
    "basins": (
        lambda: gc.basins(gc.duffing(1.2), "x=-2:2:1000000", "x_dot=-2:2:1000000", progress=False),
        "x",
    ),
    "basin_fractions": (
        lambda: gc.basin_fractions(
            gc.duffing(1.2), "gamma=0.1:0.2:1000000", starts=10_000_000, progress=False
        ),
        "starts",
    ),
}


@pytest.mark.parametrize("door", sorted(HUGE_GRIDS))
def test_a_grid_of_starts_beyond_memory_is_refused_before_allocating(
    door: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``basins --x x=…:…:1000000 --y …:10000`` tried to allocate 7.28 TiB."""
    monkeypatch.chdir(tmp_path)
    call, keyword = HUGE_GRIDS[door]
    exc = refused(door, call, "memory")
    assert getattr(exc, "name", None) == keyword and "TiB" in str(exc)


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (["basins", "--x", "x=-2:2:1000000", "--y", "x_dot=-2:2:1000000"], "--x"),
        (["basin-fractions", "--vary", "gamma=0.1:0.2:1000000", "--starts", "10000000"],
         "--starts"),
    ],
)  # fmt: skip
def test_cli_refuses_a_grid_of_starts_beyond_memory(
    args: list[str], option: str, tmp_path: Path
) -> None:
    full = [*args, "--model", DUFFING, "--set", "omega=1.2", "-o", "b.zarr", "-q"]
    with inside(tmp_path):
        text = cli_refused(f"CLI {args[0]}", full, option)
    assert text.startswith(f"error: {option}") and "memory" in text
