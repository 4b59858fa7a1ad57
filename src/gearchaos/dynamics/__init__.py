"""What drives the integrator to decide a question about the motion, by concept.

:mod:`.lyapunov` (exponents from the variational equations); :mod:`.orbits` (periodic orbits by
shooting, Floquet multipliers, many orbits at once, orbit files); :mod:`.continuation`
(pseudo-arclength continuation of branches, their events, cascades and branch files);
:mod:`.curves` (two-parameter boundary curves of those events); :mod:`.verdict` (the one motion
verdict — nT confirmed by shooting and Floquet multipliers, chaos and quasi-periodicity by a
Lyapunov exponent with its error, transients finished by extending the run — used by
``simulate``, sweeps, ``classify``, galleries, ``attractors``, the explorer, ``response`` and the
reproduction report, and one operating point end to end); :mod:`.attractors` (coexisting
attractors from several starts, and basins).

The front doors :func:`gearchaos.continuation` and :func:`gearchaos.attractors` are the
package's (``gearchaos.dynamics.continuation`` and ``gearchaos.dynamics.attractors`` are the
subpackages that define them).

The subpackages depend on each other in one direction: ``lyapunov → orbits → continuation →
curves`` and ``orbits → verdict → attractors``.
"""

from .attractors.coexistence import Attractor
from .continuation.branch import branch_multipliers, branch_summary, open_branch, save_branch
from .continuation.events import Event, events
from .curves.boundary import boundary_curve
from .curves.file import open_curve
from .lyapunov import LyapunovResult, lyapunov_spectrum, max_lyapunov
from .orbits.batch import periodic_orbits
from .orbits.orbit import PeriodicOrbit, periodic_orbit
from .verdict.decide import decide_motion
from .verdict.evidence import EVIDENCE, Verdict
from .verdict.point import PointAnalysis, analyse_point
from .verdict.settings import VerdictSettings

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
    "boundary_curve",
    "branch_multipliers",
    "branch_summary",
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
