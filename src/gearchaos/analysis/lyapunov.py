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

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, Status
from ..integrate.simulate import integrate
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
    if periods * renormalizations_per_period < 2:
        raise ParameterError("periods × renormalizations_per_period must be >= 2")
    traj = integrate(
        system,
        y0=y0,
        transient_periods=transient_periods,
        periods=periods,
        samples_per_period=renormalizations_per_period,
        rtol=rtol,
        atol=atol,
        max_steps=max_steps,
        n_tangent=k,
    )
    ns = periods * renormalizations_per_period
    duration = (ns - 1) * system.period / renormalizations_per_period
    ex = traj.tangent_log_sums / duration if traj.ok else np.full(k, np.nan)
    return LyapunovResult(
        exponents=ex,
        duration=duration,
        renormalizations=ns - 1,
        status=traj.status,
        steps_accepted=traj.steps_accepted,
        steps_rejected=traj.steps_rejected,
    )


def max_lyapunov(system: System, **kwargs: object) -> float:
    """Largest Lyapunov exponent (per unit τ) of ``system``; see :func:`lyapunov_spectrum`."""
    return lyapunov_spectrum(system, n_exponents=1, **kwargs).largest  # type: ignore[arg-type]
