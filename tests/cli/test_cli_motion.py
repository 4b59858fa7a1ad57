"""``gearchaos classify | poincare | simulate --lyapunov | bifurcation --lyapunov | reproduce
fig5``: regime tables, motion labels and Poincaré galleries from the command line."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import GALLERY_FIGURES, PAPER_FIGURES, app

#: the gear set whose Ω = 0.5 is a 1T response below resonance (the recalibrated default is
#: chaotic there: its meshes separate and hit their back flanks)
V1 = ["--preset", "sheng2016-v1"]


@pytest.fixture(scope="module")
def runner() -> CliRunner:
    return CliRunner()


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """8-point Ω sweep of sheng2016 with two damping ratios: 100 recorded periods, so the
    0-1 test runs on every point without a period."""
    path = tmp_path_factory.mktemp("motion") / "run.zarr"
    gc.bifurcation(
        gc.preset("hindawi2021"),
        "omega=0.5:2.5:8",
        family={"xi": [0.03, 0.09]},
        transient_periods=20,
        periods=100,
        store=str(path),
        progress=False,
    )
    return path


# --------------------------------------------------------------------------- classify
def test_classify_prints_the_regime_table(runner: CliRunner, store: Path) -> None:
    result = runner.invoke(app, ["classify", str(store)])
    assert result.exit_code == 0, result.output
    out = result.stdout
    assert "regime" in out
    assert "ξ = 0.03" in out and "ξ = 0.09" in out
    assert "%" in out
    labels = {str(v) for v in np.asarray(xr.open_zarr(store)["motion"].values).ravel()}
    for label in labels:
        assert label in out


def test_classify_json_fractions_sum_to_one_per_family_value(
    runner: CliRunner, store: Path
) -> None:
    result = runner.invoke(app, ["classify", str(store), "--json", "--rtol", "1e-3"])
    assert result.exit_code == 0, result.output
    table = json.loads(result.stdout)
    assert list(table) == ["xi=0.03", "xi=0.09"]
    motion = np.asarray(xr.open_zarr(store)["motion"].values)  # (xi, omega)
    for k, (key, fractions) in enumerate(table.items()):
        assert sum(fractions.values()) == pytest.approx(1.0)
        # each fraction counts the stored labels of that family value
        for label, f in fractions.items():
            assert f == pytest.approx(np.mean(motion[k] == label)), key
    assert json.loads(xr.open_zarr(store).attrs["regime_table"]) == table


def test_classify_reports_bad_input(runner: CliRunner, store: Path, tmp_path: Path) -> None:
    for args, needle in [
        (["classify", str(tmp_path / "missing.zarr")], "store not found"),
        (["classify", str(store), "--rtol", "0"], "--rtol"),
        (["classify", str(store), "--max-period", "0"], "--max-period"),
    ]:
        result = runner.invoke(app, args)
        assert result.exit_code == 2, args
        assert needle in result.stderr
        assert "Traceback" not in result.output


def test_bifurcation_lyapunov_stores_lle_and_prints_the_regime_table(
    runner: CliRunner, tmp_path: Path
) -> None:
    path = tmp_path / "lle.zarr"
    sweep = ["bifurcation", *V1, "--vary", "omega=0.5,1.5", "--transient", "10", "--periods", "20"]
    sweep.append("--lyapunov")
    result = runner.invoke(
        app,
        [*sweep, "-o", str(path), "--quiet"],
    )
    assert result.exit_code == 0, result.output
    ds = xr.open_zarr(path)
    assert ds["lle"].dims == ("omega",)
    assert float(ds["lle"].sel(omega=0.5)) < 0  # the 1T response below resonance
    result = runner.invoke(
        app,
        [*sweep, "-o", str(path)],
    )
    assert result.exit_code == 0, result.output
    assert "motion regimes" in result.stdout
    assert "all points" in result.stdout


# --------------------------------------------------------------------------- simulate
def test_simulate_lyapunov_json_labels_the_1t_response(runner: CliRunner) -> None:
    # sheng2016-v1 at Ω = 0.5 (below the first resonance): one section point, no separation
    args = ["simulate", *V1, "--set", "omega=0.5", "--transient", "20", "--periods", "100"]
    # the verdict (default): a stable orbit by shooting, λ₁ = ln max|μ| / T exactly
    result = runner.invoke(app, [*args, "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert data["motion"] == "1T" and data["evidence"] == "floquet"
    assert 0 < data["max_multiplier"] < 1 and data["lle_error"] == 0
    assert data["lle"] == pytest.approx(math.log(data["max_multiplier"]) / (2 * math.pi / 0.5))
    human = runner.invoke(app, args).stdout
    assert "decided by" in human and "floquet" in human and "(exact)" in human
    # from the record alone: λ₁ only with --lyapunov, the indicators in the table
    result = runner.invoke(app, [*args, "--no-verdict", "--lyapunov", "--json"])
    data = json.loads(result.stdout)
    # (the record's own label is named as such, never the motion: issue 32)
    assert data["motion"] is None and data["record_label"] == "1T"
    assert data["evidence"] == "record"
    assert data["lle"] is not None and data["lle"] < 0
    assert data["indicators_agree"] is True
    plain = json.loads(runner.invoke(app, [*args, "--no-verdict", "--json"]).stdout)
    assert plain["lle"] is None and plain["motion"] is None and plain["record_label"] == "1T"
    human = runner.invoke(app, [*args, "--no-verdict", "--lyapunov"]).stdout
    assert "λ₁" in human and "0–1 test K" in human and "indicators agree" in human


# --------------------------------------------------------------------------- poincare
def test_poincare_writes_one_panel_per_value(
    runner: CliRunner, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import gearchaos.plot as gplot

    figures: list = []
    save = gplot.savefig

    def keep(fig, path, **kwargs):
        figures.append(fig)
        return save(fig, path, **kwargs)

    monkeypatch.setattr(gplot, "savefig", keep)
    png = tmp_path / "gallery.png"
    values = [0.5, 1.5, 2.62]
    result = runner.invoke(
        app,
        [
            *("poincare", *V1, "--vary", "omega=" + ",".join(map(str, values))),
            *("--transient", "20", "--periods", "100", "-o", str(png), "--json"),
        ],
    )
    assert result.exit_code == 0, result.output
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    data = json.loads(result.stdout)
    assert data["figure"] == str(png) and data["param"] == "omega"
    assert [r["value"] for r in data["rows"]] == values
    for r in data["rows"]:
        assert set(r) >= {"value", "motion", "lle", "k01", "distinct_section_points"}
        assert r["status"] == "ok"
    assert data["rows"][0]["motion"] == "1T" and data["rows"][0]["lle"] < 0
    (fig,) = figures
    panels = [a for a in fig.axes if a.get_visible() and a.get_title(loc="left").startswith("(")]
    assert len(panels) == len(values)
    for ax, r in zip(panels, data["rows"], strict=True):
        assert f"· {r['motion']} ·" in ax.get_title(loc="left")


def test_poincare_varies_a_dotted_parameter_with_extra_rows(
    runner: CliRunner, tmp_path: Path
) -> None:
    png = tmp_path / "g.png"
    result = runner.invoke(
        app,
        [
            *("poincare", "--vary", "backlash.sun_planet=2,4", "--set", "omega=0.5"),
            *("--transient", "10", "--periods", "20", "--with", "phase,spectrum", "-o", str(png)),
        ],
    )
    assert result.exit_code == 0, result.output
    assert png.stat().st_size > 0
    assert "b̄_sp" in result.stdout and "motion" in result.stdout


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["-o", "g.png"], "--vary is required"),
        (["--vary", "omega=1,2"], "--output is required"),
        (["--vary", "omega=1,2", "-o", "g.gif"], "--output must end"),
        (["--vary", "omega=1,2", "--set", "omega=1", "-o", "g.png"], "both varied and set"),
        (["--vary", "omega=1,2", "--with", "orbit", "-o", "g.png"], "--with"),
        (["--vary", "backlash.sun_plnet=1,2", "-o", "g.png"], "backlash.sun_planet"),
    ],
)
def test_poincare_reports_bad_input(
    runner: CliRunner, tmp_path: Path, args: list[str], needle: str
) -> None:
    args = [a if a != "g.png" else str(tmp_path / "g.png") for a in args]
    result = runner.invoke(app, ["poincare", *args])
    assert result.exit_code == 2
    assert needle in result.stderr
    assert "Traceback" not in result.output
    assert not (tmp_path / "g.png").exists()


# --------------------------------------------------------------------------- reproduce
def test_reproduce_knows_the_galleries() -> None:
    assert set(GALLERY_FIGURES) == {"fig5", "fig7", "fig10"}
    assert set(GALLERY_FIGURES) <= set(PAPER_FIGURES)


def test_reproduce_fig5_quick(runner: CliRunner, tmp_path: Path) -> None:
    result = runner.invoke(app, ["reproduce", "fig5", "--quick", "-o", str(tmp_path), "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    png, meta, table = (tmp_path / f"fig5-quick.{ext}" for ext in ("png", "json", "csv"))
    assert data["figure"] == str(png) and data["table"] == str(table)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    saved = json.loads(meta.read_text())
    assert saved["param"] == "omega" and saved["fixed"]["xi"] == 0.03
    assert [r["value"] for r in saved["rows"]] == saved["values"]
    assert saved["rows"] == data["rows"]
    lines = table.read_text().splitlines()
    # the rows carry the verdict's evidence beside the label (ROW_KEYS)
    assert lines[0].startswith("value,motion,lle,lle_error,evidence,max_multiplier,k01")
    assert len(lines) == 1 + len(saved["values"])
    assert data["points"] == len(saved["values"])
    # the human output is a table of the rows
    again = runner.invoke(app, ["reproduce", "fig5", "--quick", "-o", str(tmp_path)])
    assert again.exit_code == 0, again.output
    assert "Poincaré gallery fig5" in again.stdout and "3.58" in again.stdout
