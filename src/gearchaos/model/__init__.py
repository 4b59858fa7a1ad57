"""Assembly layer: dimensionless models with compiled right-hand sides.

``nondimensionalise(gearset)`` → :class:`PlanetaryParameters` + :class:`Scales`;
:func:`planetary_system` builds the :class:`System` the integrator runs; :mod:`.library` holds
reference systems (single-mesh backlash oscillator, linear systems, Duffing, Lorenz).
"""

from .library import (
    backlash_oscillator,
    duffing,
    linear_oscillator,
    linear_system,
    lorenz,
)
from .planetary import (
    PlanetaryModel,
    PlanetaryParameters,
    Scales,
    nondimensionalise,
    planetary_system,
)
from .system import Model, Observable, System
from .target import DEFAULT_OMEGA, OMEGA, resolve

__all__ = [
    "DEFAULT_OMEGA",
    "OMEGA",
    "Model",
    "Observable",
    "PlanetaryModel",
    "PlanetaryParameters",
    "Scales",
    "System",
    "backlash_oscillator",
    "duffing",
    "linear_oscillator",
    "linear_system",
    "lorenz",
    "nondimensionalise",
    "planetary_system",
    "resolve",
]
