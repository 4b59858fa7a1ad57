"""Fuzzing what ``--model`` and ``--from`` load (issue 33): a user's model file that fails while
it is imported, and data files with a missing or malformed attribute.

* **A model file** that raises, has a syntax error, imports a missing module or calls
  ``sys.exit`` when imported gave a traceback (or, for ``sys.exit``, exit 3 and nothing at all,
  so ``--json`` output was no JSON and no error): now one ``error:`` line naming the file, the
  line and the exception; what the file prints goes to stderr.
* **An orbit or branch file** without ``omega``, with ``period = "abc"`` (``KeyError: 'omega'``
  in ``cli/_start.py``), ``period = 0`` (silently accepted), a short or non-finite state
  ("guess must be a vector of 16 entries", naming neither the file nor ``--from``), a junk
  ``gearset_toml`` or ``fixed``: one line naming ``--from``, the file and the attribute.
* **``--at`` on a store**: ``--at omega=1.33333`` names the stored 4/3, which the refusal
  prints as 1.33333; every value a refusal lists is accepted when typed back.

Every case is a test with its expected class (see :mod:`fuzz_helpers`).
"""

from __future__ import annotations

import itertools
import json
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fuzz_helpers import cli_refused, inside, refused
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app
from gearchaos.cli._start import load_start
from gearchaos.dynamics.continuation.branch import save_branch
from gearchaos.dynamics.orbits.file import save_orbit
from gearchaos.model import load_model_class

_SERIAL = itertools.count()

# ----------------------------------------------------------------------------- model files
#: Model files that fail while imported: (body, the line that fails, the exception's name).
BROKEN_MODELS = {
    "raises": ("x = 1\nraise RuntimeError('boom at import')\n", 2, "RuntimeError"),
    "syntax error": ("x = 1\ndef f(:\n    pass\n", 2, "SyntaxError"),
    "missing import": ("import math\nimport not_a_module_of_c33\n", 2, "ModuleNotFoundError"),
    "sys.exit": ("import sys\n\nsys.exit(3)\n", 3, "sys.exit(3)"),
    "prints, then raises": (
        "print('hello from the model')\nraise ValueError('bad\\nvalue')\n",
        2,
        "ValueError",
    ),
    "deep in a function": (
        "def build():\n    return {}['key']\n\n\nMODEL = build()\n",
        2,
        "KeyError",
    ),
}


def _model_file(folder: Path, kind: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"c33_broken_{next(_SERIAL)}.py"
    path.write_text(BROKEN_MODELS[kind][0], encoding="utf-8")
    return path


@pytest.mark.parametrize("kind", sorted(BROKEN_MODELS))
@pytest.mark.parametrize("command", ["simulate", "orbit", "bifurcation"])
def test_a_model_file_that_fails_to_import_is_one_line(
    kind: str, command: str, tmp_path: Path
) -> None:
    """File, line and exception in one ``error:`` line; stdout empty, so --json is no half
    output."""
    path = _model_file(tmp_path / "models", kind)
    _, line, exception = BROKEN_MODELS[kind]
    args = [command, "--model", f"{path}:Oscillator", "--json"]
    if command == "bifurcation":
        args += ["-v", "omega=1:2:2", "-o", "b.zarr"]
    with inside(tmp_path / "run"):
        text = cli_refused(f"CLI {command}", args, str(path))
        result = CliRunner().invoke(app, args)
    assert f"{path}, line {line}" in text and exception in text, text
    assert result.stdout == "", "the model's own output reached stdout"


@pytest.mark.parametrize("kind", sorted(BROKEN_MODELS))
def test_load_model_class_refuses_a_failing_file_in_one_line(kind: str, tmp_path: Path) -> None:
    path = _model_file(tmp_path, kind)
    exc = refused("load_model_class", lambda: load_model_class(f"{path}:Oscillator"), str(path))
    assert f"line {BROKEN_MODELS[kind][1]}" in str(exc)


def test_a_module_named_by_import_path_that_fails_is_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--model MODULE:CLASS`` of an importable module that raises (it was caught only as an
    ImportError), and of a module that does not exist."""
    name = f"c33_module_{next(_SERIAL)}"
    (tmp_path / f"{name}.py").write_text("import math\n\nmath.sqrt(-1)\n", encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    with inside(tmp_path / "run"):
        text = cli_refused("CLI simulate", ["simulate", "--model", f"{name}:M"], name)
        assert f"{name}.py, line 3" in text and "ValueError: math domain error" in text
        text = cli_refused("CLI simulate", ["simulate", "--model", "no_module_c33:M"], "no_module")
        assert "ModuleNotFoundError" in text


# ----------------------------------------------------------------------------- data files
@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """An orbit file and a branch file of the Duffing oscillator, and a sweep store over
    Ω = 1 … 2 in 4 values (1, 4/3, 5/3, 2)."""
    root = tmp_path_factory.mktemp("c33_files")
    system = gc.duffing(1.2)
    orbit = gc.periodic_orbit(system, period=1, transient_periods=20)
    assert orbit.converged
    branch = gc.continuation(system, "omega=1.2:1.3", max_points=4, transient_periods=20)
    store = root / "s.zarr"
    gc.bifurcation(
        gc.duffing(1.0), "omega=1:2:4", transient_periods=1, periods=2, store=store,
        progress=False,
    )  # fmt: skip
    omega = np.asarray(branch["omega"].values)
    return {
        "orbit": Path(save_orbit(orbit, root / "orbit.nc")),
        "branch": Path(save_branch(branch, root / "branch.nc")),
        "store": store,
        "branch_at": f"omega={float(np.median(omega)):.10g}",
    }


def _set_attrs(path: Path, changes: dict[str, Any]) -> None:
    """Change (None: delete) root attributes of a netCDF file in place."""
    import h5py

    with h5py.File(path, "a") as f:
        for key, value in changes.items():
            if value is None:
                del f.attrs[key]
            else:
                f.attrs[key] = value


def _rewrite(path: Path, change: Any) -> None:
    """Rewrite a netCDF file with ``change(dataset)`` applied."""
    import xarray as xr

    ds = change(xr.load_dataset(path, engine="h5netcdf"))
    path.unlink()
    ds.to_netcdf(path, engine="h5netcdf", invalid_netcdf=True)


def _nan_state(ds: Any) -> Any:
    ds["orbit_state"].values[..., 0] = np.nan
    return ds


#: (file, damage, the attribute the refusal must name); a damage is attribute changes or a
#: rewrite of the dataset.
DAMAGE: list[tuple[str, str, Any, str]] = [
    ("orbit", "no omega", {"omega": None}, "omega"),
    ("orbit", "omega = 'abc'", {"omega": "abc"}, "omega"),
    ("orbit", "omega = nan", {"omega": np.nan}, "omega"),
    ("orbit", "omega = -1", {"omega": -1.0}, "omega"),
    ("orbit", "no period", {"period": None}, "period"),
    ("orbit", "period = 'abc'", {"period": "abc"}, "period"),
    ("orbit", "period = 0", {"period": np.int64(0)}, "period"),
    ("orbit", "period = -3", {"period": np.int64(-3)}, "period"),
    ("orbit", "period = 1.5", {"period": 1.5}, "period"),
    ("orbit", "period = 10**6", {"period": np.int64(10**6)}, "period"),
    ("orbit", "section_phase = 'abc'", {"section_phase": "abc"}, "section_phase"),
    ("orbit", "transient_periods = -1", {"transient_periods": -1.0}, "transient_periods"),
    ("orbit", "parameter:omega = [1, 2]", {"parameter:omega": np.array([1.0, 2.0])}, "omega"),
    ("orbit", "parameter:gamma = 'abc'", {"parameter:gamma": "abc"}, "gamma"),
    ("orbit", "short state", lambda ds: ds.isel(state=slice(0, 1)), "orbit_state"),
    ("orbit", "state NaN", _nan_state, "orbit_state"),
    ("branch", "no fixed", {"fixed": None}, "fixed"),
    ("branch", "fixed = '{'", {"fixed": "{"}, "fixed"),
    ("branch", "fixed = '[1]'", {"fixed": "[1]"}, "fixed"),
    ("branch", "parameter = 'nope'", {"parameter": "nope"}, "parameter"),
    ("branch", "period = 0", {"period": np.int64(0)}, "period"),
    ("branch", "period = 'abc'", {"period": "abc"}, "period"),
    ("branch", "state NaN", _nan_state, "orbit_state"),
]


@pytest.mark.filterwarnings("ignore:You are writing invalid netcdf features")
@pytest.mark.parametrize(
    ("kind", "damage", "change", "attribute"),
    DAMAGE,
    ids=[f"{k}: {d}" for k, d, *_ in DAMAGE],
)
@pytest.mark.parametrize("command", ["orbit", "continue"])
def test_a_damaged_attribute_of_a_from_file_is_named(
    files: dict[str, Any],
    kind: str,
    damage: str,
    change: Any,
    attribute: str,
    command: str,
    tmp_path: Path,
) -> None:
    path = tmp_path / f"{kind}.nc"
    path.write_bytes(files[kind].read_bytes())
    if callable(change):
        _rewrite(path, change)
    else:
        _set_attrs(path, change)
    at = ["--at", files["branch_at"]] if kind == "branch" else []
    args = {
        "orbit": ["orbit", "--from", str(path), *at, "--json"],
        "continue": [
            "continue",
            "--from",
            str(path),
            *at,
            "--vary",
            "omega=1.25:1.3",
            "-o",
            "b.nc",
            "--max-points",
            "3",
            "-q",
        ],
    }[command]
    with inside(tmp_path / "run"):
        text = cli_refused(f"CLI {command}", args, str(path))
    assert "--from" in text and attribute in text, text
    with inside(tmp_path / "api"):
        where = files["branch_at"] if kind == "branch" else None
        exc = refused("load_start", lambda: load_start(str(path), where), str(path))
    assert attribute in str(exc)


def test_the_undamaged_files_start(files: dict[str, Any]) -> None:
    """The damage above must be what is refused: the files as written give starts."""
    start = load_start(str(files["orbit"]), None)
    assert start.period == 1 and start.values["omega"] == 1.2 and start.state.shape == (2,)
    start = load_start(str(files["branch"]), files["branch_at"])
    assert start.period == 1 and f"omega={start.values['omega']:.10g}" == files["branch_at"]


# ----------------------------------------------------------------------------- --at on a store
@pytest.mark.parametrize(
    ("text", "value"),
    [("1.33333", 4 / 3), ("1.333333333333", 4 / 3), ("1.66667", 5 / 3), ("2", 2.0), ("1", 1.0)],
)
def test_at_names_a_stored_value_at_the_printed_precision(
    files: dict[str, Any], text: str, value: float
) -> None:
    """The store's Ω axis is linspace(1, 2, 4): 4/3 and 5/3 are named by their 6 digits."""
    start = load_start(str(files["store"]), f"omega={text}")
    assert start.values["omega"] == pytest.approx(value, rel=1e-15)


@pytest.mark.parametrize("text", ["1.3", "1.333", "1.6667", "1.5", "0.5", "2.5"])
def test_at_between_stored_values_lists_values_that_are_accepted(
    files: dict[str, Any], text: str
) -> None:
    exc = refused("load_start", lambda: load_start(str(files["store"]), f"omega={text}"), "--at")
    listed = re.search(r"nearest stored values are ([^:]+):", str(exc))
    assert listed, str(exc)
    for shown in listed.group(1).split(", "):
        load_start(str(files["store"]), f"omega={shown}")  # each listed value is a point
    with inside(Path(files["store"]).parent / f"at{next(_SERIAL)}"):
        cli_refused("CLI orbit", ["orbit", "--from", str(files["store"]), "--at", f"omega={text}"],
                    "--at")  # fmt: skip


def test_store_start_keeps_its_identity(files: dict[str, Any]) -> None:
    """The start from the store is the stored point itself (its final state), not a nearby
    value: the record the sweep wrote at Ω = 4/3."""
    start = load_start(str(files["store"]), "omega=1.33333")
    ds = gc.open_sweep(files["store"])
    stored = np.asarray(ds["final_state"].sel(omega=4 / 3, method="nearest").values).reshape(-1)
    np.testing.assert_array_equal(start.state, stored)
    assert json.dumps(start.values["omega"]) == json.dumps(4 / 3)
