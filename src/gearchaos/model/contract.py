r"""The model contract: what a model gives gearchaos, and models written outside the package.

Every analysis of gearchaos — simulations, sweeps and stores, motion verdicts, periodic orbits,
continuation, Lyapunov exponents, attractors, plots, the explorer and the command line — works on
a :class:`~gearchaos.model.System`, a model at one forcing frequency Ω. A *model* is a frozen
description of a dimensionless system that provides (:class:`Model`):

``name``
    A short name (titles, store attributes).
``state_names``, ``n_state``
    The state components y, in order.
``obs_names``, ``n_track``
    The observables the right-hand side writes, in order: first the ``n_track`` *tracked* ones
    (the integrator records their extrema over every run and lands steps on their switches),
    then their τ-derivatives (``n_track`` more), then any others (forces, stiffness …).
``pack(omega)``
    The float64 parameter vector ``p`` the compiled right-hand side reads, at Ω.
``kind``
    The integer that selects the compiled right-hand side (built-in models have fixed kinds;
    models from outside get theirs from :func:`register_kernels`).
``switch_widths`` (optional, default: none)
    Half clearance b_k of the dead zone acting on each tracked observable (``inf``: smooth):
    the integrator lands a step where a tracked observable crosses ±b_k, where the vector field
    has a kink.
``clearances`` (optional)
    Half clearances by name (store attributes, figures).
``contacts`` (optional)
    The :class:`Contact` s whose regime (no impact, single-sided, double-sided) analyses
    report: a name, the tracked observable it is judged on, its half clearance and its kind.
``n_contact_forces`` (optional, default 0)
    How many tracked observables, at the end of the tracked ones, are contact forces (their
    extrema give peak forces; they have no switch).
``default_observables`` (optional)
    The pair of variables sections and labels use (default: the first tracked observable and
    its derivative).
``scales`` (optional)
    Physical scales (``omega_n``, ``length`` …) for axes in SI units.
``symbols`` (optional)
    Figure symbols of its variables: variable (or group) name → (mathtext symbol without
    ``$``, its definition or ``None``, the name of its clearance in ``clearances`` or
    ``None``, the clearance's symbol or ``None``), e.g. ``{"delta": (r"\bar{\delta}",
    r"\delta/b_c", "mesh", r"\bar{b}_h")}``; axes and labels of its variables use them.
``parameter_symbols`` (optional)
    Figure symbols of its parameters: field name → mathtext symbol without ``$``, e.g.
    ``{"zeta_h": r"\zeta_h", "f_mean": r"\bar F_m"}``; the axis of a swept or continued
    parameter and the ``at …`` line of figure titles use them (a parameter without one is
    named by its field, or left out of titles). Keys must be fields of the model, values
    strings (:func:`check_model`).

The right-hand side is a compiled function ``rhs(t, y, p, dydt, obs, level)`` writing dy/dτ
into ``dydt[:n_state]`` and the observables into ``obs`` (at least the first ``2 n_track``;
``level`` says whether all are needed, :data:`~gearchaos.model.kernels.OBS_ALL`); the optional
tangent ``tangent(t, y, p, obs, dydt, n, k)`` writes J(τ, y[:n]) applied to the ``k`` vectors
stored after the state in ``y`` into ``dydt[n:]``. A model without a tangent gets a central
finite-difference one (:func:`~gearchaos.model.kernels.tangent`).

A model defined outside the package subclasses :class:`UserModel` (a frozen dataclass whose
fields are its parameters) and names its compiled functions ``rhs`` (and ``tangent``); see the
how-to *Your own gear model* (``docs/howto/own-model.md``) and ``examples/kahraman_singh_1991.py``.
"""

from __future__ import annotations

import hashlib
import inspect
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np

from ..errors import ParameterError
from .layout import FD_MAX_OBS, FD_MAX_STATE

__all__ = [
    "Contact",
    "Model",
    "UserModel",
    "contacts_of",
    "default_observables",
    "register_kernels",
]

#: Kinds of models from outside the package start here (built-in kinds are below 1000).
EXTERNAL_KIND_BASE = 1 << 24


@dataclass(frozen=True)
class Contact:
    """A contact whose regime analyses report: ``name``, the index ``column`` of the tracked
    observable (a deflection) it is judged on, its half clearance b̄ and its ``kind``
    (``mesh``: teeth meet at δ = ±b̄, regime from min δ; ``bearing``: a journal touches the
    bearing at ±b̄, regime from both extrema)."""

    name: str
    column: int
    clearance: float
    kind: str = "mesh"


@runtime_checkable
class Model(Protocol):
    """What a dimensionless model provides to build a :class:`~gearchaos.model.System` (see
    the module docstring for the optional members)."""

    name: str

    @property
    def kind(self) -> int: ...

    @property
    def n_state(self) -> int: ...

    @property
    def state_names(self) -> tuple[str, ...]: ...

    @property
    def obs_names(self) -> tuple[str, ...]: ...

    @property
    def n_track(self) -> int: ...

    def pack(self, omega: float) -> np.ndarray: ...


def contacts_of(model: Any) -> tuple[Contact, ...]:
    """The model's contacts: its ``contacts``, else none."""
    return tuple(getattr(model, "contacts", ()))


def default_observables(model: Any) -> tuple[str, str]:
    """The (variable, derivative) pair a model's sections and labels use by default."""
    pair = getattr(model, "default_observables", None)
    if pair is not None:
        return (str(pair[0]), str(pair[1]))
    names = tuple(model.obs_names)
    n_track = int(model.n_track)
    if n_track >= 1 and len(names) >= 2 * n_track:
        return (names[0], names[n_track])
    states = tuple(model.state_names)
    return (states[0], states[1] if len(states) > 1 else states[0])


# ------------------------------------------------------------------ models from outside
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


class UserModel:
    """Base of a model written outside gearchaos: subclass it as a frozen dataclass whose
    fields are the dimensionless parameters, and give it

    * ``name``, ``state_names``, ``obs_names`` and ``n_track`` (class attributes),
    * ``rhs`` (and optionally ``tangent``): ``numba.njit(cache=True)`` functions with the
      signatures of the module docstring,
    * ``pack(self, omega)``: the parameter vector ``rhs`` reads,
    * optionally ``switch_widths``, ``clearances``, ``contacts``, ``n_contact_forces``,
      ``default_observables``, ``scales``, ``symbols`` (of its variables) and
      ``parameter_symbols`` (of its fields).

    ``System(MyModel(...), omega)`` then runs in every analysis; parameters are changed by
    field name (``params={"zeta": 0.1}``, ``--set zeta=0.1``).
    """

    def __init_subclass__(cls, **kwargs: Any) -> None:
        """Keep the compiled ``rhs``/``tangent`` plain functions: a numba dispatcher set as a
        class attribute would bind like a method (``model.rhs(t, …)`` passing the model as
        ``t``), so they are stored as static methods."""
        super().__init_subclass__(**kwargs)
        for attr in ("rhs", "tangent"):
            fn = cls.__dict__.get(attr)
            if fn is not None and hasattr(fn, "py_func"):
                setattr(cls, attr, staticmethod(fn))

    name: ClassVar[str]
    state_names: ClassVar[tuple[str, ...]]
    obs_names: ClassVar[tuple[str, ...]]
    n_track: ClassVar[int]
    n_contact_forces: ClassVar[int] = 0

    @property
    def kind(self) -> int:
        """The kernel kind (registered on first use, :func:`register_kernels`)."""
        return register_kernels(type(self))

    @property
    def n_state(self) -> int:
        return len(self.state_names)

    @property
    def switch_widths(self) -> np.ndarray:
        """No switches unless the model says otherwise."""
        return np.full(int(self.n_track), np.inf)

    @property
    def clearances(self) -> dict[str, float]:
        return {c.name: c.clearance for c in contacts_of(self)}

    def check(self) -> None:
        """Refuse a model that breaks the contract (called by :func:`check_model`)."""
        check_model(self)


def check_model(model: Any) -> None:
    """Raise :class:`~gearchaos.errors.ParameterError` naming the member of ``model`` that
    breaks the contract (names, sizes, packed parameters, switch widths, contacts, parameter
    symbols)."""
    what = type(model).__name__
    for attr in ("name", "state_names", "obs_names", "n_track", "pack", "kind"):
        if not hasattr(model, attr):
            raise ParameterError(f"{what} must define {attr} (the model contract)")
    states, obs = tuple(model.state_names), tuple(model.obs_names)
    if len(states) != int(model.n_state) or len(set(states)) != len(states) or not states:
        raise ParameterError(f"{what}.state_names must be {model.n_state} distinct names")
    if len(set(obs)) != len(obs):
        raise ParameterError(f"{what}.obs_names must be distinct names: got {obs}")
    n_track = int(model.n_track)
    if not (0 <= n_track and 2 * n_track <= len(obs)):
        raise ParameterError(
            f"{what}.n_track must be in [0, len(obs_names)/2] (tracked observables and their "
            f"derivatives come first): got {n_track} with {len(obs)} observables"
        )
    widths = np.asarray(getattr(model, "switch_widths", np.full(n_track, np.inf)), dtype=float)
    if widths.shape != (n_track,) or np.any(np.isnan(widths)) or np.any(widths < 0):
        raise ParameterError(
            f"{what}.switch_widths must be {n_track} half clearances >= 0 (inf: no switch): "
            f"got {widths.tolist()}"
        )
    for c in contacts_of(model):
        if not 0 <= c.column < n_track or c.kind not in ("mesh", "bearing"):
            raise ParameterError(
                f"{what}.contacts: {c.name} must be judged on a tracked observable (column in "
                f"[0, {n_track})) and be a mesh or a bearing: got {c}"
            )
    _check_parameter_symbols(model, what)
    if getattr(model, "tangent", None) is None and (
        len(states) > FD_MAX_STATE or len(obs) > FD_MAX_OBS
    ):
        raise ParameterError(
            f"{what} has no tangent and {len(states)} states / {len(obs)} observables: the "
            f"finite-difference tangent handles at most {FD_MAX_STATE} / {FD_MAX_OBS}; give "
            "the model a tangent"
        )


def _check_parameter_symbols(model: Any, what: str) -> None:
    """Refuse ``parameter_symbols`` that are no mapping of the model's field names to
    mathtext strings."""
    import dataclasses
    from collections.abc import Mapping

    table = getattr(model, "parameter_symbols", None)
    if table is None:
        return
    if not isinstance(table, Mapping):
        raise ParameterError(
            f"{what}.parameter_symbols must map field names to mathtext symbols: got "
            f"{type(table).__name__}"
        )
    fields = (
        [f.name for f in dataclasses.fields(model) if f.init]
        if dataclasses.is_dataclass(model)
        else []
    )
    for key, value in table.items():
        if key not in fields:
            raise ParameterError(
                f"{what}.parameter_symbols: key {key!r} must be a field of the model (its "
                f"fields: {', '.join(fields) or 'none'})"
            )
        if not isinstance(value, str):
            raise ParameterError(
                f"{what}.parameter_symbols[{key!r}] must be a mathtext string (without $): "
                f"got {value!r}"
            )
