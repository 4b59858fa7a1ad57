"""The compiled integrator's interface, written once: its configuration record and the columns
of its per-point ``info`` record.

:class:`Config` names the slots of the float64 configuration record every point of a run
shares (built by :func:`~gearchaos.integrate._chains.config_record` from a
:class:`~gearchaos.integrate._chains.ChainRun`, whose fields the slots are named after, and read
by :func:`~gearchaos.integrate.dopri.dopri_run` slot by slot); :class:`Info` names the columns of
the ``info`` record the kernel fills for each point. Both are ``IntEnum`` s, which numba folds
into the machine code as constants. Status codes are :class:`~gearchaos.errors.Status`.
"""

from __future__ import annotations

import enum

__all__ = ["Config", "Info"]


class Config(enum.IntEnum):
    """Slots of the configuration record (float64; integers and flags stored exactly as
    floats). Each name is the lower-case name of a :class:`~gearchaos.integrate._chains.ChainRun`
    field."""

    N_SAMPLES = 0  # samples per point
    N_OBS = 1  # observables the right-hand side writes
    N_TRACK = 2  # tracked observables (extrema, contact switches)
    N_STATE = 3  # system components of the state (the tangent vectors follow them)
    RTOL = 4
    ATOL = 5
    H_INIT = 6  # first step size (≤ 0: Hairer's starting step)
    MAX_STEP = 7
    MAX_STEPS = 8  # step attempts allowed per point
    CONTINUATION = 9  # 1: a point starts from its predecessor's final state
    SETTLE = 10  # 1: the transient may end early once its section points repeat
    TANGENT_TOL = 11  # factor on the error tolerances of the tangent components
    SAMPLES_PER_PERIOD = 12  # samples per section interval (every such sample is a section)


class Info(enum.IntEnum):
    """Columns of the float64 ``info`` record of each integrated point."""

    ACCEPTED = 0  # steps accepted
    REJECTED = 1  # step attempts rejected by the error test (or not finite)
    TAU_REACHED = 2  # the time τ the integration reached
    NEXT_STEP = 3  # the step size it would take next
    SKIPPED = 4  # transient periods skipped (settle="auto")
    SWITCH_RETRIES = 5  # step attempts discarded to end the step on a contact switch
