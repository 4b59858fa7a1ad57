"""The kernel interface is written once: the configuration record is generated from the fields
of a ChainRun, the info columns and status codes are named by enumerations."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.errors import Status
from gearchaos.integrate import dopri
from gearchaos.integrate._chains import ChainRun, config_record, run_chains
from gearchaos.integrate.interface import Config, Info
from gearchaos.integrate.settings import SolverSettings


@pytest.fixture(scope="module")
def run() -> ChainRun:
    system = gc.planetary_system(gc.preset("hindawi2021"), 1.5)
    settings = SolverSettings(transient_periods=3, periods=4, samples_per_period=2)
    return ChainRun.from_systems([[system]], settings, continuation=True, first_step=0.01)


def test_config_slots_are_consecutive_and_name_chain_run_fields(run: ChainRun) -> None:
    assert [int(s) for s in Config] == list(range(len(Config)))
    names = {f.name for f in dataclasses.fields(ChainRun)}
    assert {s.name.lower() for s in Config} <= names


def test_config_record_holds_each_field_exactly(run: ChainRun) -> None:
    cfg = config_record(run)
    assert cfg.dtype == np.float64 and cfg.shape == (len(Config),)
    for slot in Config:
        value = getattr(run, slot.name.lower())
        assert cfg[slot] == float(value), slot.name
    assert cfg[Config.CONTINUATION] == 1.0
    assert cfg[Config.H_INIT] == 0.01
    assert cfg[Config.MAX_STEPS] == run.max_steps


def test_info_columns_are_what_their_names_say(run: ChainRun) -> None:
    out = run_chains(run)
    assert [int(c) for c in Info] == list(range(len(Info)))
    assert out.info.shape == (1, 1, len(Info))
    info = out.info[0, 0]
    assert info[Info.TAU_REACHED] == run.t_end[0, 0] >= out.tau[0, 0, -1]
    assert info[Info.ACCEPTED] > 0 and info[Info.ACCEPTED] == int(info[Info.ACCEPTED])
    assert info[Info.REJECTED] >= 0 and info[Info.NEXT_STEP] > 0
    assert info[Info.SKIPPED] == 0  # settle is off
    assert info[Info.SWITCH_RETRIES] > 0  # the meshes open and close at Ω = 1.5


def test_switch_retries_are_counted_apart_from_rejections() -> None:
    """A step retried to end on a contact switch is no error-test rejection: smooth systems
    have none, and a budget counts every attempt."""
    smooth = gc.integrate.integrate(gc.linear_oscillator(1.0, zeta=0.1), periods=5)
    assert smooth.steps_switch == 0
    res = gc.simulate(gc.preset("sheng2016-v1"), omega=1.5, transient_periods=5, periods=5)
    assert res.steps_switch > 0 and res.steps_rejected >= 0
    attempts = res.steps_accepted + res.steps_rejected + res.steps_switch
    capped = gc.simulate(
        gc.preset("sheng2016-v1"), omega=1.5, transient_periods=5, periods=5,
        max_steps=attempts - 1, check=False,
    )  # fmt: skip
    assert capped.status is Status.MAX_STEPS
    assert capped.steps_accepted + capped.steps_rejected + capped.steps_switch == attempts - 1
    assert res.to_dataset().attrs["steps_switch"] == res.steps_switch


def test_kernel_status_codes_are_status_members() -> None:
    assert dopri.ST_OK == Status.OK
    assert dopri.ST_MAX_STEPS == Status.MAX_STEPS
    assert dopri.ST_UNDERFLOW == Status.STEP_UNDERFLOW
    assert dopri.ST_NON_FINITE == Status.NON_FINITE


def test_step_budget_stops_with_max_steps(run: ChainRun) -> None:
    out = run_chains(dataclasses.replace(run, max_steps=7))
    assert out.statuses() == [Status.MAX_STEPS]
    info = out.info[0, 0]
    assert info[Info.ACCEPTED] + info[Info.REJECTED] + info[Info.SWITCH_RETRIES] == 7
