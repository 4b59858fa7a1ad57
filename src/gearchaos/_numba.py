"""Calling kernels specialised on a literal system ``kind`` without per-call re-dispatch.

Kernels call ``numba.literally(kind)`` so that each system kind gets its own machine code (a
direct call of its right-hand side, cached on disk). Called through the dispatcher with a plain
``int``, numba would re-type the call every time (milliseconds); :func:`call_literal` resolves
the specialisation once and then calls its entry point directly (sub-microsecond).
"""

from __future__ import annotations

from typing import Any

from numba import typeof, types

__all__ = ["call_literal"]

_ENTRIES: dict[tuple[Any, ...], Any] = {}


def call_literal(dispatcher: Any, kind: int, *args: Any) -> Any:
    """``dispatcher(kind, *args)`` with ``kind`` specialised as a compile-time literal."""
    kind = int(kind)
    key = (dispatcher, kind, *(typeof(a) for a in args))
    entry = _ENTRIES.get(key)
    if entry is None:
        result = dispatcher(kind, *args)  # compiles or loads the literal specialisation
        sig = (types.literal(kind), *key[2:])
        cres = dispatcher.overloads.get(sig)
        if cres is not None:
            _ENTRIES[key] = cres.entry_point
        return result
    return entry(kind, *args)
