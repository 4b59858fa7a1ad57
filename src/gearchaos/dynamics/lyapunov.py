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
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._checks import check_int
from ..analysis.summary import format_exponent
from ..errors import ParameterError, Status
from ..integrate.settings import MAX_SAMPLES_PER_PERIOD, SolverSettings, split_keywords
from ..integrate.simulate import integrate
from ..model.system import System
from ..model.target import Target, resolve

__all__ = [
    "LYAPUNOV_BLOCKS",
    "LyapunovResult",
    "exponent_estimate",
    "lyapunov_spectrum",
    "max_lyapunov",
    "random_tangents",
]

#: Blocks the record is cut into for the standard error of λ₁ (batch means).
LYAPUNOV_BLOCKS = 10
#: Seed of the default random initial tangent vectors.
TANGENT_SEED = 0


def random_tangents(n: int, k: int = 1, *, seed: int = TANGENT_SEED, points: int = 1) -> np.ndarray:
    """``points`` × k × n standard normal tangent vectors from ``default_rng(seed)`` (the
    kernel orthonormalises them at the first sample). A random start has a component along
    every Oseledets direction with probability one; a basis vector does not when the system
    has an invariant subspace (identical in-phase planets: the sun's x translation stays in
    the symmetry-breaking subspace, whose exponent it then reports)."""
    rng = np.random.default_rng(seed)
    return rng.standard_normal((int(points), int(k), int(n)))


def exponent_estimate(
    log_stretch: np.ndarray, dt: float, *, blocks: int = LYAPUNOV_BLOCKS
) -> tuple[float, float]:
    """λ₁ and its standard error from the log stretch factors of one tangent vector.

    Parameters
    ----------
    log_stretch
        ln‖v(τ_j)‖ / ‖v(τ_{j−1})‖ over consecutive renormalisation intervals of length ``dt``
        (NaN entries, such as the first sample's, are dropped).
    dt
        The renormalisation interval (T / renormalisations per period).
    blocks
        Number B of consecutive blocks (batch means).

    Returns
    -------
    (float, float)
        λ₁ = Σ ln stretch / (m·dt), and the standard error s_B/√B of the B block means λ_b
        (s_B their sample standard deviation): for a chaotic attractor the block means are
        nearly independent once a block is much longer than the correlation time, and the
        error falls like 1/√(record); for a regular attractor they scatter around zero by
        O(ln C / block length). NaN error with fewer than 2·B intervals.
    """
    x = np.asarray(log_stretch, dtype=np.float64)
    x = x[np.isfinite(x)]
    m = x.size
    if m == 0:
        return math.nan, math.nan
    lam = float(np.sum(x) / (m * dt))
    b = int(blocks)
    if m < 2 * b:
        return lam, math.nan
    size = m // b
    means = x[: size * b].reshape(b, size).sum(axis=1) / (size * dt)
    return lam, float(np.std(means, ddof=1) / math.sqrt(b))


@dataclass(frozen=True)
class LyapunovResult:
    """Exponents (descending as computed by Gram–Schmidt order), run length and status."""

    exponents: np.ndarray
    duration: float
    renormalizations: int
    status: Status
    steps_accepted: int
    steps_rejected: int
    largest_error: float = math.nan

    def __str__(self) -> str:
        return f"λ₁ = {format_exponent(self.largest, self.largest_error)}"

    @property
    def largest(self) -> float:
        return float(self.exponents[0])

    @property
    def sum(self) -> float:
        return float(np.sum(self.exponents))


#: Lyapunov runs average over more periods than a simulation records by default.
LYAPUNOV_SETTINGS = SolverSettings(periods=500)


def lyapunov_spectrum(
    system: Target,
    settings: SolverSettings | None = None,
    *,
    n_exponents: int | None = None,
    renormalizations_per_period: int = 1,
    y0: np.ndarray | None = None,
    seed: int | None = TANGENT_SEED,
    params: Mapping[str, Any] | None = None,
    **values_and_settings: Any,
) -> LyapunovResult:
    """The ``n_exponents`` largest Lyapunov exponents (all by default) of ``system``.

    Parameters
    ----------
    system
        A :class:`~gearchaos.gearset.GearSet` (with ``omega=``) or any
        :class:`~gearchaos.model.System`; its forcing period T = 2π/Ω sets the
        renormalisation interval T / ``renormalizations_per_period``.
    settings, params, **values_and_settings
        Parameter values by name, as for :func:`~gearchaos.dynamics.orbits.orbit.periodic_orbit`
        (``omega=1.7``, ``xi=0.05``; dotted names in ``params={"backlash.sun_planet": 2}``),
        and :class:`~gearchaos.integrate.settings.SolverSettings` (default: 100 transient
        periods, 500 periods averaged over) and/or its fields by name: ``transient_periods``,
        ``periods`` (the statistical error of a chaotic estimate decays like 1/√(periods); a
        regular orbit's like log(·)/periods), ``rtol`` and ``atol`` (of the state and of the
        normalised tangent vectors), ``max_steps``, ``perturbation`` (of the start from
        rest: the default takes even an equilibrium start, such as the origin of the Lorenz
        system, off the equilibrium).
    y0
        Initial state (default: the perturbed rest state of the settings).
    seed
        Seed of the random initial tangent vectors (:func:`random_tangents`), orthonormalised
        when the recording starts; None starts them as the first basis vectors (for
        comparison with a tangent map computed from the identity).

    Returns
    -------
    LyapunovResult
        The exponents, and ``largest_error``: the standard error of λ₁ from
        :data:`LYAPUNOV_BLOCKS` block means (:func:`exponent_estimate`).

    Warns
    -----
    RuntimeWarning
        When the state does not move over the recorded window (an equilibrium): the exponents
        are then those of the equilibrium, not of an attractor.
    """
    values, cfg = split_keywords(
        values_and_settings, settings, params, LYAPUNOV_SETTINGS, door=lyapunov_spectrum,
        target=system,
    )  # fmt: skip
    if not isinstance(system, Target):
        raise ParameterError(
            f"system must be a System or a GearSet (with omega=): got {type(system).__name__}"
        )
    if not isinstance(system, System) or values:
        system = resolve(system, values)
    per_period = check_int(
        "renormalizations_per_period", renormalizations_per_period, lo=1, hi=MAX_SAMPLES_PER_PERIOD
    )
    cfg = cfg.replace(samples_per_period=per_period)
    n = system.n_state
    k = n if n_exponents is None else check_int("n_exponents", n_exponents, lo=1, hi=n)
    if cfg.n_samples < 2:
        raise ParameterError("periods × renormalizations_per_period must be >= 2")
    traj = integrate(
        system,
        cfg,
        y0=y0,
        n_tangent=k,
        tangent_start=None if seed is None else random_tangents(n, k, seed=seed),
    )
    ns = cfg.n_samples
    dt = system.period / renormalizations_per_period
    duration = (ns - 1) * dt
    ex = traj.tangent_log_sums / duration if traj.ok else np.full(k, np.nan)
    err = math.nan
    if traj.ok:
        _, err = exponent_estimate(traj.tangent_log_stretch, dt)
        s = traj.states
        if float(np.max(np.ptp(s, axis=0))) <= 1e-12 * max(1.0, float(np.max(np.abs(s)))):
            warnings.warn(
                f"{system.name}: the state stays at {s[-1].tolist()!r} over the recorded "
                "window (an equilibrium): these are the exponents of that equilibrium; start "
                "elsewhere (y0, or perturbation > 0)",
                RuntimeWarning,
                stacklevel=2,
            )
    return LyapunovResult(
        exponents=ex,
        duration=duration,
        renormalizations=ns - 1,
        status=traj.status,
        steps_accepted=traj.steps_accepted,
        steps_rejected=traj.steps_rejected,
        largest_error=err,
    )


def max_lyapunov(system: Target, **kwargs: object) -> float:
    """Largest Lyapunov exponent (per unit τ) of a gear set at ``omega=`` or of any system;
    see :func:`lyapunov_spectrum` (``gc.max_lyapunov(gs, omega=1.7)``)."""
    return lyapunov_spectrum(system, n_exponents=1, **kwargs).largest  # type: ignore[arg-type]
