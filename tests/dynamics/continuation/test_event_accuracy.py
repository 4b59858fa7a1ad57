"""Events of a continuation are located as accurately as the integrator allows, and say how
accurately (issue 24).

The backlash oscillator (MODEL.md §10.5) with F_a = F_m grazes where Ω² = 1/(2 − 4ζ²) (closed
form; see tests/dynamics/continuation/test_continuation.py), folds at Ω ≈ 0.731 and has a period
doubling near Ω ≈ 1.95. With the default settings (rtol 1e-8) each event's stated uncertainty must

* cover the distance to the same event located with a much tighter event tolerance (the
  root-finding part: the old default, range × 1e-6 in arclength, left ~3e-8 there),
* cover the distance to the event of an independent continuation with rtol 1e-11 (the
  integrator's part) and, for the grazing, to the closed form,
* and be small: below 1e-8 for this oscillator.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app
from gearchaos.dynamics.continuation.branch import branch_summary, open_branch
from gearchaos.dynamics.continuation.events import events

ZETA = 0.05
FINE = {"rtol": 1e-11, "atol": 1e-13}


def backlash() -> gc.System:
    return gc.backlash_oscillator(1.0, zeta=ZETA, f_alt=0.1, f_mean=0.1)


def one_event(ds, kind: str):
    (found,) = [e for e in events(ds) if e.kind == kind]
    return found


@pytest.mark.parametrize(
    ("vary", "kind"),
    [
        ("omega=2.1:1.8", "period_doubling"),
        ("omega=0.6:0.72", "grazing"),
        ("omega=0.6:0.8", "fold"),  # the branch turns back at Ω ≈ 0.731, after grazing
    ],
)
def test_default_event_location_is_within_its_stated_uncertainty(vary, kind, tmp_path) -> None:
    path = tmp_path / "branch.nc"
    default = one_event(gc.continuation(backlash(), vary, store=path), kind)
    tight = one_event(gc.continuation(backlash(), vary, event_tol=1e-13), kind)
    fine = one_event(gc.continuation(backlash(), vary, event_tol=1e-13, **FINE), kind)
    u = default.uncertainty
    assert default.located and 0.0 < u <= 1e-8
    # root finding: the same test function, its root found far more tightly
    assert abs(default.value - tight.value) <= u
    # the integrator: an independent continuation, 1000 times tighter
    assert abs(default.value - fine.value) <= u
    assert fine.uncertainty < 1e-2 * u  # which is itself far more accurate
    if kind == "grazing":
        omega_g = 1.0 / math.sqrt(2.0 - 4.0 * ZETA**2)
        assert abs(default.value - omega_g) <= u
        assert abs(fine.value - omega_g) <= max(fine.uncertainty, 1e-12)
    # the uncertainty is kept in the branch file and its summary
    (stored,) = [e for e in events(open_branch(path)) if e.kind == kind]
    assert stored.uncertainty == u and stored.value == default.value
    (row,) = [r for r in branch_summary(open_branch(path))["events"] if r["kind"] == kind]
    assert row["uncertainty"] == u


def test_files_without_uncertainty_still_read(tmp_path) -> None:
    path = tmp_path / "old.nc"
    ds = gc.continuation(backlash(), "omega=0.6:0.72", max_step=0.005)
    gc.dynamics.continuation.branch.save_branch(ds.drop_vars("event_uncertainty"), path)
    (graze,) = events(open_branch(path))
    assert math.isnan(graze.uncertainty)
    assert branch_summary(open_branch(path))["events"][0]["uncertainty"] is None


def test_cli_continue_reports_each_event_with_its_uncertainty(tmp_path: Path) -> None:
    """The Neimark–Sacker bifurcation of sheng2016-v1 near Ω = 1.496 (README): the
    text table and the JSON give its uncertainty, and a run with rtol 1e-11 lands inside it."""
    runner = CliRunner()
    V1 = ["--preset", "sheng2016-v1"]  # the recalibrated default has no NS point near 1.5

    def run(*extra: str) -> dict:
        out = tmp_path / f"b{len(list(tmp_path.iterdir()))}.nc"
        args = ["continue", *V1, "--vary", "omega=1.49:1.50", "-o", str(out), *extra]
        result = runner.invoke(app, [*args, "--json"])
        assert result.exit_code == 0, result.output
        return json.loads(result.stdout)

    (ns,) = [e for e in run()["events"] if e["kind"] == "neimark_sacker"]
    (fine,) = [
        e
        for e in run("--rtol", "1e-11", "--atol", "1e-13")["events"]
        if e["kind"] == "neimark_sacker"
    ]
    # the gear model's integrator error at rtol 1e-8 is ~2e-8 in Ω here (far above the bracket)
    assert 0.0 < ns["uncertainty"] <= 1e-7
    assert abs(ns["value"] - fine["value"]) <= ns["uncertainty"]
    assert fine["uncertainty"] < ns["uncertainty"]
    # a terminal wide enough for the event table's row on one line (the table wraps its
    # cells on a narrow one rather than cutting them)
    text = runner.invoke(
        app,
        ["continue", *V1, "--vary", "omega=1.49:1.50", "-o", str(tmp_path / "t.nc")],
        env={"COLUMNS": "200"},
    )
    assert text.exit_code == 0, text.output
    (line,) = [ln for ln in text.output.splitlines() if "neimark_sacker" in ln]
    assert "±" in line and f"{ns['uncertainty']:.1g}" in line
