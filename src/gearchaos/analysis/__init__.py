"""Analyses of recorded simulation results: pure functions of the recorded arrays, for any
:class:`~gearchaos.System`.

:mod:`.poincare` (section points, distinct-point count), :mod:`.periodicity` (period-n),
:mod:`.chaos01` (0–1 test), :mod:`.spectral` (broadband spectra), :mod:`.recurrence`,
:mod:`.motion` (the :class:`Motion` value a label names), :mod:`.classify` (motion labels
from a record), :mod:`.contact` (contact regimes per mesh) and
:mod:`.summary` (a JSON-serialisable summary of one simulation). What drives the integrator —
Lyapunov exponents, periodic orbits, continuation and its events, branch files, attractors and
the motion verdict — is in :mod:`gearchaos.dynamics`; the linear modal analysis of a gear set
is in :mod:`gearchaos.model.modal`.
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
from .motion import Motion, MotionKind
from .periodicity import detect_period, period_label
from .poincare import count_distinct, section_points
from .summary import format_exponent, summarize

__all__ = [
    "Motion",
    "MotionClass",
    "MotionKind",
    "chaos01",
    "classify_motion",
    "classify_sections",
    "contact_fractions",
    "contact_regime",
    "contact_regimes",
    "count_distinct",
    "detect_period",
    "format_exponent",
    "period_label",
    "regime_table",
    "section_points",
    "separation_fraction",
    "sort_labels",
    "spectral_broadband",
    "summarize",
]
