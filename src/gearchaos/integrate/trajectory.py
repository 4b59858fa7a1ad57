"""Raw result of one integration: :class:`Trajectory`."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import Status
from ..model.system import System
from ._chains import SampleArrays
from .settings import SolverSettings

__all__ = ["Trajectory"]


@dataclass(frozen=True, eq=False)
class Trajectory(SampleArrays):
    """Samples of one integration of a :class:`System`.

    Attributes
    ----------
    tau
        (m,) sample times; every ``samples_per_period``-th one is a Poincaré section time.
    states
        (m, n_state) states at ``tau``.
    observables
        (m, n_obs) observables (``system.obs_names``) at ``tau``.
    obs_min
        (n_track,) minima of the tracked observables over the recorded window.
    obs_max
        (n_track,) maxima of the tracked observables over the recorded window.
    final_state
        (n_state,) the state at the end.
    system
        The integrated system.
    status
        How the integration ended.
    solver
        The :class:`~gearchaos.integrate.settings.SolverSettings` of the run.
    t0
        Start time.
    y0
        Initial state (``None``: the zero state).
    tau_reached
        Where the integration stopped (the end time when it succeeded).
    steps_accepted, steps_rejected, steps_switch
        Steps accepted, step attempts rejected by the error test, and step attempts discarded
        to end the step on a contact switch (steps_rejected counted these before issue 25).
    """

    system: System
    status: Status
    steps_accepted: int
    steps_rejected: int
    steps_switch: int = 0
    solver: SolverSettings = field(default_factory=SolverSettings)
    t0: float = 0.0
    y0: np.ndarray | None = None
    next_step: float = 0.0
    tau_reached: float = float("nan")
    tangent_log_sums: np.ndarray = field(default_factory=lambda: np.empty(0))
    tangent_log_stretch: np.ndarray = field(default_factory=lambda: np.empty(0))
    #: Where a run that did not start from ``y0`` or rest comes from, in words (a motion
    #: verdict's record: the confirmed orbit, or the end of its extension); "" otherwise.
    origin: str = ""
    #: Periods by which a continuation of the run (the motion verdict's, to finish a
    #: transient) lengthened the transient beyond the protocol's ``solver.transient_periods``
    #: before this record; 0 for a record that follows the protocol's transient.
    extra_periods: int = 0

    @property
    def samples_per_period(self) -> int:
        return int(self.solver.samples_per_period)

    @property
    def section_index(self) -> np.ndarray:
        """Indices of the Poincaré section samples within ``tau``."""
        return np.arange(0, self.tau.size, self.samples_per_period)

    @property
    def section_tau(self) -> np.ndarray:
        return self.tau[self.section_index]

    def section(self, name: str) -> np.ndarray:
        """Section values of a state or observable, by name."""
        return self.series(name)[self.section_index]

    def series(self, name: str) -> np.ndarray:
        """All samples of a variable by name (:meth:`System.observable`): a state, an
        observable, or a per-planet group such as ``delta_sp`` (one column per planet)."""
        return self.system.observable(name).take(self.states, self.observables)

    def extrema(self, name: str) -> tuple[float, float]:
        """(min, max) of a tracked observable over the recorded window."""
        on = self.system.obs_names[: self.system.n_track]
        if name not in on:
            raise KeyError(f"{name!r} is not tracked; tracked: {on}")
        k = on.index(name)
        return float(self.obs_min[k]), float(self.obs_max[k])

    @property
    def ok(self) -> bool:
        return self.status is Status.OK
