"""Many independent integrations in one compiled, thread-parallel call.

:func:`integrate_batch` runs a list of systems of the same kind and layout (e.g. one model at
many Ω, or many gear sets with the same number of planets) with ``numba.prange`` over the
points. Each point runs exactly the same code as :func:`~gearchaos.integrate.integrate`, so a
point's result is bitwise identical whether it runs alone, in a batch, or on any number of
threads. Sweeps (issue 3) call this on chunks of their grid.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._numba import call_literal
from ..errors import ParameterError, Status
from ..model.system import System
from .dopri import dopri_batch
from .simulate import _default_max_steps, check_settings

__all__ = ["BatchResult", "integrate_batch"]


@dataclass(frozen=True, eq=False)
class BatchResult:
    """Outputs of :func:`integrate_batch`, point index first.

    ``tau`` (m, s), ``states`` (m, s, n_state), ``observables`` (m, s, n_obs),
    ``obs_min``/``obs_max`` (m, n_track), ``final_state`` (m, n_state), ``status`` (m,) int codes
    (:class:`~gearchaos.errors.Status`), ``steps_accepted``/``steps_rejected`` (m,).
    """

    systems: tuple[System, ...]
    tau: np.ndarray
    states: np.ndarray
    observables: np.ndarray
    obs_min: np.ndarray
    obs_max: np.ndarray
    final_state: np.ndarray
    status: np.ndarray
    steps_accepted: np.ndarray
    steps_rejected: np.ndarray
    samples_per_period: int

    def __len__(self) -> int:
        return len(self.systems)

    def statuses(self) -> list[Status]:
        return [Status(int(s)) for s in self.status]

    @property
    def section_index(self) -> np.ndarray:
        return np.arange(0, self.tau.shape[1], self.samples_per_period)


def integrate_batch(
    systems: Sequence[System],
    *,
    y0: np.ndarray | None = None,
    transient_periods: float = 100,
    periods: int = 200,
    samples_per_period: int = 1,
    section_phase: float = 0.0,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    max_steps: int | None = None,
    max_step: float = math.inf,
) -> BatchResult:
    """Integrate many systems of one kind in parallel (``numba.prange`` over points).

    Parameters are those of :func:`~gearchaos.integrate.integrate`; ``y0`` is ``None`` (zero
    start everywhere) or an array (m, n_state) of initial states. Never raises on solver
    failure: each point carries its own status.
    """
    check_settings(
        transient_periods=transient_periods,
        periods=periods,
        samples_per_period=samples_per_period,
        rtol=rtol,
        atol=atol,
        section_phase=section_phase,
    )
    systems = tuple(systems)
    if not systems:
        raise ParameterError("systems must contain at least one System: got none")
    first = systems[0]
    for i, s in enumerate(systems):
        if s.kind != first.kind or s.params.shape != first.params.shape:
            raise ParameterError(
                "all systems of a batch must share kind and parameter layout: "
                f"system {i} ({s.name}, {s.params.size} parameters) differs from system 0 "
                f"({first.name}, {first.params.size} parameters)"
            )
    m, n = len(systems), first.n_state
    P = np.ascontiguousarray(np.stack([s.params for s in systems]))
    if y0 is None:
        Y0 = np.zeros((m, n))
    else:
        Y0 = np.array(y0, dtype=np.float64)
        if Y0.shape != (m, n):
            raise ParameterError(f"y0 must have shape ({m}, {n}): got {Y0.shape}")
        if not np.all(np.isfinite(Y0)):
            raise ParameterError("y0 must be finite: got NaN or inf")
    SW = np.ascontiguousarray(np.stack([s.switch_widths for s in systems]))
    periods_T = np.array([s.period for s in systems])
    omegas = np.array([s.omega for s in systems])
    t0 = np.zeros(m)
    t_rec = transient_periods * periods_T + section_phase / omegas
    dt = periods_T / samples_per_period
    t_end = t_rec + periods * periods_T
    ns = periods * samples_per_period
    if max_steps is None:
        max_steps = _default_max_steps(transient_periods + periods)
    out_t = np.full((m, ns), np.nan)
    out_y = np.full((m, ns, n), np.nan)
    out_o = np.full((m, ns, first.n_obs), np.nan)
    omin = np.zeros((m, first.n_track))
    omax = np.zeros((m, first.n_track))
    yf = np.zeros((m, n))
    info = np.zeros((m, 4))
    status = np.zeros(m, dtype=np.int64)
    call_literal(
        dopri_batch,
        first.kind,
        Y0,
        P,
        t0,
        t_rec,
        dt,
        ns,
        t_end,
        first.n_obs,
        first.n_track,
        SW,
        float(rtol),
        float(atol),
        float(max_step),
        int(max_steps),
        out_t,
        out_y,
        out_o,
        omin,
        omax,
        yf,
        info,
        status,
    )
    return BatchResult(
        systems=systems,
        tau=out_t,
        states=out_y,
        observables=out_o,
        obs_min=omin,
        obs_max=omax,
        final_state=yf,
        status=status,
        steps_accepted=info[:, 0].astype(np.int64),
        steps_rejected=info[:, 1].astype(np.int64),
        samples_per_period=samples_per_period,
    )
