"""Basins of attraction against systems whose basins are known exactly.

* A damped, forced linear oscillator has one attractor: its image is one colour, the orbit's
  section point is the exact steady state and |μ| = exp(−ζT).
* The unforced twin-well Duffing oscillator x'' + δx' − x + x³ = 0 has two stable equilibria
  x = ±1 (|μ| = exp(−δT/2) of the period T the sections are taken at). The energy
  E = x'²/2 − x²/2 + x⁴/4 decreases along every motion and is ≥ 0 on x = 0, so a start with
  E < 0 stays in its own well; the system is odd (x ↦ −x), so the start −p reaches the other
  well than p, and a box symmetric about the origin splits exactly 1/2 : 1/2.
* Forced twin well (small forcing): each start's attractor agrees with an independent scipy
  DOP853 integration.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.analysis.fractions import wilson_interval
from gearchaos.dynamics.attractors.basins import FAILED, BasinAttractor, Catalogue, link_tracks

SHORT = {"transient_periods": 60, "periods": 8, "progress": False}


def entries(ds):
    return [
        BasinAttractor.from_record(e) for e in json.loads(ds.attrs["attractors"])["0"]["entries"]
    ]


def test_linear_oscillator_has_one_attractor_everywhere():
    omega, zeta, force = 1.3, 0.1, 0.5
    system = gc.linear_oscillator(omega, zeta=zeta, force=force)
    names = system.state_names
    ds = gc.basins(system, f"{names[0]}=-3:3:7", f"{names[1]}=-3:3:6", **SHORT)
    codes = ds["attractor"].values
    assert codes.shape == (6, 7)
    assert np.all(codes == 0)
    (a,) = entries(ds)
    assert a.label == "1T"
    T = 2 * math.pi / omega
    assert a.max_multiplier == pytest.approx(math.exp(-zeta * T), rel=1e-6)
    X = force / (1 - omega**2 + 2j * zeta * omega)  # x = Re(X e^{iΩt}) at t = kT
    np.testing.assert_allclose(a.section_states[0], [X.real, -omega * X.imag], atol=1e-6)
    assert set(ds["label"].values.ravel()) == {"1T"}


@pytest.fixture(scope="module")
def twin_well():
    delta, omega = 0.3, 1.0
    system = gc.duffing(omega, delta=delta, alpha=-1.0, beta=1.0, gamma=0.0)
    ds = gc.basins(system, "x=-1.9:1.9:16", "x_dot=-1.9:1.9:16", **SHORT)
    return system, ds, delta, omega


def test_twin_well_attractors_are_the_two_equilibria(twin_well):
    _, ds, delta, omega = twin_well
    found = sorted(entries(ds), key=lambda a: a.section_states[0, 0])
    assert [a.label for a in found] == ["1T", "1T"]
    np.testing.assert_allclose(found[0].section_states[0], [-1.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(found[1].section_states[0], [1.0, 0.0], atol=1e-6)
    T = 2 * math.pi / omega
    for a in found:  # linearisation x'' + δx' + 2x = 0: a complex pair, |μ| = exp(−δT/2)
        assert a.max_multiplier == pytest.approx(math.exp(-0.5 * delta * T), rel=1e-5)


def test_twin_well_starts_below_the_barrier_stay_in_their_well(twin_well):
    _, ds, *_ = twin_well
    x, v = np.meshgrid(ds["x"].values, ds["x_dot"].values)
    energy = 0.5 * v**2 - 0.5 * x**2 + 0.25 * x**4
    codes = ds["attractor"].values
    where = {int(np.sign(a.section_states[0, 0])): k for k, a in enumerate(entries(ds))}
    inside = energy < 0
    assert inside.sum() > 20
    assert np.all(codes[inside & (x > 0)] == where[1])
    assert np.all(codes[inside & (x < 0)] == where[-1])


def test_twin_well_image_is_odd_and_splits_in_half(twin_well):
    _, ds, *_ = twin_well
    codes = ds["attractor"].values
    assert not np.any(codes == FAILED)
    flipped = codes[::-1, ::-1]  # the grid is symmetric about the origin
    assert np.all(codes != flipped)
    assert np.mean(codes == 0) == 0.5


@pytest.mark.slow
def test_forced_twin_well_agrees_with_scipy():
    from scipy.integrate import solve_ivp

    delta, gamma, omega = 0.25, 0.1, 1.2
    system = gc.duffing(omega, delta=delta, alpha=-1.0, beta=1.0, gamma=gamma)
    ds = gc.basins(system, "x=-1.5:1.5:3", "x_dot=-1.5:1.5:3", transient_periods=100, periods=8,
                   rtol=1e-10, atol=1e-10, progress=False)  # fmt: skip
    found = entries(ds)
    T = 2 * math.pi / omega

    def rhs(t, y):
        return [y[1], -delta * y[1] + y[0] - y[0] ** 3 + gamma * math.cos(omega * t)]

    for i, v0 in enumerate(ds["x_dot"].values):
        for j, x0 in enumerate(ds["x"].values):
            sol = solve_ivp(rhs, (0, 108 * T), [x0, v0], method="DOP853", rtol=1e-10, atol=1e-10,
                            t_eval=[108 * T])  # fmt: skip
            end = sol.y[:, -1]
            d = [np.min(np.max(np.abs(a.section_states - end), axis=1)) for a in found]
            assert int(np.argmin(d)) == ds["attractor"].values[i, j]
            assert min(d) < 1e-4


def test_wilson_interval_known_values_and_coverage():
    lo, hi = wilson_interval(5, 10)
    assert (float(lo), float(hi)) == pytest.approx((0.2366, 0.7634), abs=1e-4)
    lo, hi = wilson_interval(0, 10)
    assert (float(lo), float(hi)) == pytest.approx((0.0, 0.2775), abs=1e-4)
    lo, hi = wilson_interval(10, 10)
    assert float(hi) == 1.0 and float(lo) == pytest.approx(10 / (10 + 1.959964**2), rel=1e-6)
    # coverage of the true fraction over many binomial samples is close to 95 %
    rng = np.random.default_rng(1)
    p, n = 0.3, 50
    k = rng.binomial(n, p, 4000)
    lo, hi = wilson_interval(k, n)
    cover = np.mean((lo <= p) & (p <= hi))
    assert 0.93 <= cover <= 0.97


def test_fractions_cover_the_exact_values():
    system = gc.duffing(1.0, delta=0.3, alpha=-1.0, beta=1.0, gamma=0.0)
    # a symmetric box: each well holds exactly half (the odd symmetry), at each damping
    ds = gc.basin_fractions(system, "delta=0.3,0.5", starts=120, box={"x": (-1.8, 1.8),
                            "x_dot": (-1.8, 1.8)}, **SHORT)  # fmt: skip
    assert ds["fraction"].shape == (2, 2)
    assert np.all(ds["track_label"].values == "1T")
    assert np.all(ds["present"].values)  # the two wells are followed as two tracks
    np.testing.assert_allclose(ds["fraction"].values.sum(axis=1), 1.0)
    assert np.all(ds["fraction_low"].values <= 0.5) and np.all(0.5 <= ds["fraction_high"].values)
    # below the barrier on the right: every start ends right, fraction exactly 1
    right = gc.basin_fractions(system, "delta=0.3", starts=60, box={"x": (0.4, 1.3),
                               "x_dot": (-0.25, 0.25)}, **SHORT)  # fmt: skip
    assert right["fraction"].values.tolist() == [[1.0]]
    assert right["fraction_low"].values[0, 0] < 1.0 == right["fraction_high"].values[0, 0]


def test_tracks_link_the_nearest_attractor_of_the_same_label():
    def cat(*points, label="1T"):
        e = [BasinAttractor(label, 1, -0.1, 0.5, "floquet", np.array([p], float)) for p in points]
        return Catalogue(e, np.ones(2))

    tracks = link_tracks([cat([1, 0], [-1, 0]), cat([-0.95, 0], [1.02, 0]), cat([3, 3])])
    assert tracks == [[0, 1], [1, 0], [2]]


def test_errors_name_the_argument():
    system = gc.duffing(1.0, alpha=-1.0, gamma=0.0)
    with pytest.raises(gc.ParameterError, match=r"x must name a state .*x, x_dot.*'q'"):
        gc.basins(system, "q=0:1:3", "x_dot=0:1:3", progress=False)
    with pytest.raises(gc.ParameterError, match="two different states"):
        gc.basins(system, "x=0:1:3", "x=0:1:3", progress=False)
    with pytest.raises(gc.ParameterError, match="base_state names an unknown state 'z'"):
        gc.basins(system, "x=0:1:3", "x_dot=0:1:3", base_state={"z": 1}, progress=False)
    with pytest.raises(gc.ParameterError, match=r"box\['x'\] must be finite with low < high"):
        gc.basin_fractions(system, "delta=0.1", box={"x": (1, 0)}, progress=False)


def test_one_chaotic_attractor_is_one_entry_as_attractors_says() -> None:
    """sheng2016 at Ω = 1.45 has one chaotic attractor (gc.attractors from its own starts);
    the basin catalogue built from random starts far from it found three before their short
    records were merged by the rule that assigns the starts (two instruments disagreed)."""
    gs = gc.preset("sheng2016-v1")
    found = gc.attractors(gs, omega=1.45, starts=8)
    assert [a.label for a in found] == ["chaos"]
    out = gc.basin_fractions(gs, "omega=1.45", starts=24, sample=8, seed=0, progress=False)
    present = out["present"].values[0]
    assert int(np.sum(present)) == 1
    assert float(out["fraction"].values[0][present][0]) == 1.0


def test_a_chaotic_transient_is_confirmed_as_the_orbit_it_ends_on() -> None:
    """Twin-well Duffing, δ = 0.15, Ω = 1, γ = 0.32: some starts wander chaotically for
    hundreds of periods before they settle on the one stable 1T. Decided over two windows of
    100 periods (``confirm_periods=0``), such a start is a chaotic attractor; over a last
    window of 2000 periods (the default) it is the 1T. The truth: scipy's DOP853 from every
    start called chaos ends on the 1T that shooting finds from rest."""
    from scipy.integrate import solve_ivp

    from gearchaos.dynamics.verdict.decide import CONFIRM_PERIODS

    delta, gamma, omega = 0.15, 0.32, 1.0
    system = gc.duffing(omega, delta=delta, alpha=-1.0, beta=1.0, gamma=gamma)
    grid = ("x=-2:2:4", "x_dot=-2:2:4")
    short = gc.basins(system, *grid, confirm_periods=0, progress=False)
    full = gc.basins(system, *grid, progress=False)
    assert short.attrs["confirm_periods"] == 0
    assert full.attrs["confirm_periods"] == CONFIRM_PERIODS == 2000
    assert json.loads(full.attrs["basin_spec"])["confirm_periods"] == CONFIRM_PERIODS
    chaos = np.argwhere(short["label"].values == "chaos")
    assert chaos.size  # the short window takes a transient for an attractor
    ref = gc.periodic_orbit(system, period=1, rtol=1e-11, atol=1e-11, transient_periods=3000)
    assert ref.converged and ref.stable and ref.minimal_period == 1
    (one,) = entries(full)
    assert one.label == "1T" and np.all(full["label"].values == "1T")
    assert one.max_multiplier == pytest.approx(ref.max_multiplier, abs=1e-6)
    np.testing.assert_allclose(one.section_states[0], ref.sections[0], atol=1e-6)
    T = 2 * math.pi / omega

    def rhs(t, y):
        return [y[1], -delta * y[1] + y[0] - y[0] ** 3 + gamma * math.cos(omega * t)]

    for i, j in chaos:
        y0 = [short["x"].values[j], short["x_dot"].values[i]]
        sol = solve_ivp(rhs, (0, 2000 * T), y0, method="DOP853", rtol=1e-9, atol=1e-9,
                        t_eval=[2000 * T])  # fmt: skip
        assert np.max(np.abs(sol.y[:, -1] - ref.sections[0])) < 1e-5
