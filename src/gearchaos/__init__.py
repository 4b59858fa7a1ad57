"""gearchaos — nonlinear dynamics of geared transmissions with clearances.

The central model is the transverse–torsional 2K-H planetary gear train of Sheng et al. (2016)
in the reconstruction of ``MODEL.md``: time-varying mesh stiffness, transmission and eccentricity
errors, sun–planet and planet–ring backlash and sun bearing clearance.

>>> import gearchaos as gc
>>> gs = gc.preset("sheng2016")
>>> res = gc.simulate(gs, omega=1.5)          # doctest: +SKIP
>>> res.to_dataset().delta_sp.sel(planet=1)   # doctest: +SKIP
"""

from typing import TYPE_CHECKING

from ._version import __version__
from .errors import IntegrationError, ParameterError, Status, StoreError
from .gearset import GearSet, preset, preset_of
from .integrate import SimulationResult, open_simulation, simulate
from .model import (
    System,
    backlash_oscillator,
    duffing,
    linear_oscillator,
    linear_system,
    lorenz,
    nondimensionalise,
    planetary_system,
)
from .sweep import bifurcation, open_sweep, response
from .sweep.exports import export

__all__ = [
    "Event",
    "GearSet",
    "IntegrationError",
    "ParameterError",
    "PeriodicOrbit",
    "SimulationResult",
    "Status",
    "StoreError",
    "System",
    "__version__",
    "attractors",
    "backlash_oscillator",
    "basin_fractions",
    "basins",
    "bifurcation",
    "boundary_curve",
    "continuation",
    "duffing",
    "explore",
    "export",
    "linear_oscillator",
    "linear_system",
    "lorenz",
    "lyapunov_spectrum",
    "max_lyapunov",
    "nondimensionalise",
    "open_branch",
    "open_curve",
    "open_simulation",
    "open_sweep",
    "periodic_orbit",
    "periodic_orbits",
    "planetary_system",
    "preset",
    "preset_of",
    "response",
    "save_branch",
    "simulate",
    "summarize",
]

if TYPE_CHECKING:
    from .dynamics.attractors.coexistence import attractors
    from .dynamics.continuation.arclength import continuation
    from .dynamics.continuation.branch import open_branch, save_branch
    from .dynamics.continuation.events import Event
    from .dynamics.curves.boundary import boundary_curve
    from .dynamics.curves.file import open_curve
    from .dynamics.lyapunov import lyapunov_spectrum, max_lyapunov
    from .dynamics.orbits.batch import periodic_orbits
    from .dynamics.orbits.orbit import PeriodicOrbit, periodic_orbit
    from .dynamics.verdict.point import summarize
    from .explore import explore
    from .sweep.basin_fractions import basin_fractions
    from .sweep.basins import basins

_LAZY_SUBPACKAGES = ("analysis", "dynamics", "plot", "paper", "explore")
#: Functions of the lazy subpackages exported here, by the module that defines them.
_LAZY_ATTRIBUTES = {
    "PeriodicOrbit": "dynamics.orbits.orbit",
    "periodic_orbit": "dynamics.orbits.orbit",
    "continuation": "dynamics.continuation.arclength",
    "boundary_curve": "dynamics.curves.boundary",
    "open_curve": "dynamics.curves.file",
    "Event": "dynamics.continuation.events",
    "open_branch": "dynamics.continuation.branch",
    "save_branch": "dynamics.continuation.branch",
    "lyapunov_spectrum": "dynamics.lyapunov",
    "max_lyapunov": "dynamics.lyapunov",
    "periodic_orbits": "dynamics.orbits.batch",
    "attractors": "dynamics.attractors.coexistence",
    "summarize": "dynamics.verdict.point",
    "basins": "sweep.basins",
    "basin_fractions": "sweep.basin_fractions",
}


def __getattr__(name: str) -> object:
    """``gearchaos.plot`` etc. import on first use (matplotlib only when plotting; Panel only
    for ``gearchaos.explore``, a callable package: ``gearchaos.explore(store)``), and so do
    the periodic-orbit, branch and Lyapunov front doors (``gc.periodic_orbit``,
    ``gc.continuation``, ``gc.max_lyapunov``, ``gc.attractors`` …)."""
    import importlib

    if name in _LAZY_SUBPACKAGES:
        return importlib.import_module(f"{__name__}.{name}")
    if name in _LAZY_ATTRIBUTES:
        return getattr(importlib.import_module(f"{__name__}.{_LAZY_ATTRIBUTES[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
