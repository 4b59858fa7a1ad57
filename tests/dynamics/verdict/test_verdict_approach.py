"""Slow approaches to a stable orbit: the verdict names the orbit the record approaches, or
says why it could not, never a period the record only seems to have.

Independent truths here: orbits and multipliers of the single-point shooting
(:func:`gearchaos.periodic_orbit`, its own Newton from its own start, at 100 times tighter
tolerances), and a long plain run's distance from that orbit. The gear set is the frozen
``sheng2016-v1`` (the default's values before its recalibration).
"""

from __future__ import annotations

import math
import re
from types import SimpleNamespace

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.analysis.recurrence import distance_to_orbit
from gearchaos.dynamics import periodic_orbit
from gearchaos.dynamics.verdict.decide import VerdictSettings, decide_motion
from gearchaos.dynamics.verdict.point import point_verdict
from gearchaos.dynamics.verdict.rules import Window, decide_by_exponent
from gearchaos.integrate.settings import SolverSettings
from gearchaos.integrate.simulate import integrate
from gearchaos.model.target import resolve

V1 = gc.preset("sheng2016-v1")


def _reference(values, period):
    ref = periodic_orbit(V1, period=period, rtol=1e-10, atol=1e-12, **values)
    assert ref.converged, ref.message
    return ref


def test_a_slow_spiral_onto_a_1t_is_that_1t_not_a_long_period() -> None:
    # Ω = 3.59, ξ = 0.032 after 150 + 16 periods: the record spirals onto a 1T (a complex pair
    # |μ| ≈ 0.977 turning ~0.92 rad a period) within the noise floor of the recurrence test,
    # whose gaps then fit a period of 17; the verdict said 17T (record_contracting)
    values = {"omega": 3.59, "xi": 0.032}
    res = gc.simulate(V1, transient_periods=150, periods=16, **values)
    ref = _reference(values, 1)
    assert ref.minimal_period == 1 and ref.max_multiplier < 1 - 1e-3
    # the truth: the motion from rest ends on that 1T (a long plain run)
    system = resolve(V1, values)
    long = integrate(system, SolverSettings(transient_periods=2000, periods=8))
    assert np.max(distance_to_orbit(long.states, ref.sections)) < 1e-8
    summary = gc.summarize(res)
    assert summary["motion"] != "17T" and summary["evidence"] != "record_contracting"
    assert summary["motion"] == "1T", summary["motion_note"]
    assert summary["evidence"] == "floquet"
    assert abs(summary["max_multiplier"] - ref.max_multiplier) <= 1e-6
    assert summary["distinct_section_points"] == 1  # the record shown agrees with the label
    v = point_verdict(V1, values, res)
    assert v.label == "1T" and v.record is not None
    d = distance_to_orbit(v.record.states[-16:], ref.sections)
    assert np.max(d) < 1e-5  # the recorded sections lie on the shot orbit


def test_a_long_period_is_not_decided_while_a_stable_orbit_may_be_approached() -> None:
    # the rule itself: a record that repeats with a long period and contracts, while the
    # shooting found a stable 1T it may still approach (too close to measure), runs on, and
    # when the budget ends it is unresolved with 'converging', never that period
    rng = np.random.default_rng(3)
    x = 3.0 + 1e-6 * rng.standard_normal((100, 4))
    p = SimpleNamespace(
        windows=[Window(0, 100, -0.02, 0.004, 0.06)],
        fresh=True,
        sections=x,
        history=x,
        long_period=17,
        approaching=1,
        unstable=None,
        coexisting={},
        extra=100,
        record=None,
        tests=None,
        prev_tests=None,
    )
    vs = VerdictSettings()
    assert decide_by_exponent(p, vs, last=False) is None
    v = decide_by_exponent(p, vs, last=True)
    assert v is not None and v.label == "unresolved" and v.evidence == "converging", v
    # without the stable orbit the same record is the long period
    p.approaching = 0
    v = decide_by_exponent(p, vs, last=False)
    assert v is not None and (v.label, v.evidence) == ("17T", "record_contracting")


@pytest.fixture(scope="module")
def slow_2t():
    # Ω = 2.62: the motion from rest reaches a 2T whose slowest multiplier is ≈ 0.9985 per
    # two periods; measuring that approach needs a record of ≈ 1180 periods, more than the
    # 1000 the verdict used to keep, so it ended 'unresolved' (converging)
    values = {"omega": 2.62}
    res = gc.simulate(V1, transient_periods=100, periods=200, **values)
    # the shooting's own guess: a run from rest long enough to lie near the 2T
    ref = periodic_orbit(
        V1, period=2, rtol=1e-10, atol=1e-12, transient_periods=4000, settle=4000, **values
    )
    assert ref.converged, ref.message
    return values, res, ref


def test_a_slow_approach_is_measured_and_reaches_its_orbit(slow_2t) -> None:
    values, res, ref = slow_2t
    mu = np.sort(np.abs(ref.multipliers))[::-1]
    assert ref.minimal_period == 2 and 0.998 < mu[0] < 1 - 1e-4  # the truth: slow, stable
    # the record length the slowest rate needs to fall by 1.25² over half of it
    assert 2 * 2 * math.log(1.25) / -(math.log(mu[0]) / 2) > 1000
    v = point_verdict(V1, values, res)
    assert v.label == "2T", v.reason
    assert v.evidence == "floquet"
    assert abs(v.max_multiplier - ref.max_multiplier) <= 1e-6
    assert v.record is not None
    d = distance_to_orbit(v.record.states[-200:], ref.sections)
    assert np.max(d) < 1e-4  # the record shown lies on the orbit


def test_an_approach_beyond_the_budget_says_how_long_it_needs(slow_2t) -> None:
    values, res, ref = slow_2t
    v = point_verdict(V1, values, res, VerdictSettings(settle_budget=500))
    assert (v.label, v.evidence) == ("unresolved", "converging"), v.reason
    assert abs(v.max_multiplier - ref.max_multiplier) <= 1e-6
    assert "settle budget of 500 periods" in v.reason
    found = re.search(r"only after (\d+) more periods", v.reason) or re.search(
        r"needs a record of (\d+) periods", v.reason
    )
    assert found is not None, v.reason
    assert int(found.group(1)) > 500


def test_a_measured_approach_shows_a_record_as_long_as_the_protocols() -> None:
    # x'' + 2ζx' + x = F cos Ωτ: its 1T and the approach to it are known exactly, y_k = y* +
    # Mᵏ e₀ with M = exp(A T) and |μ| = exp(−ζT) (0.976 a period). The record of 20 sections
    # starts just outside the reach of the 1T; measuring the approach needs a longer record,
    # so the run is continued, and it ends on the orbit: the record shown must still be the
    # protocol's 20 periods (a sweep stores that many), all on the orbit
    from scipy.linalg import expm

    zeta, force, omega, m = 0.005, 0.5, 1.3, 20
    system = gc.linear_oscillator(omega, zeta=zeta, force=force)
    settings = SolverSettings(transient_periods=0, periods=m)
    vs = VerdictSettings()
    T = 2 * math.pi / omega
    X = force / (1 - omega**2 + 2j * zeta * omega)
    y_star = np.array([X.real, -omega * X.imag])  # at τ = kT
    M = expm(np.array([[0.0, 1.0], [-1.0, -2 * zeta]]) * T)
    e = np.array([1.0, 0.0])
    devs = [np.linalg.matrix_power(M, k) @ e for k in range(3 * m)]
    size = np.array([np.max(np.abs(d)) for d in devs])
    reach = 0.5 * vs.noise_factor * (settings.atol + settings.rtol)  # half the recurrence tol
    scale = 1.2 * reach / np.max(size[:m])
    assert np.max(size[m:]) * scale < 0.8 * reach  # the next periods lie within reach
    record = np.array([y_star + scale * d for d in devs[:m]])
    final = y_star + scale * devs[m - 1]
    v = decide_motion(
        system, [{"omega": omega}], [system], record[None], final[None], [True], settings, vs
    )[0]
    assert (v.label, v.evidence) == ("1T", "floquet"), v.reason
    assert v.max_multiplier == pytest.approx(math.exp(-zeta * T), rel=1e-6)
    assert v.record is not None and v.record.states.shape[0] >= m
    assert np.max(np.abs(v.record.states[-m:] - y_star)) <= reach


def test_a_spiral_onto_a_1t_is_that_1t_not_a_torus() -> None:
    # Ω = 1.2 from the symmetric state the response how-to's up sweep reaches at Ω = 1.18
    # (in-phase planets, the sun at rest in the centre): the record spirals onto a stable 1T
    # (a complex pair, |μ| ≈ 0.99). Measured over the shortest record that can show it, the
    # spiral's wobbling envelope made the fall insignificant, the 1T was taken as coexisting,
    # and the spiral's cyclic order on the section made a torus: QP
    values = {"omega": 1.2}
    system = resolve(V1, values)
    names = list(system.state_names)
    y0 = np.zeros(system.n_state)
    for i in range(1, 6):
        y0[names.index(f"p_{i}")] = 3.0483650912899516
        y0[names.index(f"p_{i}_dot")] = 0.10916492070065517
    y0[names.index("sigma")] = 6.575750905927513
    y0[names.index("sigma_dot")] = 0.013631201417236567
    cfg = SolverSettings(transient_periods=100, periods=50, perturbation=0.0)
    ref = _reference(values, 1)
    assert ref.minimal_period == 1 and ref.max_multiplier < 1 - 1e-3
    # the truth: the motion from that state ends on the 1T
    long = integrate(system, cfg.replace(transient_periods=2000, periods=8), y0=y0)
    assert np.max(distance_to_orbit(long.states, ref.sections)) < 1e-8
    tr = integrate(system, cfg, y0=y0)
    v = decide_motion(V1, [values], [system], tr.states[None], tr.final_state[None], [tr.ok], cfg)
    assert (v[0].label, v[0].evidence) == ("1T", "floquet"), v[0].reason
    assert abs(v[0].max_multiplier - ref.max_multiplier) <= 1e-6
    assert v[0].record is not None
    assert np.max(distance_to_orbit(v[0].record.states[-50:], ref.sections)) < 1e-5
