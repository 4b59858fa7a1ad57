"""What drives the integrator to decide a question about the motion.

:mod:`.lyapunov` (exponents from the variational equations), :mod:`.orbits` (periodic orbits
by shooting, Floquet multipliers; :mod:`.shooting` the map evaluations and the Newton
corrector, :mod:`.orbit_batch` many orbits in one Newton iteration, :mod:`.orbit_file` orbit
files), :mod:`.arclength` (pseudo-arclength continuation of branches; :mod:`.branch_events`
their folds, period doublings, Neimark–Sacker and grazing events, located by
:mod:`.branch_locate`; :mod:`.branch` their datasets and files; :mod:`.boundary`
two-parameter boundary curves of their events (:mod:`.curves` the method,
:mod:`.curve_tests` test functions and codimension-2 points, :mod:`.curve_file` curve files).

:mod:`.verdict` — the one motion verdict (nT confirmed by shooting and Floquet multipliers,
chaos and quasi-periodicity by a Lyapunov exponent with its error, transients finished by
extending the run) used by ``simulate``, sweeps, ``classify``, galleries, ``attractors``, the
explorer, ``response`` and the reproduction report; :mod:`.point` (one operating point end
to end) and :mod:`.coexistence` (coexisting attractors from several starts) use it.
"""

from .arclength import continuation
from .boundary import boundary_curve
from .branch import branch_multipliers, branch_summary, open_branch, save_branch
from .branch_events import Event, events
from .coexistence import Attractor, attractors
from .curve_file import open_curve
from .evidence import EVIDENCE, Verdict
from .lyapunov import LyapunovResult, lyapunov_spectrum, max_lyapunov
from .orbit_batch import periodic_orbits
from .orbits import PeriodicOrbit, periodic_orbit
from .point import PointAnalysis, analyse_point
from .verdict import VerdictSettings, decide_motion

__all__ = [
    "EVIDENCE",
    "Attractor",
    "Event",
    "LyapunovResult",
    "PeriodicOrbit",
    "PointAnalysis",
    "Verdict",
    "VerdictSettings",
    "analyse_point",
    "attractors",
    "boundary_curve",
    "branch_multipliers",
    "branch_summary",
    "continuation",
    "decide_motion",
    "events",
    "lyapunov_spectrum",
    "max_lyapunov",
    "open_branch",
    "open_curve",
    "periodic_orbit",
    "periodic_orbits",
    "save_branch",
]
