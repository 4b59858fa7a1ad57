"""Sweeps: bifurcation diagrams and 2-D maps over any parameter, resumable, on any executor."""

from .classify import classify_dataset, classify_store
from .contact import ContactRange, contact_ranges
from .execute import Execution
from .frequency import find_jumps, response
from .result import SweepLayout, SweepResult
from .run import bifurcation, run_sweep
from .spec import Axis, SweepSpec, parse_axis, parse_values
from .store import SweepStore, open_sweep

__all__ = [
    "Axis",
    "ContactRange",
    "Execution",
    "SweepLayout",
    "SweepResult",
    "SweepSpec",
    "SweepStore",
    "bifurcation",
    "classify_dataset",
    "classify_store",
    "contact_ranges",
    "find_jumps",
    "open_sweep",
    "parse_axis",
    "parse_values",
    "response",
    "run_sweep",
]
