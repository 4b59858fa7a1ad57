"""``gearchaos basins``, ``basin-fractions`` and ``plot`` of their stores."""

from __future__ import annotations

import json

import numpy as np
from typer.testing import CliRunner

from gearchaos.cli import app

MODEL = ["--model", "gearchaos.model.library:Duffing", "--set", "alpha=-1", "--set", "gamma=0"]
SHORT = ["--transient", "40", "--periods", "8"]


def test_basins_command_json_and_plot(tmp_path):
    out = tmp_path / "b.zarr"
    args = ["--set", "omega=1", "--x", "x=-1.5:1.5:6", "--y", "x_dot=-1.5:1.5:6", *SHORT]
    r = CliRunner().invoke(app, ["basins", *MODEL, *args, "-o", str(out), "--json"])
    assert r.exit_code == 0, r.output
    res = json.loads(r.stdout)
    assert res["starts"] == 36 and res["failed"] == 0
    found = sorted(res["attractors"], key=lambda a: a["share"])
    assert [a["label"] for a in found] == ["1T", "1T"]
    assert sum(a["share"] for a in found) == 1.0 and found[0]["share"] == 0.5  # odd system
    png = tmp_path / "b.png"
    r = CliRunner().invoke(app, ["plot", str(out), "-o", str(png)])
    assert r.exit_code == 0, r.output
    assert png.stat().st_size > 10_000
    r = CliRunner().invoke(app, ["plot", str(out), "-o", str(png), "--var", "x"])
    assert r.exit_code == 2 and "--var" in r.output


def test_basin_fractions_command(tmp_path):
    out = tmp_path / "f.zarr"
    args = ["--set", "omega=1", "--vary", "delta=0.3,0.4", "--starts", "20", "--box",
            "x=0.4:1.3", "--box", "x_dot=-0.25:0.25", *SHORT]  # fmt: skip
    r = CliRunner().invoke(app, ["basin-fractions", *MODEL, *args, "-o", str(out), "--json"])
    assert r.exit_code == 0, r.output
    rows = json.loads(r.stdout)["fractions"]
    assert [row["fraction"] for row in rows] == [1.0, 1.0]  # below the barrier: the right well
    assert all(row["high"] == 1.0 and row["low"] < 1.0 for row in rows)
    assert np.all([row["attractor"].startswith("1T (x ≈ 1,") for row in rows])
    r = CliRunner().invoke(app, ["plot", str(out), "-o", str(tmp_path / "f.png")])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(app, ["basin-fractions", *MODEL, "--vary", "delta=0.3", "--box",
                                 "x=1", "-o", str(tmp_path / "g.zarr")])  # fmt: skip
    assert r.exit_code == 2 and "--box must be STATE=LOW:HIGH" in r.output


#: Twin-well Duffing with chaotic transients of hundreds of periods onto its one stable 1T
#: (tests/dynamics/attractors/test_basins.py checks that against scipy).
TRANSIENT = [*MODEL[:4], "--set", "delta=0.15", "--set", "omega=1"]


def test_confirm_periods_reach_the_verdict_and_the_store(tmp_path):
    from gearchaos.sweep.basins import open_basins

    grid = ["--set", "gamma=0.32", "--x", "x=-2:2:4", "--y", "x_dot=-2:2:4"]
    box = ["--vary", "gamma=0.32", "--starts", "16", "--seed", "1", "--box", "x=-2:2", "--box",
           "x_dot=-2:2"]  # fmt: skip
    found = {}
    for confirm in ([], ["--confirm-periods", "0"]):
        key = "0" if confirm else "default"
        out = tmp_path / f"b{key}.zarr"
        r = CliRunner().invoke(app, ["basins", *TRANSIENT, *grid, *confirm, "-o", str(out),
                                     "--json"])  # fmt: skip
        assert r.exit_code == 0, r.output
        image = {a["label"] for a in json.loads(r.stdout)["attractors"]}
        assert open_basins(out).attrs["confirm_periods"] == (0 if confirm else 2000)
        out = tmp_path / f"f{key}.zarr"
        r = CliRunner().invoke(app, ["basin-fractions", *TRANSIENT, *box, *confirm, "-o",
                                     str(out), "--json"])  # fmt: skip
        assert r.exit_code == 0, r.output
        shares = {row["attractor"].split(" ")[0] for row in json.loads(r.stdout)["fractions"]}
        assert open_basins(out).attrs["confirm_periods"] == (0 if confirm else 2000)
        found[key] = (image, shares)
    # two windows of 100 periods take a chaotic transient for an attractor; 2000 do not
    assert found["0"] == ({"1T", "chaos"}, {"1T", "chaos"})
    assert found["default"] == ({"1T"}, {"1T"})
    r = CliRunner().invoke(app, ["basins", *TRANSIENT, *grid, "--confirm-periods", "-1", "-o",
                                 str(tmp_path / "bad.zarr")])  # fmt: skip
    assert r.exit_code == 2 and "--confirm-periods" in r.output and ">= 0" in r.output
