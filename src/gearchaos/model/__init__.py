"""Assembly layer: dimensionless models with compiled right-hand sides.

``nondimensionalise(gearset)`` → :class:`PlanetaryParameters` + :class:`Scales`;
:func:`planetary_system` builds the :class:`System` the integrator runs; :mod:`.library` holds
reference systems (single-mesh backlash oscillator, linear systems, Duffing, Lorenz);
:mod:`.contract` is the model contract every model meets, written once as the record
:class:`Capabilities`, and :class:`UserModel` the base of a model written outside the package
(docs/howto/own-model.md).
"""

from .contract import Capabilities, Contact, UserModel, check_model
from .library import (
    backlash_oscillator,
    duffing,
    linear_oscillator,
    linear_system,
    lorenz,
)
from .loading import load_model_class
from .planetary import (
    PlanetaryModel,
    PlanetaryParameters,
    Scales,
    nondimensionalise,
    planetary_system,
)
from .system import Model, Observable, System
from .target import DEFAULT_OMEGA, OMEGA, Target, resolve

__all__ = [
    "DEFAULT_OMEGA",
    "OMEGA",
    "Capabilities",
    "Contact",
    "Model",
    "Observable",
    "PlanetaryModel",
    "PlanetaryParameters",
    "Scales",
    "System",
    "Target",
    "UserModel",
    "backlash_oscillator",
    "check_model",
    "duffing",
    "linear_oscillator",
    "linear_system",
    "load_model_class",
    "lorenz",
    "nondimensionalise",
    "planetary_system",
    "resolve",
]
