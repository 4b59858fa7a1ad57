"""Compiled step-size control of the integrator: the new step after a rejected or accepted step.

PI control as in Hairer's DOPRI5 code (Gustafsson; Hairer & Wanner, *Solving ODEs II*, §IV.2):
after an accepted step with scaled error err_n (:func:`~gearchaos.integrate._step.error_norm`)

    h_{n+1} = h_n · clip(SAFETY · err_n^(−α) · err_{n−1}^β, MIN_FACTOR, MAX_FACTOR),

β = 0.04 and α = 1/(q̂ + 1) − 0.75 β for an embedded estimate of order q̂ (α = 1/5 − 0.75 β for
Dormand–Prince 5(4), :func:`pi_alpha`), no growth right after a rejection; after a rejected step
h = h_n · max(MIN_FACTOR, SAFETY · err_n^(−α)), and h_n · MIN_FACTOR after a step whose error
is not finite. err_{n−1} is kept as its logarithm (one log and one exp a step, no pow), bounded
below by ERR_OLD_MIN (Hairer's facold); a step cut short to land on a sample or a switch does not
update it and keeps the proposal made before the cut.
"""

from __future__ import annotations

import math

import numba

__all__ = ["accepted_step", "pi_alpha", "rejected_step"]

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0
BETA = 0.04
ERR_OLD_MIN = 1e-4  # lower bound on err_{n−1} (Hairer's facold)
LOG_ERR_OLD_MIN = math.log(ERR_OLD_MIN)


def pi_alpha(order_hat: int) -> float:
    """The exponent α of err_n for an embedded error estimate of order ``order_hat``."""
    return 1.0 / (order_hat + 1) - 0.75 * BETA


@numba.njit(cache=True, inline="always")
def rejected_step(err, hs, alpha):  # pragma: no cover - compiled
    """The step to retry with after the step ``hs`` was rejected with scaled error ``err`` > 1
    (or not finite)."""
    if not math.isfinite(err):
        return hs * MIN_FACTOR
    return hs * max(MIN_FACTOR, SAFETY * math.exp(-alpha * math.log(err)))


@numba.njit(cache=True, inline="always")
def accepted_step(
    err, hs, h, log_err_old, last_rejected, cut, max_step, alpha
):  # pragma: no cover - compiled
    """The next step after the step ``hs`` was accepted with scaled error ``err`` ≤ 1, and the
    new log err_{n−1}: ``h`` is the step proposed before ``hs`` was cut short (``cut``: to land
    on a sample or a switch; the proposal is then kept if larger and err_{n−1} unchanged);
    ``last_rejected``: the attempt before was rejected (no growth). Returns
    ``(h_next, log_err_old)``, h_next at most ``max_step``."""
    if err == 0.0:
        log_err = LOG_ERR_OLD_MIN
        factor = MAX_FACTOR
    else:
        log_err = math.log(err)
        factor = SAFETY * math.exp(BETA * log_err_old - alpha * log_err)
        factor = min(MAX_FACTOR, max(MIN_FACTOR, factor))
    if last_rejected and factor > 1.0:
        factor = 1.0
    h_next = hs * factor
    if cut:
        if h_next < h:
            h_next = h  # restore the proposal made before clipping to a sample or switch
    else:
        log_err_old = max(log_err, LOG_ERR_OLD_MIN)  # steps cut short say little
    return min(h_next, max_step), log_err_old
