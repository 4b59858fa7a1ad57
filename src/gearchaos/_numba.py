"""Calling kernels specialised on a literal system ``kind`` without per-call re-dispatch.

Kernels call ``numba.literally(kind)`` so that each system kind gets its own machine code (a
direct call of its right-hand side, cached on disk). Called through the dispatcher with a plain
``int``, numba would re-type the call every time (milliseconds); :func:`call_literal` resolves
the specialisation once and then calls its entry point directly (sub-microsecond).
"""

from __future__ import annotations

import threading
import warnings
from typing import Any

import numba
import numpy as np
from numba import typeof, types
from numba.core import cgutils
from numba.core.errors import NumbaIRAssumptionWarning
from numba.extending import intrinsic

__all__ = ["call_literal", "entry_point", "njit_noalloc", "on_first_compile", "stack_array"]

#: ``@njit_noalloc``: a cached kernel compiled without numba's reference counting, for kernels
#: that allocate nothing (right-hand sides, tangents, the integrator's switch helpers). A call
#: to it then costs no atomic reference-count updates of its array arguments: as fast as the
#: kernel inlined into its caller, without the seconds of compile time inlining costs.
_NO_NRT: dict[str, Any] = {"cache": True, "_nrt": False}
njit_noalloc: Any = numba.njit(**_NO_NRT)

_ENTRIES: dict[tuple[Any, ...], Any] = {}
#: Called once per process before the first kernel that is not in numba's on-disk cache.
_FIRST_COMPILE: list[Any] = []
_FIRST_COMPILE_LOCK = threading.Lock()


def _first_compile_notice() -> None:
    """Call the first-compile callback once, whichever thread gets here first (a sweep's
    driver threads compile side by side: both saw the callback and the second pop failed,
    'pop from empty list')."""
    with _FIRST_COMPILE_LOCK:
        callback = _FIRST_COMPILE.pop() if _FIRST_COMPILE else None
    if callback is not None:
        callback()


def on_first_compile(callback: Any) -> None:
    """Call ``callback()`` once, before this process first compiles a kernel that numba's
    on-disk cache does not hold (the command line says "compiling numerical kernels (first
    run only…)" there); ``None`` removes it."""
    _FIRST_COMPILE.clear()
    if callback is not None:
        _FIRST_COMPILE.append(callback)


def _in_disk_cache(dispatcher: Any, sig: tuple[Any, ...]) -> bool:
    """Whether numba's on-disk cache of ``dispatcher`` holds the specialisation ``sig`` (a new
    planet count, say, is compiled although others are cached); True where that cannot be
    told."""
    try:
        index = dispatcher._cache._cache_file._load_index()
        return any(key[0] == sig for key in index)
    except Exception:  # numba's internals changed: assume cached, print nothing
        return True


def _type_key(a: Any) -> Any:
    """What decides numba's type of an argument, cheaply: an array's dtype, dimensions,
    layout, writability and alignment; a tuple's items'; otherwise the Python type (a
    number's numba type follows from it)."""
    if isinstance(a, np.ndarray):
        f = a.flags
        return (a.dtype.str, a.ndim, f.c_contiguous, f.f_contiguous, f.writeable, f.aligned)
    if isinstance(a, tuple):
        return tuple(_type_key(x) for x in a)
    return type(a)


def _ignore_ir_assumption_warnings() -> None:
    """Ignore numba's NumbaIRAssumptionWarning, which its IR inliner emits (internal,
    "pedantic") for the inlined dispatch of the right-hand side: harmless and not actionable.

    A filter put first and left there, not a ``warnings.catch_warnings()`` block around the
    compile: that block saves the process-wide warning state on entry and puts it back on exit,
    from whichever thread compiles. A sweep's driver thread still compiling after its sweep was
    interrupted put back, seconds later, the state of a block long closed — in the middle of
    another ``catch_warnings`` (a ``pytest.warns`` of a later test), whose recorded warnings
    then went to the stale recorder: the test failed now and then, depending on what had run
    before it in the process."""
    warnings.filterwarnings("ignore", category=NumbaIRAssumptionWarning)


def entry_point(dispatcher: Any, kind: int, *args: Any) -> Any:
    """The compiled entry point of ``dispatcher`` specialised on the literal ``kind`` for
    arguments like ``args``: compiled (or loaded from the disk cache) on first use, then
    looked up by a cheap key of the arguments' types (numba's own typing of every argument
    costs far more than a short kernel call); call it as ``entry(kind, *args)``. Safe to call
    from several threads once resolved (resolve it in one thread first)."""
    kind = int(kind)
    fast = (dispatcher, kind, *(_type_key(a) for a in args))
    entry = _ENTRIES.get(fast)
    if entry is None:
        sig = (types.literal(kind), *(typeof(a) for a in args))
        if _FIRST_COMPILE and not _in_disk_cache(dispatcher, sig):
            _first_compile_notice()
        _ignore_ir_assumption_warnings()
        entry = dispatcher.compile(sig)  # compiles or loads the literal specialisation
        _ENTRIES[fast] = entry
    return entry


def call_literal(dispatcher: Any, kind: int, *args: Any) -> Any:
    """``dispatcher(kind, *args)`` with ``kind`` specialised as a compile-time literal."""
    return entry_point(dispatcher, kind, *args)(int(kind), *args)


def guard_cache(dispatchers: list[Any], sources: list[str]) -> None:
    """Drop numba's on-disk cache of ``dispatchers`` when any file in ``sources`` changed.

    numba keys a cached kernel on its *own* source file only. The integrator inlines the
    right-hand sides from another module, so an edited ``kernels.py`` would otherwise leave a
    stale compiled integrator in place (a real hazard with editable installs). We keep a
    fingerprint of all sources beside the cache and delete the module's cache files when it
    differs. Failures (read-only locations, numba internals changing) are ignored: the worst
    case is numba's own behaviour.
    """
    import hashlib
    import os

    h = hashlib.sha256()
    for path in sorted(sources):
        try:
            with open(path, "rb") as f:
                h.update(f.read())
        except OSError:
            return
    digest = h.hexdigest()
    for disp in dispatchers:
        try:
            cache_dir = disp._cache._cache_path
            stem = os.path.splitext(os.path.basename(disp.py_func.__code__.co_filename))[0]
            stamp = os.path.join(cache_dir, f"{stem}.gearchaos-sources.sha256")
            old = None
            if os.path.exists(stamp):
                with open(stamp) as f:
                    old = f.read().strip()
            if old == digest:
                continue
            for name in os.listdir(cache_dir):
                if name.startswith(stem + ".") and name.endswith((".nbi", ".nbc")):
                    os.remove(os.path.join(cache_dir, name))
            os.makedirs(cache_dir, exist_ok=True)
            with open(stamp, "w") as f:
                f.write(digest)
        except Exception:  # best effort: never break an import
            continue


def _stack_array(typingctx: Any, size: Any) -> Any:
    """``stack_array(N)``: an uninitialised float64 work array of the compile-time constant
    length N on the stack of the compiled function (allocated once, in its entry block): work
    space for kernels compiled without numba's allocator (:data:`njit_noalloc`), such as the
    finite-difference tangent of a model without its own."""
    if not isinstance(size, types.IntegerLiteral):
        return None
    n = int(size.literal_value)
    arr_t = types.Array(types.float64, 1, "C")

    def codegen(context: Any, builder: Any, sig: Any, args: Any) -> Any:
        length = context.get_constant(types.intp, n)
        ptr = cgutils.alloca_once(builder, context.get_value_type(types.float64), size=length)
        ary = context.make_array(arr_t)(context, builder)
        context.populate_array(
            ary,
            data=ptr,
            shape=cgutils.pack_array(builder, [length]),
            strides=cgutils.pack_array(builder, [context.get_constant(types.intp, 8)]),
            itemsize=context.get_constant(types.intp, 8),
            meminfo=None,
        )
        return ary._getvalue()

    return arr_t(size), codegen


stack_array: Any = intrinsic(_stack_array)
