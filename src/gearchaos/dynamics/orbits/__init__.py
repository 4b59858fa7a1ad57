"""Periodic orbits: shooting on the stroboscopic map and their Floquet multipliers.

:mod:`.shooting` (map evaluations), :mod:`.corrector` (the one Newton corrector, over K
points at once, and :mod:`.problem`, what it is given and returns), :mod:`.orbit`
(:func:`periodic_orbit` and :class:`PeriodicOrbit`, K = 1), :mod:`.batch` (many orbits in one
compiled call per round), :mod:`.stability` (one stability criterion) and :mod:`.file` (orbit
files).
"""

from .batch import periodic_orbits
from .orbit import PeriodicOrbit, periodic_orbit

__all__ = ["PeriodicOrbit", "periodic_orbit", "periodic_orbits"]
