"""Compiled settling check of the integrator (``settle="auto"``): has the transient ended?

The transient ends at the first transient section point τ_k at which the section sequence has
repeated with some period n ≤ SETTLE_MAX_PERIOD, every component within SETTLE_TOL·(1 + |y|) of
its value n periods earlier, for the last max(SETTLE_CYCLES·n, SETTLE_MIN_MATCHES) section points
in a row. The newest SETTLE_MAX_PERIOD + 1 section points are kept in a ring.
"""

from __future__ import annotations

import numba

from .._numba import njit_noalloc

__all__ = ["SETTLE_MAX_PERIOD", "first_section", "settled"]

SETTLE_MAX_PERIOD = 64
SETTLE_CYCLES = 3
SETTLE_MIN_MATCHES = 8
SETTLE_TOL = 1e-7


@numba.njit(cache=True, inline="always")
def first_section(t, t_rec, period):  # pragma: no cover - compiled
    """The number m of whole periods before ``t_rec`` of the first section point τ_rec − mT
    after ``t``."""
    return int((t_rec - t) / period - 1e-9)


@njit_noalloc
def settled(y, ring, runs, n_sec, n_base):  # pragma: no cover - compiled
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
