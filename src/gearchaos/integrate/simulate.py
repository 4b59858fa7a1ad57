"""Front doors for single simulations: :func:`integrate` (any system) and :func:`simulate`.

``simulate(gearset_or_system, omega=..., transient_periods=100, periods=200, ...)`` runs the
seed's protocol (MODEL.md §8): zero initial state, Dormand–Prince 5(4), the first
``transient_periods`` forcing periods discarded, then one Poincaré sample per forcing period at
τ_k = (2πk + φ)/Ω, optionally with ``samples_per_period`` samples per period for time histories.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np

from .._checks import check_bool, check_int, check_real
from ..errors import IntegrationError, ParameterError
from ..model.response import compressive_contact_forces
from ..model.system import System
from ..model.target import resolve
from ._chains import ChainRun, run_chains
from .interface import Info
from .result import SimulationResult
from .settings import SIMULATION, SolverSettings, split_keywords
from .trajectory import Trajectory

__all__ = ["Trajectory", "integrate", "run_simulation", "simulate"]

_DEFAULT = SIMULATION


def _initial_state(system: System, y0: Any) -> np.ndarray | None:
    return None if y0 is None else system.check_state(y0, "y0")


def integrate(
    system: System,
    settings: SolverSettings | None = None,
    *,
    y0: Any = None,
    t0: float = 0.0,
    max_step: float = math.inf,
    first_step: float | None = None,
    n_tangent: int = 0,
    tangent_start: Any = None,
    **solver: Any,
) -> Trajectory:
    """Integrate any :class:`System` with the compiled Dormand–Prince 5(4) kernel.

    Samples land exactly on τ = t0 + (2π(k + transient_periods) + section_phase)/Ω + j T/s for
    k = 0 … periods−1 and j = 0 … s−1 (s = ``samples_per_period``). Never raises on solver
    failure: check :attr:`Trajectory.status`.

    Parameters
    ----------
    system
        Any :class:`~gearchaos.model.System`.
    settings, **solver
        A :class:`~gearchaos.integrate.settings.SolverSettings`, and/or its fields by name
        (``transient_periods``, ``periods``, ``samples_per_period``, ``section_phase``,
        ``rtol``, ``atol``, ``max_steps``), which override it.
    y0, t0
        Initial state (default zero) and time.
    max_step, first_step
        Largest step, and the first step to try (default: Hairer's estimate).
    n_tangent
        With ``k > 0`` the variational equations of k tangent vectors ride along (orthonormal
        from the first sample, re-orthonormalised at every later one) and
        :attr:`Trajectory.tangent_log_sums` holds their accumulated log stretch factors — the
        raw material of :func:`gearchaos.dynamics.lyapunov.lyapunov_spectrum`;
        :attr:`Trajectory.tangent_log_stretch` the first vector's log stretch per sample.
    tangent_start
        (k, n) start of the tangent vectors (orthonormalised at the first sample); default the
        first k basis vectors.
    """
    if not isinstance(system, System):
        raise ParameterError(f"system must be a System: got {type(system).__name__}")
    cfg = SolverSettings.build(settings, **solver)
    n = system.n_state
    y = _initial_state(system, y0)
    k = check_int("n_tangent", n_tangent, lo=0, hi=n)
    t_start = check_real("t0", t0)
    step_max = math.inf
    if not (isinstance(max_step, float) and max_step == math.inf):  # inf: no limit
        step_max = check_real("max_step", max_step, lo=0.0, lo_open=True)
    h0 = None if first_step is None else check_real("first_step", first_step, lo=0.0, lo_open=True)
    cfg.check_memory(n * (1 + k) + system.n_obs + 1)
    run = ChainRun.from_systems(
        [[system]],
        cfg,
        y0=y,
        t0=t_start,
        n_tangent=k,
        first_step=h0,
        max_step=step_max,
        tangent_start=None if k == 0 else tangent_start,
    )
    out = run_chains(run)
    # contact forces as the flanks carry them: no tension (model.response)
    observables, obs_min, obs_max = compressive_contact_forces(
        system, out.observables[0, 0], out.obs_min[0, 0], out.obs_max[0, 0]
    )
    return Trajectory(
        system=system,
        tau=out.tau[0, 0],
        states=out.states[0, 0, :, :n],
        observables=observables,
        obs_min=obs_min,
        obs_max=obs_max,
        final_state=out.final_state[0, 0, :n],
        status=out.statuses()[0],
        steps_accepted=int(out.info[0, 0, Info.ACCEPTED]),
        steps_rejected=int(out.info[0, 0, Info.REJECTED]),
        steps_switch=int(out.info[0, 0, Info.SWITCH_RETRIES]),
        solver=cfg,
        t0=t_start,
        y0=None if y is None else y.copy(),
        next_step=float(out.info[0, 0, Info.NEXT_STEP]),
        tau_reached=float(out.info[0, 0, Info.TAU_REACHED]),
        tangent_log_sums=out.log_sums[0, 0],
        tangent_log_stretch=out.stretch(n)[0, 0] if k else np.empty(0),
    )


def simulate(
    system_or_gearset: Any,
    *,
    settings: SolverSettings | None = None,
    params: Mapping[str, Any] | None = None,
    y0: Any = None,
    check: bool = True,
    **values_and_settings: Any,
) -> SimulationResult:
    """Simulate a gear set (or any :class:`System`) with the seed's protocol.

    Parameters
    ----------
    system_or_gearset
        A :class:`~gearchaos.gearset.GearSet` (then ``omega`` is required) or a
        :class:`~gearchaos.model.System` (``omega``, if given, replaces its Ω).
    settings
        A :class:`~gearchaos.integrate.settings.SolverSettings` (default
        :data:`~gearchaos.integrate.settings.SIMULATION`: 100 transient and 200 recorded
        periods, 64 samples per period); settings given by name override it.
    params
        Parameter values by dotted name (``{"backlash.sun_planet": 2.4}``).
    y0
        Initial state (default: rest, MODEL.md §6, perturbed by ``perturbation``).
    check
        Raise :class:`~gearchaos.errors.IntegrationError` (carrying ``.result``) when the
        integration fails; with ``check=False`` inspect ``result.status`` instead.
    **values_and_settings
        Parameters whose names are Python identifiers by name: ``omega``, the dimensionless
        mesh frequency Ω = ω/ω_n, ``xi`` …; and solver settings by name
        (:class:`~gearchaos.integrate.settings.SolverSettings`):

        ``transient_periods``, ``periods``
            Forcing periods discarded, then recorded (one Poincaré point each).
        ``samples_per_period``
            Samples per period for time histories, phase portraits and spectra.
        ``rtol``, ``atol``
            Error tolerances of the Dormand–Prince 5(4) controller.
        ``section_phase``
            Phase φ of the Poincaré section, τ_k = (2πk + φ)/Ω.
        ``max_steps``
            Step budget (default: 100 000 + 50 000 per simulated period).
        ``perturbation``
            Size of the reproducible perturbation of the start from rest (default 1e-6; 0:
            the exact zero state).
        ``settle``
            ``"auto"``: end the transient early once the section sequence repeats;
            ``"off"`` (default): the full transient.

        This is the vocabulary of every front door (``bifurcation``, ``response``,
        ``periodic_orbit``, ``continuation``, ``attractors``).

    Returns
    -------
    SimulationResult
        Samples, extrema, status and step statistics; ``.to_dataset()`` gives an
        :class:`xarray.Dataset` with units and the full gear set in its attributes.
    """
    values, cfg = split_keywords(
        values_and_settings, settings, params, _DEFAULT, door=simulate, target=system_or_gearset
    )
    raise_on_failure = check_bool("check", check)
    system = resolve(system_or_gearset, values)
    return run_simulation(system, cfg, y0=y0, check=raise_on_failure)


def run_simulation(
    system: System,
    settings: SolverSettings,
    *,
    y0: Any = None,
    t0: float = 0.0,
    check: bool = True,
) -> SimulationResult:
    """:func:`simulate` of a resolved system with given settings (the library's own door),
    from ``y0`` at τ = ``t0``."""
    system.warn_for("Poincaré section")
    traj = integrate(system, settings, y0=y0, t0=t0)
    result = SimulationResult.from_trajectory(traj)
    if check and not traj.ok:
        err = IntegrationError(
            f"simulation at omega={system.omega:g} stopped at tau={traj.tau_reached:.6g} "
            f"after {traj.steps_accepted + traj.steps_rejected + traj.steps_switch} step attempts: "
            f"{traj.status.name}: {traj.status.message}"
        )
        err.result = result  # type: ignore[attr-defined]
        raise err
    if not traj.ok:
        warnings.warn(f"{traj.status.name}: {traj.status.message}", RuntimeWarning, stacklevel=3)
    return result
