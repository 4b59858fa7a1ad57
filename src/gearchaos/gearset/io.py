"""TOML input and output of gear sets, dotted-name access and ``evolve``: the public functions.

The file layout is described in :mod:`gearchaos.gearset.tomltext`. Every parameter has a
stable dotted name (``teeth.sun``, ``backlash.sun_planet``; see :func:`field_names`) used
alike by :func:`evolve`, :func:`get_value`, the CLI and sweep stores.

Reading (:func:`from_toml`, :func:`from_toml_string`, :func:`from_dict`) is strict: unknown
tables or keys raise :class:`~gearchaos.errors.ParameterError` suggesting the closest valid
name, missing required keys are named, integers are accepted (and converted) where floats are
expected but not the reverse, and every value passes :func:`~gearchaos.gearset.validation.validate`.
Files are read only if they are regular UTF-8 files of at most 1 MiB.

Writing (:func:`to_toml`) needs no TOML library: floats are written in a shortest form that
parses back to the identical double (checked as it is written), so
``from_toml_string(to_toml(gs)) == gs`` holds exactly.

This module sits on top of the package's gear-set layer (registry → validation → mappings →
TOML text → ``GearSet`` → presets → here) and holds no logic of its own but the template.
"""

from __future__ import annotations

import os
from collections.abc import Mapping

from .mapping import field_names, get_value
from .presets import preset
from .records import GearSet
from .schema import ALIASES
from .tomltext import template_text

__all__ = [
    "ALIASES",
    "evolve",
    "field_names",
    "from_dict",
    "from_toml",
    "from_toml_string",
    "get_value",
    "template_toml",
    "to_dict",
    "to_toml",
]


def _check_gearset(gs: object, function: str) -> GearSet:
    if not isinstance(gs, GearSet):
        raise TypeError(f"{function}() expects a GearSet: got {type(gs).__name__}")
    return gs


def evolve(gs: GearSet, changes: Mapping[str, object]) -> GearSet:
    """A validated copy of a gear set with some parameters changed.

    Parameters
    ----------
    gs : GearSet
        The gear set to copy.
    changes : mapping of str to object
        New values by dotted name (``"backlash.sun_planet"``, ``"teeth.sun"``), or ``"name"``,
        ``"description"``, a table name (``"backlash"``) with a record instance or a mapping of
        some of its fields, or the alias ``"xi"`` that sets ``damping.sun_planet``,
        ``damping.planet_ring`` and ``damping.sun_bearing`` at once (a dotted damping name in
        the same call overrides the alias for that ratio). Integers are accepted for float
        fields and sequences for the harmonics; they are converted to float and tuple.

    Returns
    -------
    GearSet
        The new gear set, validated as a whole (so a change of ``teeth.planet`` must come with a
        consistent ``teeth.ring``).

    Raises
    ------
    TypeError
        If ``gs`` is not a GearSet.
    ParameterError
        If ``changes`` is not a mapping, for an unknown name (suggesting the closest valid one)
        or an invalid resulting set.
    """
    return _check_gearset(gs, "evolve").evolve(changes)


def to_dict(gs: GearSet) -> dict[str, object]:
    """The gear set as a nested plain dictionary in TOML layout (see :meth:`GearSet.to_dict`)."""
    return _check_gearset(gs, "to_dict").to_dict()


def from_dict(data: Mapping[str, object]) -> GearSet:
    """Build a gear set from a nested mapping in TOML layout (the inverse of :func:`to_dict`).

    Parameters
    ----------
    data : mapping
        Top-level ``name`` and ``description`` (optional) and one table per record. Tables
        whose fields all have defaults (``transmission_error``, ``eccentricity``,
        ``mesh_phasing``) and fields with defaults may be omitted.

    Returns
    -------
    GearSet

    Raises
    ------
    ParameterError
        For unknown tables or keys (suggesting the closest valid name), missing required keys,
        values of the wrong type and values that break a rule of
        :func:`~gearchaos.gearset.validation.validate`.
    """
    return GearSet.from_dict(data)


def from_toml_string(text: str) -> GearSet:
    """Parse a gear set from TOML text in the layout of :func:`to_toml` (see
    :func:`template_toml`); :class:`~gearchaos.errors.ParameterError` for text that is not a
    ``str`` or not TOML (also nested too deeply to parse), and for everything
    :func:`from_dict` rejects."""
    return GearSet.from_toml_string(text)


def from_toml(path: str | os.PathLike[str]) -> GearSet:
    """Read a gear set from a UTF-8 TOML file.

    Parameters
    ----------
    path : str or os.PathLike
        The file (``gearchaos init-gearset`` writes a commented template). It must be a regular
        file (a symbolic link to one is followed) of at most 1 MiB
        (:data:`gearchaos.gearset.records.MAX_FILE_BYTES`).

    Returns
    -------
    GearSet

    Raises
    ------
    FileNotFoundError
        If there is no such file (a :class:`gearchaos._files.MissingFileError`, which is also a
        :class:`~gearchaos.errors.StoreError`).
    StoreError
        If the path cannot be used as a file: a directory, FIFO, device or socket, a loop of
        symbolic links, no permission, or more than 1 MiB. Opening never blocks (a FIFO
        without writer is refused at once).
    ParameterError
        If ``path`` is not a str or path-like, is empty or holds a NUL character; for contents
        that are not UTF-8, not TOML or not a valid gear set. The message starts with the path.
    """
    return GearSet.from_toml(path)


def to_toml(gs: GearSet) -> str:
    """The gear set as TOML text with the units of every value in a trailing comment; reads
    back to an equal gear set (see :meth:`GearSet.to_toml`)."""
    return _check_gearset(gs, "to_toml").to_toml()


def template_toml(name: str = "sheng2016") -> str:
    """A commented gear-set file to start from: the values of a preset (by default
    ``sheng2016``, the calibrated stand-in for the seed's Table 1), every line explained.

    Parameters
    ----------
    name : str
        The preset whose values the file holds (:func:`list_presets`).

    Returns
    -------
    str
        TOML that :func:`from_toml_string` reads back to that preset (except for ``name`` and
        ``description``); each parameter line carries its symbol, units and meaning.
    """
    gs = preset(name).evolve(
        {
            "name": "my_gearset",
            "description": f"describe the gear set here (values: the {name} preset)",
        }
    )
    return template_text(gs)
