"""``gearchaos continue --cascade`` and the charts of ``gearchaos plot`` (issue 26, 3 and 5)."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from gearchaos.cli import app
from gearchaos.dynamics.continuation.cascade import open_cascade

MODEL = ["--model", "gearchaos.model.library:BacklashOscillator", "--set", "b=1",
         "--set", "zeta=0.05", "--set", "f_alt=0.1", "--set", "f_mean=0.1"]  # fmt: skip


def test_continue_cascade_writes_every_branch_and_lists_their_events(tmp_path) -> None:
    runner = CliRunner()
    path = tmp_path / "cascade.nc"
    out = runner.invoke(
        app, ["continue", *MODEL, "--vary", "omega=2.1:1.8", "--cascade", "2", "-o", str(path),
              "--json"],
    )  # fmt: skip
    assert out.exit_code == 0, out.output
    summary = json.loads(out.stdout)
    assert summary["period"] == 1
    assert [b["period"] for b in summary["cascade"]] == [2, 4]
    assert [b["parent"] for b in summary["cascade"]] == ["branch_0", "branch_1"]
    pd1 = [e["value"] for e in summary["events"] if e["kind"] == "period_doubling"]
    assert summary["cascade"][0]["parent_value"] == pytest.approx(pd1[0])
    assert all(b["events"] for b in summary["cascade"])
    assert [int(b.attrs["period"]) for b in open_cascade(path)] == [1, 2, 4]
    png = tmp_path / "cascade.png"
    drawn = runner.invoke(app, ["plot", str(path), "-o", str(png)])
    assert drawn.exit_code == 0, drawn.output
    assert png.stat().st_size > 0


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--cascade", "1", "-o", "{tmp}/b.zarr"], "--output must end in .nc"),
        (["--cascade-all", "-o", "{tmp}/b.nc"], "--cascade-all needs --cascade"),
    ],
)
def test_continue_cascade_refusals(tmp_path, extra, message) -> None:
    args = [a.replace("{tmp}", str(tmp_path)) for a in extra]
    out = CliRunner().invoke(app, ["continue", *MODEL, "--vary", "omega=2.1:1.8", *args])
    assert out.exit_code != 0
    assert message in out.output


def test_plot_draws_impact_maps_and_response_with_branches(tmp_path) -> None:
    import gearchaos as gc

    runner = CliRunner()
    store = tmp_path / "map.zarr"
    gc.bifurcation(
        gc.preset("sheng2016-v1"), ["omega=0.6:2.4:4", "backlash.sun_planet=0.5:4:3"],
        transient_periods=20, periods=8, progress=False, store=store,
    )  # fmt: skip
    png = tmp_path / "impact.png"
    out = runner.invoke(app, ["plot", str(store), "--impact", "planet_ring", "-o", str(png)])
    assert out.exit_code == 0, out.output
    assert png.stat().st_size > 0
    bad = runner.invoke(app, ["plot", str(store), "--impact", "ring", "-o", str(png)])
    assert bad.exit_code != 0 and "mesh must be one of" in bad.output
    system = gc.backlash_oscillator(1.0, zeta=0.05, f_alt=0.1, f_mean=0.1)
    resp = tmp_path / "resp.zarr"
    gc.response(system, "omega=0.9:1.1:3", progress=False, store=resp)
    branch = tmp_path / "branch.nc"
    gc.continuation(system, "omega=0.9:1.1", store=branch)
    png = tmp_path / "amplitude.png"
    out = runner.invoke(app, ["plot", str(resp), "--branch", str(branch), "-o", str(png)])
    assert out.exit_code == 0, out.output
    assert png.stat().st_size > 0
    force = tmp_path / "force.png"
    args = ["plot", str(resp), "--branch", str(branch), "-o", str(force), "--quantity"]
    out = runner.invoke(app, [*args, "force_peak"])
    assert out.exit_code == 0, out.output
    assert force.stat().st_size > 0
    # refused by name where it does not apply or is not a quantity, never ignored
    for bad, message in (
        ([*args, "force"], "'force' is not one of 'amplitude', 'force_peak'"),
        (["plot", str(resp), "-o", str(force), "--quantity", "force_peak"], "--quantity applies"),
        (["plot", str(branch), "-o", str(force), "--quantity", "amplitude"], "--quantity applies"),
    ):
        out = runner.invoke(app, bad, env={"COLUMNS": "200"})  # the refusal on one line
        assert out.exit_code != 0 and message in out.output, out.output
        assert "--quantity" in out.output
