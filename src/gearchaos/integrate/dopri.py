"""Compiled adaptive Dormand–Prince 5(4) integrator that lands exactly on the section times.

The kernel integrates ``y' = f(τ, y)`` of any built-in system (selected by ``kind``) from τ_0,
discards everything before the record start τ_rec, then stops *exactly* on each section time
τ_rec + kT (the step is clipped, not interpolated: 3–9× more accurate than interpolation), and
continues to τ_end. With s > 1 samples per period, the samples between two sections,
τ_rec + jΔ (Δ = T/s, j not a multiple of s), are taken inside the accepted step that contains
them from the method's continuous extension (Hairer's dense output of order 4 for DOPRI5,
:func:`~._step.dense_state`), their observables from the right-hand side at the interpolated
state: so the steps, and with them the section points, the final state, the step counts and
the extrema, are the same bit for bit whatever s is (issue 32: on a chaotic transient a
different step sequence can end on a different attractor). Runs that carry tangent vectors
still end a step on every sample, where the vectors are renormalised. Over [τ_rec, τ_end] it
keeps the running minimum and maximum of the first ``n_track`` observables, refining the
extremum inside each accepted step by the cubic Hermite interpolant of the observable and its
derivative (the observables come for free from the FSAL stage).

:func:`dopri_run` is the loop; each of its parts is a compiled function of its own that a test
can call alone:

* the step (:mod:`~gearchaos.integrate._step`): :func:`~._step.rk_step` (the stages, from the
  Butcher tableau as data, :data:`~gearchaos.integrate.tableau.DOPRI5`),
  :func:`~._step.error_norm` (the scaled RMS norm of h Σ (b_i − b̂_i) k_i with scale
  atol + rtol·max(|y_n|, |y_{n+1}|), as in Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4 and
  scipy's ``RK45``), :func:`~._step.initial_step` (Hairer's starting step);
* step-size control (:mod:`~gearchaos.integrate._control`): PI control as in Hairer's DOPRI5
  code, after an accepted or a rejected step;
* events (:mod:`~gearchaos.integrate._switch`): contact switches are predicted from the points
  of the current smooth piece and a step is shortened to end just past the next one
  (:func:`~._switch.aim_step`), a step that crossed one is retried to end on it
  (:func:`~._switch.land_switch`), and the extrema are refined in each step
  (:func:`~._switch.track`);
* settling (:mod:`~gearchaos.integrate._settle`): whether the transient's section points repeat;
* sampling (:mod:`~gearchaos.integrate._sample`): a sample recorded, tangent vectors
  renormalised there; a sample between sections interpolated (:func:`record_interpolated`).

After a step clipped to land on a section the pre-clip step size is restored, so sampling does
not throttle the integration. Another explicit FSAL pair runs this same code with its own
constants (:func:`~gearchaos.integrate.methods.kernels_for`).

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
from ..model.kernels import OBS_ALL, OBS_TRACK, rhs
from ._control import LOG_ERR_OLD_MIN, accepted_step, rejected_step
from ._sample import copy_into, record_sample, renormalize, start_extrema
from ._settle import SETTLE_MAX_PERIOD, first_section, settled
from ._step import ALPHA, STAGES, dense_state, error_norm, fsal_advance, initial_step, rk_step
from ._switch import aim_step, land_switch, push_point, track
from .interface import Config, Info

__all__ = ["dopri_chains", "dopri_run"]

ST_OK = int(Status.OK)
ST_MAX_STEPS = int(Status.MAX_STEPS)
ST_UNDERFLOW = int(Status.STEP_UNDERFLOW)
ST_NON_FINITE = int(Status.NON_FINITE)


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
        np.empty(n),  # f1: scratch of initial_step and of an interpolated sample
        np.empty(n_obs),  # o1: scratch of initial_step and of an interpolated sample
        np.empty(n),  # yi: an interpolated sample's state
        np.empty(STAGES),  # wd: the dense output's weights b_i(θ)
    )


@numba.njit(cache=True, inline="always")
def sample_time(t_rec, period, dt_sample, spp, j):  # pragma: no cover - compiled
    """τ_j of sample j: a section (j = k·spp) at τ_rec + k·T, any other at τ_rec + j·Δ (the
    same numbers for s = 1 and for every power of two s, since T/s is then exact)."""
    k = j // spp
    if j == k * spp:
        return t_rec + k * period
    return t_rec + j * dt_sample


@numba.njit(cache=True, inline="always")
def record_interpolated(
    kind, j, tj, theta, y, K, hs, p, yi, wd, f1, o1, out_t, out_y, out_obs, n, n_obs
):  # pragma: no cover - compiled
    """Record sample ``j`` at τ_j = ``tj``, the fraction ``theta`` of the accepted step ``hs``
    from ``y`` (its stages ``K``, before the step is taken over): the state from the continuous
    extension (:func:`~._step.dense_state`), the observables from the right-hand side there.
    Inlined into its caller, where ``kind`` must be a compile-time literal."""
    dense_state(yi, y, K, hs, theta, wd, n)
    rhs(kind, tj, yi, p, f1, o1, OBS_ALL)
    out_t[j] = tj
    copy_into(out_y[j], yi, n)
    copy_into(out_obs[j], o1, n_obs)


@njit_noalloc
def dopri_run(
    kind, y0, p, sw, t0, t_rec, period, t_end, cfg, out, info, lsum, ws
):  # pragma: no cover - compiled
    """Integrate one system; fill the output arrays ``out`` = (out_t, out_y, out_obs,
    obs_min, obs_max, y_final); return the status code. ``cfg`` is the configuration record
    (float64, slots :class:`~gearchaos.integrate.interface.Config`): the numbers every point
    of a run shares (n_samples, n_obs, n_track, n_base = n_state, rtol, atol, h_init, max_step,
    max_steps, settle, tan_tol = tangent_tol, spp = samples_per_period). ``tan_tol`` scales the
    error tolerances of the tangent components.

    Samples are taken at τ_j = t_rec + j·Δ, Δ = ``period``/spp, j = 0 … n_samples−1
    (t_rec ≥ t0; :func:`sample_time`), then the integration goes on to t_end. The steps end
    exactly on the sections j = k·spp (τ_rec + k·``period``) and on t_end; a sample in between
    is interpolated inside the accepted step that contains it (:func:`record_interpolated`), so
    the steps do not depend on spp. With tangent vectors every sample is a step end. Extrema of
    obs[:n_track] are tracked over [t_rec, t_end]. ``sw`` holds the half clearances b_k of the
    dead zones acting on the tracked observables (``inf``: smooth); a step that crosses a
    switch obs_k = ±b_k is discarded and retried so that it ends on the switch, so no step
    straddles a kink of the vector field (DOPRI5's error estimate can miss a kink inside a
    step: 10–100× larger errors).
    ``info`` (float64, columns :class:`~gearchaos.integrate.interface.Info`) receives accepted
    steps, steps rejected by the error test, steps discarded to land on a switch, the final time
    reached, the next step size and the transient periods skipped by ``settle``.

    Settling (``settle``, T = ``period``): the steps also land on the transient section points
    τ_rec − mT, and once their sequence repeats (:func:`~gearchaos.integrate._settle.settled`)
    at τ_rec − mT, the recording starts there:
    τ_rec and τ_end move back by mT (whole periods, so the forcing phase of every sample is
    unchanged).

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
    settle = cfg[Config.SETTLE] != 0.0
    tan_tol = cfg[Config.TANGENT_TOL]
    spp = int(cfg[Config.SAMPLES_PER_PERIOD])
    dt_sample = period / spp
    # the samples the steps end on: the sections (every sample while tangents ride along)
    land = 1 if lsum.size > 0 else spp
    out_t, out_y, out_obs, obs_min, obs_max, y_final = out
    y, yt, K, obs, hist, t_hist, ring, runs, f1, o1, yi, wd = ws
    n = y0.size
    copy_into(y, y0, n)
    for s in range(STAGES):
        for i in range(n):
            K[s, i] = 0.0  # tangent components stay zero until the tangents start
    n_tr2 = 2 * n_track
    for k in range(n_track):
        obs_min[k] = np.inf
        obs_max[k] = -np.inf

    t = t0
    # np.bool_ (and np.int64 for n_pts, n_sec): a plain literal would make numba compile the
    # helpers that take these variables twice, once for the literal value and once widened
    tan_on = np.bool_(False)
    for r in range(lsum.size):
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
        tan_on = record_sample(
            kind, 0, t, y, p, obs, K, out_t, out_y, out_obs, n_base, n_obs, lsum, tan_on
        )
        j = 1
        tracking = True
        start_extrema(obs, n_track, obs_min, obs_max)
    # tracked observables at the last three accepted points, newest first, and their times;
    # n_pts of them lie on the current smooth piece (since the last switch)
    for r in range(3):
        t_hist[r] = 0.0
    copy_into(hist[0], obs, n_tr2)
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
    settling = settle and n_samples > 0 and t < t_rec
    m_next = first_section(t, t_rec, period) if settling else 0
    for r in range(SETTLE_MAX_PERIOD + 1):
        runs[r] = 0
    n_sec = int(np.int64(0))  # not a literal: see tan_on
    skipped = 0

    while status == ST_OK:
        sec_step = settling and m_next >= 1
        on_sample = False  # the target is the next landed sample
        if sec_step:
            target = t_rec - m_next * period
        else:
            j_land = ((j + land - 1) // land) * land
            if j_land < n_samples:
                target = sample_time(t_rec, period, dt_sample, spp, j_land)
                on_sample = True
            else:
                target = t_end
                if j < n_samples:  # samples left to interpolate: reach the last one
                    target = max(t_end, sample_time(t_rec, period, dt_sample, spp, n_samples - 1))
        if j >= n_samples and t >= t_end:
            break
        if n_acc + n_rej + n_sw >= max_steps:
            status = ST_MAX_STEPS
            break
        hmin = 16.0 * 2.220446049250313e-16 * max(abs(t), abs(target))
        if h < hmin:
            status = ST_NON_FINITE if nonfinite else ST_UNDERFLOW
            break
        # the step: aimed past a predicted switch, clipped to the target; the last stage is
        # evaluated at (t_new, y_new) (FSAL), with all observables on a sample step
        hs, clipped, shortened = aim_step(
            h, h_event, t, target, hist, n_pts, t_hist, n_track, sw, has_switch, hmin
        )
        h_event = -1.0
        t_new = target if clipped else t + hs
        last_level = OBS_ALL if (clipped or tan_on) else OBS_TRACK
        rk_step(kind, t, y, hs, t_new, p, K, yt, obs, n, n_base, lsum.size, tan_on, last_level)
        err = error_norm(y, yt, K, hs, n, n_base, rtol, atol, tan_tol)
        if not math.isfinite(err):
            nonfinite = True
            n_rej += 1
            h = rejected_step(err, hs, ALPHA)
            last_rejected = True
            continue
        nonfinite = False

        where = 0
        if has_switch:
            h_event, where = land_switch(hist, obs, hs, h, n_track, sw, hmin)
            if h_event > 0.0:
                n_sw += 1  # a switch lies inside the step: retry, ending just past it
                continue

        if err > 1.0:
            n_rej += 1
            h = rejected_step(err, hs, ALPHA)
            last_rejected = True
            continue

        n_acc += 1
        cut = clipped or shortened
        h, log_err_old = accepted_step(err, hs, h, log_err_old, last_rejected, cut, max_step, ALPHA)
        last_rejected = False
        # the samples between sections inside this step, from its continuous extension
        while j < n_samples and j % land != 0:
            tj = t_rec + j * dt_sample
            if tj > t_new:
                break
            theta = (tj - t) / hs
            record_interpolated(
                kind, j, tj, theta, y, K, hs, p, yi, wd, f1, o1, out_t, out_y, out_obs, n, n_obs
            )
            j += 1
        t = t_new
        fsal_advance(y, yt, K, n)
        if tracking:
            track(hist, obs, hs, n_track, obs_min, obs_max)
        record = clipped and on_sample
        if clipped and sec_step:
            m_next -= 1
            if settled(y, ring, runs, n_sec, n_base):
                # settled: the recording starts here, whole periods before the planned start
                skipped = m_next + 1
                t_rec = t
                t_end -= skipped * period
                settling = False
                record = True
            n_sec += 1
        if record:
            tan_on = record_sample(
                kind, j, t, y, p, obs, K, out_t, out_y, out_obs, n_base, n_obs, lsum, tan_on
            )
            if not tracking:
                tracking = True
                start_extrema(obs, n_track, obs_min, obs_max)
            j += 1
        # the smooth piece: a switch at the end starts a new one, at the start one of two points
        n_pts = 1 if where == 2 else (2 if where == 1 else min(n_pts + 1, 3))
        push_point(hist, t_hist, obs, t, n_tr2)

    copy_into(y_final, y, n)
    info[Info.ACCEPTED] = n_acc
    info[Info.REJECTED] = n_rej
    info[Info.SWITCH_RETRIES] = n_sw
    info[Info.TAU_REACHED] = t
    info[Info.NEXT_STEP] = h
    info[Info.SKIPPED] = skipped
    return status


@numba.njit(cache=True, nogil=True)
def dopri_chains(
    kind, Y0, P, SW, t0, t_rec, T, t_end, cfg, out_t, out_y, out_obs, obs_min, obs_max,
    y_final, info, status, LSUM
):  # pragma: no cover - compiled  # fmt: skip
    """Chains of integrations, one chain after another, points of a chain in order: the one
    compiled entry point of the integrator (single runs are chains of length one). It releases
    the GIL: :func:`~gearchaos.integrate._chains.run_chains` runs blocks of chains on several
    threads (a ``parallel=True`` kernel would cost seconds more to compile).

    The arguments after ``kind`` are the arrays of a
    :class:`~gearchaos.integrate._chains.ChainRun` (``_CHAIN_INPUTS``), its configuration
    record ``cfg`` (:class:`~gearchaos.integrate.interface.Config`) and the arrays of a
    :class:`~gearchaos.integrate._chains.ChainOutput` (``_CHAIN_OUTPUTS``), chain axis first
    (``T`` the section interval of each point).
    Point j of chain c has parameters ``P[c, j]`` and runs from τ = ``t0[c, j]``; it starts
    from ``Y0[c]`` (fresh) or, with ``continuation``, from the final state of point j−1 of the
    same chain (point 0 from ``Y0[c]``); a failed point restarts its successor from ``Y0[c]``.
    ``LSUM[c, j]`` (k ≥ 0 entries) receives the Lyapunov log sums when the state carries k
    tangent vectors after its ``n_base`` system components. ``settle`` lets every point end
    its transient early once its section sequence repeats.
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
                T[c, j],
                t_end[c, j],
                cfg,
                out + ext,
                info[c, j],
                LSUM[c, j],
                ws,
            )
            status[c, j] = st
            # a successor: the final system state, tangents afresh from Y0 (monodromy factors)
            copy_into(y, Y0[c], y.size)
            if continuation and st == ST_OK:
                copy_into(y, y_final[c, j], n_base)


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
        os.path.join(here, "_step.py"),
        os.path.join(here, "_control.py"),
        os.path.join(here, "_sample.py"),
        os.path.join(here, "_settle.py"),
        os.path.join(here, "_switch.py"),
        os.path.join(here, "tableau.py"),
        os.path.join(here, "interface.py"),
        os.path.join(os.path.dirname(here), "errors.py"),
    ]
    _numba.guard_cache([dopri_run, dopri_chains, initial_step, renormalize], sources)


_guard()
