"""``gearchaos boundary`` and ``gearchaos plot MAP --boundaries``: the stability chart from the
command line (a period-doubling curve of sheng2016 in (Ω, ξ))."""

from __future__ import annotations

import json

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app
from gearchaos.dynamics.continuation.events import events

runner = CliRunner()


@pytest.fixture(scope="module")
def curve_file(tmp_path_factory):
    where = tmp_path_factory.mktemp("boundary")
    branch = where / "branch.nc"
    # sheng2016-v1's period doubling near Ω = 3.4 (the recalibrated default is 1T there)
    args = ["continue", "--preset", "sheng2016-v1", "--vary", "omega=3.3:3.45", "-o", str(branch)]
    got = runner.invoke(app, args)
    assert got.exit_code == 0, got.output
    pd = next(e for e in events(gc.open_branch(branch)) if e.kind == "period_doubling")
    curve = where / "pd.nc"
    args = ["boundary", "--from", str(branch), "--event", "pd1", "--vary", "xi=0.02:0.035",
            "--within", "omega=3.2:3.7", "--at", "0.025", "-o", str(curve), "--json"]  # fmt: skip
    got = runner.invoke(app, args)
    assert got.exit_code == 0, got.output
    return where, curve, pd, json.loads(got.stdout)


def test_boundary_command_writes_the_curve_with_provenance(curve_file) -> None:
    _, path, pd, summary = curve_file
    ds = gc.open_curve(path)
    assert summary["kind"] == "period_doubling" and summary["parameter2"] == "xi"
    # the gear set of the first point (at its ξ), as branch files record it
    stored = gc.GearSet.from_toml_string(ds.attrs["gearset_toml"])
    assert stored.name == gc.preset("sheng2016-v1").name  # the branch's gear set
    assert "version" in ds.attrs and "rtol" in ds.attrs
    # it starts at the branch's event (ξ = 0.03) and lands on ξ = 0.025 on both sides
    assert np.isclose(ds.omega.values[ds.direction.values == 0][0], pd.value, atol=1e-7)
    assert (ds.on_grid.values == 1).sum() == 2
    # by default the two landed points state their uncertainty, no other point does
    assert summary["uncertainty"]["assessed"] == 2 and ds.attrs["assessed"] == "landed"
    assert np.isfinite(ds.uncertainty.values).sum() == 2
    assert 0 < summary["uncertainty"]["max"] < 1e-6 and summary["uncertainty"]["max2"] == 0.0


def test_boundary_refuses_unknown_events_by_name(curve_file) -> None:
    where, *_ = curve_file
    got = runner.invoke(
        app, ["boundary", "--from", str(where / "branch.nc"), "--event", "fold1", "--vary",
              "xi=0.02:0.04", "-o", str(where / "x.nc")],
    )  # fmt: skip
    assert got.exit_code != 0 and "0 fold events" in got.output
    got = runner.invoke(
        app, ["boundary", "--from", str(where / "branch.nc"), "--vary", "xi=0.02:0.04",
              "--assess", "some", "-o", str(where / "y.nc")], env={"COLUMNS": "200"},
    )  # fmt: skip
    assert got.exit_code != 0
    assert "'--assess'" in got.output
    assert "'some' is not one of 'landed', 'all', 'none'" in got.output


@pytest.fixture(scope="module")
def map_store(curve_file):
    where, *_ = curve_file
    store = where / "map.zarr"
    gc.bifurcation(
        gc.preset("sheng2016-v1"), ["omega=3.3:3.6:7", "xi=0.02:0.035:3"],
        transient_periods=30, periods=8, progress=False, store=store,
    )  # fmt: skip
    return store


def test_plot_boundaries_over_a_map_and_alone(curve_file, map_store) -> None:
    where, curve, *_ = curve_file
    store = map_store
    for args in (
        ["plot", str(store), "--boundaries", str(curve), "-o", str(where / "chart.png")],
        ["plot", str(curve), "-o", str(where / "alone.png")],
    ):
        got = runner.invoke(app, args)
        assert got.exit_code == 0, got.output
        assert (where / args[-1].rsplit("/", 1)[-1]).stat().st_size > 10_000
    from gearchaos.cli.boundary import boundaries_figure
    from gearchaos.sweep.result import SweepResult

    fig = boundaries_figure([curve], SweepResult.open(str(store)))
    ax = fig.axes[0]
    assert [ln.get_gid() for ln in ax.lines] == ["boundary:period_doubling"]
    # the sun speed in rpm opposite Ω
    assert any("rpm" in a.get_xlabel() for a in fig.axes[1:] + ax.child_axes)


def test_the_explorer_draws_the_curves_over_the_map(curve_file, map_store) -> None:
    """Issue 26, item 6: the explorer shows the boundaries over a 2-D map when a curve file is
    given — the line is the curve's own (Ω, ξ) points, named by its kind; a 1-D store or a
    curve of other parameters is refused."""
    from gearchaos.explore import explore

    where, curve, *_ = curve_file
    ex = explore(map_store, boundaries=[curve])
    fig = ex._map_figure()
    (line,) = [r for r in fig.renderers if r.name == "boundary-0"]
    cv = gc.open_curve(curve)
    np.testing.assert_array_equal(line.data_source.data["x"], cv["omega"].values)
    np.testing.assert_array_equal(line.data_source.data["y"], cv["xi"].values)
    labels = [item.label["value"] for item in fig.legend[0].items]
    assert "period doubling" in labels
    one_d = where / "line.zarr"
    gc.bifurcation(gc.preset("sheng2016-v1"), "omega=3.3:3.6:3", transient_periods=10, periods=4,
                   progress=False, store=one_d)  # fmt: skip
    with pytest.raises(gc.ParameterError, match="2-D sweep"):
        explore(one_d, boundaries=[curve])
