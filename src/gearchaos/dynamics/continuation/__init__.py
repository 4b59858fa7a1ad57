"""One-parameter continuation of periodic orbits.

:mod:`.arclength` (pseudo-arclength continuation in any parameter), :mod:`.events` (folds,
period doublings, Neimark–Sacker and grazing events), :mod:`.locate` (finding and locating them
between two points), :mod:`.cascade` (the period-2ⁿ branches of a cascade) and :mod:`.branch`
(branch datasets and their files). The event list of a branch is
:func:`gearchaos.dynamics.continuation.events.events` (``gearchaos.dynamics.events``).
"""

from .arclength import continuation
from .branch import branch_multipliers, branch_summary, open_branch, save_branch
from .events import Event

__all__ = [
    "Event",
    "branch_multipliers",
    "branch_summary",
    "continuation",
    "open_branch",
    "save_branch",
]
