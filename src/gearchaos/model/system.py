"""The :class:`System` interface that the integrator and every analysis work on.

A :class:`System` is a *model* (a frozen dimensionless description with an integer ``kind`` that
selects its compiled right-hand side) evaluated at one forcing frequency Ω: a packed float64
parameter vector, a state layout, a forcing period and the names of its observables. The
integrator and the analyses know nothing about gears; they only see this.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .contract import Capabilities, Model

__all__ = ["Model", "Observable", "System"]


def _group_of(name: str) -> str | None:
    """``"force_sp_3"`` → ``"force_sp"``, ``"p_3_dot"`` → ``"p_dot"``; names without a planet
    index → None."""
    head, _, tail = name.rpartition("_")
    if tail.isdigit():
        return head
    if tail == "dot":
        inner, _, index = head.rpartition("_")
        if index.isdigit():
            return f"{inner}_dot"
    return None


def _planet_of(name: str) -> int:
    """The planet index of a per-planet name (``delta_sp_3`` and ``p_3_dot`` → 3)."""
    parts = name.split("_")
    return int(parts[-1] if parts[-1].isdigit() else parts[-2])


@dataclass(frozen=True, eq=False)
class Observable:
    """A variable located in the kernel's outputs: ``source`` ``"state"`` or ``"obs"``,
    the ``columns`` there, and whether it is a per-planet group (one column per planet)."""

    name: str
    source: str
    columns: np.ndarray
    per_planet: bool

    def take(self, states: np.ndarray, observables: np.ndarray) -> np.ndarray:
        """Its values from state and observable arrays (samples on the leading axes): the
        columns on the last axis for a group, else that axis dropped."""
        arr = states if self.source == "state" else observables
        values = arr[..., self.columns]
        return values if self.per_planet else values[..., 0]


def _packed(model: Any, omega: float) -> np.ndarray:
    """``model.pack(omega)`` as a vector of float64; anything else is refused naming the
    model's ``pack``."""
    from ..errors import ParameterError

    what = f"{type(model).__name__}.pack(omega)"
    raw = model.pack(omega)
    try:
        p = np.ascontiguousarray(raw, dtype=np.float64)
    except (TypeError, ValueError, OverflowError) as exc:
        shown = repr(raw) if len(repr(raw)) <= 80 else repr(raw)[:77] + "..."
        raise ParameterError(
            f"{what} must return a vector of numbers (the parameters the right-hand side "
            f"reads): got {shown} ({type(exc).__name__}: {exc})"
        ) from None
    if p.ndim != 1 or np.asarray(raw).dtype.kind not in "fiu":
        raise ParameterError(
            f"{what} must return a vector of numbers: got an array of shape {p.shape} and "
            f"dtype {np.asarray(raw).dtype}"
        )
    return p


def _not_finite(model: Any, p: np.ndarray) -> str:
    """The refusal of packed parameters that are not all finite: the model's fields (a
    dataclass model's parameters) that are NaN or infinite, else the positions in the vector."""
    import dataclasses
    import numbers

    bad = []
    if dataclasses.is_dataclass(model):
        for f in dataclasses.fields(model):
            value = getattr(model, f.name, None)
            if isinstance(value, numbers.Real) and not isinstance(value, bool):
                if not math.isfinite(float(value)):
                    bad.append(f"{f.name} = {value!r}")
    if bad:
        return (
            f"{model.name}: the parameter {', '.join(bad)} must be a finite number; give "
            "it a finite value"
        )
    where = ", ".join(str(int(k)) for k in np.flatnonzero(~np.isfinite(p))[:8])
    return (
        f"{model.name}: pack(omega) gave NaN or inf at position {where} of the packed "
        f"parameters (a parameter it derives from the model's fields is not finite)"
    )


@dataclass(frozen=True, eq=False)
class System:
    """A model at one forcing frequency, ready for the compiled integrator.

    Parameters
    ----------
    model
        The dimensionless model (e.g. :class:`~gearchaos.model.planetary.PlanetaryModel`).
    omega
        Dimensionless forcing frequency Ω; the forcing period is T = 2π/Ω. For autonomous
        systems (Lorenz) Ω only sets the sampling interval.

    Attributes
    ----------
    params : numpy.ndarray
        Packed, read-only float64 parameter vector (layout in :mod:`gearchaos.model.layout`).
    """

    model: Any
    omega: float
    params: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        from .._checks import check_real
        from ..errors import ParameterError

        om = check_real("omega", self.omega, lo=0.0, lo_open=True)
        if not hasattr(self.model, "pack"):
            raise ParameterError(
                f"model must be a gearchaos model: got {type(self.model).__name__}"
            )
        object.__setattr__(self, "omega", om)
        p = _packed(self.model, om)
        if not np.all(np.isfinite(p)):
            raise ParameterError(_not_finite(self.model, p))
        p.setflags(write=False)
        object.__setattr__(self, "params", p)

    @property
    def capabilities(self) -> Capabilities:
        """What the model gives: the model contract's record
        (:class:`~gearchaos.model.contract.Capabilities`, read once per model)."""
        return Capabilities.of(self.model)

    # -- delegated layout -------------------------------------------------------------
    kind = property(lambda self: int(self.model.kind), doc="Kind of the compiled model.")
    name = property(lambda self: str(self.model.name), doc="Name of the model.")
    n_state = property(lambda self: int(self.model.n_state), doc="Length of the state.")
    state_names = property(
        lambda self: tuple(self.model.state_names), doc="Names of the state components."
    )
    obs_names = property(
        lambda self: tuple(self.model.obs_names), doc="Names of the observables, in order."
    )
    n_obs = property(lambda self: len(self.model.obs_names), doc="Number of observables.")
    n_track = property(
        lambda self: int(self.model.n_track),
        doc="Number of leading observables whose extrema are tracked (the dead-zone arguments).",
    )

    def observable(self, name: str, planets: Sequence[int] | None = None) -> Observable:
        """Where a variable lives in the kernel's outputs, by name.

        ``name`` is a state (``x_s``, ``sigma``) or an observable (``delta_sp_1``), or a
        per-planet group: ``delta_sp`` → ``delta_sp_1 … delta_sp_N`` (observables, in planet
        order), ``p`` / ``p_dot`` → ``p_1 … p_N`` / ``p_1_dot …`` (states). ``planets``
        (1-based) picks planets of a group (default: all).

        Raises
        ------
        ParameterError
            For an unknown name (suggesting the closest one) or a planet out of range.
        """
        from ..errors import ParameterError

        sn, on = self.state_names, self.obs_names
        if name in sn:
            return Observable(name, "state", np.array([sn.index(name)]), False)
        if name in on:
            return Observable(name, "obs", np.array([on.index(name)]), False)
        source, names = "obs", on
        cols = [k for k, nm in enumerate(on) if _group_of(nm) == name]
        if not cols:
            source, names = "state", sn
            cols = [k for k, nm in enumerate(sn) if _group_of(nm) == name]
        if not cols:
            import difflib

            groups = {g for g in map(_group_of, (*sn, *on)) if g is not None}
            valid = sorted(set(sn) | set(on) | groups)
            close = difflib.get_close_matches(name, valid, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ParameterError(f"unknown observed variable {name!r}{hint}")
        cols.sort(key=lambda k: _planet_of(names[k]))
        if planets is not None:
            n_pl = len(cols)
            for p in planets:
                if not 1 <= int(p) <= n_pl:
                    raise ParameterError(
                        f"planets must be between 1 and {n_pl} for this gear set: got {p}"
                    )
            cols = [cols[int(p) - 1] for p in planets]
        return Observable(name, source, np.array(cols), True)

    @property
    def contacts(self) -> tuple[Any, ...]:
        """The model's :class:`~gearchaos.model.contract.Contact` s (none for smooth systems)."""
        return self.capabilities.contacts

    @property
    def default_observables(self) -> tuple[str, str]:
        """The (variable, derivative) pair sections and labels use by default (a group name
        such as ``delta_sp`` stands for its members)."""
        return self.capabilities.default_observables

    def section_pair(self, planet: int = 1) -> tuple[str, str]:
        """The default section variables as concrete names: :attr:`default_observables`, a
        group's member ``planet`` (``delta_sp`` → ``delta_sp_1``, ``delta_sp_dot_1``)."""
        var, dot = self.default_observables
        return self.member(var, planet) or var, self.member(dot, planet) or dot

    def member(self, name: str, planet: int) -> str | None:
        """The name of member ``planet`` (1-based) of the per-member group ``name``
        (``delta_sp`` → ``delta_sp_2``, ``p_dot`` → ``p_2_dot``); None when ``name`` is a
        variable's own name or no group. A member out of range raises
        :class:`~gearchaos.errors.ParameterError`."""
        from ..errors import ParameterError

        if name in self.state_names or name in self.obs_names:
            return None
        try:
            group = self.observable(name)
        except ParameterError:
            return None
        if not group.per_planet:
            return None
        count = int(group.columns.size)
        if isinstance(planet, bool) or not (
            isinstance(planet, int | np.integer) and 1 <= planet <= count
        ):
            raise ParameterError(f"planet must be an integer in 1..{count}: got {planet!r}")
        names = self.state_names if group.source == "state" else self.obs_names
        return names[int(group.columns[int(planet) - 1])]

    @property
    def group_size(self) -> int:
        """Members of the model's per-member variable groups (``delta_sp_1 … delta_sp_N``: the
        planets of a planetary model), 0 for a model without groups."""
        sizes = [len(cols) for _, cols, per in self.tracked_groups() if per]
        return max(sizes, default=0)

    @property
    def force_groups(self) -> tuple[tuple[str, str, str], ...]:
        """(label, contact-force variable, deflection variable) of each mesh type whose contact
        forces the kernel tracks (empty without contact forces)."""
        if self.n_contact_forces == 0:
            return ()
        return self.capabilities.force_groups

    n_contact_forces = property(
        lambda self: self.capabilities.n_contact_forces,
        doc="How many of the tracked observables, at their end, are mesh contact forces.",
    )

    def tracked_groups(self, contact_forces: bool = False) -> list[tuple[str, np.ndarray, bool]]:
        """The tracked observables grouped as sweeps and orbits store them: per-planet groups
        (``delta_sp`` → its columns, True) and scalars (``x_s`` → one column, False).

        Without ``contact_forces`` these are the tracked observables that are not contact
        forces (the dead-zone arguments); with it, only the contact forces
        (``contact_force_sp`` …), whose extrema give peak dynamic mesh forces."""
        n_dz = self.n_track - self.n_contact_forces
        first = n_dz if contact_forces else 0
        names = self.obs_names[: self.n_track if contact_forces else n_dz]
        out: list[tuple[str, np.ndarray, bool]] = []
        seen: set[str] = set()
        for k in range(first, len(names)):
            nm = names[k]
            head, _, tail = nm.rpartition("_")
            if tail.isdigit():
                if head not in seen:
                    seen.add(head)
                    idx = [j for j, m in enumerate(names) if m.rpartition("_")[0] == head]
                    out.append((head, np.array(idx), True))
            else:
                out.append((nm, np.array([k]), False))
        return out

    def check_state(self, value: Any, what: str = "y0") -> np.ndarray:
        """``value`` as a state of this system: ``n_state`` finite numbers, else a
        :class:`~gearchaos.errors.ParameterError` naming ``what`` and the components."""
        from .._checks import real_array
        from ..errors import ParameterError

        names = ", ".join(self.state_names)
        y = real_array(value)
        if y is None:
            raise ParameterError(
                f"{what} must be {self.n_state} numbers ({names}): got {type(value).__name__}"
            )
        if y.ndim != 1 or y.size != self.n_state:
            raise ParameterError(
                f"{what} must be a vector of {self.n_state} entries ({names}): got shape {y.shape}"
            )
        if not np.all(np.isfinite(y)):
            raise ParameterError(f"{what} must be finite: got {y.tolist()}")
        return y

    @property
    def switch_widths(self) -> np.ndarray:
        """Half clearances b_k of the dead zones acting on the tracked observables.

        The integrator lands steps on the switches obs_k = ±b_k, where the vector field has a
        kink; ``inf`` means the observable has no switch (smooth systems).
        """
        return self.capabilities.switch_widths

    @property
    def period(self) -> float:
        """Forcing period T = 2π/Ω in units of τ, times the model's ``period_factor`` (the
        model contract: a forcing with several frequencies declares the multiple of 2π/Ω
        after which it repeats)."""
        T = 2.0 * math.pi / self.omega
        factor = self.capabilities.period_factor
        return T if factor == 1.0 else factor * T

    def warn_for(self, analysis: str) -> None:
        """Let the model warn when ``analysis`` is questionable for it (a planetary model with
        eccentricities has no 1T-periodic section, MODEL.md §3)."""
        hook = self.capabilities.warn_for
        if hook is not None:
            hook(analysis)

    def at(self, omega: float) -> System:
        """The same model at another forcing frequency."""
        return System(self.model, omega)

    def evaluate(self, tau: Any, states: Any) -> tuple[np.ndarray, np.ndarray]:
        """(observables (m, n_obs), derivatives f(τ, y) (m, n_state)) at m times and states,
        with the compiled right-hand side."""
        from .._numba import call_literal
        from .kernels import observe_many

        tau = np.ascontiguousarray(tau, dtype=np.float64).reshape(-1)
        states = np.ascontiguousarray(states, dtype=np.float64).reshape(tau.size, self.n_state)
        obs, d = call_literal(observe_many, self.kind, tau, states, self.params, self.n_obs)
        return np.asarray(obs), np.asarray(d)

    def observe(self, tau: np.ndarray, states: np.ndarray) -> np.ndarray:
        """Observables (``obs_names``) at the given times and states, shape (m, n_obs)."""
        return self.evaluate(tau, states)[0]

    def derivative(self, tau: float, state: np.ndarray) -> np.ndarray:
        """The right-hand side f(τ, y) evaluated once (for tests and users)."""
        return self.evaluate([float(tau)], state)[1][0]

    def __repr__(self) -> str:
        return f"System({self.name}, omega={self.omega:g}, n_state={self.n_state})"
