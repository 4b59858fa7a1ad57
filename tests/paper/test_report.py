"""`gearchaos reproduce --all --quick`: every figure and the HTML report with its verdict tables."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from gearchaos.cli import app
from gearchaos.paper.report import FIGURES, HONESTY

FIGS = ("fig4", "fig5", "fig6", "fig7", "fig8", "fig9", "fig10", "fig11", "fig12")


@pytest.mark.slow  # the whole quick report: every figure, branch and landmark (minutes on 2 cores)
def test_reproduce_all_quick_writes_every_figure_and_the_report(tmp_path: Path) -> None:
    assert FIGURES == FIGS
    out = tmp_path / "report"
    args = ["reproduce", "--all", "-o", str(out), "--quick", "-w", "2", "-p", "hindawi2021"]
    res = CliRunner().invoke(app, args)
    assert res.exit_code == 0, res.output
    index = out / "index.html"
    assert str(index) in res.output.replace("\n", "")
    page = index.read_text(encoding="utf-8")
    for fig in FIGS:
        assert (out / f"{fig}-quick.png").is_file(), fig
        assert f"src='{fig}-quick.png'" in page  # relative path: the page is self-contained
        assert f"<a href='{fig}-quick.png'" in page  # a click opens it at full resolution
        assert f"id='{fig}'" in page
    assert "id='conclusions'" in page
    for cid in range(1, 9):
        assert f"<td>C{cid}</td>" in page
    assert "Honesty" in page
    for title, _ in HONESTY:
        assert title in page
    assert "Gear set TOML" in page
    # the chosen gear set ran (its name is in the stored TOML) and the page says which
    assert "<code>preset hindawi2021</code>" in page
    assert "name = &quot;hindawi2021&quot;" in page
    summary = json.loads((out / "report.json").read_text(encoding="utf-8"))
    assert summary["gearset"] == "preset hindawi2021"
    assert [c["id"] for c in summary["conclusions"]] == list(range(1, 9))
    verdicts = {"holds", "partly", "does not hold", "not evaluated"}
    assert {c["verdict"] for c in summary["conclusions"]} <= verdicts
    assert all(not f.get("error") for f in summary["figures"].values())
    # every landmark row says whether its swept parameter acts and what the seed's protocol says
    from gearchaos.paper.landmarks import VERDICTS, load_landmarks

    rows = summary["landmarks"]
    assert [r["id"] for r in rows] == [m.id for m in load_landmarks()]
    assert {r["acts"] for r in rows} <= {"acts", "constant", "undecided"}
    assert all(r["action"] for r in rows)
    assert {r["verdict"] for r in rows} | {r["paper_verdict"] for r in rows} <= set(VERDICTS)
    for r in rows:  # a constant panel never holds as a hold
        assert not (r["acts"] == "constant" and r["verdict"] == "holds"), r["id"]
    counts = summary["counts"]
    assert list(counts["landmarks"]) == list(VERDICTS)
    assert sum(counts["landmarks"].values()) == sum(counts["landmarks_paper"].values()) == len(rows)
    assert counts["landmarks"]["holds (constant)"] == sum(
        r["verdict"] == "holds (constant)" for r in rows
    )
    assert "id='landmarks'" in page and "paper protocol" in page and "acts?" in page
    for fig in ("fig4", "fig6", "fig8", "fig9", "fig11", "fig12"):  # the seed's protocol ran
        assert (out / f"{fig}-quick-paper.zarr").is_dir(), fig
        assert f"<a href='{fig}-quick-paper.png'>" in page, fig
    printed = res.output.replace("\n", " ")
    assert "holds (constant)" in printed


def test_reproduce_needs_a_figure_or_all(tmp_path: Path) -> None:
    res = CliRunner().invoke(app, ["reproduce", "-o", str(tmp_path)])
    assert res.exit_code == 2
    res = CliRunner().invoke(app, ["reproduce", "fig4", "--all", "-o", str(tmp_path)])
    assert res.exit_code == 2


def test_html_escapes_text(tmp_path: Path) -> None:
    from gearchaos.paper.conclusions import Verdict
    from gearchaos.paper.report import render_html

    v = Verdict(1, "<script>x</script>", "holds", "a < b & c", {})
    page = render_html(
        quick=True,
        results={},
        stores={},
        verdicts=[v],
        landmark_rows=[],
        landmark_note="",
        total_seconds=0.0,
        outdir=tmp_path,
    )
    assert "<script>x" not in page
    assert "&lt;script&gt;" in page and "a &lt; b &amp; c" in page
    assert "<code>preset sheng2016</code>" in page  # the default gear set is named


def test_regime_table_columns_in_fixed_order_with_zero_written_out() -> None:
    import json
    import re

    import xarray as xr

    from gearchaos.paper.report import _regime_table

    table = {
        "xi = 0.03": {"chaos": 0.5, "2T": 0.25, "unresolved": 0.25},
        "xi = 0.07": {"1T": 0.75, "QP": 0.25},
    }
    ds = xr.Dataset(attrs={"regime_table": json.dumps(table)})
    html = _regime_table(ds)
    head = re.findall(r"<th>([^<]*)</th>", html.split("</tr>")[0])
    assert head == ["panel", "1T", "2T", "QP", "chaos", "unresolved"]
    rows = re.findall(r"<tr><th>([^<]*)</th>(.*?)</tr>", html)
    cells = {panel: re.findall(r"<td>([^<]*)</td>", body) for panel, body in rows}
    assert cells["xi = 0.03"] == ["0 %", "25 %", "0 %", "50 %", "25 %"]
    assert cells["xi = 0.07"] == ["75 %", "0 %", "25 %", "0 %", "0 %"]
    assert "—" not in html
