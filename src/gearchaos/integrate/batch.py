"""Many independent integrations in one compiled, thread-parallel call.

:func:`integrate_batch` runs a list of systems of the same kind and layout (e.g. one model at
many Ω, or many gear sets with the same number of planets) as chains of length one, with
a pool of threads over the points. Each point runs exactly the same code as
:func:`~gearchaos.integrate.integrate`, so a point's result is bitwise identical whether it runs
alone, in a batch, or on any number of threads.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._checks import check_real
from ..errors import ParameterError, Status
from ..model.response import compressive_contact_forces
from ..model.system import System
from ._chains import ChainRun, SampleArrays, run_chains
from .interface import Info
from .settings import SolverSettings

__all__ = ["BatchResult", "integrate_batch"]


@dataclass(frozen=True, eq=False)
class BatchResult(SampleArrays):
    """Outputs of :func:`integrate_batch`, point index first.

    The :class:`~gearchaos.integrate._chains.SampleArrays` with shapes ``tau`` (m, s),
    ``states`` (m, s, n_state), ``observables`` (m, s, n_obs), ``obs_min``/``obs_max``
    (m, n_track), ``final_state`` (m, n_state); then the ``systems``, ``status`` (m,) int codes
    (:class:`~gearchaos.errors.Status`), ``steps_accepted``/``steps_rejected``/``steps_switch``
    (m,) as in :class:`~gearchaos.integrate.Trajectory`.
    """

    systems: tuple[System, ...]
    status: np.ndarray
    steps_accepted: np.ndarray
    steps_rejected: np.ndarray
    steps_switch: np.ndarray
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
    settings: SolverSettings | None = None,
    *,
    y0: np.ndarray | None = None,
    max_step: float = np.inf,
    **solver: Any,
) -> BatchResult:
    """Integrate many systems of one kind in parallel (threads over the points).

    ``settings`` and ``**solver`` are those of :func:`~gearchaos.integrate.integrate`; ``y0`` is
    ``None`` (zero start everywhere) or an array (m, n_state) of initial states. Never raises on
    solver failure: each point carries its own status.
    """
    cfg = SolverSettings.build(settings, **solver)
    if isinstance(systems, System) or not isinstance(systems, Sequence):
        raise ParameterError(
            f"systems must be a sequence of Systems (a list): got {type(systems).__name__}"
        )
    systems = tuple(systems)
    if not systems:
        raise ParameterError("systems must contain at least one System: got none")
    for i, s in enumerate(systems):
        if not isinstance(s, System):
            raise ParameterError(f"systems[{i}] must be a System: got {type(s).__name__}")
    m, n = len(systems), systems[0].n_state
    if not (isinstance(max_step, float) and max_step == np.inf):  # inf: no limit
        check_real("max_step", max_step, lo=0.0, lo_open=True)
    if y0 is not None:
        try:
            y0 = np.array(y0, dtype=np.float64)
        except (TypeError, ValueError):
            raise ParameterError(
                f"y0 must be an array of shape ({m}, {n}): got {type(y0).__name__}"
            ) from None
        if y0.shape != (m, n):
            raise ParameterError(f"y0 must have shape ({m}, {n}): got {y0.shape}")
        if not np.all(np.isfinite(y0)):
            raise ParameterError("y0 must be finite: got NaN or inf")
    cfg.check_memory(n + systems[0].n_obs + 1, points=m)
    run = ChainRun.from_systems([[s] for s in systems], cfg, y0=y0, max_step=max_step)
    out = run_chains(run)
    # contact forces as the flanks carry them, each point with its own clearances (as simulate)
    observables = np.array(out.observables[:, 0], dtype=np.float64)
    obs_min = np.array(out.obs_min[:, 0], dtype=np.float64)
    obs_max = np.array(out.obs_max[:, 0], dtype=np.float64)
    for i, system in enumerate(systems):
        observables[i], obs_min[i], obs_max[i] = compressive_contact_forces(
            system, observables[i], obs_min[i], obs_max[i]
        )
    return BatchResult(
        systems=systems,
        tau=out.tau[:, 0],
        states=out.states[:, 0],
        observables=observables,
        obs_min=obs_min,
        obs_max=obs_max,
        final_state=out.final_state[:, 0],
        status=out.status[:, 0],
        steps_accepted=out.info[:, 0, Info.ACCEPTED].astype(np.int64),
        steps_rejected=out.info[:, 0, Info.REJECTED].astype(np.int64),
        steps_switch=out.info[:, 0, Info.SWITCH_RETRIES].astype(np.int64),
        samples_per_period=cfg.samples_per_period,
    )
