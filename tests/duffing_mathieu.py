"""A test model with a fold–flip point of known location: a forced Duffing oscillator beside an
uncoupled damped Mathieu oscillator driven at the same frequency,

    x'' + δx' + x + βx³ = γ cos Ωτ,        u'' + c u' + (1 + 2q cos Ωτ) u = 0.

Its period-1 orbits are the Duffing's with u ≡ 0, and their monodromy matrix is block diagonal:
the Duffing's block does not depend on q, so a fold of the Duffing is a vertical line Ω = Ω_fold
in (Ω, q); the Mathieu block's multipliers move with q and one passes −1 on the boundary of the
principal instability tongue, where the fold curve meets a period doubling (fold–flip). Both
locations follow from the two oscillators alone (computed in the test with scipy)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from gearchaos.model.contract import UserModel

OMEGA, DELTA, BETA, GAMMA, C, Q = range(6)


@numba.njit(cache=True)
def rhs(t, y, p, dydt, obs, level):  # pragma: no cover - compiled
    x, u, v, w = y[0], y[1], y[2], y[3]
    c = math.cos(p[OMEGA] * t)
    dydt[0] = v
    dydt[1] = w
    dydt[2] = p[GAMMA] * c - p[DELTA] * v - x - p[BETA] * x * x * x
    dydt[3] = -p[C] * w - (1.0 + 2.0 * p[Q] * c) * u
    obs[0] = x
    obs[1] = u
    obs[2] = v
    obs[3] = w


@numba.njit(cache=True)
def tangent(t, y, p, obs, dydt, n, k):  # pragma: no cover - compiled
    kx = 1.0 + 3.0 * p[BETA] * y[0] * y[0]
    ku = 1.0 + 2.0 * p[Q] * math.cos(p[OMEGA] * t)
    for r in range(k):
        o = n + r * n
        dydt[o] = y[o + 2]
        dydt[o + 1] = y[o + 3]
        dydt[o + 2] = -kx * y[o] - p[DELTA] * y[o + 2]
        dydt[o + 3] = -ku * y[o + 1] - p[C] * y[o + 3]


@dataclass(frozen=True)
class DuffingMathieu(UserModel):
    delta: float = 0.2
    beta: float = 1.0
    gamma: float = 0.5
    c: float = 0.05
    q: float = 0.0
    name = "duffing_mathieu"
    state_names = ("x", "u", "x_dot", "u_dot")
    obs_names = ("x", "u", "x_dot", "u_dot")
    n_track = 2
    default_observables = ("x", "x_dot")
    rhs = rhs
    tangent = tangent

    def pack(self, omega: float) -> np.ndarray:
        return np.array([omega, self.delta, self.beta, self.gamma, self.c, self.q])
