"""Reference problem for ``bench_speed.py``: a plain compiled Dormand–Prince loop over a chain.

Eight unit masses in a line, each tied to its predecessor (the first to a wall driven by a
transmission error) by a mesh with a dead zone of half width b, a time-varying stiffness
k_i(τ) = 1 + ε cos(Ωτ + φ_i) and viscous damping c; a mean force F_m and an alternating force
F_a cos Ωτ pull the last mass:

    x_i'' = F_{i+1} − F_i (F_9 = F_m + F_a cos Ωτ),
    F_i = k_i(τ) f(δ_i; b) + c δ_i',   δ_i = x_i − x_{i−1} (x_0 = e sin Ωτ),

f(δ; b) the dead zone. 16 states, 8 dead zones, parametric stiffness: the same size and kind of
problem as the N = 5 planetary model, with one sin/cos pair of Ωτ per right-hand side (the
phases by angle addition), as a careful hand-written kernel would do it.

The integrator is textbook DOPRI5 with no gearchaos code: stages unrolled, the embedded error
estimate in the scaled RMS norm, step factor 0.9 err^(−1/5) clipped to [0.2, 10], no growth
right after a rejection. It does *not* land on switches or sample times: it is the floor that
an adaptive explicit integrator of this problem costs per step.
"""

from __future__ import annotations

import math

import numba
import numpy as np

N_MASS = 8
N_STATE = 2 * N_MASS

# Dormand–Prince 5(4) (Hairer, Nørsett & Wanner I, Table 5.2), written out independently
C2, C3, C4, C5 = 1 / 5, 3 / 10, 4 / 5, 8 / 9
A21 = 1 / 5
A31, A32 = 3 / 40, 9 / 40
A41, A42, A43 = 44 / 45, -56 / 15, 32 / 9
A51, A52, A53, A54 = 19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729
A61, A62, A63, A64, A65 = 9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656
A71, A73, A74, A75, A76 = 35 / 384, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84
E1, E3, E4 = 71 / 57600, -71 / 16695, 71 / 1920
E5, E6, E7 = -17253 / 339200, 22 / 525, -1 / 40


def parameters(omega: float) -> np.ndarray:
    """Packed parameters: Ω, ε, b, c, F_m, F_a, e, then cos φ_i and sin φ_i (i = 1..8)."""
    phi = 2.0 * np.pi * np.arange(N_MASS) / N_MASS * 0.37
    head = np.array([omega, 0.25, 1.0, 0.04, 0.3, 0.15, 0.6])
    return np.concatenate([head, np.cos(phi), np.sin(phi)])


@numba.njit(cache=True, inline="always")
def _rhs(t, y, p, dy):  # pragma: no cover - compiled
    om = p[0]
    eps = p[1]
    b = p[2]
    c = p[3]
    c1 = math.cos(om * t)
    s1 = math.sin(om * t)
    n = N_MASS
    x_prev = p[6] * s1
    v_prev = p[6] * om * c1
    f_prev = 0.0
    for i in range(n):
        x = y[i]
        v = y[n + i]
        d = x - x_prev
        dd = v - v_prev
        k = 1.0 + eps * (c1 * p[7 + i] - s1 * p[7 + n + i])
        f = k * (d - min(max(d, -b), b)) + c * dd
        if i > 0:
            dy[n + i - 1] = f - f_prev
        f_prev = f
        x_prev = x
        v_prev = v
        dy[i] = v
    dy[2 * n - 1] = p[4] + p[5] * c1 - f_prev


@numba.njit(cache=True)
def integrate(p, y0, t_end, rtol, atol):  # pragma: no cover - compiled
    """Integrate from τ = 0 to ``t_end``; returns (accepted, rejected, y(t_end))."""
    n = y0.size
    y = y0.copy()
    yt = np.empty(n)
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    k5 = np.empty(n)
    k6 = np.empty(n)
    k7 = np.empty(n)
    _rhs(0.0, y, p, k1)
    t = 0.0
    h = 1e-3
    acc = 0
    rej = 0
    last_rejected = False
    while t < t_end:
        if not h > 1e-14 * max(1.0, t):
            break  # non-finite or underflowing step: give up (never loops forever)
        if t + h > t_end:
            h = t_end - t
        for i in range(n):
            yt[i] = y[i] + h * A21 * k1[i]
        _rhs(t + C2 * h, yt, p, k2)
        for i in range(n):
            yt[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i])
        _rhs(t + C3 * h, yt, p, k3)
        for i in range(n):
            yt[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i])
        _rhs(t + C4 * h, yt, p, k4)
        for i in range(n):
            yt[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i])
        _rhs(t + C5 * h, yt, p, k5)
        for i in range(n):
            yt[i] = y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i])
        _rhs(t + h, yt, p, k6)
        for i in range(n):
            yt[i] = y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i])
        _rhs(t + h, yt, p, k7)
        s = 0.0
        for i in range(n):
            e = h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i])
            sc = atol + rtol * max(abs(y[i]), abs(yt[i]))
            s += (e / sc) ** 2
        err = math.sqrt(s / n)
        if err <= 1.0:
            acc += 1
            t += h
            for i in range(n):
                y[i] = yt[i]
                k1[i] = k7[i]
            fac = 10.0 if err == 0.0 else min(10.0, 0.9 * err**-0.2)
            if last_rejected:
                fac = min(fac, 1.0)
            last_rejected = False
            h *= fac
        else:
            rej += 1
            h *= max(0.2, 0.9 * err**-0.2)
            last_rejected = True
    return acc, rej, y
