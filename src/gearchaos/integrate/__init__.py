"""Compiled Dormand–Prince 5(4) integration of any :class:`~gearchaos.model.System`.

:class:`SolverSettings` configures every run; :func:`run_chains` is the one caller of the
compiled kernel; :func:`integrate` (any system), :func:`integrate_batch` and :func:`simulate`
(gear sets and systems, the seed's protocol) are the front doors.
"""

from ._chains import ChainOutput, ChainRun, run_chains
from .batch import BatchResult, integrate_batch
from .result import SimulationResult, open_simulation
from .settings import SampleTimes, SolverSettings
from .simulate import integrate, simulate
from .tableau import DOPRI5, ButcherTableau
from .trajectory import Trajectory

__all__ = [
    "DOPRI5",
    "BatchResult",
    "ButcherTableau",
    "ChainOutput",
    "ChainRun",
    "SampleTimes",
    "SimulationResult",
    "SolverSettings",
    "Trajectory",
    "integrate",
    "integrate_batch",
    "open_simulation",
    "run_chains",
    "simulate",
]
