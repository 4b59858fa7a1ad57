"""Compiled Runge–Kutta step of the integrator, its error estimate and its starting step, with
the Butcher tableau as data.

The coefficients come from :data:`TABLEAU` (:data:`~gearchaos.integrate.tableau.DOPRI5`) as
constant float64 arrays (:func:`tableau_constants`: ``TAB_A``, ``TAB_C``, ``TAB_E`` = b − b̂,
``STAGES``), which numba folds into the machine code. The loops over a stage's coefficients run
over the data; a term whose coefficient is exactly zero is skipped, and the sums run in the
order of the tableau's columns starting from −0.0 (the identity of IEEE addition), so that the
folded code does exactly the arithmetic of the stages written out by hand. For that the stage
index must be a compile-time constant inside each sum: :func:`stage_input` branches on it (up to
``MAX_STAGES`` stages) to one specialisation of the sum per stage.

Another explicit FSAL pair runs the same code with its own constants
(:func:`~gearchaos.integrate.methods.kernels_for`).
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

from .._numba import njit_noalloc
from ..model.kernels import OBS_ALL, OBS_NONE, rhs, tangent
from ._control import pi_alpha
from .tableau import DOPRI5, ButcherTableau

__all__ = [
    "MAX_STAGES",
    "TABLEAU",
    "dense_state",
    "error_norm",
    "fsal_advance",
    "initial_step",
    "rk_step",
    "stage_input",
    "tableau_constants",
]

#: The most stages a tableau may have (the branches of :func:`stage_input`).
MAX_STAGES = 12


def tableau_constants(tab: ButcherTableau) -> dict[str, Any]:
    """The module constants the kernels read for the explicit FSAL pair ``tab``: ``STAGES``,
    ``TAB_A`` (s × s), ``TAB_C``, ``TAB_E`` (b − b̂), ``TAB_D`` (s × q: the coefficients of
    θ¹ … θ^q of the continuous extension's weights b_i(θ),
    :meth:`~gearchaos.integrate.tableau.ButcherTableau.dense_matrix`), ``ALPHA`` (the step
    controller's exponent, from the embedded order) and ``INIT_EXPONENT`` (1/order, Hairer's
    starting step)."""
    tab.check()
    if not tab.fsal:
        raise ValueError(f"{tab.name}: the integrator needs an FSAL pair (last row of A = b)")
    if not 2 <= tab.stages <= MAX_STAGES:
        raise ValueError(f"{tab.name}: {tab.stages} stages, the kernel takes 2 … {MAX_STAGES}")
    arr = tab.arrays()
    return {
        "TABLEAU": tab,
        "STAGES": tab.stages,
        "TAB_A": arr.A,
        "TAB_C": arr.c,
        "TAB_E": arr.e,
        "TAB_D": np.array([[float(x) for x in row] for row in tab.dense_matrix()]),
        "ALPHA": pi_alpha(tab.order_hat),
        "INIT_EXPONENT": 1.0 / tab.order,
    }


_CONSTANTS = tableau_constants(DOPRI5)
TABLEAU: ButcherTableau = _CONSTANTS["TABLEAU"]
STAGES: int = _CONSTANTS["STAGES"]
TAB_A: np.ndarray = _CONSTANTS["TAB_A"]
TAB_C: np.ndarray = _CONSTANTS["TAB_C"]
TAB_E: np.ndarray = _CONSTANTS["TAB_E"]
TAB_D: np.ndarray = _CONSTANTS["TAB_D"]
ALPHA: float = _CONSTANTS["ALPHA"]
INIT_EXPONENT: float = _CONSTANTS["INIT_EXPONENT"]


@numba.njit(cache=True, inline="always")
def _stage_row(yt, y, K, hs, n, s):  # pragma: no cover - compiled
    """yt = y + hs Σ_{j<s} a_sj K_j for a constant stage index s (inlined: the loop over the
    row unrolls with the coefficients folded in, zero ones skipped)."""
    if s < STAGES:
        for i in range(n):
            acc = -0.0
            for j in range(s):
                a = TAB_A[s, j]
                if a != 0.0:
                    acc += a * K[j, i]
            yt[i] = y[i] + hs * acc


@numba.njit(cache=True, inline="always")
def stage_input(yt, y, K, hs, n, s):  # pragma: no cover - compiled
    """The argument of stage s ≥ 1: yt[:n] = y + hs Σ_{j<s} a_sj K_j (row s of ``TAB_A``),
    one branch per stage index so that the index is a constant in each sum."""
    if s == 1:
        _stage_row(yt, y, K, hs, n, 1)
    elif s == 2:
        _stage_row(yt, y, K, hs, n, 2)
    elif s == 3:
        _stage_row(yt, y, K, hs, n, 3)
    elif s == 4:
        _stage_row(yt, y, K, hs, n, 4)
    elif s == 5:
        _stage_row(yt, y, K, hs, n, 5)
    elif s == 6:
        _stage_row(yt, y, K, hs, n, 6)
    elif s == 7:
        _stage_row(yt, y, K, hs, n, 7)
    elif s == 8:
        _stage_row(yt, y, K, hs, n, 8)
    elif s == 9:
        _stage_row(yt, y, K, hs, n, 9)
    elif s == 10:
        _stage_row(yt, y, K, hs, n, 10)
    elif s == 11:
        _stage_row(yt, y, K, hs, n, 11)


@numba.njit(cache=True, inline="always")
def rk_step(
    kind, t, y, hs, t_new, p, K, yt, obs, n, n_base, n_tan, tan_on, last_level
):  # pragma: no cover - compiled
    """One Runge–Kutta step of size ``hs`` from (t, y) with K[0] = f(t, y) given (FSAL): the
    stages K[1:STAGES] and, in ``yt``, y_{n+1} = the argument of the last stage, which is
    evaluated at (``t_new``, y_{n+1}) (``t_new`` = t + hs, or the sample time the step was
    clipped to, exactly) so that K[STAGES − 1] = f(t_new, y_{n+1}).

    The inner stages ask the right-hand side for no observables (all of them while the
    ``n_tan`` tangent vectors after the ``n_base`` system components are integrated,
    ``tan_on``), the last one for ``last_level`` (``obs`` then holds the observables at the new
    point). Stage i is evaluated at t + c_i hs.

    Inlined into its caller, where ``kind`` must be a compile-time literal (the right-hand side
    is chosen by it): a call with a dozen arrays would cost more than the stages' arithmetic.
    """
    inner = OBS_ALL if tan_on else OBS_NONE
    for s in range(1, STAGES):
        stage_input(yt, y, K, hs, n, s)
        if s == STAGES - 1:
            ts = t_new
            level = last_level
        else:
            ts = t + TAB_C[s] * hs
            level = inner
        rhs(kind, ts, yt, p, K[s], obs, level)
        if tan_on:
            tangent(kind, ts, yt, p, obs, K[s], n_base, n_tan)


@numba.njit(cache=True, inline="always")
def error_norm(y, yt, K, hs, n, n_base, rtol, atol, tan_tol):  # pragma: no cover - compiled
    """The scaled RMS norm of the embedded error estimate hs Σ_j (b_j − b̂_j) K_j with scale
    atol + rtol·max(|y_n|, |y_{n+1}|) (y_{n+1} in ``yt``), multiplied by ``tan_tol`` for the
    components after ``n_base`` (the tangent vectors; inf: left out of the norm). NaN also when
    y_{n+1} is not finite."""
    n_err = n_base if math.isinf(tan_tol) else n
    acc = 0.0
    for i in range(n):
        d = -0.0
        for j in range(STAGES):
            w = TAB_E[j]
            if w != 0.0:
                d += w * K[j, i]
        e = hs * d
        sc = atol + rtol * max(abs(y[i]), abs(yt[i]))
        if i >= n_base:
            sc *= tan_tol  # the tangents' own tolerance (1: the state's; inf: r = 0)
        r = e / sc
        acc += r * r + 0.0 * yt[i]
    return math.sqrt(acc / n_err)


@numba.njit(cache=True, inline="always")
def fsal_advance(y, yt, K, n):  # pragma: no cover - compiled
    """Accept the step: y ← y_{n+1} (``yt``), K[0] ← the last stage (first same as last)."""
    for i in range(n):
        y[i] = yt[i]
        K[0, i] = K[STAGES - 1, i]


@numba.njit(cache=True, inline="always")
def dense_state(yi, y, K, hs, theta, w, n):  # pragma: no cover - compiled
    """The continuous extension of the accepted step of size ``hs`` from ``y`` (= y_n, with its
    stages ``K``) at the fraction ``theta`` ∈ [0, 1] of the step:
    yi[:n] = y_n + hs Σ_i b_i(θ) K_i, b_i(θ) = Σ_m TAB_D[i, m] θ^(m+1) (Horner; ``w``: scratch
    of one weight per stage). For DOPRI5 Hairer's dense output of order 4, for a pair without
    one the cubic Hermite interpolant of the step's ends
    (:meth:`~gearchaos.integrate.tableau.ButcherTableau.dense_matrix`)."""
    q = TAB_D.shape[1]
    for s in range(STAGES):
        acc = 0.0
        for m in range(q - 1, -1, -1):
            acc = acc * theta + TAB_D[s, m]
        w[s] = acc * theta
    for i in range(n):
        acc = -0.0
        for s in range(STAGES):
            if w[s] != 0.0:  # a stage without weight (DOPRI5's second)
                acc += w[s] * K[s, i]
        yi[i] = y[i] + hs * acc


@njit_noalloc
def initial_step(kind, t, y, f0, p, rtol, atol, obs, n, y1, f1):  # pragma: no cover - compiled
    """Hairer's starting step (HNW I, §II.4) for a pair of order p (exponent 1/p), from the
    first n components (``obs``, ``y1``, ``f1``: scratch)."""
    numba.literally(kind)
    d0 = 0.0
    d1 = 0.0
    for i in range(n):
        sc = atol + rtol * abs(y[i])
        d0 += (y[i] / sc) ** 2
        d1 += (f0[i] / sc) ** 2
    d0 = math.sqrt(d0 / n)
    d1 = math.sqrt(d1 / n)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    for i in range(y.size):
        y1[i] = y[i] + h0 * f0[i]
    rhs(kind, t + h0, y1, p, f1, obs, OBS_NONE)
    d2 = 0.0
    for i in range(n):
        sc = atol + rtol * abs(y[i])
        d2 += ((f1[i] - f0[i]) / sc) ** 2
    d2 = math.sqrt(d2 / n) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** INIT_EXPONENT
    return min(100.0 * h0, h1)
