"""What drives the integrator to decide a question about the motion.

:mod:`.verdict` — the one motion verdict (nT confirmed by shooting and Floquet multipliers,
chaos and quasi-periodicity by a Lyapunov exponent with its error, transients finished by
extending the run) used by ``simulate``, sweeps, ``classify``, galleries, ``attractors``, the
explorer, ``response`` and the reproduction report; :mod:`.point` (one operating point end
to end) and :mod:`.coexistence` (coexisting attractors from several starts) use it.
"""

from .coexistence import Attractor, attractors
from .evidence import EVIDENCE, Verdict
from .point import PointAnalysis, analyse_point
from .verdict import VerdictSettings, decide_motion

__all__ = [
    "EVIDENCE",
    "Attractor",
    "PointAnalysis",
    "Verdict",
    "VerdictSettings",
    "analyse_point",
    "attractors",
    "decide_motion",
]
