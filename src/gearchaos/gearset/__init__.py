"""Physical layer: frozen gear-set records, TOML I/O, validation and presets.

The records of the tables (:class:`Teeth` … :class:`MeshPhasing`) are those of
:mod:`.tables`; :class:`GearSet` holds one of each (:mod:`.records`).
"""

from . import tables
from .io import from_toml, from_toml_string, template_toml, to_toml
from .presets import list_presets, preset, preset_of
from .records import UNITS, GearSet
from .tables import *  # noqa: F403 - the record classes, listed in tables.__all__

__all__ = [
    "UNITS",
    "GearSet",
    "from_toml",
    "from_toml_string",
    "list_presets",
    "preset",
    "preset_of",
    "template_toml",
    "to_toml",
]
__all__ += tables.__all__
