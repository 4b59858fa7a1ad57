"""``gearchaos plot RUN.zarr --branch BRANCH.nc``: the branch is drawn over the sweep's diagram.

The backlash oscillator's 1T branch, continued down from Ω = 2.1, loses stability at a period
doubling (multiplier −1) near Ω ≈ 1.95, where the brute-force sweep underneath turns 2T. The
figure the command writes must show the branch's stable part solid and its unstable part
dashed on the correct sides of the event, and name the event in the legend. The figure object
is caught on its way to the file (``gearchaos.plot.savefig``) and its artists inspected; the
PNG itself is checked to be a real image of the figure's size.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.analysis.branch_events import events
from gearchaos.cli import app

TIGHT = {"rtol": 1e-10, "atol": 1e-12}


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> tuple[Path, Path, float]:
    system = gc.backlash_oscillator(1.0, zeta=0.05, f_alt=0.1, f_mean=0.1)
    root = tmp_path_factory.mktemp("plot_branch")
    run, branch = root / "run.zarr", root / "branch.nc"
    gc.bifurcation(
        system, "omega=1.8:2.1:31", initial_conditions="continuation", direction="down",
        transient_periods=300, periods=16, store=run, progress=False,
    )  # fmt: skip
    ds = gc.continuation(system, "omega=2.1:1.8", store=branch, **TIGHT)
    pd = next(e for e in events(ds) if e.kind == "period_doubling")
    return run, branch, pd.value


def test_plot_draws_the_branch_solid_where_stable_dashed_where_not(files, tmp_path) -> None:
    import matplotlib.image as mpimg

    import gearchaos.plot as gplot

    run, branch, pd = files
    caught = []
    original = gplot.savefig

    def catch(fig, path, *a, **kw):
        caught.append(fig)
        return original(fig, path, *a, **kw)

    out = tmp_path / "fig.png"
    mp = pytest.MonkeyPatch()
    mp.setattr(gplot, "savefig", catch)
    try:
        result = CliRunner().invoke(
            app, ["plot", str(run), "--var", "x", "--branch", str(branch), "-o", str(out)]
        )
    finally:
        mp.undo()
    assert result.exit_code == 0, result.output
    (fig,) = caught
    lines = [
        ln for ax in fig.axes for ln in ax.get_lines() if str(ln.get_gid()).startswith("branch")
    ]
    stable = [ln for ln in lines if ln.get_gid() == "branch:stable"]
    unstable = [ln for ln in lines if ln.get_gid() == "branch:unstable"]
    assert stable and unstable
    assert all(ln.get_linestyle() == "-" for ln in stable)
    assert all(ln.get_linestyle() == "--" for ln in unstable)
    # stable above the period doubling, unstable below it (the joins share one point)
    for ln in stable:
        x, y = np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float)
        assert np.all(x[np.isfinite(y)] >= pd - 0.01)
    for ln in unstable:
        x, y = np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float)
        assert np.all(x[np.isfinite(y)] <= pd + 0.01)
    # the event is marked at its parameter value and named in the legend
    marks = [
        c
        for ax in fig.axes
        for c in ax.collections
        if c.get_gid() == "branch:event:period_doubling"
    ]
    assert marks and np.allclose(marks[0].get_offsets()[:, 0], pd)
    legend_texts = {
        t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()
    }
    assert "PD" in legend_texts
    assert any("stable" in t for t in legend_texts) and any("unstable" in t for t in legend_texts)
    # the file is the figure, rendered
    img = mpimg.imread(out)
    w, h = fig.get_size_inches() * 150  # savefig's resolution
    assert img.shape[0] == pytest.approx(h, abs=2) and img.shape[1] == pytest.approx(w, abs=2)

    assert np.ptp(img[..., :3]) > 0.5  # not a blank image
