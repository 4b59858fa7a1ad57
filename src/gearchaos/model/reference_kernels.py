"""Compiled right-hand sides and tangent kernels of the reference systems (backlash
oscillator, linear system, Duffing, Lorenz): see :mod:`gearchaos.model.kernels` for the
signatures and :mod:`gearchaos.model.library` for the systems."""

from __future__ import annotations

import math

import numba

from .._numba import njit_noalloc
from .layout import (
    BO_B,
    BO_EPS,
    BO_FA,
    BO_FM,
    BO_OMEGA,
    BO_ZETA,
    DU_ALPHA,
    DU_BETA,
    DU_DELTA,
    DU_GAMMA,
    DU_OMEGA,
    LIN_HEADER,
    LIN_N,
    LIN_OMEGA,
    LZ_BETA,
    LZ_RHO,
    LZ_SIGMA,
)

__all__ = [
    "backlash_oscillator_rhs",
    "backlash_oscillator_tangent",
    "dead_zone",
    "duffing_rhs",
    "duffing_tangent",
    "engaged",
    "in_contact",
    "linear_rhs",
    "linear_tangent",
    "lorenz_rhs",
    "lorenz_tangent",
]


@numba.njit(cache=True, inline="always")
def dead_zone(x: float, b: float) -> float:
    """f(x; b) = x − b (x > b), 0 (|x| ≤ b), x + b (x < −b): contact law with half clearance b."""
    return x - min(max(x, -b), b)  # branch-free: the contact state is unpredictable


@numba.njit(cache=True, inline="always")
def in_contact(x: float, b: float) -> bool:
    """Whether x lies outside the clearance [−b, b] (teeth in contact)."""
    return x > b or x < -b


@numba.njit(cache=True, inline="always")
def engaged(x: float, b: float) -> float:
    """f'(x; b): 1 outside the clearance (teeth in contact), 0 inside."""
    return 1.0 if in_contact(x, b) else 0.0


@njit_noalloc
def backlash_oscillator_rhs(t, y, p, dydt, obs, level):  # pragma: no cover - compiled
    """x'' + 2ζx' + (1 + ε cos Ωτ) f(x; b) = F_m + F_a Ω^q cos Ωτ;
    obs = (x, Fᶜ, x', Fᶜ', stiffness 1 + ε cos Ωτ) with the contact force
    Fᶜ = (1 + ε cos Ωτ) f(x; b) + 2ζx' while |x| > b and 0 while |x| ≤ b (teeth apart)."""
    om = p[BO_OMEGA]
    c = math.cos(om * t)
    x = y[0]
    v = y[1]
    b = p[BO_B]
    k = 1.0 + p[BO_EPS] * c
    fz = dead_zone(x, b)
    damp = 2.0 * p[BO_ZETA] * v
    dydt[0] = v
    dydt[1] = p[BO_FM] + p[BO_FA] * c - damp - k * fz
    obs[0] = x
    obs[2] = v
    if in_contact(x, b):
        obs[1] = k * fz + damp
        dk = -p[BO_EPS] * om * math.sin(om * t)
        obs[3] = dk * fz + k * v + 2.0 * p[BO_ZETA] * dydt[1]
    else:
        obs[1] = 0.0
        obs[3] = 0.0
    obs[4] = k


@njit_noalloc
def linear_rhs(t, y, p, dydt, obs, level):  # pragma: no cover - compiled
    """y' = A y + f cos Ωτ + g sin Ωτ; obs = (y, y')."""
    n = int(p[LIN_N])
    om = p[LIN_OMEGA]
    c = math.cos(om * t)
    s = math.sin(om * t)
    a0 = LIN_HEADER
    f0 = a0 + n * n
    g0 = f0 + n
    for i in range(n):
        acc = p[f0 + i] * c + p[g0 + i] * s
        for j in range(n):
            acc += p[a0 + i * n + j] * y[j]
        dydt[i] = acc
        obs[i] = y[i]
        obs[n + i] = acc


@njit_noalloc
def duffing_rhs(t, y, p, dydt, obs, level):  # pragma: no cover - compiled
    """x'' + δx' + αx + βx³ = γ cos Ωτ; obs = (x, x')."""
    x = y[0]
    v = y[1]
    dydt[0] = v
    dydt[1] = (
        p[DU_GAMMA] * math.cos(p[DU_OMEGA] * t)
        - p[DU_DELTA] * v
        - p[DU_ALPHA] * x
        - p[DU_BETA] * x * x * x
    )
    obs[0] = x
    obs[1] = v


@njit_noalloc
def lorenz_rhs(t, y, p, dydt, obs, level):  # pragma: no cover - compiled
    """Lorenz (1963): x' = σ(y − x), y' = x(ρ − z) − y, z' = xy − βz;
    obs = (x, y, z, x', y', z')."""
    dydt[0] = p[LZ_SIGMA] * (y[1] - y[0])
    dydt[1] = y[0] * (p[LZ_RHO] - y[2]) - y[1]
    dydt[2] = y[0] * y[1] - p[LZ_BETA] * y[2]
    for i in range(3):
        obs[i] = y[i]
        obs[3 + i] = dydt[i]


@njit_noalloc
def backlash_oscillator_tangent(t, y, p, obs, dydt, n, k):  # pragma: no cover - compiled
    kx = obs[4] * engaged(obs[0], p[BO_B])
    for r in range(k):
        o = n + r * n
        dydt[o] = y[o + 1]
        dydt[o + 1] = -kx * y[o] - 2.0 * p[BO_ZETA] * y[o + 1]


@njit_noalloc
def linear_tangent(t, y, p, obs, dydt, n, k):  # pragma: no cover - compiled
    a0 = LIN_HEADER
    for r in range(k):
        o = n + r * n
        for i in range(n):
            acc = 0.0
            for j in range(n):
                acc += p[a0 + i * n + j] * y[o + j]
            dydt[o + i] = acc


@njit_noalloc
def duffing_tangent(t, y, p, obs, dydt, n, k):  # pragma: no cover - compiled
    kx = p[DU_ALPHA] + 3.0 * p[DU_BETA] * y[0] * y[0]
    for r in range(k):
        o = n + r * n
        dydt[o] = y[o + 1]
        dydt[o + 1] = -kx * y[o] - p[DU_DELTA] * y[o + 1]


@njit_noalloc
def lorenz_tangent(t, y, p, obs, dydt, n, k):  # pragma: no cover - compiled
    s = p[LZ_SIGMA]
    for r in range(k):
        o = n + r * n
        a = y[o]
        b = y[o + 1]
        c = y[o + 2]
        dydt[o] = s * (b - a)
        dydt[o + 1] = (p[LZ_RHO] - y[2]) * a - b - y[0] * c
        dydt[o + 2] = y[1] * a + y[0] * b - p[LZ_BETA] * c
