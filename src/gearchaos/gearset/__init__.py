"""Physical layer: frozen gear-set records, TOML I/O, validation and presets.

The records of the tables (:class:`Teeth` … :class:`MeshPhasing`) are those of
:mod:`.tables`; :class:`GearSet` holds one of each (:mod:`.records`).
"""

from .io import from_toml, from_toml_string, template_toml, to_toml
from .presets import list_presets, preset
from .records import UNITS, GearSet
from .tables import (
    Backlash,
    Clearance,
    Damping,
    Eccentricity,
    Geometry,
    Inertia,
    Mass,
    MeshPhasing,
    Stiffness,
    Teeth,
    Torque,
    TransmissionError,
)

__all__ = [
    "UNITS",
    "Backlash",
    "Clearance",
    "Damping",
    "Eccentricity",
    "GearSet",
    "Geometry",
    "Inertia",
    "Mass",
    "MeshPhasing",
    "Stiffness",
    "Teeth",
    "Torque",
    "TransmissionError",
    "from_toml",
    "from_toml_string",
    "list_presets",
    "preset",
    "template_toml",
    "to_toml",
]
