"""Compiled Dormand–Prince 5(4) integration of any :class:`~gearchaos.model.System`."""

from .batch import BatchResult, integrate_batch
from .dopri import dopri_batch, dopri_run
from .result import SimulationResult, open_simulation
from .simulate import integrate, simulate
from .tableau import DOPRI5, ButcherTableau
from .trajectory import Trajectory

__all__ = [
    "DOPRI5",
    "BatchResult",
    "ButcherTableau",
    "SimulationResult",
    "Trajectory",
    "dopri_batch",
    "dopri_run",
    "integrate",
    "integrate_batch",
    "open_simulation",
    "simulate",
]
