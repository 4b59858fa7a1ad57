"""summarize(): exact keys, JSON round trip and values that follow from the model."""

from __future__ import annotations

import json

import pytest

import gearchaos as gc
from gearchaos.analysis.summary import SUMMARY_KEYS, motion_name, summarize
from gearchaos.cli._render import format_summary

REQUIRED = {
    "omega",
    "omega_n_rad_s",
    "sun_speed_rpm",
    "distinct_section_points",
    "motion",
    "record_label",
    "x_sp1_section_min",
    "x_sp1_section_max",
    "contact",
    "status",
    "steps_accepted",
    "steps_rejected",
}


@pytest.fixture(scope="module")
def planetary() -> gc.SimulationResult:
    return gc.simulate(
        gc.preset("hindawi2021"), omega=0.5, transient_periods=20, periods=20, samples_per_period=8
    )


def test_planetary_summary(planetary: gc.SimulationResult) -> None:
    s = summarize(planetary)
    assert set(SUMMARY_KEYS) == REQUIRED
    assert REQUIRED <= set(s)
    assert list(s)[: len(SUMMARY_KEYS)] == list(SUMMARY_KEYS)
    text = json.dumps(s, allow_nan=False)
    assert json.loads(text) == s
    gs = gc.preset("hindawi2021")
    assert s["omega"] == 0.5
    assert s["omega_n_rad_s"] == pytest.approx(gs.omega_n)
    assert s["sun_speed_rpm"] == pytest.approx(gs.sun_speed_rpm(0.5))
    assert s["distinct_section_points"] == 1
    assert s["motion"] is None and s["record_label"] == "1T"
    x = planetary.section("delta_sp_1")
    assert s["x_sp1_section_min"] == x.min()
    assert s["x_sp1_section_max"] == x.max()
    N = gs.n_planets
    assert [c["mesh"] for c in s["contact"]] == [f"sun_planet_{i}" for i in range(1, N + 1)] + [
        f"planet_ring_{i}" for i in range(1, N + 1)
    ]
    assert {c["regime"] for c in s["contact"]} == {"none"}
    assert s["status"] == "ok"
    assert s["steps_accepted"] == planetary.steps_accepted > 0
    assert s["steps_rejected"] == planetary.steps_rejected
    # mesh frequency in Hz matches the gear set's kinematics at that sun speed
    assert s["mesh_frequency_hz"] == pytest.approx(
        gs.mesh_frequency(s["sun_speed_rpm"]) / (2 * 3.141592653589793)
    )
    assert s["load_factor_sp_max"] > 1.0


def test_reference_system_summary() -> None:
    r = gc.simulate(
        gc.backlash_oscillator(1.0, zeta=0.1, b=1.0, f_mean=2.0, f_alt=0.3, omega_power=0),
        transient_periods=20,
        periods=10,
        samples_per_period=1,
    )
    s = summarize(r)
    assert REQUIRED <= set(s)
    json.dumps(s, allow_nan=False)
    # separation fraction needs a time history (samples_per_period > 1): None here
    assert s["contact"] == [{"mesh": "mesh", "regime": "none", "separation_fraction": None}]
    assert s["motion"] is None and s["record_label"] == "1T"
    assert s["omega_n_rad_s"] is None and s["sun_speed_rpm"] is None
    s = summarize(gc.simulate(gc.duffing(1.0), transient_periods=1, periods=3))
    assert s["contact"] == []


def test_a_model_with_force_groups_gets_its_load_factor() -> None:
    """Issue 36: the load factor and the transmission error come from the model's force groups
    and static load, not from whether it is a planetary train. The backlash oscillator declares
    one group (``mesh``: the contact force on x) and its static load F̄_m. Unforced (ε = 0,
    F̄_a = 0) it comes to rest on its drive flank, x = b + F̄_m: the peak contact force is the
    static load (load factor 1) and the transmission error has no RMS; forced at resonance the
    peak exceeds it."""
    rest = gc.backlash_oscillator(1.0, zeta=0.1, eps=0.0, b=1.0, f_mean=0.5, f_alt=0.0)
    s = summarize(gc.simulate(rest, transient_periods=60, periods=10, samples_per_period=8))
    assert s["load_factor_mesh_max"] == pytest.approx(1.0, rel=1e-6)
    assert s["dte_mesh1_rms"] == pytest.approx(0.0, abs=1e-6)
    # the planetary train's keys stay, empty: this model has no sun–planet mesh
    assert s["load_factor_sp_max"] is None and s["load_factor_rp_max"] is None
    assert s["dte_sp1_rms"] is None
    json.dumps(s, allow_nan=False)
    forced = gc.backlash_oscillator(1.0, zeta=0.1, b=1.0, f_mean=0.5, f_alt=0.3, omega_power=0)
    s = summarize(gc.simulate(forced, transient_periods=60, periods=10, samples_per_period=8))
    assert s["load_factor_mesh_max"] > 1.0 and s["dte_mesh1_rms"] > 0.0


def test_motion_name() -> None:
    assert motion_name(1) == "1T"
    assert motion_name(3) == "3T"
    assert motion_name(65) == "many"
    assert motion_name(11, max_count=10) == "many"
    assert motion_name(0) == "unknown"


def test_format_summary_renders(planetary: gc.SimulationResult) -> None:
    from rich.console import Console

    console = Console(record=True, width=100)
    console.print(format_summary(summarize(planetary)))
    text = console.export_text()
    assert "sun speed [rpm]" in text  # brackets survive rich markup
    assert "sun_planet_5" in text and "none" in text


def test_format_summary_shows_the_true_count_of_distinct_points() -> None:
    """The count is the true number of distinct points among the recorded ones, shown with
    that number (issue 12: a counter's cap, 65, used to read as data)."""
    from rich.console import Console

    console = Console(record=True, width=120)
    summary = {"distinct_section_points": 200, "recorded_section_points": 200, "motion": "chaos"}
    console.print(format_summary(summary))
    assert "200 of 200" in console.export_text()


def test_summary_counts_every_distinct_point() -> None:
    """A chaotic run's Poincaré points are all distinct: the count is the number recorded."""
    res = gc.simulate(
        gc.lorenz(), y0=[1.0, 1.0, 1.0], transient_periods=20, periods=150, check=False
    )
    s = summarize(res)
    assert s["recorded_section_points"] == 150
    assert 120 < s["distinct_section_points"] <= 150


def test_summary_carries_the_verdicts_window_and_coexisting_orbits(
    planetary: gc.SimulationResult,
) -> None:
    """The README's summary contract: ``simulate --json`` (a summary with the verdict) has the
    window λ₁ was measured over and the stable orbits beside the motion; a record-only summary
    says that no window ran and names none."""
    from gearchaos.dynamics.verdict.evidence import Verdict

    v = Verdict(
        "QP",
        0,
        "lyapunov",
        lle=1e-4,
        lle_error=1e-4,
        window_start=300,
        window_periods=800,
        coexisting=((1, 0.97),),
    )
    s = summarize(planetary, verdict=v.to_dict())
    assert (s["window_start"], s["window_periods"]) == (300, 800)
    assert s["coexisting"] == [{"period": 1, "max_multiplier": 0.97}]
    json.dumps(s)
    r = summarize(planetary)
    assert (r["window_start"], r["window_periods"], r["coexisting"]) == (-1, 0, [])
