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
from typing import Any

import numpy as np

from .._checks import check_int
from ..errors import ParameterError, Status
from ..integrate.settings import MAX_SAMPLES_PER_PERIOD, SolverSettings
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


#: Lyapunov runs average over more periods than a simulation records by default.
LYAPUNOV_SETTINGS = SolverSettings(periods=500)


def lyapunov_spectrum(
    system: System,
    settings: SolverSettings | None = None,
    *,
    n_exponents: int | None = None,
    renormalizations_per_period: int = 1,
    y0: np.ndarray | None = None,
    **solver: Any,
) -> LyapunovResult:
    """The ``n_exponents`` largest Lyapunov exponents (all by default) of ``system``.

    Parameters
    ----------
    system
        Any :class:`~gearchaos.model.System`; its forcing period T = 2π/Ω sets the
        renormalisation interval T / ``renormalizations_per_period``.
    settings, **solver
        :class:`~gearchaos.integrate.settings.SolverSettings` (default: 100 transient periods,
        500 periods averaged over) and/or its fields by name: ``transient_periods``,
        ``periods`` (the statistical error of a chaotic estimate decays like 1/√(periods); a
        regular orbit's like log(·)/periods), ``rtol`` and ``atol`` (of the state and of the
        normalised tangent vectors), ``max_steps``.
    """
    if not isinstance(system, System):
        raise ParameterError(f"system must be a System: got {type(system).__name__}")
    per_period = check_int(
        "renormalizations_per_period", renormalizations_per_period, lo=1, hi=MAX_SAMPLES_PER_PERIOD
    )
    cfg = SolverSettings.build(
        LYAPUNOV_SETTINGS if settings is None else settings, **solver
    ).replace(samples_per_period=per_period)
    n = system.n_state
    k = n if n_exponents is None else check_int("n_exponents", n_exponents, lo=1, hi=n)
    if cfg.n_samples < 2:
        raise ParameterError("periods × renormalizations_per_period must be >= 2")
    traj = integrate(system, cfg, y0=y0, n_tangent=k)
    ns = cfg.n_samples
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
