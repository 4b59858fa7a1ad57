"""The :class:`System` interface that the integrator and every analysis work on.

A :class:`System` is a *model* (a frozen dimensionless description with an integer ``kind`` that
selects its compiled right-hand side) evaluated at one forcing frequency Ω: a packed float64
parameter vector, a state layout, a forcing period and the names of its observables. The
integrator and the analyses know nothing about gears; they only see this.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

import numpy as np

__all__ = ["Model", "System"]


def _group_of(name: str) -> str | None:
    """``"force_sp_3"`` → ``"force_sp"``; names without a planet index → None."""
    head, _, tail = name.rpartition("_")
    return head if tail.isdigit() else None


@runtime_checkable
class Model(Protocol):
    """What a dimensionless model provides to build a :class:`System`."""

    kind: int
    name: str

    @property
    def n_state(self) -> int: ...

    @property
    def state_names(self) -> tuple[str, ...]: ...

    @property
    def obs_names(self) -> tuple[str, ...]: ...

    @property
    def n_track(self) -> int: ...

    def pack(self, omega: float) -> np.ndarray: ...


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
        from ..errors import ParameterError

        om = float(self.omega)
        if not math.isfinite(om) or om <= 0.0:
            raise ParameterError(f"omega must be a finite number > 0: got {self.omega!r}")
        object.__setattr__(self, "omega", om)
        p = np.ascontiguousarray(self.model.pack(om), dtype=np.float64)
        if not np.all(np.isfinite(p)):
            raise ParameterError(f"{self.model.name}: packed parameters contain NaN or inf")
        p.setflags(write=False)
        object.__setattr__(self, "params", p)

    # -- delegated layout -------------------------------------------------------------
    @property
    def kind(self) -> int:
        return int(self.model.kind)

    @property
    def name(self) -> str:
        return str(self.model.name)

    @property
    def n_state(self) -> int:
        return int(self.model.n_state)

    @property
    def state_names(self) -> tuple[str, ...]:
        return tuple(self.model.state_names)

    @property
    def obs_names(self) -> tuple[str, ...]:
        return tuple(self.model.obs_names)

    @property
    def n_obs(self) -> int:
        return len(self.model.obs_names)

    @property
    def n_track(self) -> int:
        return int(self.model.n_track)

    def obs_indices(self, group: str) -> np.ndarray:
        """Positions in ``obs_names`` of a per-planet group, e.g. ``"force_sp"`` →
        indices of ``force_sp_1 … force_sp_N`` (in planet order); a plain name gives one index."""
        names = self.obs_names
        if group in names:
            return np.array([names.index(group)])
        idx = [k for k, nm in enumerate(names) if _group_of(nm) == group]
        if not idx:
            raise KeyError(f"no observable {group!r} or {group}_<i>; observables: {names}")
        return np.array(sorted(idx, key=lambda k: int(names[k].rsplit("_", 1)[1])))

    @property
    def switch_widths(self) -> np.ndarray:
        """Half clearances b_k of the dead zones acting on the tracked observables.

        The integrator lands steps on the switches obs_k = ±b_k, where the vector field has a
        kink; ``inf`` means the observable has no switch (smooth systems).
        """
        w = getattr(self.model, "switch_widths", None)
        if w is None:
            return np.full(self.n_track, np.inf)
        return np.asarray(w, dtype=np.float64)

    @property
    def period(self) -> float:
        """Forcing period T = 2π/Ω in units of τ."""
        return 2.0 * math.pi / self.omega

    def at(self, omega: float) -> System:
        """The same model at another forcing frequency."""
        return System(self.model, omega)

    def observe(self, tau: np.ndarray, states: np.ndarray) -> np.ndarray:
        """Observables (``obs_names``) at the given times and states, shape (m, n_obs)."""
        from .._numba import call_literal
        from .kernels import observe_many

        tau = np.ascontiguousarray(tau, dtype=np.float64).reshape(-1)
        states = np.ascontiguousarray(states, dtype=np.float64).reshape(tau.size, self.n_state)
        obs, _ = call_literal(observe_many, self.kind, tau, states, self.params, self.n_obs)
        return np.asarray(obs)

    def derivative(self, tau: float, state: np.ndarray) -> np.ndarray:
        """The right-hand side f(τ, y) evaluated once (for tests and users)."""
        from .._numba import call_literal
        from .kernels import observe_many

        y = np.ascontiguousarray(state, dtype=np.float64).reshape(1, self.n_state)
        _, d = call_literal(
            observe_many, self.kind, np.array([float(tau)]), y, self.params, self.n_obs
        )
        return np.asarray(d[0])

    def __repr__(self) -> str:
        return f"System({self.name}, omega={self.omega:g}, n_state={self.n_state})"
