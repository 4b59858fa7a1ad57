"""Built-in gear sets, one TOML file per preset in this package.

``sheng2016`` is the default gear set of gearchaos (MODEL.md §9): a physically consistent
stand-in for the seed paper's lost Table 1.
"""

from __future__ import annotations

import difflib
import functools
from importlib import resources

from ...errors import ParameterError
from ..io import from_toml_string
from ..records import GearSet

__all__ = ["list_presets", "preset"]

_SUFFIX = ".toml"


def _names() -> list[str]:
    root = resources.files(__name__)
    return sorted(
        entry.name[: -len(_SUFFIX)]
        for entry in root.iterdir()
        if entry.name.endswith(_SUFFIX) and entry.is_file()
    )


@functools.cache
def _load(name: str) -> GearSet:
    text = resources.files(__name__).joinpath(name + _SUFFIX).read_text(encoding="utf-8")
    try:
        return from_toml_string(text)
    except ParameterError as exc:  # pragma: no cover - the shipped presets are tested
        raise ParameterError(f"preset {name!r}: {exc}") from exc


def preset(name: str) -> GearSet:
    """A built-in gear set by name.

    Parameters
    ----------
    name : str
        Preset name, e.g. ``"sheng2016"`` (see :func:`list_presets`).

    Returns
    -------
    GearSet
        The validated gear set (immutable, so the same object may be returned on every call).

    Raises
    ------
    ParameterError
        For an unknown name; the message suggests the closest preset and lists them all.
    """
    available = _names()
    if not isinstance(name, str) or name not in available:
        close = difflib.get_close_matches(str(name).lower(), available, n=1)
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise ParameterError(
            f"unknown preset {name!r}; {hint}available presets: {', '.join(available)}"
        )
    return _load(name)


def list_presets() -> list[tuple[str, str]]:
    """The built-in gear sets.

    Returns
    -------
    list of (str, str)
        ``(name, description)`` pairs sorted by name; ``name`` is what :func:`preset` takes.
    """
    return [(name, _load(name).description) for name in _names()]
