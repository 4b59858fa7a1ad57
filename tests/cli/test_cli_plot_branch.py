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
from gearchaos.cli import app
from gearchaos.dynamics.continuation.events import events

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
    assert any("period doubling" in t for t in legend_texts)
    assert any("stable" in t for t in legend_texts) and any("unstable" in t for t in legend_texts)
    # the file is the figure, rendered
    img = mpimg.imread(out)
    w, h = fig.get_size_inches() * 150  # savefig's resolution
    assert img.shape[0] == pytest.approx(h, abs=2) and img.shape[1] == pytest.approx(w, abs=2)

    assert np.ptp(img[..., :3]) > 0.5  # not a blank image


# ------------------------------------------------------------------------- branch files alone
def _caught_figure(args: list[str]):
    """Run ``gearchaos`` with ``args`` and return (result, the figure it saved)."""
    import gearchaos.plot as gplot

    caught = []
    original = gplot.savefig

    def catch(fig, path, *a, **kw):
        caught.append(fig)
        return original(fig, path, *a, **kw)

    mp = pytest.MonkeyPatch()
    mp.setattr(gplot, "savefig", catch)
    try:
        result = CliRunner().invoke(app, args)
    finally:
        mp.undo()
    return result, (caught[0] if caught else None)


def test_plot_draws_a_branch_file_on_its_own(files, tmp_path) -> None:
    """``gearchaos plot branch.nc`` (issue 24: it was refused as 'not a sweep store')."""
    _, branch, pd = files
    out = tmp_path / "alone.png"
    result, fig = _caught_figure(["plot", str(branch), "--var", "x", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert out.exists()
    (ax,) = [a for a in fig.axes if a.get_lines()]
    stable = [ln for ln in ax.get_lines() if ln.get_gid() == "branch:stable"]
    unstable = [ln for ln in ax.get_lines() if ln.get_gid() == "branch:unstable"]
    assert stable and unstable
    for ln in stable:  # stable above the period doubling, unstable below it
        x, y = np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float)
        assert np.all(x[np.isfinite(y)] >= pd - 0.01) and ln.get_linestyle() == "-"
    for ln in unstable:
        x, y = np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float)
        assert np.all(x[np.isfinite(y)] <= pd + 0.01) and ln.get_linestyle() == "--"
    # the event is marked at its value, on the branch, and named in the legend
    (mark,) = [c for c in ax.collections if c.get_gid() == "branch:event:period_doubling"]
    xy = mark.get_offsets()
    assert np.allclose(xy[:, 0], pd)
    x, y = np.asarray(stable[0].get_xdata(), float), np.asarray(stable[0].get_ydata(), float)
    ok = np.isfinite(y)
    assert xy[0, 1] == pytest.approx(np.interp(pd, x[ok], y[ok]), abs=1e-3)
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("period doubling" in t for t in legend)
    # axes with symbols, the model and its fixed values in the title
    assert "Omega" in ax.get_xlabel() and "omega_n" in ax.get_xlabel()
    assert ax.get_ylabel() == "$x$"
    title = fig.get_suptitle()
    assert "backlash_oscillator" in title and r"$\zeta$ = 0.05" in title
    assert "rtol 1e\N{MINUS SIGN}10" in title  # the branch's solver setting (a true minus)


def test_plot_draws_several_branch_files_apart(files, tmp_path) -> None:
    _, branch, _ = files
    from gearchaos.dynamics import open_branch

    system = gc.backlash_oscillator(1.0, zeta=0.05, f_alt=0.1, f_mean=0.1)
    (event,) = [e for e in events(open_branch(branch)) if e.kind == "period_doubling"]
    two = tmp_path / "two.nc"
    gc.continuation(system, "omega=2.1:1.8", start=event, store=two, **TIGHT)
    out = tmp_path / "both.png"
    result, fig = _caught_figure(["plot", str(branch), str(two), "--var", "x", "-o", str(out)])
    assert result.exit_code == 0, result.output
    (ax,) = [a for a in fig.axes if a.get_lines()]
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert len(legend) == len(set(legend))  # every entry tells its branch apart
    assert any("branch.nc" in t and "period-1" in t for t in legend)
    assert any("two.nc" in t and "period-2" in t for t in legend)
    # the period-2 branch has two section values per point: two lines per stability
    colours = {ln.get_color() for ln in ax.get_lines() if str(ln.get_gid()).startswith("branch")}
    assert len(colours) == 2
    # a sweep store among the positional paths is refused with the way to overlay
    result = CliRunner().invoke(app, ["plot", str(files[0]), str(two), "-o", str(out)])
    assert result.exit_code == 2 and "--branch" in result.output


# ---------------------------------------------------------- the clearance swept and continued
def test_branch_over_a_backlash_diagram_is_drawn_relative_to_the_backlash(tmp_path) -> None:
    """A diagram swept in the clearance b draws x − b (issue 24: with --branch it silently
    switched to x, and the branch was drawn in x). Below grazing (Ω = 0.5 < 0.709) the teeth
    never separate: x − b = F_m + F_a Ω²|H| cos(−arg(1 − Ω² + 2iζΩ)) for every b (MODEL.md
    §10.5), so diagram and branch lie on that constant."""
    zeta, omega = 0.05, 0.5
    system = gc.backlash_oscillator(1.0, zeta=zeta, f_alt=0.1, f_mean=0.1)
    run = tmp_path / "b.zarr"
    gc.bifurcation(
        system, "b=0.5:1.5:11", params={"omega": omega}, transient_periods=300, periods=4,
        store=run, progress=False,
    )  # fmt: skip
    up, down = tmp_path / "up.nc", tmp_path / "down.nc"
    gc.continuation(system, "b=0.5:1.5", omega=omega, store=up, **TIGHT)
    gc.continuation(system, "b=1.5:0.5", omega=omega, store=down, **TIGHT)
    den = 1 - omega**2 + 2j * zeta * omega
    expected = 0.1 + 0.1 * omega**2 / abs(den) * np.cos(-np.angle(den))
    out = tmp_path / "fig.png"
    args = ["plot", str(run), "--var", "x", "--branch", str(up), "--branch", str(down)]
    result, fig = _caught_figure([*args, "-o", str(out)])
    assert result.exit_code == 0, result.output
    ax = next(a for a in fig.axes if a.get_ylabel())
    assert ax.get_ylabel() == "$x - b$"
    dots = np.concatenate([c.get_offsets()[:, 1] for c in ax.collections if c.get_gid() is None])
    assert np.allclose(dots, expected, atol=1e-6)
    lines = [ln for ln in ax.get_lines() if ln.get_gid() == "branch:stable"]
    assert len(lines) == 2
    for ln in lines:
        y = np.asarray(ln.get_ydata(), float)
        assert np.allclose(y[np.isfinite(y)], expected, atol=1e-6)
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert len(legend) == len(set(legend))
    assert any("up.nc" in t for t in legend) and any("down.nc" in t for t in legend)
