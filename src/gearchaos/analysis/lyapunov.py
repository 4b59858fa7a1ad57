"""Lyapunov exponents of any :class:`~gearchaos.model.System` from its variational equations.

The tangent vectors obey V' = J(τ, y) V with the piecewise Jacobian of the dead zones — valid
because every vector field here is continuous (damping acts inside the clearances, MODEL.md §4),
so no saltation matrix is needed at contact changes. They are integrated with the trajectory by
the same compiled Dormand–Prince kernel (with error control on the tangent vectors too),
started orthonormal after the transient and re-orthonormalised by
modified Gram–Schmidt at every sample (Benettin et al. 1980; Shimada & Nagashima 1979):
λ_j = (1/t) Σ log ‖v_j‖ over the recorded window.

Two levels (STYLE principle 8): :func:`lyapunov_spectrum` / :func:`max_lyapunov` for users, and
the kernel itself (``lsum`` of :func:`gearchaos.integrate.dopri.dopri_run`), which sweeps call
with ``lyapunov=True``. Exponents are per unit of dimensionless time τ = ω_n t; multiply by ω_n
for 1/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._numba import call_literal
from ..errors import ParameterError, Status
from ..integrate.dopri import dopri_run
from ..integrate.simulate import _default_max_steps, check_settings
from ..model.system import System

__all__ = ["LyapunovResult", "lyapunov_spectrum", "max_lyapunov"]


@dataclass(frozen=True)
class LyapunovResult:
    """Exponents (descending as computed by Gram–Schmidt order), run length and status."""

    exponents: np.ndarray
    duration: float
    renormalizations: int
    status: Status
    steps_accepted: int
    steps_rejected: int

    @property
    def largest(self) -> float:
        return float(self.exponents[0])

    @property
    def sum(self) -> float:
        return float(np.sum(self.exponents))


def lyapunov_spectrum(
    system: System,
    *,
    n_exponents: int | None = None,
    transient_periods: float = 100,
    periods: int = 500,
    renormalizations_per_period: int = 1,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    y0: np.ndarray | None = None,
    max_steps: int | None = None,
) -> LyapunovResult:
    """The ``n_exponents`` largest Lyapunov exponents (all by default) of ``system``.

    Parameters
    ----------
    system
        Any :class:`~gearchaos.model.System`; its forcing period T = 2π/Ω sets the
        renormalisation interval T / ``renormalizations_per_period``.
    transient_periods, periods
        Forcing periods discarded, then averaged over. The statistical error of a chaotic
        estimate decays like 1/√(periods); a regular orbit's like log(·)/periods.
    rtol, atol
        Tolerances of the system state and of the (normalised) tangent vectors.
    """
    n = system.n_state
    k = n if n_exponents is None else int(n_exponents)
    if not 1 <= k <= n:
        raise ParameterError(f"n_exponents must be between 1 and {n}: got {n_exponents!r}")
    check_settings(
        transient_periods=transient_periods,
        periods=periods,
        samples_per_period=renormalizations_per_period,
        rtol=rtol,
        atol=atol,
    )
    if periods * renormalizations_per_period < 2:
        raise ParameterError("periods × renormalizations_per_period must be >= 2")
    y = np.zeros(n * (1 + k))
    if y0 is not None:
        y0a = np.asarray(y0, dtype=float).ravel()
        if y0a.size != n or not np.all(np.isfinite(y0a)):
            raise ParameterError(f"y0 must be {n} finite numbers: got {y0!r}")
        y[:n] = y0a
    T = system.period
    ns = periods * renormalizations_per_period
    dt = T / renormalizations_per_period
    t_rec = transient_periods * T
    t_end = t_rec + periods * T
    if max_steps is None:
        max_steps = _default_max_steps(transient_periods + periods)
    out_t = np.full(ns, np.nan)
    out_y = np.full((ns, y.size), np.nan)
    out_o = np.full((ns, system.n_obs), np.nan)
    omin = np.zeros(system.n_track)
    omax = np.zeros(system.n_track)
    yf = np.zeros(y.size)
    info = np.zeros(4)
    lsum = np.zeros(k)
    code = call_literal(
        dopri_run,
        system.kind,
        y,
        system.params,
        0.0,
        float(t_rec),
        float(dt),
        ns,
        float(t_end),
        system.n_obs,
        system.n_track,
        system.switch_widths,
        n,
        float(rtol),
        float(atol),
        -1.0,
        math.inf,
        int(max_steps),
        out_t,
        out_y,
        out_o,
        omin,
        omax,
        yf,
        info,
        lsum,
    )
    duration = (ns - 1) * dt
    status = Status(int(code))
    ex = lsum / duration if status.ok else np.full(k, np.nan)
    return LyapunovResult(
        exponents=ex,
        duration=duration,
        renormalizations=ns - 1,
        status=status,
        steps_accepted=int(info[0]),
        steps_rejected=int(info[1]),
    )


def max_lyapunov(system: System, **kwargs: object) -> float:
    """Largest Lyapunov exponent (per unit τ) of ``system``; see :func:`lyapunov_spectrum`."""
    return lyapunov_spectrum(system, n_exponents=1, **kwargs).largest  # type: ignore[arg-type]
