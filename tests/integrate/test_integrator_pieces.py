"""The integrator's compiled pieces, each called alone on a small problem with a known answer.

One Runge–Kutta step of a linear system is the tableau's stability polynomial R(hM) applied to
y₀ (R from the tableau's arrays in numpy); the error estimate is h (b − b̂)·K of the stages; a
step of y' = 5τ⁴ is exact (order ≥ 5 quadrature); the controller's new step is its formula; a
switch is landed on within tolerance of the analytic crossing; the cubic Hermite interpolant
reproduces a cubic and the tracked extremum is the analytic one; the settling check fires on
constructed periodic sequences and not on others; sections land exactly on their times and, on
y' = 5τ⁴, equal the analytic solution, and the samples between them (the order-4 dense output)
do so on y' = 4τ³. A second tableau (Bogacki–Shampine 3(2)), compiled from
the same code with its own constants, converges with order 3 — the tableau is data.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np
import pytest

import gearchaos as gc
from gearchaos.integrate import _control, _settle, _step, _switch
from gearchaos.integrate.methods import kernels_for, use_tableau
from gearchaos.integrate.tableau import BS32, DOPRI5, TSIT5, ButcherTableau
from gearchaos.model import System
from gearchaos.model.contract import UserModel
from gearchaos.model.kernels import OBS_ALL


@numba.njit(cache=True)
def _rotation_rhs(t, y, p, dydt, obs, level):  # pragma: no cover - compiled
    """y' = M y, M = [[a, w], [−w, a]] (a damped rotation)."""
    a, w = p[0], p[1]
    dydt[0] = a * y[0] + w * y[1]
    dydt[1] = -w * y[0] + a * y[1]
    obs[0] = y[0]
    obs[1] = dydt[0]


@dataclass(frozen=True)
class Rotation(UserModel):
    """A linear test system with complex eigenvalues a ± iw."""

    a: float = -0.3
    w: float = 1.7
    name = "rotation"
    state_names = ("x", "v")
    obs_names = ("x", "x_dot")
    n_track = 1
    rhs = _rotation_rhs

    def pack(self, omega: float) -> np.ndarray:
        return np.array([self.a, self.w, omega])

    def matrix(self) -> np.ndarray:
        return np.array([[self.a, self.w], [-self.w, self.a]])


@numba.njit(cache=True)
def _quartic_rhs(t, y, p, dydt, obs, level):  # pragma: no cover - compiled
    """y' = 5 τ⁴: y = τ⁵ + const (a polynomial an order-5 step integrates exactly)."""
    dydt[0] = 5.0 * t**4
    obs[0] = y[0]
    obs[1] = dydt[0]


@dataclass(frozen=True)
class Quartic(UserModel):
    name = "quartic"
    state_names = ("y",)
    obs_names = ("y", "y_dot")
    n_track = 1
    rhs = _quartic_rhs

    def pack(self, omega: float) -> np.ndarray:
        return np.array([omega])


def _stability_coefficients(tab: ButcherTableau) -> np.ndarray:
    """γ_k = bᵀ A^(k−1) 1 (γ_0 = 1): R(z) = Σ γ_k z^k, an explicit s-stage method's
    polynomial of degree s, computed from the tableau's arrays."""
    arr = tab.arrays()
    gam = [1.0]
    v = np.ones(tab.stages)
    for _ in range(tab.stages):
        gam.append(float(arr.b @ v))
        v = arr.A @ v
    return np.array(gam)


@numba.njit
def _call_step(step, kind, t, y, hs, p, K, yt, obs):  # pragma: no cover - compiled
    """``step`` (an rk_step, inlined where it is used) with ``kind`` as the literal it needs."""
    numba.literally(kind)
    n = y.size
    step(kind, t, y, hs, t + hs, p, K, yt, obs, n, n, 0, False, OBS_ALL)


def _one_step(kern: Any, kind: int, p: np.ndarray, y0: np.ndarray, t: float, hs: float) -> Any:
    """One step with ``kern``'s rk_step from (t, y0), K[0] = f(t, y0) evaluated here."""
    n = y0.size
    S = kern.tableau.stages
    K = np.zeros((S, n))
    obs = np.zeros(4)
    from gearchaos.model.kernels import rhs

    rhs(kind, t, y0, p, K[0], obs, OBS_ALL)
    yt = np.empty(n)
    _call_step(kern.rk_step, kind, t, y0, hs, p, K, yt, obs)
    return yt, K, obs


# -------------------------------------------------------------------------------- the step
@pytest.mark.parametrize("tab", [DOPRI5, TSIT5, BS32], ids=lambda t: t.name)
def test_one_step_is_the_stability_polynomial(tab: ButcherTableau) -> None:
    model = Rotation()
    p = model.pack(1.0)
    y0 = np.array([0.8, -0.35])
    hs = 0.37
    yt, K, obs = _one_step(kernels_for(tab), model.kind, p, y0, 0.0, hs)
    Z = hs * model.matrix()
    gam = _stability_coefficients(tab)
    expected = sum(g * np.linalg.matrix_power(Z, k) for k, g in enumerate(gam)) @ y0
    assert yt == pytest.approx(expected, rel=1e-14, abs=1e-15)
    # FSAL: the last stage is f at the new point, whose observables the step leaves in obs
    assert K[-1] == pytest.approx(model.matrix() @ yt, rel=1e-14)
    assert obs[0] == yt[0]


def test_dopri5_polynomial_matches_exp_through_order_5() -> None:
    gam = _stability_coefficients(DOPRI5)
    assert gam[:6] == pytest.approx([1 / math.factorial(k) for k in range(6)], rel=1e-15)
    assert gam[6] != pytest.approx(1 / math.factorial(6))  # not a 6th-order method


def test_step_of_a_quartic_is_exact() -> None:
    kind = Quartic().kind
    p = np.array([1.0])
    yt, _, _ = _one_step(kernels_for(DOPRI5), kind, p, np.array([0.25]), 0.3, 0.9)
    assert yt[0] == pytest.approx(0.25 + 1.2**5 - 0.3**5, rel=1e-15)


def test_stage_input_is_the_tableau_row_in_column_order() -> None:
    """Each stage argument is y + h Σ_j a_sj K_j, summed from j = 0 up, zero terms skipped:
    bitwise the arithmetic of the stages written out by hand."""
    rng = np.random.default_rng(3)
    n = 5
    y = rng.standard_normal(n)
    K = rng.standard_normal((DOPRI5.stages, n))
    hs = 0.013
    A = DOPRI5.arrays().A
    yt = np.empty(n)
    for s in range(1, DOPRI5.stages):
        _step.stage_input(yt, y, K, hs, n, s)
        for i in range(n):
            acc = -0.0
            for j in range(s):
                if A[s, j] != 0.0:
                    acc += A[s, j] * K[j, i]
            assert yt[i] == y[i] + hs * acc  # bitwise
        assert yt == pytest.approx(y + hs * (A[s, :s] @ K[:s]), rel=1e-14)


def test_error_norm_is_b_minus_b_hat_of_the_stages() -> None:
    model = Rotation()
    y0 = np.array([0.8, -0.35])
    hs = 0.21
    yt, K, _ = _one_step(kernels_for(DOPRI5), model.kind, model.pack(1.0), y0, 0.0, hs)
    rtol, atol = 1e-6, 1e-9
    e = hs * (DOPRI5.arrays().e @ K)
    sc = atol + rtol * np.maximum(np.abs(y0), np.abs(yt))
    expected = math.sqrt(float(np.mean((e / sc) ** 2)))
    got = _step.error_norm(y0, yt, K, hs, 2, 2, rtol, atol, 1.0)
    assert got == pytest.approx(expected, rel=1e-12)
    # components after n_base are scaled by tan_tol, and left out of the norm when it is inf
    only_first = _step.error_norm(y0, yt, K, hs, 2, 1, rtol, atol, math.inf)
    assert only_first == pytest.approx(abs(e[0] / sc[0]), rel=1e-12)
    # the embedded estimate is O(h^5): halving h divides it by about 32
    yt2, K2, _ = _one_step(kernels_for(DOPRI5), model.kind, model.pack(1.0), y0, 0.0, hs / 2)
    ratio = got / _step.error_norm(y0, yt2, K2, hs / 2, 2, 2, rtol, atol, 1.0)
    assert 20 < ratio < 40


# ------------------------------------------------------------------------------ the control
def test_step_controller_is_its_formula() -> None:
    alpha = _step.ALPHA
    assert alpha == 0.2 - 0.75 * _control.BETA  # DOPRI5: 1/(4 + 1) − 0.75 β
    err, hs, h, err_old = 0.37, 0.01, 0.02, 0.5
    h_new, log_old = _control.accepted_step(
        err, hs, h, math.log(err_old), False, False, math.inf, alpha
    )
    fac = min(10.0, max(0.2, 0.9 * err**-alpha * err_old**_control.BETA))
    assert h_new == pytest.approx(hs * fac, rel=1e-14)
    assert log_old == pytest.approx(math.log(err))
    # cut short (a sample or a switch): the larger proposal is kept, err_{n−1} unchanged
    h_cut, log_cut = _control.accepted_step(err, hs, 1.0, -1.0, False, True, math.inf, alpha)
    assert (h_cut, log_cut) == (1.0, -1.0)
    # no growth right after a rejection; err = 0 grows by MAX_FACTOR; max_step caps
    assert _control.accepted_step(1e-6, hs, h, 0.0, True, False, math.inf, alpha)[0] == hs
    assert _control.accepted_step(0.0, hs, h, 0.0, False, False, math.inf, alpha)[0] == 10 * hs
    assert _control.accepted_step(0.0, hs, h, 0.0, False, False, 0.03, alpha)[0] == 0.03
    # rejected: shrink by 0.9 err^(−α), at most by MIN_FACTOR; not finite: by MIN_FACTOR
    assert _control.rejected_step(3.0, hs, alpha) == pytest.approx(hs * 0.9 * 3.0**-alpha)
    assert _control.rejected_step(1e30, hs, alpha) == pytest.approx(0.2 * hs)
    assert _control.rejected_step(math.nan, hs, alpha) == pytest.approx(0.2 * hs)
    assert _control.pi_alpha(BS32.order_hat) == pytest.approx(1 / 3 - 0.03)


# ------------------------------------------------------------------------ events (switches)
def _cos_point(t: float) -> tuple[float, float]:
    return math.cos(t), -math.sin(t)


def test_land_switch_retries_to_end_on_the_analytic_crossing() -> None:
    b = 0.5  # cos τ crosses +b at τ* = arccos(b), leaving the upper region
    t_star = math.acos(b)
    t0, hs = 0.9, 0.25  # the step [0.9, 1.15] contains τ* ≈ 1.0472
    hist = np.zeros((3, 2))
    hist[0] = _cos_point(t0)
    obs = np.array(_cos_point(t0 + hs))
    sw = np.array([b])
    h_event, where = _switch.land_switch(hist, obs, hs, hs, 1, sw, 1e-12)
    assert where == 0
    # the crossing of the step's cubic Hermite interpolant: within its error bound
    # h⁴ max|v''''| / 384 in v, divided by |v'| in τ
    bound = hs**4 / 384 / math.sin(t_star)
    assert t0 + h_event == pytest.approx(t_star + _switch.AIM * hs, abs=bound)
    # a step ending within LAND·h past the crossing has landed on it
    hs2 = (t_star - t0) * (1 + 0.2 * _switch.LAND)
    h_event, where = _switch.land_switch(hist, np.array(_cos_point(t0 + hs2)), hs2, hs2, 1, sw, 0.0)
    assert (h_event, where) == (-1.0, 2)


def test_aim_step_ends_just_past_the_predicted_crossing_or_on_the_target() -> None:
    b = 0.5
    t_star = math.acos(b)
    times = np.array([0.95, 0.9, 0.85])  # the last three accepted points, newest first
    hist = np.array([_cos_point(t) for t in times])
    sw = np.array([b])
    args = (hist, 3, times, 1, sw, True, 1e-12)
    hs, clipped, shortened = _switch.aim_step(0.3, -1.0, 0.95, 10.0, *args)
    assert shortened and not clipped
    # the quintic Hermite extrapolation of the three points (spacing 0.05) over 0.1: ~1e-8
    assert 0.95 + hs == pytest.approx(t_star + _switch.AIM * 0.3, abs=1e-7)
    # a target before the predicted crossing: the step is clipped to end exactly on it
    hs, clipped, shortened = _switch.aim_step(0.3, -1.0, 0.95, 1.0, *args)
    assert (clipped, shortened, 0.95 + hs) == (True, False, 1.0)
    # a retry after a missed switch takes the event's step
    assert _switch.aim_step(0.3, 0.07, 0.95, 10.0, *args)[:2] == (0.07, False)


def test_push_point_keeps_the_three_newest() -> None:
    hist = np.zeros((3, 2))
    t_hist = np.zeros(3)
    for k in range(4):
        _switch.push_point(hist, t_hist, np.array([k, 10.0 * k]), 0.5 * k, 2)
    assert hist.tolist() == [[3, 30], [2, 20], [1, 10]]
    assert t_hist.tolist() == [1.5, 1.0, 0.5]


# ------------------------------------------------------------- dense output and the extrema
def test_hermite_reproduces_a_cubic() -> None:
    def v(t: float) -> float:
        return 2.0 * t**3 - t**2 + 0.5 * t - 3.0

    def dv(t: float) -> float:
        return 6.0 * t**2 - 2.0 * t + 0.5

    t0, h = 0.4, 0.7
    for s in (0.0, 0.13, 0.5, 0.91, 1.0):
        got = _switch.hermite(v(t0), v(t0 + h), h * dv(t0), h * dv(t0 + h), s)
        assert got == pytest.approx(v(t0 + s * h), rel=1e-14)


def test_track_finds_the_interior_extremum_of_a_step() -> None:
    # v = −(τ − 0.3)² + 1 (a quadratic: the Hermite cubic is exact): maximum 1 at τ = 0.3
    def point(t: float) -> tuple[float, float]:
        return -((t - 0.3) ** 2) + 1.0, -2.0 * (t - 0.3)

    t0, h = 0.1, 0.5
    hist = np.zeros((3, 2))
    hist[0] = point(t0)
    omin, omax = np.array([np.inf]), np.array([-np.inf])
    _switch.track(hist, np.array(point(t0 + h)), h, 1, omin, omax)
    assert omax[0] == pytest.approx(1.0, rel=1e-15)
    assert omin[0] == point(t0 + h)[0]  # the step's end: no interior minimum


# ------------------------------------------------------------------------------ settling
def _first_settled(seq: np.ndarray) -> int | None:
    ring = np.zeros((_settle.SETTLE_MAX_PERIOD + 1, seq.shape[1]))
    runs = np.zeros(_settle.SETTLE_MAX_PERIOD + 1, dtype=np.int64)
    for k, y in enumerate(seq):
        if _settle.settled(y, ring, runs, k, seq.shape[1]):
            return k
    return None


def test_settled_fires_after_enough_repeats_of_a_period() -> None:
    fixed = np.tile([1.0, -2.0], (40, 1))
    assert _first_settled(fixed) == _settle.SETTLE_MIN_MATCHES  # 8 matches of period 1
    per5 = np.array([[math.sin(k * 2 * math.pi / 5), 0.3] for k in range(60)])
    # period 5: the first 5 points have nothing to match, then 3 cycles = 15 matches
    assert _first_settled(per5) == 5 + _settle.SETTLE_CYCLES * 5 - 1
    noisy = per5 + np.random.default_rng(1).standard_normal(per5.shape) * 1e-3
    assert _first_settled(noisy) is None
    # a transient that decays into the period-5 cycle settles once it is within the tolerance
    decaying = per5 + np.exp(-np.arange(60))[:, None]
    k = _first_settled(decaying)
    assert k is not None and math.exp(-(k - 15)) < _settle.SETTLE_TOL * 10
    assert _settle.first_section(0.0, 10.0, 2.5) == 3  # τ_rec − 3T is the first after 0


# ------------------------------------------------------------------------------ sampling
@numba.njit(cache=True)
def _cubic_rhs(t, y, p, dydt, obs, level):  # pragma: no cover - compiled
    """y' = 4 τ³: y = τ⁴ + const (a polynomial an order-4 dense output reproduces exactly)."""
    dydt[0] = 4.0 * t**3
    obs[0] = y[0]
    obs[1] = dydt[0]


@dataclass(frozen=True)
class Cubic(Quartic):
    name = "cubic"
    rhs = _cubic_rhs


def test_samples_land_on_their_times_and_match_a_polynomial_solution() -> None:
    """Sections are step ends, the samples between them come from the order-4 continuous
    extension: on y' = 5τ⁴ the sections are exact (the steps are), on y' = 4τ³ every sample
    is (the dense output integrates cubics exactly), on y' = 5τ⁴ the samples between are not
    (order 4, not 5)."""
    kw = dict(transient_periods=1, periods=2, samples_per_period=7, rtol=1e-10, atol=1e-12)
    T = 2 * math.pi / 0.9
    sec = np.arange(14) % 7 == 0
    for model, power in ((Quartic(), 5), (Cubic(), 4)):
        res = gc.simulate(System(model, 0.9), **kw)  # type: ignore[arg-type]
        tau = np.asarray(res.tau)
        j = np.arange(14)
        assert np.array_equal(tau, np.where(sec, T + (j // 7) * T, T + j * (T / 7)))
        y = np.asarray(res.states)[:, 0]
        exact = tau**power - tau[0] ** power
        assert y[sec] - y[0] == pytest.approx(exact[sec], rel=1e-12)
        if power == 4:
            assert y - y[0] == pytest.approx(exact, rel=1e-12)
        else:
            assert np.max(np.abs(y - y[0] - exact)[~sec] / np.abs(exact[~sec])) > 1e-11


# ------------------------------------------------------------------ a second tableau: data
def _fixed_step_error(tab: ButcherTableau, steps: int) -> float:
    model = Rotation()
    kern = kernels_for(tab)
    kind, p = model.kind, model.pack(1.0)
    y = np.array([1.0, 0.0])
    h = 2.0 / steps
    for k in range(steps):
        y, _, _ = _one_step(kern, kind, p, y, k * h, h)
    c, sn = math.cos(2.0 * model.w), math.sin(2.0 * model.w)
    exact = math.exp(2.0 * model.a) * np.array([c, -sn])  # e^{2M} (1, 0)
    return float(np.max(np.abs(y - exact)))


@pytest.mark.parametrize(("tab", "order"), [(BS32, 3), (DOPRI5, 5)], ids=["BS32", "DOPRI5"])
def test_a_tableau_converges_with_its_order(tab: ButcherTableau, order: int) -> None:
    errors = [_fixed_step_error(tab, n) for n in (20, 40, 80)]
    rates = [math.log2(a / b) for a, b in itertools.pairwise(errors)]
    assert all(abs(r - order) < 0.3 for r in rates), rates


def test_the_integrator_runs_another_tableau_from_its_data() -> None:
    system = System(Rotation(), 1.0)
    kw = dict(transient_periods=0, periods=2, samples_per_period=4, rtol=1e-7, atol=1e-10)
    dp = gc.simulate(system, **kw)
    with use_tableau(BS32):
        bs = gc.simulate(system, **kw)
    # a third-order pair needs many more steps for the same tolerance, and still meets it
    assert bs.steps_accepted > 2 * dp.steps_accepted
    assert np.asarray(bs.states) == pytest.approx(np.asarray(dp.states), abs=1e-5)
    assert gc.simulate(system, **kw).steps_accepted == dp.steps_accepted  # the block ended
