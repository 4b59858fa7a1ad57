"""Compiled helpers of the integrator for the tracked observables: contact switches and extrema.

The first ``n_track`` observables of every system are the arguments of its dead zones (or just
variables worth tracking), followed by their τ-derivatives. A *switch* is a crossing of one of
the levels ±b_k (b_k the half clearance; ``inf``: none) where the vector field has a kink. The
integrator keeps every step on one side of every switch (DOPRI5's error estimate can miss a kink
inside a step): it *predicts* the next switch before a step and shortens the step to end just
past it, *checks* every accepted step for a switch it missed and retries that step to end just
past it, and treats a switch that lies within the fraction ``LAND`` of either end of a step as
landed on. The extrema of the tracked observables are refined inside each accepted step.

Interpolants (all on the values v and derivatives v' of an observable at accepted points):

* the cubic Hermite interpolant of one step (:func:`hermite`), for the check and the extrema
  (4th order; exact for cubic polynomials);
* the quintic Hermite interpolant of the last three accepted points, extrapolated forward for the
  prediction (6th order), in Newton form on the confluent nodes (0, 0, −h₁, −h₁, −h₁−h₂,
  −h₁−h₂) of local time u = τ − τ_n. Only points since the last switch are used (v''' jumps at a
  kink); with two of them the cubic is extrapolated instead.

The integrator's loop calls :func:`aim_step` before a step (the step to try: the proposal,
shortened to end just past a predicted switch, clipped to the next target time),
:func:`land_switch` after it (the step to retry with when it crossed a switch it should have
ended on), :func:`track` after an accepted step and :func:`push_point` to keep the points of
the current smooth piece.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .._numba import njit_noalloc

__all__ = [
    "AIM",
    "LAND",
    "aim_step",
    "check_step",
    "hermite",
    "land_switch",
    "predict_switch",
    "push_point",
    "track",
]

#: A switch within this fraction of a step from either end counts as landed on. The local error
#: a kink at distance δ from a step end leaves is ~ b·h·J·δ v' (J the contact stiffness over
#: mass, b ≈ 0.1 a quadrature weight), far below the tolerance for δ ≤ 1e-6 h.
LAND = 1e-6
#: Relative margin by which a predicted or retried step is aimed past the switch.
AIM = 0.5 * LAND
#: An observable this close to a level, relative to its magnitude (four units in the last
#: place), is on the level: no switch is predicted ahead of it.
ON_LEVEL = 4.0 * 2.220446049250313e-16


@numba.njit(cache=True, inline="always")
def hermite(v0, v1, d0, d1, s):  # pragma: no cover - compiled
    """Cubic Hermite interpolant on s ∈ [0, 1] (d0, d1 already multiplied by the step)."""
    s2 = s * s
    s3 = s2 * s
    return (
        (2.0 * s3 - 3.0 * s2 + 1.0) * v0
        + (s3 - 2.0 * s2 + s) * d0
        + (-2.0 * s3 + 3.0 * s2) * v1
        + (s3 - s2) * d1
    )


@numba.njit(cache=True, inline="always")
def _region(v, b):  # pragma: no cover - compiled
    return 0 if v < -b else (2 if v > b else 1)


@numba.njit(cache=True, inline="always")
def _first_level(r0, r1, b):  # pragma: no cover - compiled
    """The level crossed first when the region changes from r0 to r1."""
    if r0 == 2:
        return b
    if r0 == 0:
        return -b
    return b if r1 == 2 else -b


@njit_noalloc
def _hermite_root(v0, v1, d0, d1, level):  # pragma: no cover - compiled
    """Root s ∈ (0, 1) of the cubic Hermite interpolant minus ``level`` (Illinois iteration),
    given v0 − level and v1 − level of opposite signs."""
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
        fx = hermite(v0, v1, d0, d1, x) - level
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
    return x


@njit_noalloc
def check_step(hist, obs, dt, n_track, sw, win):  # pragma: no cover - compiled
    """Switches inside one step of length ``dt`` from the point ``hist[0]`` to ``obs`` (``hist``
    as in :func:`predict_switch`).

    A switch that the end of the step has passed by at most ``win`` (in τ, from the value and
    derivative at the end: (v₁ − level)/v₁′) is landed on; one that the start of the step was
    at most ``win`` before ((level − v₀)/v₀′) lies at the start; any other is located on the
    cubic Hermite interpolant of the step. Returns ``(theta, where)``: ``theta`` the fraction of
    the step at the first switch of the last kind (the step must be retried to end there), 2.0
    if none; ``where`` 0 if no switch was crossed, 1 if those crossed lie at the start of the
    step only, 2 if one lies at its end.
    """
    best = 2.0
    where = 0
    for k in range(n_track):
        b = sw[k]
        if not b < np.inf:
            continue
        v0 = hist[0, k]
        v1 = obs[k]
        r0 = _region(v0, b)
        r1 = _region(v1, b)
        if r0 == r1:
            continue
        level = _first_level(r0, r1, b)
        d0 = hist[0, n_track + k]
        d1 = obs[n_track + k]
        if abs(r1 - r0) == 1:
            gap = v1 - level
            if gap * d1 >= 0.0 and abs(gap) <= win * abs(d1):
                where = 2  # passed at most win ago: landed on
                continue
            gap = level - v0
            if gap * d0 >= 0.0 and abs(gap) <= win * abs(d0):
                if where == 0:
                    where = 1  # reached at most win after the start
                continue
        x = _hermite_root(v0, v1, d0 * dt, d1 * dt, level)
        if x < best:
            best = x
    return best, where


@njit_noalloc
def track(hist, obs, dt, n_track, omin, omax):  # pragma: no cover - compiled
    """Update running extrema over one accepted step from ``hist[0]`` to ``obs`` (values and
    Hermite interior extremum)."""
    for k in range(n_track):
        v0 = hist[0, k]
        v1 = obs[k]
        if v1 < omin[k]:
            omin[k] = v1
        if v1 > omax[k]:
            omax[k] = v1
        d0 = hist[0, n_track + k] * dt
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
                v = hermite(v0, v1, d0, d1, s)
                if v < omin[k]:
                    omin[k] = v
                if v > omax[k]:
                    omax[k] = v


@numba.njit(cache=True, inline="always")
def _newton_d(u, ub, ua, c0, c1, c2, c3, c4, c5):  # pragma: no cover - compiled
    """The Newton form on the nodes (0, 0, ub, ub, ua, ua) at u, and its derivative in u."""
    a = c5 * (u - ua) + c4
    w = u - ub
    b = a * w + c3
    db = c5 * w + a
    q = b * w + c2
    dq = db * w + b
    r = q * u + c1
    dr = dq * u + q
    return r * u + c0, dr * u + r


@njit_noalloc
def predict_switch(hist, n_pts, t_hist, n_track, sw, h):  # pragma: no cover - compiled
    """Time from the current point to the first switch predicted within (0, h], or −1.

    ``hist`` holds the tracked observables and derivatives of the last three accepted points,
    newest first (rows 0, 1, 2) at times ``t_hist``; only the ``n_pts`` ≥ 2 newest are used
    (those since the last switch). Observables far from every level are skipped by a cheap
    bound; for the others the Hermite interpolant through the points is extrapolated to
    τ_n + h and, if it changes contact region, its root is found by Newton's method kept
    inside the bracket (bisection where a Newton step would leave it): 3–5 evaluations where
    plain bisection to the same 1e-9 h took 30, which had made the prediction a quarter of a
    step's time (issue 13).
    """
    u1 = t_hist[1] - t_hist[0]  # < 0
    u2 = t_hist[2] - t_hist[0]
    r1 = 1.0 / u1
    r2 = 1.0 / u2 if n_pts >= 3 else 0.0
    r21 = 1.0 / (u2 - u1) if n_pts >= 3 else 0.0
    best = -1.0
    for k in range(n_track):
        b = sw[k]
        if not b < np.inf:
            continue
        v0 = hist[0, k]
        d0 = hist[0, n_track + k]
        d1 = hist[1, n_track + k]
        r0 = _region(v0, b)
        gap = min(abs(v0 - b), abs(v0 + b))
        if gap <= ON_LEVEL * max(abs(v0), b):
            # on the level to rounding: the switch is at the start of the step (check_step
            # lands it there); aiming a step at it would be a step too short to move the
            # observable in floating point, again and again (a grazing contact stalled so)
            continue
        # a crossing within h needs |Δv| ≥ gap; |v'| is bounded generously by the two last
        # derivatives and their trend
        reach = h * (abs(d0) + abs(d0 - d1) * (1.0 - h * r1))
        if gap > 2.0 * reach:
            continue
        v1 = hist[1, k]
        # confluent divided differences, nodes 0, 0, u1, u1 (, u2, u2)
        s01 = (v1 - v0) * r1
        c2 = (s01 - d0) * r1
        f12 = (d1 - s01) * r1
        c3 = (f12 - c2) * r1
        c4 = 0.0
        c5 = 0.0
        if n_pts >= 3:
            v2 = hist[2, k]
            d2 = hist[2, n_track + k]
            s12 = (v2 - v1) * r21
            g2 = (s12 - d1) * r21
            g3 = (d2 - s12) * r21
            f23 = (g2 - f12) * r2
            f34 = (g3 - g2) * r21
            e3 = (f34 - f23) * r2
            c4 = (f23 - c3) * r2
            c5 = (e3 - c4) * r2
        ve = _newton_d(h, u1, u2, v0, d0, c2, c3, c4, c5)[0]
        re = _region(ve, b)
        if re == r0:
            continue
        level = _first_level(r0, re, b)
        lo = 0.0
        hi = h
        f_lo = v0 - level
        f_hi = ve - level
        x = lo + f_lo * (lo - hi) / (f_hi - f_lo) if f_hi != f_lo else 0.5 * h  # regula falsi
        if not lo < x < hi:
            x = 0.5 * (lo + hi)
        for _ in range(60):
            fx, dfx = _newton_d(x, u1, u2, v0, d0, c2, c3, c4, c5)
            fx -= level
            if fx == 0.0:
                break
            if (fx > 0.0) == (f_lo > 0.0):
                lo = x
                f_lo = fx
            else:
                hi = x
            step = fx / dfx if dfx != 0.0 else np.inf
            if abs(step) <= 1e-9 * h:
                x -= step  # converged (a step this small may touch the bracket's end)
                break
            x -= step
            if not lo < x < hi:
                x = 0.5 * (lo + hi)  # Newton left the bracket: bisect
            if hi - lo <= 1e-9 * h:
                break
        if best < 0.0 or x < best:
            best = x
    return best


@numba.njit(cache=True, inline="always")
def aim_step(
    h, h_event, t, target, hist, n_pts, t_hist, n_track, sw, has_switch, hmin
):  # pragma: no cover - compiled
    """The step to try from ``t``: ``h_event`` (> 0: a retry that ends just past a switch
    the last attempt crossed), else the proposal ``h``, shortened to end just past a switch
    predicted within it (from the ``n_pts`` ≥ 2 points of the current smooth piece, see
    :func:`predict_switch`), and clipped to end exactly on ``target`` (the next sample or
    section time, or the end) if it would reach it. Returns ``(hs, clipped, shortened)``."""
    clipped = False
    shortened = False
    hs = h
    if h_event > 0.0:
        hs = h_event
        shortened = True
    elif has_switch and n_pts >= 2:
        hp = predict_switch(hist, n_pts, t_hist, n_track, sw, min(h, target - t))
        if hp > LAND * hs and hp > hmin:
            hs = hp + AIM * hs
            shortened = True
    if t + hs >= target:
        hs = target - t
        clipped = True
        shortened = False
    return hs, clipped, shortened


@numba.njit(cache=True, inline="always")
def land_switch(hist, obs, hs, h, n_track, sw, hmin):  # pragma: no cover - compiled
    """After a step ``hs`` (proposal ``h``) from ``hist[0]`` to ``obs``: a switch within
    LAND·max(h, hs) of either end counts as landed on (h the proposal: a shortened step must not
    make that window shrink); one inside the step (farther than ``hmin`` from its start) means
    the step must be retried to end just past it. Returns ``(h_event, where)``: the step to
    retry with (−1: keep the step) and ``where`` as in :func:`check_step`."""
    win = LAND * max(h, hs)
    theta, where = check_step(hist, obs, hs, n_track, sw, win)
    h_event = -1.0
    if theta < 1.0 and theta * hs > hmin:
        h_event = theta * hs + AIM * max(h, hs)
        if h_event >= hs:
            h_event = theta * hs
    return h_event, where


@numba.njit(cache=True, inline="always")
def push_point(hist, t_hist, obs, t, n):  # pragma: no cover - compiled
    """Make the accepted point (t, ``obs[:n]``) the newest of the three kept: rows of ``hist``
    one older (row 2 ← 1 ← 0), row 0 ← obs[:n], and their times ``t_hist`` likewise."""
    for i in range(n):
        hist[2, i] = hist[1, i]
        hist[1, i] = hist[0, i]
        hist[0, i] = obs[i]
    t_hist[2] = t_hist[1]
    t_hist[1] = t_hist[0]
    t_hist[0] = t
