"""Analyses of simulation results; they work on any :class:`~gearchaos.System`.

:mod:`.poincare` (section points, distinct-point count), :mod:`.periodicity` (period-n),
:mod:`.lyapunov` (exponents from the variational equations), :mod:`.chaos01` (0–1 test),
:mod:`.classify` (motion labels), :mod:`.contact` (contact regimes per mesh), :mod:`.summary`
(a JSON-serialisable summary of one simulation) and, for gear sets, :mod:`.modal` (linear
natural frequencies).
"""

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
from .periodicity import detect_period, period_label
from .poincare import count_distinct, section_points
from .point import PointAnalysis, analyse_point
from .summary import format_summary, summarize

__all__ = [
    "LyapunovResult",
    "MotionClass",
    "PointAnalysis",
    "analyse_point",
    "chaos01",
    "classify_motion",
    "classify_sections",
    "contact_fractions",
    "contact_regime",
    "contact_regimes",
    "count_distinct",
    "detect_period",
    "format_summary",
    "lyapunov_spectrum",
    "max_lyapunov",
    "period_label",
    "regime_table",
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
