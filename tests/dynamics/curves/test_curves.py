"""Two-parameter boundary curves (gearchaos.boundary_curve) against independent truth.

* The fold curve of the single-mesh backlash oscillator in (Ω, ε) passes through the folds that
  a scipy shooting solver finds at fixed ε: solve_ivp (DOP853, rtol 1e-12, stopped at every
  kink of the dead zone) for the map and its monodromy (variational equations), and
  scipy.optimize.fsolve on (P(y) − y, det(DP(y) − I)) in (y, Ω) — the project's own code
  only supplies the starting guess, which fsolve moves by its own equations.
* From one fold, the fold curve in (Ω, ζ) turns at a cusp and comes back as the other fold of
  the branch (both folds of the one-parameter continuation at ζ = 0.05).
* A period-doubling curve of the planetary model in (Ω, ξ) passes through the period doublings
  of one-parameter continuations at three fixed ξ, within their location uncertainties.
* The Neimark–Sacker curve of the Duffing oscillator is δ = 0 (Liouville's formula), and its
  1:3 and 1:4 resonances are where scipy shooting puts them.
* The fold curve of a Duffing oscillator beside an uncoupled Mathieu oscillator meets a period
  doubling (fold–flip) where scipy finds the Mathieu block's multiplier −1 at the Duffing's
  fold.
* The curve file round-trips, refuses a different curve on resume and extends on resume.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import fsolve

import gearchaos as gc
from duffing_mathieu import DuffingMathieu
from gearchaos.dynamics.continuation.events import events
from gearchaos.dynamics.curves.boundary import boundary_curve
from gearchaos.dynamics.curves.file import open_curve
from gearchaos.model.system import System

ZETA, B, FM, FA = 0.05, 1.0, 0.1, 0.1
TIGHT = {"rtol": 1e-10, "atol": 1e-12}


def _rhs(omega: float, eps: float):
    def f(t, u):
        x, v = u[0], u[1]
        c = np.cos(omega * t)
        k = 1.0 + eps * c
        fz = x - B if x > B else (x + B if x < -B else 0.0)
        df = 1.0 if abs(x) > B else 0.0
        out = [v, FM + FA * omega**2 * c - 2 * ZETA * v - k * fz]
        # variational equations of the 2x2 fundamental matrix (column-major in u[2:])
        phi = u[2:].reshape(2, 2, order="F")
        a = np.array([[0.0, 1.0], [-k * df, -2 * ZETA]])
        return np.concatenate([out, (a @ phi).ravel(order="F")])

    return f


def scipy_map(y: np.ndarray, omega: float, eps: float) -> tuple[np.ndarray, np.ndarray]:
    """P(y) and DP(y) over one forcing period from τ = 0, integrating from kink to kink."""
    T = 2 * np.pi / omega
    u = np.concatenate([y, np.eye(2).ravel(order="F")])
    t = 0.0
    f = _rhs(omega, eps)

    def hit_hi(t, u):
        return u[0] - B

    def hit_lo(t, u):
        return u[0] + B

    for ev in (hit_hi, hit_lo):
        ev.terminal = True
    while t < T:
        sol = solve_ivp(
            f, (t, T), u, method="DOP853", rtol=1e-12, atol=1e-13, events=(hit_hi, hit_lo)
        )
        u = sol.y[:, -1]
        t_new = sol.t[-1]
        if sol.status == 1:  # a kink: step just across it (the field is continuous there)
            t_new = min(T, t_new + 1e-12)
            u = u + 1e-12 * f(sol.t[-1], u)
        t = t_new
    return u[:2], u[2:].reshape(2, 2, order="F")


def scipy_fold(guess_y: np.ndarray, guess_omega: float, eps: float) -> float:
    def eqs(w):
        y, om = w[:2], w[2]
        p, m = scipy_map(y, om, eps)
        return np.append(p - y, np.linalg.det(m - np.eye(2)))

    w, _info, ok, msg = fsolve(eqs, np.append(guess_y, guess_omega), xtol=1e-12, full_output=True)
    assert ok == 1, msg
    assert np.max(np.abs(eqs(w))) < 1e-9
    return float(w[2])


@pytest.fixture(scope="module")
def folds():
    system = gc.backlash_oscillator(0.5, zeta=ZETA, b=B, f_mean=FM, f_alt=FA)
    ds = gc.continuation(system, "omega=0.5:1.6", **TIGHT)
    found = sorted((e for e in events(ds) if e.kind == "fold"), key=lambda e: -e.value)
    assert len(found) == 2, found
    return system, found


def test_fold_curve_passes_through_scipy_folds_at_fixed_eps(folds) -> None:
    system, (upper, _) = folds
    at = [0.1, 0.3]
    curve = boundary_curve(system, upper, "eps=0:0.4", at=at, **TIGHT)
    assert curve.attrs["curve_kind"] == "fold"
    assert "reached the range end eps=0.4" in curve.attrs["stop_reason_forward"]
    assert np.all(curve.residual.values <= curve.attrs["tol"])
    crit = curve.critical_re.values + 1j * curve.critical_im.values
    assert np.all(np.abs(crit - 1.0) < 1e-3)
    for eps in at:
        (k,) = np.flatnonzero((curve.on_grid.values == 1) & np.isclose(curve.eps.values, eps))
        om = float(curve.omega.values[k])
        # scipy starts 1e-3 away in Ω; fsolve finds the fold by its own equations
        truth = scipy_fold(curve.orbit_state.values[k], om - 1e-3, eps)
        assert abs(om - truth) < 1e-6, (eps, om, truth)
    # the fold moves: at ε = 0.3 it is far from the ε = 0 value (not a constant curve)
    assert abs(truth - upper.value) > 0.05


def test_fold_curve_in_zeta_turns_at_a_cusp_into_the_other_fold(folds) -> None:
    system, (upper, lower) = folds
    curve = boundary_curve(system, upper, "zeta=0.05:0.5", within="omega=0.3:1.2", **TIGHT)
    kinds = list(curve.event_kind.values)
    assert kinds == ["cusp"], kinds
    # at the cusp ζ is largest along the curve; both ends are back at ζ = 0.05
    zc = float(curve.event_value2.values[0])
    assert zc >= curve.zeta.values.max() - float(curve.event_uncertainty2.values[0]) - 1e-9
    ends = curve.omega.values[[0, -1]]
    assert np.allclose(curve.zeta.values[[0, -1]], 0.05)
    assert np.isclose(ends[0], upper.value, atol=1e-8)
    assert abs(ends[-1] - lower.value) < 1e-6, (ends, lower)


def test_curve_file_round_trip_resume_and_refusal(folds, tmp_path) -> None:
    system, (upper, _) = folds
    path = tmp_path / "curve.nc"
    first = boundary_curve(system, upper, "eps=0:0.4", max_points=5, store=path, **TIGHT)
    assert first.attrs["stop_reason_forward"].startswith("max_points")
    back = open_curve(path)
    assert np.array_equal(back.omega.values, first.omega.values)
    for key in ("gearset_toml", "version", "rtol", "parameter2", "fixed"):
        assert key in back.attrs or key == "gearset_toml"
    with pytest.raises(gc.StoreError, match="exists"):
        boundary_curve(system, upper, "eps=0:0.4", max_points=5, store=path, **TIGHT)
    with pytest.raises(gc.StoreError, match="vary"):
        boundary_curve(system, upper, "eps=0:0.3", store=path, resume=True, **TIGHT)
    more = boundary_curve(system, upper, "eps=0:0.4", store=path, resume=True, **TIGHT)
    assert more.sizes["point"] > first.sizes["point"]
    assert "reached the range end eps=0.4" in more.attrs["stop_reason_forward"]
    # the resumed curve starts with the stored points
    n = first.sizes["point"]
    assert np.allclose(more.omega.values[:n], first.omega.values)
    # a finished curve read back is assessed everywhere on request (its stored points hold no
    # monodromy: the borders of the test function are computed again for each)
    assert np.isnan(more.uncertainty.values).all()  # nothing landed, nothing assessed
    assessed = boundary_curve(
        system, upper, "eps=0:0.4", store=path, resume=True, assess="all", **TIGHT
    )
    assert assessed.attrs["assessed"] == "all"
    assert np.array_equal(assessed.omega.values, more.omega.values)
    assert np.all(np.isfinite(assessed.uncertainty.values))
    assert np.all(assessed.uncertainty.values < 1e-8)
    with pytest.raises(gc.ParameterError, match="event kind"):
        bp = type(upper)(**{**upper.__dict__, "kind": "branch_point"})
        boundary_curve(system, bp, "eps=0:0.4")
    with pytest.raises(gc.ParameterError, match="outside"):
        boundary_curve(system, upper, "eps=0.1:0.4")


def test_planetary_period_doubling_curve_matches_one_parameter_branches() -> None:
    gs = gc.preset("sheng2016-v1")
    branch = gc.continuation(gs, "omega=3.3:3.45", max_step=0.01)
    (pd,) = [e for e in events(branch) if e.kind == "period_doubling"]
    # sheng2016 has ξ = 0.03; its period-doubling tongue closes near ξ = 0.032, so every ξ
    # below crosses the curve twice (both sides of the tongue)
    at = [0.015, 0.02, 0.025]
    curve = boundary_curve(gs, pd, "xi=0.01:0.05", within="omega=3:4", at=at)
    assert curve.attrs["curve_kind"] == "period_doubling"
    crit = curve.critical_re.values + 1j * curve.critical_im.values
    assert np.all(np.abs(crit + 1.0) < 1e-3)
    assert curve.xi.values.max() < 0.035  # the tongue closes
    checked = 0
    for xi in at:
        landed = np.flatnonzero((curve.on_grid.values == 1) & np.isclose(curve.xi.values, xi))
        assert landed.size == 2, (xi, curve.xi.values[curve.on_grid.values == 1])
        for k in landed:
            om = float(curve.omega.values[k])
            one = gc.continuation(gs, f"omega={om - 0.03}:{om + 0.03}", xi=xi, max_step=0.01)
            pds = [e for e in events(one) if e.kind == "period_doubling"]
            assert pds, (xi, om)
            e = min(pds, key=lambda e: abs(e.value - om))
            u = float(curve.uncertainty.values[k])
            assert 0 <= u < 1e-7, (xi, om, u)  # the curve point's own stated uncertainty
            assert abs(e.value - om) <= e.uncertainty + u, (xi, om, e, u)
            checked += 1
    assert checked == 6


def test_grazing_curve_of_the_backlash_oscillator_is_the_closed_form() -> None:
    """The backlash oscillator with constant stiffness (ε = 0) is a linear forced oscillator
    while its teeth stay in contact: x = b + F_m + A cos(Ωτ − φ) with
    A = F_a Ω² / √((1 − Ω²)² + (2ζΩ)²), so contact is first lost (grazing) where A = F_m:
    for F_a = F_m, Ω² = 1/(2 − 4ζ²). The grazing curve in (Ω, ζ) continued from the grazing
    event at ζ = 0.05 must lie on that curve (no simulation in the check)."""
    system = gc.backlash_oscillator(1.0, zeta=0.05, f_alt=0.1, f_mean=0.1)
    branch = gc.continuation(system, "omega=0.6:0.72")
    (graze,) = [e for e in events(branch) if e.kind == "grazing"]
    at = [0.03, 0.08, 0.12]
    curve = boundary_curve(
        system, graze, "zeta=0.02:0.15", within="omega=0.6:0.8", at=at, assess="all"
    )
    assert curve.attrs["curve_kind"] == "grazing"
    omega, zeta = curve.omega.values, curve.zeta.values
    assert zeta.min() <= 0.021 and zeta.max() >= 0.149  # it crossed the whole range
    exact = 1.0 / np.sqrt(2.0 - 4.0 * zeta**2)
    landed = curve.on_grid.values == 1
    assert landed.sum() == len(at)
    u, u2 = curve.uncertainty.values, curve.uncertainty2.values
    assert np.all(u < 1e-8) and np.all(u2[landed] == 0.0)
    # each point is as far from the truth as it says (u: its shift to the correction 100
    # times tighter, with 5 % for that one's own error); a point off the landed values moved
    # across the curve, by u2 in ζ too: the truth at its ζ moved by dΩ/dζ·u2 at most
    slope = np.abs(np.gradient(exact, zeta))
    assert np.all(np.abs(omega - exact) <= u + slope * np.nan_to_num(u2))


# ---------------------------------------------------------------- Neimark–Sacker and resonances
DU_BETA, DU_GAMMA = 0.5, 0.3


def _duffing_map(y: np.ndarray, omega: float) -> tuple[np.ndarray, np.ndarray]:
    """scipy's P(y) and DP(y) of the undamped Duffing x'' + x + βx³ = γ cos Ωτ (δ = 0, where
    the Neimark–Sacker curve lies), DOP853 at rtol 1e-12 with the variational equations."""

    def f(t, u):
        x, v = u[0], u[1]
        phi = u[2:].reshape(2, 2, order="F")
        a = np.array([[0.0, 1.0], [-(1.0 + 3.0 * DU_BETA * x * x), 0.0]])
        du = [v, DU_GAMMA * np.cos(omega * t) - x - DU_BETA * x**3]
        return np.concatenate([du, (a @ phi).ravel(order="F")])

    u0 = np.concatenate([y, np.eye(2).ravel(order="F")])
    sol = solve_ivp(f, (0.0, 2 * np.pi / omega), u0, method="DOP853", rtol=1e-12, atol=1e-13)
    u = sol.y[:, -1]
    return u[:2], u[2:].reshape(2, 2, order="F")


def scipy_resonance(guess_y: np.ndarray, guess_omega: float, q: int) -> float:
    """Ω of the 1:q resonance on the curve δ = 0: there det M = 1, so the multipliers are
    e^{±iθ} and θ = 2π/q means trace M = 2 cos(2π/q); fsolve on (P(y) − y, tr M − 2cos(2π/q))
    in (y, Ω)."""

    def eqs(w):
        p, m = _duffing_map(w[:2], w[2])
        return np.append(p - w[:2], np.trace(m) - 2.0 * np.cos(2.0 * np.pi / q))

    w, _info, ok, msg = fsolve(eqs, np.append(guess_y, guess_omega), xtol=1e-13, full_output=True)
    assert ok == 1, msg
    assert np.max(np.abs(eqs(w))) < 1e-10
    return float(w[2])


def test_neimark_sacker_curve_of_the_duffing_oscillator_and_its_resonances() -> None:
    """The forced Duffing oscillator x'' + δx' + x + βx³ = γ cos Ωτ has div f = −δ, so by
    Liouville's formula det M = e^{−δT} for every orbit: a complex pair of multipliers has
    |μ|² = e^{−δT} and crosses the unit circle exactly at δ = 0, whatever Ω, β and γ. The
    Neimark–Sacker curve in (Ω, δ), continued from the event of a one-parameter branch in δ at
    Ω = 3.5, must therefore be the line δ = 0, every point within its stated uncertainty
    (assess="all"). On it the pair's angle moves with Ω; the 1:3 and 1:4 resonances (θ = 2π/3,
    π/2) it reports must be where scipy's independent shooting puts them (the nonlinear term
    moves them off the linear values Ω = 3 and 4)."""
    system = gc.duffing(3.5, delta=-0.05, alpha=1.0, beta=DU_BETA, gamma=DU_GAMMA)
    branch = gc.continuation(system, "delta=-0.05:0.05")
    (ns,) = [e for e in events(branch) if e.kind == "neimark_sacker"]
    assert abs(ns.value) < 1e-8
    curve = boundary_curve(
        system, ns, "omega=2.2:4.5", within="delta=-0.1:0.1", at=[2.5, 3.5, 4.2], assess="all"
    )
    assert curve.attrs["curve_kind"] == "neimark_sacker"
    assert curve.attrs["assessed"] == "all"
    omega, delta = curve.omega.values, curve.delta.values
    assert omega.min() == 2.2 and omega.max() == 4.5  # it crossed the whole range
    u, u2 = curve.uncertainty.values, curve.uncertainty2.values
    assert np.all(np.isfinite(u)) and np.all(np.isfinite(u2))
    assert np.all(u < 1e-8)
    # each point is as far from δ = 0 as it says (u: its shift to the correction 100 times
    # tighter, with 5 % for that one's own error)
    assert np.all(np.abs(delta) <= u)
    landed = curve.on_grid.values == 1
    assert sorted(omega[landed]) == [2.5, 3.5, 4.2]  # the start (Ω = 3.5) counts as landed
    assert np.all(u2[landed] == 0.0)
    assert np.allclose(curve.multiplier_abs.values, 1.0, atol=1e-8)
    kinds = [str(k) for k in curve.event_kind.values]
    assert kinds == ["resonance_1_3", "resonance_1_4"], kinds
    for k, q in enumerate((3, 4)):
        located = float(curve.event_value2.values[k])
        truth = scipy_resonance(curve.event_state.values[k], located, q)
        assert abs(truth - q) > 1e-4  # the nonlinearity moved it: not the linear value
        assert abs(located - truth) <= curve.event_uncertainty2.values[k]
        assert abs(located - truth) < 1e-7


# --------------------------------------------------------------------------------- fold–flip
def _block_map(y: np.ndarray, omega: float, stiff, damping: float) -> tuple[np.ndarray, ...]:
    """scipy's one-period map and monodromy of z'' + damping z' + stiff(t, z) = 0 (stiff returns
    the restoring force and its z-derivative), DOP853 at rtol 1e-12."""

    def f(t, s):
        z, v = s[0], s[1]
        force, k = stiff(t, z)
        phi = s[2:].reshape(2, 2, order="F")
        a = np.array([[0.0, 1.0], [-k, -damping]])
        return np.concatenate([[v, -force - damping * v], (a @ phi).ravel(order="F")])

    s0 = np.concatenate([y, np.eye(2).ravel(order="F")])
    sol = solve_ivp(f, (0.0, 2 * np.pi / omega), s0, method="DOP853", rtol=1e-12, atol=1e-13)
    s = sol.y[:, -1]
    return s[:2], s[2:].reshape(2, 2, order="F")


@pytest.mark.slow  # a fold curve continued to a codimension-2 point (minutes on 2 cores)
def test_fold_curve_meets_a_period_doubling_at_the_scipy_fold_flip_point() -> None:
    """The Duffing–Mathieu test model (tests/duffing_mathieu.py, written as a user
    model): its fold curve in (Ω, q) is the Duffing's fold Ω_fold for every q, and it meets a
    period doubling (fold–flip) where the Mathieu block at Ω_fold has a multiplier −1:
    det(M_u + I) = 0, at ±q* (the sign of q is a half-period time shift). scipy finds Ω_fold
    from the Duffing alone (fsolve on P(y) − y, det(M − I)) and q* from the Mathieu oscillator
    alone (fsolve on det(M_u + I)); the curve and the fold–flip points it reports must be there
    within their stated uncertainties."""
    model = DuffingMathieu()
    system = System(model, 1.2)
    branch = gc.continuation(system, "omega=1.2:2.5")
    fold = next(e for e in events(branch) if e.kind == "fold")
    curve = boundary_curve(system, fold, "q=-0.8:0.8", within="omega=1.2:2.5", assess="all")

    def duffing(t, x, om):
        force = x + model.beta * x**3 - model.gamma * np.cos(om * t)
        return force, 1.0 + 3.0 * model.beta * x**2

    def fold_eqs(w):
        p, m = _block_map(w[:2], w[2], lambda t, x: duffing(t, x, w[2]), model.delta)
        return np.append(p - w[:2], np.linalg.det(m - np.eye(2)))

    w, _, ok, msg = fsolve(fold_eqs, np.append(fold.state[[0, 2]], fold.value), xtol=1e-13,
                           full_output=True)  # fmt: skip
    assert ok == 1, msg
    omega_fold = float(w[2])

    def flip_eq(q):
        def mathieu(t, u):
            k = 1.0 + 2.0 * q[0] * np.cos(omega_fold * t)
            return k * u, k

        _, m = _block_map(np.zeros(2), omega_fold, mathieu, model.c)
        return [np.linalg.det(m + np.eye(2))]

    q_star = float(fsolve(flip_eq, [0.3], xtol=1e-13)[0])
    assert abs(flip_eq([q_star])[0]) < 1e-10

    omega, u = curve.omega.values, curve.uncertainty.values
    assert curve.q.values.min() == -0.8 and curve.q.values.max() == 0.8
    assert np.all(np.abs(omega - omega_fold) <= u)
    assert np.allclose(curve.orbit_state.values[:, [1, 3]], 0.0, atol=1e-12)  # u ≡ 0
    kinds = [str(k) for k in curve.event_kind.values]
    assert kinds == ["fold_flip", "fold_flip"], kinds
    for k, sign in enumerate((-1.0, 1.0)):
        q = float(curve.event_value2.values[k])
        assert abs(q - sign * q_star) <= curve.event_uncertainty2.values[k]
        assert (
            abs(float(curve.event_value.values[k]) - omega_fold)
            <= (curve.event_uncertainty.values[k])
        )
        assert curve.event_uncertainty2.values[k] < 1e-6
