"""One Newton corrector over K points (issue 36, item 5): a point's iteration does not depend on
the points it shares its rounds with, a single orbit is the case K = 1, and every door that
solves Pⁿ(y) − y = 0 — :func:`gearchaos.periodic_orbit`, :func:`gearchaos.periodic_orbits`,
the continuation — goes through it.

The independent reference: the weakly forced Duffing oscillator x'' + δx' + αx + βx³ =
γ cos Ωτ, its stroboscopic map and monodromy matrix integrated here by scipy (DOP853 with the
variational equations, rtol 1e-12) and its fixed point found by scipy's own root finder from
the same guess.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import linear_sum_assignment, root

import gearchaos as gc
from gearchaos.dynamics.orbits import corrector
from gearchaos.dynamics.orbits.batch import periodic_orbits
from gearchaos.dynamics.orbits.corrector import Problem, Start, correct_points
from gearchaos.integrate.settings import SolverSettings

DELTA, ALPHA, BETA, GAMMA = 0.3, 1.0, 1.0, 0.2
OMEGAS = (0.7, 1.1, 1.6)
#: Tight enough that the corrector's orbits and multipliers are good to about 1e-10.
SETTINGS = SolverSettings(rtol=1e-11, atol=1e-13, transient_periods=50)
GUESS = np.array([0.05, -0.05])


def scipy_map(
    y: np.ndarray, omega: float, alpha: float = ALPHA, gamma: float = GAMMA
) -> tuple[np.ndarray, np.ndarray]:
    """P(y) and DP(y) over one forcing period from τ = 0 (the section of ``SETTINGS``)."""

    def f(t: float, u: np.ndarray) -> np.ndarray:
        x, v = u[0], u[1]
        phi = u[2:].reshape(2, 2, order="F")
        a = np.array([[0.0, 1.0], [-(alpha + 3.0 * BETA * x * x), -DELTA]])
        du = [v, gamma * np.cos(omega * t) - DELTA * v - alpha * x - BETA * x**3]
        return np.concatenate([du, (a @ phi).ravel(order="F")])

    u0 = np.concatenate([y, np.eye(2).ravel(order="F")])
    sol = solve_ivp(f, (0.0, 2 * np.pi / omega), u0, method="DOP853", rtol=1e-12, atol=1e-14)
    u = sol.y[:, -1]
    return u[:2], u[2:].reshape(2, 2, order="F")


def scipy_orbit(omega: float) -> tuple[np.ndarray, np.ndarray]:
    """The fixed point of scipy's map from ``GUESS`` and its multipliers."""

    def fun(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        p, m = scipy_map(y, omega)
        return p - y, m - np.eye(2)

    out = root(fun, GUESS, jac=True, method="hybr", tol=1e-13)
    p, m = scipy_map(out.x, omega)
    assert np.max(np.abs(p - out.x)) < 1e-11, out.message  # a fixed point of scipy's map
    return out.x, np.linalg.eigvals(m)


def mismatch(a: np.ndarray, b: np.ndarray) -> float:
    """Largest distance between two multisets of complex numbers, optimally paired."""
    cost = np.abs(np.asarray(a)[:, None] - np.asarray(b)[None, :])
    rows, cols = linear_sum_assignment(cost)
    return float(cost[rows, cols].max())


def system(omega: float) -> gc.System:
    return gc.duffing(omega, delta=DELTA, alpha=ALPHA, beta=BETA, gamma=GAMMA)


@pytest.mark.parametrize("chord", [False, True])
def test_one_point_alone_is_that_point_among_k_and_matches_scipy(chord: bool) -> None:
    """periodic_orbits of one point equals the same point in a call of three (to 1e-9; the
    chains are independent, so in fact to the bit), and both are scipy's orbit."""
    target = system(1.0)
    points = [{"omega": w} for w in OMEGAS]
    guesses = np.repeat(GUESS[None], len(OMEGAS), axis=0)
    many = periodic_orbits(target, points, guesses=guesses, settings=SETTINGS, chord=chord)
    for k, w in enumerate(OMEGAS):
        (one,) = periodic_orbits(
            target, points[k : k + 1], guesses=guesses[k : k + 1], settings=SETTINGS, chord=chord
        )
        assert one.converged and many[k].converged, (one.message, many[k].message)
        assert one.iterations > 2  # the guess is not the orbit: Newton had work to do
        assert np.max(np.abs(one.state - many[k].state)) <= 1e-9
        assert np.max(np.abs(one.multipliers - many[k].multipliers)) <= 1e-9
        assert one.iterations == many[k].iterations
        y_ref, mu_ref = scipy_orbit(w)
        assert np.max(np.abs(one.state - y_ref)) <= 1e-8
        assert mismatch(one.multipliers, mu_ref) <= 1e-8


def test_the_single_orbit_door_is_k_equals_one_of_the_same_corrector() -> None:
    """gc.periodic_orbit (Broyden updates, damped steps evaluated together) is the K = 1 call
    of correct_points with its options: the same orbit, multipliers and work as that point
    among three, and scipy's orbit."""
    prob = Problem(1, SETTINGS, SETTINGS.rtol / 10, 40, keep_failed=True)
    solved = correct_points(prob, [Start.fixed(system(w), GUESS) for w in OMEGAS])
    for k, w in enumerate(OMEGAS):
        alone = gc.periodic_orbit(system(w), guess=GUESS, settings=SETTINGS)
        sol, why = solved[k]
        assert sol is not None and sol.converged and alone.converged, why
        assert np.max(np.abs(alone.state - sol.y)) <= 1e-9
        assert np.max(np.abs(alone.multipliers - sol.mu)) <= 1e-9
        assert alone.iterations == sol.evals
        y_ref, mu_ref = scipy_orbit(w)
        assert np.max(np.abs(alone.state - y_ref)) <= 1e-8
        assert mismatch(alone.multipliers, mu_ref) <= 1e-8


def test_every_door_goes_through_the_one_corrector(monkeypatch: pytest.MonkeyPatch) -> None:
    """periodic_orbit, periodic_orbits and the continuation each iterate their points with
    the one per-point iteration, driven by the one round of evaluations."""
    calls: list[tuple[str, int]] = []
    rounds: list[int] = []
    iterate, evaluate = corrector._Point.iterate, corrector._evaluate

    def recording_iterate(self: corrector._Point) -> corrector.Iteration:
        calls.append((self.prob.jacobian, self.prob.fractions))
        return iterate(self)

    def recording_evaluate(prob: Problem, asks: dict) -> dict:
        rounds.append(len(asks))
        return evaluate(prob, asks)

    monkeypatch.setattr(corrector._Point, "iterate", recording_iterate)
    monkeypatch.setattr(corrector, "_evaluate", recording_evaluate)
    assert gc.periodic_orbit(system(1.1), guess=GUESS).converged
    assert calls == [("broyden", 4)] and rounds and max(rounds) == 1
    calls.clear()
    rounds.clear()
    points = [{"omega": w} for w in OMEGAS]
    guesses = np.repeat(GUESS[None], 3, axis=0)
    for chord, kind in ((False, "newton"), (True, "chord")):
        orbits = periodic_orbits(system(1.0), points, guesses=guesses, chord=chord)
        assert all(o.converged for o in orbits)
        assert calls == [(kind, 1)] * 3 and rounds[0] == 3  # three points in each round
        calls.clear()
        rounds.clear()
    branch = gc.continuation(system(1.0), "omega=1.0:1.05", max_points=4)
    assert branch.sizes["point"] >= 2
    assert calls and set(calls) == {("broyden", 4)}


def test_a_poor_guess_off_a_chaotic_attractor_still_reaches_the_unstable_orbit() -> None:
    """The twin-well Duffing oscillator (α = −1, γ = 0.5) at Ω = 1.15, whose attractor is
    chaotic: the default guesses (50–800 forcing periods from rest) lie off the unstable 1T by
    the orbit's size. Its first Newton steps, from a fresh M, lower max|G| only slowly; the
    corrector keeps that matrix (Broyden-updated) for the next step instead of evaluating M
    afresh at every slow step, and so reaches the orbit from the 400-period guess, as the
    corrector before the unified one did (the unified one at first did from none). The orbit
    is checked against scipy: a fixed point of its map, with its multipliers (one outside the
    unit circle)."""
    system = gc.duffing(1.15, delta=DELTA, alpha=-1.0, beta=BETA, gamma=0.5)
    orbit = gc.periodic_orbit(system, period=1)
    assert orbit.converged, orbit.message
    p, m = scipy_map(orbit.state, 1.15, alpha=-1.0, gamma=0.5)
    assert np.max(np.abs(p - orbit.state)) < 1e-7
    mu = np.linalg.eigvals(m)
    rows, cols = linear_sum_assignment(np.abs(orbit.multipliers[:, None] - mu[None, :]))
    assert np.max(np.abs(orbit.multipliers[rows] - mu[cols])) < 1e-6
    assert np.max(np.abs(mu)) > 1.0 and not orbit.stable
