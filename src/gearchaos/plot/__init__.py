"""Plots of simulation results (matplotlib); they never simulate, they take results.

Every plotting function takes ``ax=None`` (a new figure when not given) and returns the Axes:
:func:`time_history`, :func:`phase_portrait`, :func:`poincare_map`, :func:`spectrum`,
:func:`sun_orbit`, and for sweeps :func:`bifurcation`, :func:`distinct_map`,
:func:`regime_band` and :func:`regime_map` (motion labels in the one palette
:data:`REGIME_COLOURS`). :func:`summary_figure` puts a simulation on one page,
:func:`poincare_gallery` several (Poincaré maps titled with value, motion and LLE),
:func:`bifurcation_figure` and :func:`sweep_figure` a sweep (one panel per family value),
:func:`contact_figure` the contact regime of every mesh along a 1-D sweep (rattle against speed);
:func:`figure_for` gives the figure of whatever was loaded (a result, a store, branch or
curve files, a basin store), as ``gearchaos plot`` and the explorer draw it;
:func:`savefig` writes PNG, PDF or SVG by suffix. Symbols follow the seed:
X̄_sp1 = δ_sp1/b_c, time in mesh periods τΩ/2π.
"""

from ._common import axis_label, axis_symbol
from .bifurcation import bifurcation, bifurcation_figure
from .contact import contact_figure
from .figure import savefig, summary_figure
from .gallery import poincare_gallery
from .maps import distinct_counts, distinct_map, sweep_figure
from .phase import phase_portrait, poincare_map, sun_orbit
from .regimes import (
    REGIME_COLOURS,
    regime_band,
    regime_colour,
    regime_legend,
    regime_map,
)
from .response import response_figure
from .sources import FigureOptions, figure_for
from .timeseries import amplitude_spectrum, spectrum, time_history

__all__ = [
    "REGIME_COLOURS",
    "FigureOptions",
    "amplitude_spectrum",
    "axis_label",
    "axis_symbol",
    "bifurcation",
    "bifurcation_figure",
    "contact_figure",
    "distinct_counts",
    "distinct_map",
    "figure_for",
    "phase_portrait",
    "poincare_gallery",
    "poincare_map",
    "regime_band",
    "regime_colour",
    "regime_legend",
    "regime_map",
    "response_figure",
    "savefig",
    "spectrum",
    "summary_figure",
    "sun_orbit",
    "sweep_figure",
    "time_history",
]
