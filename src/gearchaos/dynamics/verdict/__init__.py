"""The one motion verdict: what an attractor is, with its evidence.

:mod:`.decide` (:func:`decide_motion`: nT confirmed by shooting and Floquet multipliers, chaos
and quasi-periodicity by a Lyapunov exponent with its error, transients finished by extending
the run), :mod:`.settings` (its settings), :mod:`.periodic` (its periodic evidence),
:mod:`.rules` (its rules without a confirmed period), :mod:`.extension` (running on from
recorded states), :mod:`.evidence` (:class:`Verdict`) and :mod:`.point` (one operating point end
to end).
"""

from .decide import decide_motion
from .evidence import EVIDENCE, Verdict
from .point import PointAnalysis, analyse_point
from .settings import VerdictSettings

__all__ = [
    "EVIDENCE",
    "PointAnalysis",
    "Verdict",
    "VerdictSettings",
    "analyse_point",
    "decide_motion",
]
