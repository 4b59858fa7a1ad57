"""``plot.figure_for`` (issue 36, item 6): one front door from what was loaded to its figure,
shared by ``gearchaos plot`` and the explorer.

For each kind of source — a simulation result, a sweep store, a response store (its response
curves, its contact chart, its diagram with ``sections``), continued branches, boundary curves
alone and over their map, a basin store — the figure of :func:`figure_for` is, pixel for
pixel, the figure of the plotting function that ``gearchaos plot`` called for it before the
command handed the choice over (named here, not derived from ``figure_for``), and the figure
the command saves now.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app
from gearchaos.dynamics.continuation.cascade import open_cascade
from gearchaos.dynamics.continuation.events import events
from gearchaos.dynamics.curves.file import open_curve
from gearchaos.plot import FigureOptions, figure_for
from gearchaos.sweep._basin_store import open_basins
from gearchaos.sweep.result import SweepResult


def _png(fig: Any, path: Path) -> np.ndarray:
    """The pixels of ``fig`` written as a PNG by :func:`gearchaos.plot.savefig`."""
    from matplotlib.image import imread

    from gearchaos.plot import savefig

    if path.exists():
        path.unlink()  # a figure of gearchaos: replaced anyway, but start clean
    savefig(fig, path)
    return imread(path)


def _saved_by_command(args: list[str], path: Path) -> np.ndarray:
    """The pixels of the figure ``gearchaos plot ARGS -o PATH`` writes."""
    from matplotlib.image import imread

    if path.exists():
        path.unlink()
    result = CliRunner().invoke(app, ["plot", *map(str, args), "-o", str(path)])
    assert result.exit_code == 0, result.output
    return imread(path)


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and bool(np.array_equal(a, b))


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("figure_for")
    s = gc.backlash_oscillator(1.0, zeta=0.05, f_alt=0.1, f_mean=0.1)
    out = {k: root / n for k, n in (("sweep", "sweep.zarr"), ("map", "map.zarr"),
                                     ("response", "response.zarr"), ("branch", "branch.nc"),
                                     ("gears", "gears.zarr"),
                                     ("curve", "pd.nc"), ("basins", "basins.zarr"))}  # fmt: skip
    gc.bifurcation(
        s, "omega=1.3:1.6:7", transient_periods=60, periods=8, progress=False, store=out["sweep"]
    )
    gc.bifurcation(
        s, ["omega=1.3:1.6:6", "eps=0.1:0.2:2"], transient_periods=60, periods=8,
        progress=False, store=out["map"],
    )  # fmt: skip
    gc.response(
        s, "omega=1.3:1.6:4", transient_periods=30, periods=6, progress=False,
        store=out["response"],
    )  # fmt: skip
    gc.response(
        gc.preset("sheng2016-v1"), "omega=0.5:3.5:7", transient_periods=20, periods=16,
        progress=False, store=out["gears"],
    )  # fmt: skip
    branch = gc.continuation(s, "omega=1.1:1.6", store=out["branch"])
    pd = next(e for e in events(branch) if e.kind == "period_doubling")
    gc.boundary_curve(s, pd, "eps=0:0.3", store=out["curve"])
    duffing = gc.duffing(1.0, delta=0.3, alpha=-1.0, beta=1.0, gamma=0.1)
    gc.basins(
        duffing, "x=-1.5:1.5:4", "x_dot=-1.5:1.5:4", transient_periods=30, periods=8,
        progress=False, store=out["basins"],
    )  # fmt: skip
    return out


def test_each_source_gets_the_figure_the_plot_command_drew(files, tmp_path) -> None:
    from gearchaos.plot.amplitude import amplitude_figure
    from gearchaos.plot.basins import basins_figure
    from gearchaos.plot.branch import branch_figure
    from gearchaos.plot.contact import contact_figure
    from gearchaos.plot.maps import sweep_figure
    from gearchaos.plot.response import response_figure
    from gearchaos.plot.stability import stability_figure

    sweep = SweepResult.open(files["sweep"])
    mapped = SweepResult.open(files["map"])
    response = SweepResult.open(files["response"])
    gears = SweepResult.open(files["gears"])
    branches = list(open_cascade(files["branch"]))
    curves = [open_curve(files["curve"])]
    basins = open_basins(files["basins"])
    cases = [  # (figure_for, what the command drew before, the command's arguments)
        (figure_for(sweep), sweep_figure(sweep, var="delta_sp", planet=1), [files["sweep"]]),
        (
            figure_for(sweep, clearance_lines=True, branches=branches),
            sweep_figure(sweep, var="delta_sp", clearance_lines=True, branches=branches),
            [files["sweep"], "--clearance-lines", "--branch", files["branch"]],
        ),
        (figure_for(response), response_figure(response), [files["response"]]),
        (
            figure_for(response, sections=True),
            sweep_figure(response, var="delta_sp"),
            [files["response"], "--sections"],
        ),
        (figure_for(gears), response_figure(gears), [files["gears"]]),
        (
            figure_for(gears, contact=True),
            contact_figure(gears),
            [files["gears"], "--contact"],
        ),
        (
            figure_for(response, branches=branches),
            amplitude_figure(response, branches, var=None, planet=1, quantity="amplitude"),
            [files["response"], "--branch", files["branch"]],
        ),
        (figure_for(branches), branch_figure(branches, planet=1), [files["branch"]]),
        (figure_for(curves), stability_figure(curves, None), [files["curve"]]),
        (
            figure_for(mapped, boundaries=curves),
            stability_figure(curves, mapped),
            [files["map"], "--boundaries", files["curve"]],
        ),
        (figure_for(basins), basins_figure(basins), [files["basins"]]),
    ]
    for new, before, args in cases:
        drawn = _png(new, tmp_path / "new.png")
        assert _same(drawn, _png(before, tmp_path / "before.png")), args
        assert _same(drawn, _saved_by_command(args, tmp_path / "command.png")), args


def test_a_simulation_gets_its_summary_or_the_explorers_point_figure(tmp_path) -> None:
    from gearchaos.plot.figure import point_figure, summary_figure

    result = gc.simulate(
        gc.backlash_oscillator(1.2, zeta=0.1, b=1.0, f_mean=0.1, f_alt=1.0),
        transient_periods=20, periods=20, samples_per_period=32,
    )  # fmt: skip
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    assert _same(_png(figure_for(result), a), _png(summary_figure(result), b))
    point = figure_for(result, panels="point", var="x")
    assert _same(_png(point, a), _png(point_figure(result, "x", 1, 10.0), b))


def test_options_that_do_not_apply_are_refused_by_the_callers_names(files) -> None:
    basins = open_basins(files["basins"])
    flags = FigureOptions(var="x", names={"var": "--var"}, where="b.zarr")
    with pytest.raises(gc.ParameterError, match=r"^--var do\(es\) not apply to the basin store"):
        figure_for(basins, flags)
    with pytest.raises(gc.ParameterError, match=r"^var do\(es\) not apply to the basin store"):
        figure_for(basins, var="x")
    branches = list(open_cascade(files["branch"]))
    with pytest.raises(gc.ParameterError, match="sections applies to response stores"):
        figure_for(branches, sections=True)
    with pytest.raises(gc.ParameterError, match="panels must be one of summary, point"):
        FigureOptions(panels="gallery")
