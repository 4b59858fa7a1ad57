"""Compiled right-hand sides of models from outside the package: :func:`register_kernels`
gives a :class:`~gearchaos.model.contract.UserModel` class its kernel kind, derived from the
model's source, and registers its ``rhs`` (and ``tangent``) with the integrator's dispatch."""

from __future__ import annotations

import hashlib
import inspect
from typing import Any

from ..errors import ParameterError

__all__ = ["EXTERNAL_KIND_BASE", "register_kernels"]

#: Kinds of models from outside the package start here (built-in kinds are below 1000).
EXTERNAL_KIND_BASE = 1 << 24

_REGISTERED: dict[Any, int] = {}


def _source_digest(cls: type, rhs: Any, tangent: Any) -> str:
    """A digest of the code that defines the model: its module's source file (so an edit of
    the model, or of a helper in the same file, gives a new kind and a new compilation), else
    the functions' own source."""
    h = hashlib.sha256(f"{cls.__module__}:{cls.__qualname__}".encode())
    try:
        path = inspect.getsourcefile(cls)
        if path is None:
            raise TypeError(cls)
        with open(path, "rb") as f:
            h.update(f.read())
    except (OSError, TypeError):
        for fn in (rhs, tangent):
            if fn is not None:
                try:
                    h.update(inspect.getsource(getattr(fn, "py_func", fn)).encode())
                except (OSError, TypeError):
                    h.update(repr(id(fn)).encode())  # no source: this process only
    return h.hexdigest()


def _compiled(cls: type, attr: str) -> Any:
    fn = inspect.getattr_static(cls, attr, None)
    if fn is None:
        return None
    if isinstance(fn, staticmethod):
        fn = fn.__func__
    if not hasattr(fn, "py_func"):
        raise ParameterError(
            f"{cls.__name__}.{attr} must be a numba.njit function (decorate it with "
            f"@numba.njit(cache=True)): got {type(fn).__name__}"
        )
    return fn


def register_kernels(cls: type) -> int:
    """The kernel kind of a model class defined outside the package, its ``rhs`` (and
    ``tangent``, or the finite-difference tangent) registered with the integrator's dispatch
    on first use. The kind is derived from the model's source, so that numba's on-disk cache
    serves a second process without compiling again, and an edited model compiles afresh."""
    kind = _REGISTERED.get(cls)
    if kind is not None:
        return kind
    from .kernels import register_kernel

    rhs = _compiled(cls, "rhs")
    if rhs is None:
        raise ParameterError(
            f"{cls.__name__} needs a compiled right-hand side: rhs = numba.njit(cache=True)("
            "function(t, y, p, dydt, obs, level))"
        )
    tangent = _compiled(cls, "tangent")
    kind = EXTERNAL_KIND_BASE + int(_source_digest(cls, rhs, tangent)[:10], 16)
    register_kernel(kind, rhs, tangent)
    _REGISTERED[cls] = kind
    return kind
