"""Compiled adaptive Dormand–Prince 5(4) integrator that lands exactly on sample times.

The kernel integrates ``y' = f(τ, y)`` of any built-in system (selected by ``kind``) from τ_0,
discards everything before the record start τ_rec, then stops *exactly* on each sample time
τ_rec + j Δ (the step is clipped, not interpolated: 3–9× more accurate than interpolation), and
continues to τ_end. Over [τ_rec, τ_end] it keeps the running minimum and maximum of the first
``n_track`` observables, refining the extremum inside each accepted step by the cubic Hermite
interpolant of the observable and its derivative (the observables come for free from the FSAL
stage).

Error control follows Hairer, Nørsett & Wanner (*Solving ODEs I*, §II.4) as in scipy's
``RK45``: the scaled RMS norm of h Σ (b_i − b̂_i) k_i with scale atol + rtol·max(|y_n|, |y_{n+1}|),
step factor 0.9·err^(−1/5) clipped to [0.2, 10] (no growth right after a rejection), and
Hairer's starting-step heuristic. After a step clipped to land on a sample the pre-clip step size
is restored, so sampling does not throttle the integration.

Kernels never raise: they return a :class:`~gearchaos.errors.Status` code.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..model.kernels import rhs, tangent
from .tableau import DOPRI5

__all__ = ["dopri_chains", "dopri_run"]

# ---------------------------------------------------------------------------- constants from data
STAGES = DOPRI5.stages
TAB_A = DOPRI5.a_matrix()  # frozen into the machine code as constants
TAB_C = np.array([float(x) for x in DOPRI5.c])
TAB_E = np.array([float(x) for x in DOPRI5.error_weights])
assert DOPRI5.fsal  # the last row of A is b, so the last stage value is y_{n+1}

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0
ERR_EXPONENT = -1.0 / 5.0  # −1/(q+1), q = 4 the lower order of the pair

SWITCH_MIN = 1e-6  # switches closer than this fraction to the step start are not re-located

ST_OK = 0
ST_MAX_STEPS = 1
ST_UNDERFLOW = 2
ST_NON_FINITE = 3


@numba.njit(cache=True, inline="always")
def _scaled_norm(v, y, ynew, rtol, atol, n):  # pragma: no cover - compiled
    acc = 0.0
    for i in range(n):
        sc = atol + rtol * max(abs(y[i]), abs(ynew[i]))
        r = v[i] / sc
        acc += r * r
    return math.sqrt(acc / n)


@numba.njit(cache=True)
def initial_step(kind, t, y, f0, p, rtol, atol, obs, n):  # pragma: no cover - compiled
    """Hairer's starting step (HNW I, §II.4) for the 5(4) pair, from the first n components."""
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
    y1 = y + h0 * f0
    f1 = np.empty(y.size)
    rhs(kind, t + h0, y1, p, f1, obs)
    d2 = 0.0
    for i in range(n):
        sc = atol + rtol * abs(y[i])
        d2 += ((f1[i] - f0[i]) / sc) ** 2
    d2 = math.sqrt(d2 / n) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** 0.2
    return min(100.0 * h0, h1)


@numba.njit(cache=True, inline="always")
def _track(obs_prev, obs, dt, n_track, omin, omax):  # pragma: no cover - compiled
    """Update running extrema over one accepted step (values and Hermite interior extremum)."""
    for k in range(n_track):
        v0 = obs_prev[k]
        v1 = obs[k]
        if v1 < omin[k]:
            omin[k] = v1
        if v1 > omax[k]:
            omax[k] = v1
        d0 = obs_prev[n_track + k] * dt
        d1 = obs[n_track + k] * dt
        if d0 * d1 < 0.0:
            # derivative of the cubic Hermite interpolant: a s² + b s + c on s ∈ [0, 1]
            a = 6.0 * (v0 - v1) + 3.0 * (d0 + d1)
            b = -6.0 * (v0 - v1) - 4.0 * d0 - 2.0 * d1
            c = d0
            if abs(a) < 1e-14 * (abs(b) + abs(c)):
                s = -c / b
            else:
                disc = max(b * b - 4.0 * a * c, 0.0)
                q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
                s1 = q / a
                s2 = c / q if q != 0.0 else -1.0
                s = s1 if 0.0 <= s1 <= 1.0 else s2
            if 0.0 < s < 1.0:
                s2_ = s * s
                s3_ = s2_ * s
                v = (
                    (2.0 * s3_ - 3.0 * s2_ + 1.0) * v0
                    + (s3_ - 2.0 * s2_ + s) * d0
                    + (-2.0 * s3_ + 3.0 * s2_) * v1
                    + (s3_ - s2_) * d1
                )
                if v < omin[k]:
                    omin[k] = v
                if v > omax[k]:
                    omax[k] = v


@numba.njit(cache=True, inline="always")
def _hermite(v0, v1, d0, d1, s):  # pragma: no cover - compiled
    """Cubic Hermite interpolant on s ∈ [0, 1] (d0, d1 already multiplied by the step)."""
    s2 = s * s
    s3 = s2 * s
    return (
        (2.0 * s3 - 3.0 * s2 + 1.0) * v0
        + (s3 - 2.0 * s2 + s) * d0
        + (-2.0 * s3 + 3.0 * s2) * v1
        + (s3 - s2) * d1
    )


@numba.njit(cache=True)
def first_switch(obs_prev, obs, dt, n_track, sw):  # pragma: no cover - compiled
    """Fraction θ ∈ (0, 1) of the step at which the first dead-zone switch obs_k = ±b_k is
    crossed, located on the cubic Hermite interpolant of obs_k (Illinois iteration); 2.0 when
    no observable changes contact state over the step."""
    best = 2.0
    for k in range(n_track):
        b = sw[k]
        if not b < np.inf:
            continue
        v0 = obs_prev[k]
        v1 = obs[k]
        r0 = 0 if v0 < -b else (2 if v0 > b else 1)
        r1 = 0 if v1 < -b else (2 if v1 > b else 1)
        if r0 == r1:
            continue
        if r0 == 2:
            level = b
        elif r0 == 0:
            level = -b
        else:
            level = b if r1 == 2 else -b
        d0 = obs_prev[n_track + k] * dt
        d1 = obs[n_track + k] * dt
        lo = 0.0
        flo = v0 - level
        hi = 1.0
        fhi = v1 - level
        side = 0
        sc = 1e-15 * (abs(level) + abs(v0) + abs(v1))
        x = 0.5
        for _ in range(100):
            if fhi == flo:
                x = 0.5 * (lo + hi)
            else:
                x = (lo * fhi - hi * flo) / (fhi - flo)
            fx = _hermite(v0, v1, d0, d1, x) - level
            if abs(fx) <= sc or hi - lo < 1e-14:
                break
            if (fx > 0.0) == (fhi > 0.0):
                hi = x
                fhi = fx
                if side == -1:
                    flo *= 0.5
                side = -1
            else:
                lo = x
                flo = fx
                if side == 1:
                    fhi *= 0.5
                side = 1
        if x < best:
            best = x
    return best


@numba.njit(cache=True)
def _renormalize(kind, t, y, p, obs, K, kbuf, n, k, lsum, tan_on):  # pragma: no cover - compiled
    """Tangent vectors in y[n:]: set them orthonormal (first call) or re-orthonormalise them by
    modified Gram–Schmidt, adding log stretch factors to ``lsum``; refresh their FSAL stage."""
    numba.literally(kind)
    if not tan_on:
        for r in range(k):
            o = n + r * n
            for i in range(n):
                y[o + i] = 1.0 if i == r else 0.0
    else:
        for r in range(k):
            o = n + r * n
            for q in range(r):
                oq = n + q * n
                d = 0.0
                for i in range(n):
                    d += y[o + i] * y[oq + i]
                for i in range(n):
                    y[o + i] -= d * y[oq + i]
            nrm = 0.0
            for i in range(n):
                nrm += y[o + i] * y[o + i]
            nrm = math.sqrt(nrm)
            lsum[r] += math.log(nrm)
            for i in range(n):
                y[o + i] /= nrm
    tangent(kind, t, y, p, obs, kbuf, n, k)
    for i in range(n, y.size):
        K[0, i] = kbuf[i]
    return True


@numba.njit(cache=True)
def dopri_run(
    kind,
    y0,
    p,
    t0,
    t_rec,
    dt_sample,
    n_samples,
    t_end,
    n_obs,
    n_track,
    sw,
    n_base,
    rtol,
    atol,
    h_init,
    max_step,
    max_steps,
    out_t,
    out_y,
    out_obs,
    obs_min,
    obs_max,
    y_final,
    info,
    lsum,
):  # pragma: no cover - compiled
    """Integrate one system; fill the output arrays; return the status code.

    Samples are taken at τ_j = t_rec + j·dt_sample, j = 0 … n_samples−1 (t_rec ≥ t0), then the
    integration goes on to t_end ≥ τ_last. Extrema of obs[:n_track] are tracked over
    [t_rec, t_end]. ``sw`` holds the half clearances b_k of the dead zones acting on the tracked
    observables (``inf``: smooth); a step that crosses a switch obs_k = ±b_k is discarded and
    retried so that it ends on the switch, so no step straddles a kink of the vector field
    (DOPRI5's error estimate can miss a kink inside a step: 10–100× larger errors).
    ``info`` (float64, length 4) receives accepted steps, rejected steps (including steps
    discarded to land on a switch), the final time reached and the next step size.

    Lyapunov exponents: with ``k = lsum.size > 0`` the state holds ``n_base`` system
    components followed by k tangent vectors, integrated with the variational equations
    (:func:`~gearchaos.model.kernels.tangent`). They start orthonormal at the first sample and
    are re-orthonormalised (modified Gram–Schmidt) at every later sample; ``lsum`` accumulates
    the logarithms of the stretch factors. The tangent components take part in the error
    control (a tangent direction the state does not excite would otherwise be integrated with
    steps sized for the state alone), so with tangents the trajectory agrees with a plain run
    to the tolerance, not bitwise.
    """
    numba.literally(kind)
    n = y0.size
    y = y0.copy()
    ynew = np.empty(n)
    yt = np.empty(n)
    K = np.empty((STAGES, n))
    kbuf = np.empty(n)
    ev = np.empty(n)
    obs = np.empty(n_obs)
    obs_prev = np.empty(n_obs)
    for k in range(n_track):
        obs_min[k] = np.inf
        obs_max[k] = -np.inf

    t = t0
    n_tan = lsum.size
    tan_on = False
    for r in range(n_tan):
        lsum[r] = 0.0
    rhs(kind, t, y, p, kbuf, obs)
    kbuf[n_base:] = 0.0
    k1 = K[0]
    k1[:] = kbuf
    n_acc = 0
    n_rej = 0
    status = ST_OK
    for i in range(n):
        if not math.isfinite(k1[i]) or not math.isfinite(y[i]):
            status = ST_NON_FINITE
    h = h_init
    if status == ST_OK and h <= 0.0:
        obs_prev[:] = obs
        h = initial_step(kind, t, y, k1, p, rtol, atol, obs, n_base)
        obs[:] = obs_prev  # the observables of the current point
    if h > max_step:
        h = max_step

    j = 0
    tracking = False
    if status == ST_OK and n_samples > 0 and t >= t_rec:
        if n_tan > 0:
            tan_on = _renormalize(kind, t, y, p, obs, K, kbuf, n_base, n_tan, lsum, tan_on)
        out_t[0] = t
        out_y[0, :] = y
        out_obs[0, :] = obs
        j = 1
        tracking = True
        for k in range(n_track):
            obs_min[k] = obs[k]
            obs_max[k] = obs[k]
    obs_prev[:] = obs
    last_rejected = False
    nonfinite = False
    has_switch = False
    for k in range(n_track):
        if sw[k] < np.inf:
            has_switch = True
    h_event = -1.0

    while status == ST_OK:
        if j < n_samples:
            target = t_rec + j * dt_sample
        else:
            target = t_end
        if j >= n_samples and t >= t_end:
            break
        if n_acc + n_rej >= max_steps:
            status = ST_MAX_STEPS
            break
        hmin = 16.0 * 2.220446049250313e-16 * max(abs(t), abs(target))
        if h < hmin:
            status = ST_NON_FINITE if nonfinite else ST_UNDERFLOW
            break
        clipped = False
        event_step = False
        hs = h
        if h_event > 0.0:
            hs = h_event
            event_step = True
            h_event = -1.0
        if t + hs >= target:
            hs = target - t
            clipped = True
            event_step = False

        t_new = target if clipped else t + hs
        # stages 2..7 from the tableau data; stage 7 is evaluated at (t_new, y_new) (FSAL)
        for s in range(1, STAGES):
            for i in range(n):
                acc = 0.0
                for q in range(s):
                    acc += TAB_A[s, q] * K[q, i]
                yt[i] = y[i] + hs * acc
            ts = t_new if s == STAGES - 1 else t + TAB_C[s] * hs
            rhs(kind, ts, yt, p, kbuf, obs)
            if n_tan > 0:
                if tan_on:
                    tangent(kind, ts, yt, p, obs, kbuf, n_base, n_tan)
                else:
                    kbuf[n_base:] = 0.0
            for i in range(n):
                K[s, i] = kbuf[i]
        for i in range(n):
            ynew[i] = yt[i]
            acc = 0.0
            for q in range(STAGES):
                acc += TAB_E[q] * K[q, i]
            ev[i] = hs * acc
        err = _scaled_norm(ev, y, ynew, rtol, atol, n)

        finite = math.isfinite(err)
        if finite:
            for i in range(n):
                if not math.isfinite(ynew[i]):
                    finite = False
                    break
        if not finite:
            nonfinite = True
            n_rej += 1
            h = hs * MIN_FACTOR
            last_rejected = True
            continue
        nonfinite = False

        if err <= 1.0 and has_switch and not event_step:
            theta = first_switch(obs_prev, obs, hs, n_track, sw)
            if SWITCH_MIN < theta < 1.0:
                # a contact switch lies inside the step: retry, ending exactly on it
                h_event = theta * hs
                n_rej += 1
                continue

        if err <= 1.0:
            n_acc += 1
            if err == 0.0:
                factor = MAX_FACTOR
            else:
                factor = min(MAX_FACTOR, SAFETY * err**ERR_EXPONENT)
            if last_rejected and factor > 1.0:
                factor = 1.0
            last_rejected = False
            h_next = hs * factor
            if (clipped or event_step) and h_next < h:
                h_next = h  # restore the proposal made before clipping to a sample or switch
            h = min(h_next, max_step)
            t = t_new
            for i in range(n):
                y[i] = ynew[i]
                K[0, i] = K[STAGES - 1, i]
            if tracking:
                _track(obs_prev, obs, hs, n_track, obs_min, obs_max)
            if clipped and j < n_samples:
                if n_tan > 0:
                    tan_on = _renormalize(kind, t, y, p, obs, K, kbuf, n_base, n_tan, lsum, tan_on)
                out_t[j] = t
                out_y[j, :] = y
                out_obs[j, :] = obs
                if not tracking:
                    tracking = True
                    for k in range(n_track):
                        obs_min[k] = obs[k]
                        obs_max[k] = obs[k]
                j += 1
            obs_prev[:] = obs
        else:
            n_rej += 1
            h = hs * max(MIN_FACTOR, SAFETY * err**ERR_EXPONENT)
            last_rejected = True

    y_final[:] = y
    info[0] = n_acc
    info[1] = n_rej
    info[2] = t
    info[3] = h
    return status


@numba.njit(cache=True, parallel=True)
def dopri_chains(
    kind,
    Y0,
    P,
    SW,
    t0,
    t_rec,
    dt_sample,
    n_samples,
    t_end,
    n_obs,
    n_track,
    n_base,
    rtol,
    atol,
    h_init,
    max_step,
    max_steps,
    continuation,
    out_t,
    out_y,
    out_obs,
    obs_min,
    obs_max,
    y_final,
    info,
    status,
    LSUM,
):  # pragma: no cover - compiled
    """Chains of integrations, ``numba.prange`` over chains, points of a chain in order: the
    one compiled entry point of the integrator (single runs are chains of length one).

    Point j of chain c has parameters ``P[c, j]`` and runs from τ = ``t0[c, j]``; it starts
    from ``Y0[c]`` (fresh) or, with ``continuation``, from the final state of point j−1 of the
    same chain (point 0 from ``Y0[c]``); a failed point restarts its successor from ``Y0[c]``.
    ``LSUM[c, j]`` (k ≥ 0 entries) receives the Lyapunov log sums when the state carries k
    tangent vectors after its ``n_base`` system components. Every point runs
    :func:`dopri_run` unchanged, so its result does not depend on the chain it runs in, on the
    other chains or on the number of threads.
    """
    numba.literally(kind)
    n_chains = P.shape[0]
    length = P.shape[1]
    for c in numba.prange(n_chains):
        y = Y0[c].copy()
        for j in range(length):
            st = dopri_run(
                kind,
                y,
                P[c, j],
                t0[c, j],
                t_rec[c, j],
                dt_sample[c, j],
                n_samples,
                t_end[c, j],
                n_obs,
                n_track,
                SW[c, j],
                n_base,
                rtol,
                atol,
                h_init,
                max_step,
                max_steps,
                out_t[c, j],
                out_y[c, j],
                out_obs[c, j],
                obs_min[c, j],
                obs_max[c, j],
                y_final[c, j],
                info[c, j],
                LSUM[c, j],
            )
            status[c, j] = st
            if continuation and st == ST_OK:
                y[:] = y_final[c, j]
            else:
                y[:] = Y0[c]


def _guard() -> None:
    import os

    from .. import _numba
    from ..model import kernels, layout

    here = os.path.dirname(__file__)
    sources = [
        kernels.__file__,
        layout.__file__,
        os.path.join(here, "dopri.py"),
        os.path.join(here, "tableau.py"),
    ]
    _numba.guard_cache([dopri_run, dopri_chains], sources)


_guard()
