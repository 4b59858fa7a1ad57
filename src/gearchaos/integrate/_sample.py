"""Compiled sampling of the integrator: recording a sample, renormalising the tangent vectors
there, and starting the running extrema.

The integrator ends a step exactly on every section time (3–9× more accurate than
interpolating), and on every sample while tangent vectors ride along, so such a sample is the
state after that step, with the observables of its last (FSAL) stage. A sample between two
sections is interpolated instead (:func:`~gearchaos.integrate.dopri.record_interpolated`, from
the continuous extension :func:`~gearchaos.integrate._step.dense_state`), so that the steps do
not depend on the number of samples per period. The interpolant of the tracked observables
inside a step (cubic Hermite, for the extrema and the switches) is
:func:`~gearchaos.integrate._switch.hermite`.
"""

from __future__ import annotations

import math

import numba

from .._numba import njit_noalloc
from ..model.kernels import tangent

__all__ = ["copy_into", "record_sample", "renormalize", "start_extrema"]


@numba.njit(cache=True, inline="always")
def copy_into(dst, src, n):  # pragma: no cover - compiled
    """dst[:n] = src[:n], as a loop: a slice assignment drags numba's shape-mismatch error
    formatting into every kernel (seconds of compile time)."""
    for i in range(n):
        dst[i] = src[i]


@njit_noalloc
def renormalize(kind, t, y, p, obs, K, n, k, lsum, tan_on):  # pragma: no cover - compiled
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


@numba.njit(cache=True, inline="always")
def record_sample(
    kind, j, t, y, p, obs, K, out_t, out_y, out_obs, n_base, n_obs, lsum, tan_on
):  # pragma: no cover - compiled
    """Record sample ``j``: time, state (the tangent vectors before renormalising: their
    stretch is readable) and observables; with tangent vectors (``lsum.size`` > 0) renormalise
    them there. Returns whether the tangents are on. Inlined into its caller (a sample can
    come every step), where ``kind`` must be a compile-time literal."""
    out_t[j] = t
    copy_into(out_y[j], y, y.size)
    if lsum.size > 0:
        tan_on = renormalize(kind, t, y, p, obs, K, n_base, lsum.size, lsum, tan_on)
    copy_into(out_obs[j], obs, n_obs)
    return tan_on


@numba.njit(cache=True, inline="always")
def start_extrema(obs, n_track, obs_min, obs_max):  # pragma: no cover - compiled
    """Start the running extrema of the tracked observables at the values ``obs``."""
    for k in range(n_track):
        obs_min[k] = obs[k]
        obs_max[k] = obs[k]
