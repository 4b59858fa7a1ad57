"""Sweeps: bifurcation diagrams and 2-D maps over any parameter, resumable, on any executor."""

from .classify import classify_dataset, classify_store
from .execute import Execution
from .result import SweepLayout, SweepResult
from .run import bifurcation, run_sweep
from .spec import Axis, SweepSpec, parse_axis, parse_values
from .store import SweepStore, open_sweep

__all__ = [
    "Axis",
    "Execution",
    "SweepLayout",
    "SweepResult",
    "SweepSpec",
    "SweepStore",
    "bifurcation",
    "classify_dataset",
    "classify_store",
    "open_sweep",
    "parse_axis",
    "parse_values",
    "run_sweep",
]
