"""Analyses of simulation results; they work on any :class:`~gearchaos.System`.

:mod:`.poincare` (section points, distinct-point count), :mod:`.contact` (contact regimes per
mesh), :mod:`.summary` (a JSON-serialisable summary of one simulation) and, for gear sets,
:mod:`.modal` (linear natural frequencies).
"""

from .contact import contact_fractions, contact_regime, contact_regimes, separation_fraction
from .poincare import count_distinct, section_points
from .summary import format_summary, summarize

__all__ = [
    "contact_fractions",
    "contact_regime",
    "contact_regimes",
    "count_distinct",
    "format_summary",
    "section_points",
    "separation_fraction",
    "summarize",
]

try:  # the modal analysis lands separately; keep this package importable without it
    from .modal import modes_table, natural_frequencies
except ImportError:  # pragma: no cover - depends on the checkout
    pass
else:
    __all__ += ["modes_table", "natural_frequencies"]
