"""Front door for single simulations: :func:`integrate` (any system) and :func:`simulate`.

``simulate(gearset_or_system, omega=..., transient_periods=100, periods=200, ...)`` runs the
seed's protocol (MODEL.md §8): zero initial state, Dormand–Prince 5(4), the first
``transient_periods`` forcing periods discarded, then one Poincaré sample per forcing period at
τ_k = (2πk + φ)/Ω, optionally with ``samples_per_period`` samples per period for time histories.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from .._numba import call_literal
from ..errors import IntegrationError, ParameterError, Status
from ..model.system import System
from .dopri import dopri_run
from .result import SimulationResult
from .trajectory import Trajectory

__all__ = ["Trajectory", "integrate", "simulate"]


def _default_max_steps(total_periods: float) -> int:
    return int(100_000 + 50_000 * max(total_periods, 1.0))


def check_settings(
    *,
    transient_periods: float,
    periods: int,
    samples_per_period: int,
    rtol: float,
    atol: float,
    section_phase: float = 0.0,
) -> None:
    """Validate solver settings; raise :class:`ParameterError` naming the setting and the rule."""
    if not (isinstance(periods, int | np.integer) and periods >= 1):
        raise ParameterError(f"periods must be an integer >= 1: got {periods!r}")
    if not (isinstance(samples_per_period, int | np.integer) and samples_per_period >= 1):
        raise ParameterError(
            f"samples_per_period must be an integer >= 1: got {samples_per_period!r}"
        )
    tp = float(transient_periods)
    if not math.isfinite(tp) or tp < 0:
        raise ParameterError(f"transient_periods must be >= 0: got {transient_periods!r}")
    for name, v in (("rtol", rtol), ("atol", atol)):
        if not (math.isfinite(v) and v > 0):
            raise ParameterError(f"{name} must be a finite number > 0: got {v!r}")
    if rtol < 1e-14:
        raise ParameterError(f"rtol must be >= 1e-14 (floating-point resolution): got {rtol!r}")
    if not math.isfinite(section_phase):
        raise ParameterError(f"section_phase must be finite: got {section_phase!r}")


def integrate(
    system: System,
    *,
    y0: np.ndarray | None = None,
    t0: float = 0.0,
    transient_periods: float = 100,
    periods: int = 200,
    samples_per_period: int = 1,
    section_phase: float = 0.0,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    max_steps: int | None = None,
    max_step: float = math.inf,
    first_step: float | None = None,
    n_tangent: int = 0,
) -> Trajectory:
    """Integrate any :class:`System` with the compiled Dormand–Prince 5(4) kernel.

    Samples land exactly on τ = t0 + (2π(k + transient_periods) + section_phase)/Ω + j T/s for
    k = 0 … periods−1 and j = 0 … s−1 (s = ``samples_per_period``). Never raises on solver
    failure: check :attr:`Trajectory.status`.

    With ``n_tangent = k > 0`` the variational equations of k tangent vectors ride along
    (orthonormal from the first sample, re-orthonormalised at every later one) and
    :attr:`Trajectory.tangent_log_sums` holds their accumulated log stretch factors — the raw
    material of :func:`gearchaos.analysis.lyapunov.lyapunov_spectrum`.
    """
    check_settings(
        transient_periods=transient_periods,
        periods=periods,
        samples_per_period=samples_per_period,
        rtol=rtol,
        atol=atol,
        section_phase=section_phase,
    )
    n = system.n_state
    if y0 is None:
        y = np.zeros(n)
    else:
        y = np.array(y0, dtype=np.float64).reshape(-1)
        if y.size != n:
            raise ParameterError(
                f"y0 must have {n} entries ({', '.join(system.state_names)}): got {y.size}"
            )
        if not np.all(np.isfinite(y)):
            raise ParameterError(f"y0 must be finite: got {y!r}")
    T = system.period
    t_rec = t0 + transient_periods * T + section_phase / system.omega
    ns = periods * samples_per_period
    dt = T / samples_per_period
    t_end = t_rec + periods * T
    if max_steps is None:
        max_steps = _default_max_steps(transient_periods + periods)
    k = int(n_tangent)
    if not 0 <= k <= n:
        raise ParameterError(f"n_tangent must be between 0 and {n}: got {n_tangent!r}")
    y_full = np.concatenate([y, np.zeros(n * k)])
    # unreached samples stay NaN, never zeros that look like data
    out_t = np.full(ns, np.nan)
    out_y = np.full((ns, y_full.size), np.nan)
    out_o = np.full((ns, system.n_obs), np.nan)
    omin = np.zeros(system.n_track)
    omax = np.zeros(system.n_track)
    yf = np.zeros(y_full.size)
    info = np.zeros(4)
    lsum = np.zeros(k)
    code = call_literal(
        dopri_run,
        system.kind,
        y_full,
        system.params,
        float(t0),
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
        -1.0 if first_step is None else float(first_step),
        float(max_step),
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
    status = Status(int(code))
    settings = {
        "transient_periods": transient_periods,
        "periods": periods,
        "samples_per_period": samples_per_period,
        "section_phase": section_phase,
        "rtol": rtol,
        "atol": atol,
        "t0": t0,
        "max_steps": max_steps,
        "y0": None if y0 is None else y.copy(),
    }
    return Trajectory(
        system=system,
        tau=out_t,
        states=out_y[:, :n],
        observables=out_o,
        obs_min=omin,
        obs_max=omax,
        final_state=yf[:n],
        status=status,
        steps_accepted=int(info[0]),
        steps_rejected=int(info[1]),
        settings=settings,
        next_step=float(info[3]),
        tangent_log_sums=lsum,
    )


def simulate(
    system_or_gearset: Any,
    *,
    omega: float | None = None,
    transient_periods: float = 100,
    periods: int = 200,
    samples_per_period: int = 1,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    y0: np.ndarray | None = None,
    section_phase: float = 0.0,
    max_steps: int | None = None,
    check: bool = True,
) -> SimulationResult:
    """Simulate a gear set (or any :class:`System`) with the seed's protocol.

    Parameters
    ----------
    system_or_gearset
        A :class:`~gearchaos.gearset.GearSet` (then ``omega`` is required) or a
        :class:`~gearchaos.model.System` (``omega``, if given, replaces its Ω).
    omega
        Dimensionless mesh frequency Ω = ω/ω_n.
    transient_periods, periods
        Forcing periods discarded, then recorded (one Poincaré point each).
    samples_per_period
        Samples per period for time histories, phase portraits and spectra.
    rtol, atol
        Error tolerances of the Dormand–Prince 5(4) controller.
    y0
        Initial state (default: zero, MODEL.md §6).
    section_phase
        Phase φ of the Poincaré section, τ_k = (2πk + φ)/Ω.
    check
        Raise :class:`~gearchaos.errors.IntegrationError` (carrying ``.result``) when the
        integration fails; with ``check=False`` inspect ``result.status`` instead.

    Returns
    -------
    SimulationResult
        Samples, extrema, status and step statistics; ``.to_dataset()`` gives an
        :class:`xarray.Dataset` with units and the full gear set in its attributes.
    """
    from ..gearset import GearSet
    from ..model.planetary import planetary_system

    if isinstance(system_or_gearset, GearSet):
        if omega is None:
            raise ParameterError("omega is required when simulating a gear set: got None")
        system = planetary_system(system_or_gearset, omega)
        gs: GearSet | None = system_or_gearset
    elif isinstance(system_or_gearset, System):
        system = system_or_gearset if omega is None else system_or_gearset.at(omega)
        gs = getattr(system.model, "gearset", None)
    else:
        raise ParameterError(
            "system_or_gearset must be a GearSet or a System: "
            f"got {type(system_or_gearset).__name__}"
        )
    if gs is not None and gs.has_eccentricity:
        from ..gearset.validation import warn_if_eccentric

        warn_if_eccentric(gs, "Poincaré section")
    traj = integrate(
        system,
        y0=y0,
        transient_periods=transient_periods,
        periods=periods,
        samples_per_period=samples_per_period,
        section_phase=section_phase,
        rtol=rtol,
        atol=atol,
        max_steps=max_steps,
    )
    result = SimulationResult.from_trajectory(traj)
    if check and not traj.ok:
        reached = float(np.nanmax(traj.tau, initial=0.0))
        err = IntegrationError(
            f"simulation at omega={system.omega:g} stopped after tau={reached:.6g}: "
            f"{traj.status.name}: {traj.status.message}"
        )
        err.result = result  # type: ignore[attr-defined]
        raise err
    if not traj.ok:
        warnings.warn(f"{traj.status.name}: {traj.status.message}", RuntimeWarning, stacklevel=2)
    return result
