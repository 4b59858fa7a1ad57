"""summarize(): exact keys, JSON round trip and values that follow from the model."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.analysis.summary import SUMMARY_KEYS, motion_name, summarize
from gearchaos.cli._render import format_summary
from gearchaos.model import System
from stage_scales import StageScales
from two_frequency_train import TwoFrequencyTrain

REQUIRED = {
    "omega",
    "omega_n_rad_s",
    "distinct_section_points",
    "motion",
    "record_label",
    "section_min",
    "section_max",
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
    assert s["section_min"] == x.min()
    assert s["section_max"] == x.max()
    N = gs.n_planets
    assert [c["mesh"] for c in s["contact"]] == [f"sun_planet_{i}" for i in range(1, N + 1)] + [
        f"planet_ring_{i}" for i in range(1, N + 1)
    ]
    assert {c["regime"] for c in s["contact"]} == {"none"}
    assert s["status"] == "ok"
    assert s["steps_accepted"] == planetary.steps_accepted > 0
    assert s["steps_rejected"] == planetary.steps_rejected
    # mesh frequency in Hz matches the gear set's kinematics at that sun speed
    assert s["omega_hz"] == pytest.approx(
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
    assert s["omega_n_rad_s"] is None and "sun_speed_rpm" not in s
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
    assert s["dte_rms"] == pytest.approx(0.0, abs=1e-6) and s["dte_contact"] == "mesh"
    # none of the planetary train's keys: this model has no sun–planet mesh
    assert not {"load_factor_sp_max", "load_factor_rp_max", "dte_sp1_rms"} & set(s)
    json.dumps(s, allow_nan=False)
    forced = gc.backlash_oscillator(1.0, zeta=0.1, b=1.0, f_mean=0.5, f_alt=0.3, omega_power=0)
    s = summarize(gc.simulate(forced, transient_periods=60, periods=10, samples_per_period=8))
    assert s["load_factor_mesh_max"] > 1.0 and s["dte_rms"] > 0.0


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


#: The summary keys that named the planetary model, whatever model ran (issue 36).
PLANETARY_KEYS = {
    "x_sp1_section_min",
    "x_sp1_section_max",
    "sun_speed_rpm",
    "dte_sp1_rms",
    "load_factor_sp_max",
    "load_factor_rp_max",
    "mesh_frequency_hz",
}
#: Words and symbols of the planetary model (the table of another model shows none of them).
PLANETARY_WORDS = re.compile(r"planet|sun|ring|sp1|rp1|X̄|mesh|b_c|gear set", re.IGNORECASE)


@pytest.fixture(scope="module")
def train() -> gc.SimulationResult:
    """The two-frequency train (tests/two_frequency_train.py): a user model with its own
    section variable (x_1, q̄_1), contacts (stage1, stage2), scales and period (T = 5·2π/Ω)."""
    return gc.simulate(
        System(TwoFrequencyTrain(), 1.2), transient_periods=20, periods=12, samples_per_period=16
    )


def test_a_user_models_summary_speaks_its_own_words(train: gc.SimulationResult) -> None:
    """Issue 36: the summary of a model of one's own has no key of the planetary model; its
    section range is that of its own section variable, its transmission error that of its
    first contact, computed here from the record."""
    s = summarize(train)
    assert not PLANETARY_KEYS & set(s), sorted(PLANETARY_KEYS & set(s))
    assert REQUIRED <= set(s) and list(s)[: len(SUMMARY_KEYS)] == list(SUMMARY_KEYS)
    # no key and no value names the planetary model (the contact list's entries keep the
    # contract's field name "mesh"; their values are the model's contacts)
    words = [k for k in s if k != "contact"] + [str(v) for k, v in s.items() if k != "contact"]
    assert not [w for w in words if PLANETARY_WORDS.search(w)], words
    assert [c["mesh"] for c in s["contact"]] == ["stage1", "stage2"]
    assert s["section_variable"] == "x_1"
    x = train.section("x_1")  # the record's section points, one per T = 5·2π/Ω
    assert x.size == 12
    assert (s["section_min"], s["section_max"]) == (float(x.min()), float(x.max()))
    # the RMS transmission error of stage 1: √⟨(x_1 − ⟨x_1⟩)²⟩ over the recorded samples
    x1 = train.series("x_1")
    assert s["dte_contact"] == "stage1"
    assert s["dte_rms"] == pytest.approx(float(np.sqrt(np.mean((x1 - x1.mean()) ** 2))))
    assert s["omega_n_rad_s"] == StageScales.omega_n
    assert s["omega_hz"] == pytest.approx(1.2 * StageScales.omega_n / (2 * math.pi))
    json.dumps(s, allow_nan=False)


def test_a_user_models_table_speaks_its_own_words(train: gc.SimulationResult) -> None:
    from rich.console import Console

    console = Console(record=True, width=100)
    console.print(format_summary(summarize(train), train.system))
    text = console.export_text()
    assert not PLANETARY_WORDS.search(text), text
    # its section variable by its own symbol, its contacts by their names
    assert "q̄_1 section min" in text and "q̄_1 section max" in text
    assert "DTE RMS stage1" in text and "contact stage2" in text
    # Ω is not the frequency of its period (T = 5·2π/Ω): the row says what it is
    assert "Ω ω_n/2π [Hz]" in text


def test_the_planetary_table_keeps_its_words(planetary: gc.SimulationResult) -> None:
    """The planetary gear set's summary in its own words: X̄_sp1 by its symbol, its mesh
    types by their contacts, Ω as its mesh frequency, and the sun speed."""
    from rich.console import Console

    s = summarize(planetary)
    console = Console(record=True, width=100)
    console.print(format_summary(s, planetary.system))
    text = console.export_text()
    for label in (
        "X̄_sp1 section min",
        "X̄_sp1 section max",
        "mesh frequency [Hz]",
        "sun speed [rpm]",
        "load factor sun_planet (max)",
        "load factor planet_ring (max)",
        "DTE RMS sun_planet_1",
    ):
        assert label in text, label
    # the transmission error of sun–planet mesh 1, from the recorded deflection δ̄_sp1
    d = planetary.series("delta_sp_1")
    assert s["dte_contact"] == "sun_planet_1"
    assert s["dte_rms"] == pytest.approx(float(np.sqrt(np.mean((d - d.mean()) ** 2))))
