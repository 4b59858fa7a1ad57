"""Command-line interface: ``gearchaos simulate | info | presets | init-gearset |
bifurcation | classify | plot | response | explore | poincare | reproduce | calibrate``.

Every command takes the gear set the same way: ``--preset NAME`` (default ``sheng2016``) or
``--gearset FILE.toml`` (one of the two), then any number of ``--set NAME=VALUE`` changes by
the dotted parameter names of :mod:`gearchaos.gearset.schema` (``backlash.sun_planet``,
``teeth.sun``, the alias ``xi`` for the three damping ratios). ``omega`` (the dimensionless mesh
frequency Ω = ω/ω_n) is a simulation setting, not a gear-set field, but is given with
``--set omega=1.5`` as well, so that a command line reads like a point of a sweep.

One module per group of commands (:mod:`.simulate`, :mod:`.gearset`, :mod:`.sweep`, :mod:`.plot`,
:mod:`.gallery`, :mod:`.paper`); the options many of them share are declared once, in groups
passed on as one object, in :mod:`._options`; what else they share — the app, error handling
and exit codes, ``--set`` parsing — is in :mod:`._common`, tables for people in :mod:`._render`.
"""

# isort: off
# the import order is the order of the commands in `gearchaos --help`
from . import simulate, gearset, sweep, plot, response, gallery  # noqa: F401
from . import orbits, basins, paper, export, explore  # noqa: F401
from . import boundary  # noqa: F401

# isort: on
from ._common import (
    DEFAULT_OMEGA,
    DEFAULT_PRESET,
    EXIT_BROKEN_PIPE,
    EXIT_FAILURE,
    EXIT_INTERRUPTED,
    EXIT_INVALID,
    INTERRUPTED_MESSAGE,
    app,
    parse_sets,
)
from .paper import GALLERY_FIGURES, PAPER_FIGURES

__all__ = [
    "DEFAULT_OMEGA",
    "DEFAULT_PRESET",
    "EXIT_BROKEN_PIPE",
    "EXIT_FAILURE",
    "EXIT_INTERRUPTED",
    "EXIT_INVALID",
    "GALLERY_FIGURES",
    "INTERRUPTED_MESSAGE",
    "PAPER_FIGURES",
    "app",
    "explore",
    "export",
    "gallery",
    "gearset",
    "orbits",
    "paper",
    "parse_sets",
    "plot",
    "simulate",
    "sweep",
]
