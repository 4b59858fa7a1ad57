"""Argument checks shared by every entry point: real numbers, integers, flags, choices, sizes.

Each check raises :class:`~gearchaos.errors.ParameterError` whose message names the argument,
the rule and the value (``rtol must be a number in [1e-14, 0.1]: got -1.0``) and whose ``name``
is the argument's name. ``bool`` is never
a number, strings are never numbers (``"1e-8"`` is refused, not parsed), numpy scalars are
accepted. A leaf module: it imports nothing from the package but :mod:`gearchaos.errors`.
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Iterable
from typing import Any

from .errors import ParameterError

__all__ = [
    "check_bool",
    "check_choice",
    "check_int",
    "check_memory",
    "check_real",
    "got",
    "real_array",
]


def got(value: Any) -> str:
    """``got -1.0`` for numbers, ``got '1e-8' (str)`` where the type is part of the problem."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        return f"got {value!r}"
    return f"got {value!r} ({type(value).__name__})"


def _num(x: float) -> str:
    return str(x) if isinstance(x, int) else f"{x:g}"


def _bound(lo: float | None, hi: float | None, lo_open: bool, hi_open: bool) -> str:
    """The range as words: ``>= 0``, ``> 0``, ``<= 1``, ``in (0, 45)``."""
    if lo is not None and hi is not None:
        return f"in {'(' if lo_open else '['}{_num(lo)}, {_num(hi)}{')' if hi_open else ']'}"
    if lo is not None:
        return f"{'>' if lo_open else '>='} {_num(lo)}"
    if hi is not None:
        return f"{'<' if hi_open else '<='} {_num(hi)}"
    return ""


def check_real(
    name: str,
    value: Any,
    *,
    lo: float | None = None,
    hi: float | None = None,
    lo_open: bool = False,
    hi_open: bool = False,
) -> float:
    """A finite real number within the bounds; returned as a Python float.

    The message names the side that is violated: ``rtol must be a finite number >= 1e-14``.
    """
    whole = _bound(lo, hi, lo_open, hi_open)
    rule = f"{name} must be a finite number" + (f" {whole}" if whole else "")
    if not isinstance(value, numbers.Real) or isinstance(value, bool):
        raise ParameterError(f"{rule}: {got(value)}", name=name)
    try:
        x = float(value)
    except (OverflowError, ValueError, TypeError):
        raise ParameterError(f"{rule}: {got(value)}", name=name) from None
    if not math.isfinite(x):
        raise ParameterError(f"{rule}: {got(value)}", name=name)
    if lo is not None and (x < lo or (lo_open and x == lo)):
        side = _bound(lo, None, lo_open, False)
        raise ParameterError(f"{name} must be a finite number {side}: {got(value)}", name=name)
    if hi is not None and (x > hi or (hi_open and x == hi)):
        side = _bound(None, hi, False, hi_open)
        raise ParameterError(f"{name} must be a finite number {side}: {got(value)}", name=name)
    return x


def check_int(name: str, value: Any, *, lo: int | None = None, hi: int | None = None) -> int:
    """An integer (not a bool, not a float such as 3.0) within the bounds; returned as int."""
    whole = _bound(lo, hi, False, False)
    if not isinstance(value, numbers.Integral) or isinstance(value, bool):
        raise ParameterError(
            f"{name} must be an integer{' ' + whole if whole else ''}: {got(value)}", name=name
        )
    n = int(value)
    if lo is not None and n < lo:
        raise ParameterError(f"{name} must be an integer >= {lo}: {got(value)}", name=name)
    if hi is not None and n > hi:
        raise ParameterError(f"{name} must be an integer <= {hi}: {got(value)}", name=name)
    return n


def real_array(value: Any) -> Any:
    """``value`` as a float64 array when it holds real numbers only (integers or floats of any
    precision), else ``None``: bools, text, complex numbers and objects are not numbers."""
    import numpy as np

    try:
        raw = np.asarray(value)
        if raw.dtype.kind not in "fiu":
            return None
        return raw.astype(np.float64)
    except (TypeError, ValueError, OverflowError):
        return None


def check_bool(name: str, value: Any) -> bool:
    """``True`` or ``False`` (numpy bools too); ``"yes"`` or 1 are refused."""
    if isinstance(value, bool) or type(value).__name__ == "bool_":
        return bool(value)
    raise ParameterError(f"{name} must be True or False: {got(value)}", name=name)


def check_choice(name: str, value: Any, choices: Iterable[str]) -> str:
    """One of ``choices`` (exactly, case-sensitive)."""
    options = tuple(choices)
    if not isinstance(value, str) or value not in options:
        allowed = ", ".join(repr(c) for c in options)
        raise ParameterError(f"{name} must be one of {allowed}: {got(value)}", name=name)
    return value


def _available_bytes() -> int:
    """Half the physical memory: a bound for one result array, generous but never swapping."""
    try:
        return int(os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")) // 2
    except (ValueError, OSError, AttributeError):  # pragma: no cover - non-POSIX
        return 8 * 2**30


def check_memory(what: str, nbytes: float) -> None:
    """Refuse, before allocating, a result that would not fit in memory."""
    limit = _available_bytes()
    if not nbytes <= limit:
        raise ParameterError(
            f"{what} would need {_size(nbytes)} of memory, more than the {_size(limit)} "
            "allowed (half the physical memory); record fewer periods, samples or points"
        )


def _size(nbytes: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if nbytes < 1024 or unit == "PiB":
            return f"{nbytes:.3g} {unit}"
        nbytes /= 1024
    return f"{nbytes:.3g} PiB"  # pragma: no cover
