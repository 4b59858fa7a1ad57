"""Every refusal names the option and the way forward (issue 33): ``boundary`` ranges and
landing values, and basin images that would be stored as damaged.

* ``boundary --vary xi=nan:0.04`` said "vary start must be a finite number" and
  ``--within omega=nan:3.5`` was blamed on "vary start": each refusal now starts with its own
  option; a reversed ``--vary`` and ``--at`` values outside its range were silently accepted.
* ``basins`` with an axis of equal or falling values (``--x x=2:2:4``) or with ``--base``
  setting a varied coordinate exited 0 and wrote a store: refused before anything runs.

(``--at`` on a store: :mod:`test_fuzz_loading`.) Every case is a test with its expected class
(see :mod:`fuzz_helpers`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from fuzz_helpers import cli_refused, inside, refused

import gearchaos as gc
from gearchaos.dynamics.continuation.branch import save_branch
from gearchaos.dynamics.continuation.events import events
from gearchaos.dynamics.curves.boundary import boundary_curve

#: The single-mesh backlash oscillator with constant stiffness (ε = 0): its branch over
#: Ω = 0.6 … 0.72 grazes once (the closed form of tests/dynamics/curves/test_curves.py).
OSCILLATOR = {"zeta": 0.05, "f_alt": 0.1, "f_mean": 0.1}


@pytest.fixture(scope="module")
def grazing(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The oscillator, its grazing event (at ε = 0) and the branch as a file."""
    system = gc.backlash_oscillator(1.0, **OSCILLATOR)
    branch = gc.continuation(system, "omega=0.6:0.72")
    (event,) = [e for e in events(branch) if e.kind == "grazing"]
    path = tmp_path_factory.mktemp("grazing") / "branch.nc"
    save_branch(branch, path)
    return {"system": system, "event": event, "path": path}


#: (boundary_curve keywords, the keyword the refusal must start with, text it must hold)
BOUNDARY_CASES = [
    ({"vary": "eps=nan:0.04"}, "vary", "start"),
    ({"vary": "eps=0:inf"}, "vary", "stop"),
    ({"vary": ("eps", 0.0, "x")}, "vary", "stop"),
    ({"vary": "eps=0:0.4", "within": "omega=nan:3.5"}, "within", "start"),
    ({"vary": "eps=0:0.4", "within": "omega=0.5:nan"}, "within", "stop"),
    ({"vary": "eps=0:0.4", "within": "zeta=0.5:1"}, "within", "omega"),
    ({"vary": "eps=0.4:0"}, "vary", "eps=0:0.4"),
    ({"vary": "eps=0.4:-0.1"}, "vary", "eps=-0.1:0.4"),
    ({"vary": "eps=0.1:0.4"}, "vary", "eps=0"),
    ({"vary": "eps=0:0.4", "at": [0.9]}, "at", "0.9"),
    ({"vary": "eps=0:0.4", "at": [0.1, -0.2]}, "at", "-0.2"),
    ({"vary": "eps=0:0.4", "at": [float("nan")]}, "at", "finite"),
    ({"vary": "eps=0:0.4", "at": ["x"]}, "at", "eps"),
]


@pytest.mark.parametrize(
    ("keywords", "keyword", "text"), BOUNDARY_CASES, ids=[repr(c[0]) for c in BOUNDARY_CASES]
)
def test_boundary_curve_refuses_ranges_by_their_keyword(
    grazing: dict[str, Any], keywords: dict[str, Any], keyword: str, text: str, tmp_path: Path
) -> None:
    kw = dict(keywords)
    exc = refused(
        "boundary_curve",
        lambda: boundary_curve(grazing["system"], grazing["event"], kw.pop("vary"), **kw),
        keyword,
    )
    assert str(exc).startswith(keyword) and text in str(exc)
    assert getattr(exc, "name", None) == keyword


CLI_CASES = [
    (["--vary", "eps=nan:0.04"], "--vary", "start"),
    (["--vary", "eps=0:0.4", "--within", "omega=nan:3.5"], "--within", "start"),
    (["--vary", "eps=0:0.4", "--within", "omega=0.5:nan"], "--within", "stop"),
    (["--vary", "eps=0.4:0"], "--vary", "eps=0:0.4"),
    (["--vary", "eps=0:0.4", "--at", "0.9"], "--at", "0.9"),
    (["--vary", "eps=0:0.4", "--at", "0.2,-0.1"], "--at", "-0.1"),
    (["--vary", "eps=0:0.4", "--at", "nan"], "--at", "finite"),
]


@pytest.mark.parametrize(
    ("args", "option", "text"), CLI_CASES, ids=[" ".join(c[0]) for c in CLI_CASES]
)
def test_boundary_command_refuses_ranges_by_their_option(
    grazing: dict[str, Any], args: list[str], option: str, text: str, tmp_path: Path
) -> None:
    """``--vary xi=nan:0.04`` said "vary start must be a finite number", ``--within
    omega=nan:3.5`` was blamed on "vary start", reversed ranges and --at values outside the
    range ran."""
    cmd = ["boundary", "--from", str(grazing["path"]), "--event", "grazing1", *args, "-o", "c.nc"]
    with inside(tmp_path):
        line = cli_refused("CLI boundary", cmd, option)
    assert line.startswith(f"error: {option}") and text in line


# ----------------------------------------------------------------------------- basin images
DUFFING = "gearchaos.model.library:Duffing"
BASIN_CLI = ["basins", "--model", DUFFING, "--set", "alpha=-1", "--set", "omega=1.2",
             "--transient", "1", "--periods", "2", "--sample", "2", "-q",
             "-o", "b.zarr"]  # fmt: skip
#: (x, y, base_state, the keyword named, text of the way forward)
BASIN_CASES = [
    ("x=2:2:4", "x_dot=-1:1:2", None, "x", "x=1:3:4"),
    ("x=2:-2:3", "x_dot=-1:1:2", None, "x", "x=-2:2:3"),
    ("x=1,0,2", "x_dot=-1:1:2", None, "x", "increasing order"),
    ("x=-2:2:3", "x_dot=1:1:2", None, "y", "x_dot=0:2:2"),
    ("x=-2:2:3", "x_dot=1,1", None, "y", "distinct"),
    ("x=-2:2:3", "x_dot=-1:1:2", {"x": 1.0}, "base_state", "leave x out"),
    ("x=-2:2:3", "x_dot=-1:1:2", {"x_dot": 0.0}, "base_state", "leave x_dot out"),
]


@pytest.mark.parametrize(("x", "y", "base", "keyword", "way"), BASIN_CASES)
def test_basins_refuses_an_image_it_would_store_as_damaged(
    x: str, y: str, base: Any, keyword: str, way: str, tmp_path: Path
) -> None:
    """An axis of equal or falling values, or a base state that sets a varied coordinate,
    ran and wrote a store; refused before anything is written, naming the keyword or option
    and how to give it."""
    system = gc.duffing(1.2, alpha=-1.0)
    store = tmp_path / "b.zarr"
    exc = refused(
        "basins",
        lambda: gc.basins(
            system,
            x,
            y,
            base_state=base,
            store=store,
            progress=False,
            transient_periods=1,
            periods=2,
            sample=2,
        ),
        keyword,
    )
    assert way in str(exc) and getattr(exc, "name", None) == keyword
    assert not store.exists()
    option = {"x": "--x", "y": "--y", "base_state": "--base"}[keyword]
    args = [*BASIN_CLI, "--x", x, "--y", y]
    if base is not None:
        args += [f"--base={k}={v}" for k, v in base.items()]
    with inside(tmp_path / "cli"):
        line = cli_refused("CLI basins", args, option)
    assert line.startswith(f"error: {option}") and way in line
