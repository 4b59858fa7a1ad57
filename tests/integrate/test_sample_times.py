"""Sample times are laid out by one constructor, :meth:`SampleTimes.over_periods` (issue 36,
item 5): the protocol of :meth:`SolverSettings.sample_times`, the shooting's one-period links
and the extension's record all come from it, and the step budget's rule is written once
(:func:`default_step_budget`). Each layout is checked against the times the protocol
defines (MODEL.md: sections at τ_k = τ_s + kT, T = 2π/Ω)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearchaos.integrate.settings import SampleTimes, SolverSettings, default_step_budget


def test_the_protocol_samples_after_the_transient_at_the_section_phase() -> None:
    T, t0 = 2.0 * math.pi / 1.7, 0.25
    cfg = SolverSettings(transient_periods=3.5, periods=4, samples_per_period=8, section_phase=1.0)
    times = cfg.sample_times(T, t0=t0)
    t_rec = t0 + 3.5 * T + 1.0 * T / (2.0 * math.pi)
    assert times.t_rec == pytest.approx(t_rec, rel=1e-15)
    assert times.n_samples == 32 and times.samples_per_period == 8
    assert times.dt == pytest.approx(T / 8, rel=1e-15)
    assert times.t_end == pytest.approx(t_rec + 4 * T, rel=1e-15)
    assert times.max_steps == 100_000 + 50_000 * (3.5 + 4)


def test_chains_of_one_period_each_sample_their_start() -> None:
    """The shooting's layout: C chains of L links, link j from τ_s + jT to τ_s + (j + 1)T,
    sampled at its start; the period of each chain broadcast over its links."""
    T = np.array([1.0, 2.0, 4.0])
    t0 = 0.5 * T[:, None] + np.arange(3)[None, :] * T[:, None]
    times = SampleTimes.over_periods(t0, T[:, None], first=0, periods=1, end=1, max_steps=7)
    np.testing.assert_array_equal(times.t_rec, t0)
    assert times.t_rec is not t0  # its own array
    np.testing.assert_array_equal(times.period, np.repeat(T[:, None], 3, axis=1))
    np.testing.assert_array_equal(times.t_end - times.t_rec, times.period)
    assert (times.n_samples, times.max_steps) == (1, 7)


def test_a_record_of_the_next_sections_ends_on_its_last_sample() -> None:
    """The extension's layout: from the section τ_s, one sample at each of the next P
    sections τ_s + T … τ_s + PT, the run ending on the last one."""
    T = np.array([[2.0 * math.pi / 1.3], [2.0 * math.pi / 0.7]])
    t0 = 0.3 * T
    P = 50
    times = SampleTimes.over_periods(
        t0, T, first=1, periods=P, end=P, max_steps=default_step_budget(P)
    )
    np.testing.assert_allclose(times.t_rec, t0 + T, rtol=1e-15)
    last = times.t_rec + (times.n_samples - 1) * times.dt
    np.testing.assert_allclose(last, times.t_end, rtol=1e-14)
    np.testing.assert_allclose(times.t_end, t0 + P * T, rtol=1e-15)
    assert times.max_steps == 100_000 + 50_000 * P


@pytest.mark.parametrize(("first", "periods", "end"), [(-1, 1, 1), (0, 0, 1), (1, 3, 2)], ids=str)
def test_an_impossible_layout_is_refused(first: int, periods: int, end: int) -> None:
    with pytest.raises(ValueError, match="sample times need"):
        SampleTimes.over_periods(0.0, 1.0, first=first, periods=periods, end=end, max_steps=1)


def test_the_step_budget_rule_is_written_once() -> None:
    """``max_steps`` where set, else 100 000 + 50 000 per simulated period (at least one)."""
    cfg = SolverSettings(transient_periods=10, periods=20)
    assert cfg.step_budget == default_step_budget(30) == 1_600_000
    assert cfg.budget_for(1) == default_step_budget(0.2) == 150_000
    capped = cfg.replace(max_steps=5000)
    assert capped.step_budget == capped.budget_for(1) == 5000
