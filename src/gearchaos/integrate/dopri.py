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
PI step-size control as in Hairer's DOPRI5 code (Gustafsson; HNW II §IV.2): factor
0.9·err_n^(−α)·err_{n−1}^β, β = 0.04, α = 1/5 − 0.75β, clipped to [0.2, 10] (no growth right after
a rejection), and Hairer's starting-step heuristic. Contact switches are predicted from the
points of the current smooth piece and a step is shortened to end just past the next one
(:mod:`~gearchaos.integrate._switch`). After a step clipped to land on a sample the pre-clip
step size is restored, so sampling does not throttle the integration.

The stages are written out with the coefficients of :data:`~gearchaos.integrate.tableau.DOPRI5`
as compile-time constants; the inner stages ask the right-hand side for no observables, the last
(FSAL) stage for the tracked ones only, or for all of them on a sample step.

:func:`dopri_run` allocates nothing: its scratch arrays come from :func:`workspace`, once per
block of chains, so it is compiled without numba's reference counting. With it, every array
view a step creates (a row of the stage matrix, say) and every array passed to a helper cost an
atomic increment and decrement: a perf profile put a quarter of a step in ``NRT_incref`` and
``NRT_decref`` (issue 13).

Kernels never raise: they return a :class:`~gearchaos.errors.Status` code.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .._numba import njit_noalloc
from ..errors import Status
from ..model.kernels import OBS_ALL, OBS_NONE, OBS_TRACK, rhs, tangent
from ._switch import AIM, LAND, check_step, predict_switch, track
from .interface import Config, Info
from .tableau import DOPRI5

__all__ = ["dopri_chains", "dopri_run"]

# ---------------------------------------------------------------------------- constants from data
STAGES = DOPRI5.stages
assert STAGES == 7 and DOPRI5.fsal  # the last row of A is b: the last stage value is y_{n+1}
_A = DOPRI5.a_matrix()
_E = [float(x) for x in DOPRI5.error_weights]
# the unrolled stages below skip these zero coefficients
assert _A[6, 1] == 0.0 and _E[1] == 0.0
C2, C3, C4, C5 = (float(x) for x in DOPRI5.c[1:5])
A21 = float(_A[1, 0])
A31, A32 = (float(x) for x in _A[2, :2])
A41, A42, A43 = (float(x) for x in _A[3, :3])
A51, A52, A53, A54 = (float(x) for x in _A[4, :4])
A61, A62, A63, A64, A65 = (float(x) for x in _A[5, :5])
A71, A73, A74, A75, A76 = (float(_A[6, q]) for q in (0, 2, 3, 4, 5))
E1, E3, E4, E5, E6, E7 = (_E[q] for q in (0, 2, 3, 4, 5, 6))

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0
#: PI step-size control (Gustafsson): h_{n+1} = h_n · SAFETY · err_n^(−α) · err_{n−1}^β with
#: β = 0.04 and α = 1/5 − 0.75 β, as in Hairer's DOPRI5 code (HNW II §IV.2)
BETA = 0.04
ALPHA = 0.2 - 0.75 * BETA
ERR_OLD_MIN = 1e-4  # lower bound on err_{n−1} (Hairer's facold)
LOG_ERR_OLD_MIN = math.log(ERR_OLD_MIN)

#: ``settle="auto"``: the transient ends at the first transient section point τ_k at which the
#: section sequence has repeated with some period n ≤ SETTLE_MAX_PERIOD, every component within
#: SETTLE_TOL·(1 + |y|) of its value n periods earlier, for the last max(SETTLE_CYCLES·n,
#: SETTLE_MIN_MATCHES) section points in a row.
SETTLE_MAX_PERIOD = 64
SETTLE_CYCLES = 3
SETTLE_MIN_MATCHES = 8
SETTLE_TOL = 1e-7

ST_OK = int(Status.OK)
ST_MAX_STEPS = int(Status.MAX_STEPS)
ST_UNDERFLOW = int(Status.STEP_UNDERFLOW)
ST_NON_FINITE = int(Status.NON_FINITE)


@numba.njit(cache=True, inline="always")
def _copy(dst, src, n):  # pragma: no cover - compiled
    """dst[:n] = src[:n], as a loop: a slice assignment drags numba's shape-mismatch error
    formatting into every kernel (seconds of compile time)."""
    for i in range(n):
        dst[i] = src[i]


@numba.njit(cache=True, inline="always")
def _shift(hist, obs, n):  # pragma: no cover - compiled
    """Rows of ``hist`` one older (row 2 ← 1 ← 0), row 0 ← obs[:n]."""
    for i in range(n):
        hist[2, i] = hist[1, i]
        hist[1, i] = hist[0, i]
        hist[0, i] = obs[i]


@njit_noalloc
def initial_step(kind, t, y, f0, p, rtol, atol, obs, n, y1, f1):  # pragma: no cover - compiled
    """Hairer's starting step (HNW I, §II.4) for the 5(4) pair, from the first n components
    (``obs``, ``y1``, ``f1``: scratch)."""
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
        h1 = (0.01 / max(d1, d2)) ** 0.2
    return min(100.0 * h0, h1)


@njit_noalloc
def _renormalize(kind, t, y, p, obs, K, n, k, lsum, tan_on):  # pragma: no cover - compiled
    """Tangent vectors in y[n:]: make them orthonormal (first call: the given ones, if any is
    nonzero, else the first k basis vectors) or re-orthonormalise them by modified Gram–Schmidt,
    adding log stretch factors to ``lsum``; refresh their FSAL stage ``K[0]`` (``obs``)."""
    numba.literally(kind)
    given = False
    if not tan_on:
        for i in range(n, n + k * n):
            if y[i] != 0.0:
                given = True
        if not given:
            for r in range(k):
                o = n + r * n
                for i in range(n):
                    y[o + i] = 1.0 if i == r else 0.0
    if tan_on or given:
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
            if tan_on:
                lsum[r] += math.log(nrm)
            for i in range(n):
                y[o + i] /= nrm
    tangent(kind, t, y, p, obs, K[0], n, k)
    return True


@njit_noalloc
def _settled(y, ring, runs, n_sec, n_base):  # pragma: no cover - compiled
    """Store transient section point number ``n_sec`` (state ``y``) in ``ring``; update the
    run lengths ``runs[n]`` of consecutive repeats with period n; whether one is long enough."""
    n_ring = ring.shape[0]
    row = n_sec % n_ring
    for i in range(n_base):
        ring[row, i] = y[i]
    done = False
    for per in range(1, min(n_sec, n_ring - 1) + 1):
        prev = (n_sec - per) % n_ring
        close = True
        for i in range(n_base):
            if abs(y[i] - ring[prev, i]) > SETTLE_TOL * (1.0 + abs(y[i])):
                close = False
                break
        runs[per] = runs[per] + 1 if close else 0
        if runs[per] >= max(SETTLE_CYCLES * per, SETTLE_MIN_MATCHES):
            done = True
    return done


@numba.njit(cache=True)
def workspace(n, n_obs, n_track, n_base):  # pragma: no cover - compiled
    """The scratch arrays of :func:`dopri_run` for states of size n (allocated once per block of
    chains, reused by every point)."""
    return (
        np.empty(n),  # y
        np.empty(n),  # yt: the stage argument, then y_{n+1}
        np.zeros((STAGES, n)),  # K: the stages
        np.empty(n_obs),  # obs
        np.empty((3, 2 * n_track)),  # hist: tracked observables of the last accepted points
        np.zeros(3),  # t_hist: their times
        np.empty((SETTLE_MAX_PERIOD + 1, n_base)),  # ring: transient section points
        np.zeros(SETTLE_MAX_PERIOD + 1, dtype=np.int64),  # runs: repeat run lengths
        np.empty(n),  # f1: scratch of initial_step
        np.empty(n_obs),  # o1: scratch of initial_step
    )


@njit_noalloc
def dopri_run(
    kind, y0, p, sw, t0, t_rec, dt_sample, t_end, cfg, out, info, lsum, ws
):  # pragma: no cover - compiled
    """Integrate one system; fill the output arrays ``out`` = (out_t, out_y, out_obs,
    obs_min, obs_max, y_final); return the status code. ``cfg`` is the configuration record
    (float64, slots :class:`~gearchaos.integrate.interface.Config`): the numbers every point
    of a run shares (n_samples, n_obs, n_track, n_base = n_state, rtol, atol, h_init, max_step,
    max_steps, settle_spp, tan_tol = tangent_tol). ``tan_tol`` scales the error tolerances of
    the tangent components.

    Samples are taken at τ_j = t_rec + j·dt_sample, j = 0 … n_samples−1 (t_rec ≥ t0), then the
    integration goes on to t_end ≥ τ_last. Extrema of obs[:n_track] are tracked over
    [t_rec, t_end]. ``sw`` holds the half clearances b_k of the dead zones acting on the tracked
    observables (``inf``: smooth); a step that crosses a switch obs_k = ±b_k is discarded and
    retried so that it ends on the switch, so no step straddles a kink of the vector field
    (DOPRI5's error estimate can miss a kink inside a step: 10–100× larger errors).
    ``info`` (float64, columns :class:`~gearchaos.integrate.interface.Info`) receives accepted
    steps, steps rejected by the error test, steps discarded to land on a switch, the final time
    reached, the next step size and the transient periods skipped by ``settle``.

    Settling (``settle_spp`` > 0, the samples per period, so T = settle_spp·dt_sample): the
    steps also land on the transient section points τ_rec − mT, and once their sequence repeats
    (see ``SETTLE_TOL``) at τ_rec − mT, the recording starts there: τ_rec and τ_end move back
    by mT (whole periods, so the forcing phase of every sample is unchanged).

    Lyapunov exponents: with ``k = lsum.size > 0`` the state holds ``n_base`` system
    components followed by k tangent vectors, integrated with the variational equations
    (:func:`~gearchaos.model.kernels.tangent`). They start orthonormal at the first sample and
    are re-orthonormalised (modified Gram–Schmidt) at every later sample; ``lsum`` accumulates
    the logarithms of the stretch factors. The tangents take part in the error control (a
    direction the state does not excite would otherwise get steps sized for the state alone),
    so the state agrees with a plain run's to the tolerance — bitwise if ``tan_tol`` is inf.
    """
    numba.literally(kind)
    n_samples = int(cfg[Config.N_SAMPLES])
    n_obs = int(cfg[Config.N_OBS])
    n_track = int(cfg[Config.N_TRACK])
    n_base = int(cfg[Config.N_STATE])
    rtol = cfg[Config.RTOL]
    atol = cfg[Config.ATOL]
    h_init = cfg[Config.H_INIT]
    max_step = cfg[Config.MAX_STEP]
    max_steps = int(cfg[Config.MAX_STEPS])
    settle_spp = int(cfg[Config.SETTLE_SPP])
    tan_tol = cfg[Config.TANGENT_TOL]
    out_t, out_y, out_obs, obs_min, obs_max, y_final = out
    y, yt, K, obs, hist, t_hist, ring, runs, f1, o1 = ws
    n = y0.size
    n_err = n_base if math.isinf(tan_tol) else n  # the components in the error norm
    _copy(y, y0, n)
    for s in range(STAGES):
        for i in range(n):
            K[s, i] = 0.0  # tangent components stay zero until the tangents start
    n_tr2 = 2 * n_track
    for k in range(n_track):
        obs_min[k] = np.inf
        obs_max[k] = -np.inf

    t = t0
    n_tan = lsum.size
    # np.bool_ (and np.int64 for n_pts, n_sec): a plain literal would make numba compile the
    # helpers that take these variables twice, once for the literal value and once widened
    tan_on = np.bool_(False)
    for r in range(n_tan):
        lsum[r] = 0.0
    rhs(kind, t, y, p, K[0], obs, OBS_ALL)
    n_acc = 0
    n_rej = 0
    n_sw = 0  # steps retried to end on a switch
    status = ST_OK
    for i in range(n):
        if not math.isfinite(K[0, i]) or not math.isfinite(y[i]):
            status = ST_NON_FINITE
    h = h_init
    if status == ST_OK and h <= 0.0:
        h = initial_step(kind, t, y, K[0], p, rtol, atol, o1, n_base, yt, f1)
    if h > max_step:
        h = max_step

    j = 0
    tracking = False
    if status == ST_OK and n_samples > 0 and t >= t_rec:
        out_t[0] = t
        _copy(out_y[0], y, n)
        if n_tan > 0:
            tan_on = _renormalize(kind, t, y, p, obs, K, n_base, n_tan, lsum, tan_on)
        _copy(out_obs[0], obs, n_obs)
        j = 1
        tracking = True
        for k in range(n_track):
            obs_min[k] = obs[k]
            obs_max[k] = obs[k]
    # tracked observables at the last three accepted points, newest first, and their times;
    # n_pts of them lie on the current smooth piece (since the last switch)
    for r in range(3):
        t_hist[r] = 0.0
    _copy(hist[0], obs, n_tr2)
    t_hist[0] = t
    n_pts = int(np.int64(1))  # not a literal: see tan_on
    last_rejected = False
    nonfinite = False
    has_switch = False
    for k in range(n_track):
        if sw[k] < np.inf:
            has_switch = True
    h_event = -1.0
    log_err_old = LOG_ERR_OLD_MIN  # log err_{n−1}: one log and one exp a step, no pow
    # settling: transient section points, the newest SETTLE_MAX_PERIOD + 1 in a ring
    settling = settle_spp > 0 and n_samples > 0 and t < t_rec
    period = dt_sample * settle_spp
    m_next = int((t_rec - t) / period - 1e-9) if settling else 0
    for r in range(SETTLE_MAX_PERIOD + 1):
        runs[r] = 0
    n_sec = int(np.int64(0))  # not a literal: see tan_on
    skipped = 0

    while status == ST_OK:
        sec_step = settling and m_next >= 1
        if sec_step:
            target = t_rec - m_next * period
        elif j < n_samples:
            target = t_rec + j * dt_sample
        else:
            target = t_end
        if j >= n_samples and t >= t_end:
            break
        if n_acc + n_rej + n_sw >= max_steps:
            status = ST_MAX_STEPS
            break
        hmin = 16.0 * 2.220446049250313e-16 * max(abs(t), abs(target))
        if h < hmin:
            status = ST_NON_FINITE if nonfinite else ST_UNDERFLOW
            break
        clipped = False
        shortened = False
        hs = h
        if h_event > 0.0:
            hs = h_event
            shortened = True
            h_event = -1.0
        elif has_switch and n_pts >= 2:
            # a switch predicted within the step (extrapolating the points of the current
            # smooth piece): shorten the step to end just past it
            hp = predict_switch(hist, n_pts, t_hist, n_track, sw, min(h, target - t))
            if hp > LAND * hs and hp > hmin:
                hs = hp + AIM * hs
                shortened = True
        if t + hs >= target:
            hs = target - t
            clipped = True
            shortened = False

        t_new = target if clipped else t + hs
        # the stages; the last one is evaluated at (t_new, y_new) (FSAL)
        last_level = OBS_ALL if (clipped or tan_on) else OBS_TRACK
        for s in range(1, STAGES):
            if s == 1:
                for i in range(n):
                    yt[i] = y[i] + hs * (A21 * K[0, i])
                ts = t + C2 * hs
            elif s == 2:
                for i in range(n):
                    yt[i] = y[i] + hs * (A31 * K[0, i] + A32 * K[1, i])
                ts = t + C3 * hs
            elif s == 3:
                for i in range(n):
                    yt[i] = y[i] + hs * (A41 * K[0, i] + A42 * K[1, i] + A43 * K[2, i])
                ts = t + C4 * hs
            elif s == 4:
                for i in range(n):
                    yt[i] = y[i] + hs * (
                        A51 * K[0, i] + A52 * K[1, i] + A53 * K[2, i] + A54 * K[3, i]
                    )
                ts = t + C5 * hs
            elif s == 5:
                for i in range(n):
                    yt[i] = y[i] + hs * (
                        A61 * K[0, i] + A62 * K[1, i] + A63 * K[2, i] + A64 * K[3, i]
                        + A65 * K[4, i]
                    )  # fmt: skip
                ts = t + hs
            else:
                for i in range(n):
                    yt[i] = y[i] + hs * (
                        A71 * K[0, i] + A73 * K[2, i] + A74 * K[3, i] + A75 * K[4, i]
                        + A76 * K[5, i]
                    )  # fmt: skip
                ts = t_new
            level = last_level if s == STAGES - 1 else (OBS_ALL if tan_on else OBS_NONE)
            rhs(kind, ts, yt, p, K[s], obs, level)
            if tan_on:
                tangent(kind, ts, yt, p, obs, K[s], n_base, n_tan)
        # yt is y_{n+1}; the scaled RMS norm of the embedded error estimate, which is NaN
        # also when y_{n+1} is not finite
        acc = 0.0
        for i in range(n):
            e = hs * (
                E1 * K[0, i] + E3 * K[2, i] + E4 * K[3, i] + E5 * K[4, i] + E6 * K[5, i]
                + E7 * K[6, i]
            )  # fmt: skip
            sc = atol + rtol * max(abs(y[i]), abs(yt[i]))
            if i >= n_base:
                sc *= tan_tol  # the tangents' own tolerance (1: the state's; inf: r = 0)
            r = e / sc
            acc += r * r + 0.0 * yt[i]
        err = math.sqrt(acc / n_err)

        if not math.isfinite(err):
            nonfinite = True
            n_rej += 1
            h = hs * MIN_FACTOR
            last_rejected = True
            continue
        nonfinite = False

        where = 0
        if has_switch:
            # a switch within LAND·h of either end of the step counts as landed on (h the
            # proposal: a shortened step must not make that window shrink)
            win = LAND * max(h, hs)
            theta, where = check_step(hist, obs, hs, n_track, sw, win)
            if theta < 1.0 and theta * hs > hmin:
                # a switch lies inside the step: retry, ending just past it
                h_event = theta * hs + AIM * max(h, hs)
                if h_event >= hs:
                    h_event = theta * hs
                n_sw += 1
                continue

        if err > 1.0:
            n_rej += 1
            h = hs * max(MIN_FACTOR, SAFETY * math.exp(-ALPHA * math.log(err)))
            last_rejected = True
            continue

        n_acc += 1
        # PI step-size control (Gustafsson; HNW II §IV.2 and Hairer's DOPRI5)
        if err == 0.0:
            log_err = LOG_ERR_OLD_MIN
            factor = MAX_FACTOR
        else:
            log_err = math.log(err)
            factor = SAFETY * math.exp(BETA * log_err_old - ALPHA * log_err)
            factor = min(MAX_FACTOR, max(MIN_FACTOR, factor))
        if last_rejected and factor > 1.0:
            factor = 1.0
        last_rejected = False
        h_next = hs * factor
        if clipped or shortened:
            if h_next < h:
                h_next = h  # restore the proposal made before clipping to a sample or switch
        else:
            log_err_old = max(log_err, LOG_ERR_OLD_MIN)  # steps cut short say little
        h = min(h_next, max_step)
        t = t_new
        for i in range(n):
            y[i] = yt[i]
            K[0, i] = K[STAGES - 1, i]
        if tracking:
            track(hist, obs, hs, n_track, obs_min, obs_max)
        record = clipped and j < n_samples and not sec_step
        if clipped and sec_step:
            m_next -= 1
            if _settled(y, ring, runs, n_sec, n_base):
                # settled: the recording starts here, whole periods before the planned start
                skipped = m_next + 1
                t_rec = t
                t_end -= skipped * period
                settling = False
                record = True
            n_sec += 1
        if record:
            out_t[j] = t
            _copy(out_y[j], y, n)  # tangents before renormalising: their stretch is readable
            if n_tan > 0:
                tan_on = _renormalize(kind, t, y, p, obs, K, n_base, n_tan, lsum, tan_on)
            _copy(out_obs[j], obs, n_obs)
            if not tracking:
                tracking = True
                for k in range(n_track):
                    obs_min[k] = obs[k]
                    obs_max[k] = obs[k]
            j += 1
        # the smooth piece: a switch at the end starts a new one, at the start one of two points
        n_pts = 1 if where == 2 else (2 if where == 1 else min(n_pts + 1, 3))
        _shift(hist, obs, n_tr2)
        t_hist[2] = t_hist[1]
        t_hist[1] = t_hist[0]
        t_hist[0] = t

    _copy(y_final, y, n)
    info[Info.ACCEPTED] = n_acc
    info[Info.REJECTED] = n_rej
    info[Info.SWITCH_RETRIES] = n_sw
    info[Info.TAU_REACHED] = t
    info[Info.NEXT_STEP] = h
    info[Info.SKIPPED] = skipped
    return status


@numba.njit(cache=True, nogil=True)
def dopri_chains(
    kind, Y0, P, SW, t0, t_rec, dt_sample, t_end, cfg, out_t, out_y, out_obs, obs_min, obs_max,
    y_final, info, status, LSUM
):  # pragma: no cover - compiled  # fmt: skip
    """Chains of integrations, one chain after another, points of a chain in order: the one
    compiled entry point of the integrator (single runs are chains of length one). It releases
    the GIL: :func:`~gearchaos.integrate._chains.run_chains` runs blocks of chains on several
    threads (a ``parallel=True`` kernel would cost seconds more to compile).

    The arguments after ``kind`` are the arrays of a
    :class:`~gearchaos.integrate._chains.ChainRun` (``_CHAIN_INPUTS``), its configuration
    record ``cfg`` (:class:`~gearchaos.integrate.interface.Config`) and the arrays of a
    :class:`~gearchaos.integrate._chains.ChainOutput` (``_CHAIN_OUTPUTS``), chain axis first.
    Point j of chain c has parameters ``P[c, j]`` and runs from τ = ``t0[c, j]``; it starts
    from ``Y0[c]`` (fresh) or, with ``continuation``, from the final state of point j−1 of the
    same chain (point 0 from ``Y0[c]``); a failed point restarts its successor from ``Y0[c]``.
    ``LSUM[c, j]`` (k ≥ 0 entries) receives the Lyapunov log sums when the state carries k
    tangent vectors after its ``n_base`` system components. ``settle_spp`` > 0 (the samples
    per period) lets every point end its transient early once its section sequence repeats.
    Every point runs :func:`dopri_run` unchanged, so its result does not depend on the chain
    it runs in, on the other chains or on the number of threads.
    """
    numba.literally(kind)
    n_chains = P.shape[0]
    length = P.shape[1]
    n_base = int(cfg[Config.N_STATE])
    continuation = cfg[Config.CONTINUATION] != 0.0
    ws = workspace(Y0.shape[1], int(cfg[Config.N_OBS]), int(cfg[Config.N_TRACK]), n_base)
    for c in range(n_chains):
        y = Y0[c].copy()
        for j in range(length):
            out = (out_t[c, j], out_y[c, j], out_obs[c, j])
            ext = (obs_min[c, j], obs_max[c, j], y_final[c, j])
            st = dopri_run(
                kind,
                y,
                P[c, j],
                SW[c, j],
                t0[c, j],
                t_rec[c, j],
                dt_sample[c, j],
                t_end[c, j],
                cfg,
                out + ext,
                info[c, j],
                LSUM[c, j],
                ws,
            )
            status[c, j] = st
            # a successor: the final system state, tangents afresh from Y0 (monodromy factors)
            _copy(y, Y0[c], y.size)
            if continuation and st == ST_OK:
                _copy(y, y_final[c, j], n_base)


def _guard() -> None:
    import os

    from .. import _numba
    from ..model import kernels, layout, reference_kernels

    here = os.path.dirname(__file__)
    sources = [
        kernels.__file__,
        reference_kernels.__file__,
        layout.__file__,
        os.path.join(here, "dopri.py"),
        os.path.join(here, "_switch.py"),
        os.path.join(here, "tableau.py"),
        os.path.join(here, "interface.py"),
        os.path.join(os.path.dirname(here), "errors.py"),
    ]
    _numba.guard_cache([dopri_run, dopri_chains], sources)


_guard()
