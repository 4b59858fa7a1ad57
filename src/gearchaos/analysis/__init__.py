"""Analyses of simulation results; they work on any :class:`~gearchaos.System`.

:mod:`.poincare` (section points, distinct-point count), :mod:`.periodicity` (period-n),
:mod:`.lyapunov` (exponents from the variational equations), :mod:`.chaos01` (0–1 test),
:mod:`.classify` (motion labels), :mod:`.contact` (contact regimes per mesh), :mod:`.summary`
(a JSON-serialisable summary of one simulation), :mod:`.orbits` (periodic orbits by shooting,
Floquet multipliers; :mod:`.shooting` holds the map evaluations and the Newton corrector,
:mod:`.orbit_batch` many orbits in one Newton iteration),
:mod:`.arclength` (pseudo-arclength continuation of branches, :mod:`.branch_events` their folds,
period doublings, Neimark–Sacker and grazing events, :mod:`.branch` their datasets and files)
and, for gear sets, :mod:`.modal` (linear natural frequencies).
"""

from .arclength import continuation
from .branch import branch_multipliers, branch_summary, open_branch, save_branch
from .branch_events import Event, events
from .chaos01 import chaos01
from .classify import (
    MotionClass,
    classify_motion,
    classify_sections,
    regime_table,
    sort_labels,
    spectral_broadband,
)
from .contact import contact_fractions, contact_regime, contact_regimes, separation_fraction
from .lyapunov import LyapunovResult, lyapunov_spectrum, max_lyapunov
from .orbit_batch import periodic_orbits
from .orbits import PeriodicOrbit, periodic_orbit
from .periodicity import detect_period, period_label
from .poincare import count_distinct, section_points
from .summary import format_summary, summarize

__all__ = [
    "Event",
    "LyapunovResult",
    "MotionClass",
    "PeriodicOrbit",
    "branch_multipliers",
    "branch_summary",
    "chaos01",
    "classify_motion",
    "classify_sections",
    "contact_fractions",
    "contact_regime",
    "contact_regimes",
    "continuation",
    "count_distinct",
    "detect_period",
    "events",
    "format_summary",
    "lyapunov_spectrum",
    "max_lyapunov",
    "open_branch",
    "period_label",
    "periodic_orbit",
    "periodic_orbits",
    "regime_table",
    "save_branch",
    "section_points",
    "separation_fraction",
    "sort_labels",
    "spectral_broadband",
    "summarize",
]

try:  # the modal analysis lands separately; keep this package importable without it
    from .modal import modes_table, natural_frequencies
except ImportError:  # pragma: no cover - depends on the checkout
    pass
else:
    __all__ += ["modes_table", "natural_frequencies"]
