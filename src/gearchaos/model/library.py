"""Reference systems with known behaviour, behind the same :class:`System` interface.

They let users and tests check the integrator and every analysis on textbook problems:

* :func:`backlash_oscillator` — single gear mesh with backlash (Kahraman & Singh 1990):
  x'' + 2ζx' + (1 + ε cos Ωτ) f(x; b) = F_m + F_a Ω^q cos Ωτ, q = 2 for transmission-error
  forcing (the default), q = 0 for a force amplitude (MODEL.md §10.5).
* :func:`linear_oscillator` and :func:`linear_system` — y' = A y + f cos Ωτ + g sin Ωτ, with
  exact solutions by the matrix exponential and exact Lyapunov exponents (Re λ(A)).
* :func:`duffing` — x'' + δx' + αx + βx³ = γ cos Ωτ.
* :func:`lorenz` — the Lorenz (1963) system (autonomous; Ω sets only the sampling interval).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._checks import check_real, real_array
from ..errors import ParameterError
from . import layout as L
from .contract import Contact
from .system import System

__all__ = [
    "BacklashOscillator",
    "Duffing",
    "LinearSystem",
    "Lorenz",
    "backlash_oscillator",
    "duffing",
    "linear_oscillator",
    "linear_system",
    "lorenz",
]


def _check(name: str, value: float, rule: str) -> float:
    """A finite real number (not a bool, not text), >= 0 or > 0 when ``rule`` says so."""
    if rule == ">=0":
        return check_real(name, value, lo=0.0)
    if rule == ">0":
        return check_real(name, value, lo=0.0, lo_open=True)
    return check_real(name, value)


@dataclass(frozen=True)
class BacklashOscillator:
    """Single-mesh backlash oscillator (dimensionless)."""

    zeta: float = 0.05
    eps: float = 0.0
    b: float = 1.0
    f_mean: float = 0.1
    f_alt: float = 0.1
    omega_power: int = 2
    # the layout (not parameters: left out of the repr, which store attributes record)
    kind: int = field(default=L.KIND_BACKLASH_OSCILLATOR, repr=False)
    name: str = field(default="backlash_oscillator", repr=False)
    n_state: int = field(default=2, repr=False)
    #: x (the dead zone's argument) and the contact force Fᶜ have their extrema tracked
    n_track: int = field(default=2, repr=False)
    #: the last tracked observable is the contact force (no switch of its own)
    n_contact_forces: int = field(default=1, repr=False)
    state_names: tuple[str, ...] = field(default=("x", "x_dot"), repr=False)
    obs_names: tuple[str, ...] = field(
        default=("x", "contact_force", "x_dot", "contact_force_dot", "stiffness"), repr=False
    )

    def __post_init__(self) -> None:
        _check("zeta", self.zeta, ">=0")
        _check("b", self.b, ">=0")
        _check("f_mean", self.f_mean, "")
        _check("f_alt", self.f_alt, "")
        if not 0.0 <= _check("eps", self.eps, "") < 1.0:
            raise ParameterError(
                f"eps must be in [0, 1) (stiffness would turn negative): got {self.eps!r}"
            )
        power = self.omega_power
        if (
            isinstance(power, bool)
            or not isinstance(power, numbers.Integral)
            or power not in (0, 2)
        ):
            raise ParameterError(f"omega_power must be 0 or 2: got {self.omega_power!r}")

    @property
    def clearances(self) -> dict[str, float]:
        return {"x": self.b}

    @property
    def contacts(self) -> tuple[Contact, ...]:
        """The single mesh, judged on x against ±b."""
        return (Contact("mesh", 0, self.b),)

    #: Mesh types whose contact forces are tracked: (label, force, deflection).
    force_groups = (("mesh", "contact_force", "x"),)

    def static_mesh_force(self, omega: float) -> float:
        """F_m, the mean load (the load factor's reference)."""
        return float(self.f_mean)

    @property
    def switch_widths(self) -> np.ndarray:
        """b for x; none (``inf``) for the contact force, whose extrema are only tracked."""
        return np.array([self.b, np.inf])

    def pack(self, omega: float) -> np.ndarray:
        p = np.zeros(L.BO_SIZE)
        p[L.BO_OMEGA] = omega
        p[L.BO_ZETA] = self.zeta
        p[L.BO_EPS] = self.eps
        p[L.BO_B] = self.b
        p[L.BO_FM] = self.f_mean
        p[L.BO_FA] = self.f_alt * omega**self.omega_power
        return p


@dataclass(frozen=True)
class LinearSystem:
    """y' = A y + f cos Ωτ + g sin Ωτ."""

    matrix: tuple[tuple[float, ...], ...]
    cos_forcing: tuple[float, ...]
    sin_forcing: tuple[float, ...]
    kind: int = L.KIND_LINEAR
    name: str = "linear"

    @property
    def n_state(self) -> int:
        return len(self.matrix)

    @property
    def n_track(self) -> int:
        return self.n_state

    @property
    def state_names(self) -> tuple[str, ...]:
        return tuple(f"y_{i}" for i in range(self.n_state))

    @property
    def obs_names(self) -> tuple[str, ...]:
        n = self.n_state
        return tuple(f"y_{i}" for i in range(n)) + tuple(f"y_{i}_dot" for i in range(n))

    def pack(self, omega: float) -> np.ndarray:
        n = self.n_state
        a = np.asarray(self.matrix, dtype=float)
        return np.concatenate(
            [[omega, n], a.ravel(), np.asarray(self.cos_forcing), np.asarray(self.sin_forcing)]
        )


@dataclass(frozen=True)
class Duffing:
    """Forced Duffing oscillator x'' + δx' + αx + βx³ = γ cos Ωτ."""

    delta: float = 0.1
    alpha: float = 1.0
    beta: float = 1.0
    gamma: float = 0.5
    kind: int = L.KIND_DUFFING
    name: str = "duffing"
    n_state: int = 2
    n_track: int = 1
    state_names: tuple[str, ...] = ("x", "x_dot")
    obs_names: tuple[str, ...] = ("x", "x_dot")

    def __post_init__(self) -> None:
        for k in ("delta", "alpha", "beta", "gamma"):
            _check(k, getattr(self, k), "")

    def pack(self, omega: float) -> np.ndarray:
        return np.array([omega, self.delta, self.alpha, self.beta, self.gamma])


@dataclass(frozen=True)
class Lorenz:
    """Lorenz system x' = σ(y − x), y' = x(ρ − z) − y, z' = xy − βz."""

    sigma: float = 10.0
    rho: float = 28.0
    beta: float = 8.0 / 3.0
    kind: int = L.KIND_LORENZ
    name: str = "lorenz"
    n_state: int = 3
    n_track: int = 3
    state_names: tuple[str, ...] = ("x", "y", "z")
    obs_names: tuple[str, ...] = ("x", "y", "z", "x_dot", "y_dot", "z_dot")

    def __post_init__(self) -> None:
        for k in ("sigma", "rho", "beta"):
            _check(k, getattr(self, k), "")

    def pack(self, omega: float) -> np.ndarray:
        return np.array([self.sigma, self.rho, self.beta])


def backlash_oscillator(
    omega: float,
    *,
    zeta: float = 0.05,
    eps: float = 0.0,
    b: float = 1.0,
    f_mean: float = 0.1,
    f_alt: float = 0.1,
    omega_power: int = 2,
) -> System:
    """Single-mesh backlash oscillator at Ω (see module docstring)."""
    return System(BacklashOscillator(zeta, eps, b, f_mean, f_alt, omega_power), omega)


def _real_array(name: str, value: Any) -> np.ndarray:
    """An array of finite real numbers (no bools, text or complex numbers)."""
    a = real_array(value)
    if a is None:
        raise ParameterError(f"{name} must be an array of real numbers: got {type(value).__name__}")
    if not np.all(np.isfinite(a)):
        raise ParameterError(f"{name} must be finite: got NaN or inf")
    return a


def linear_system(
    matrix: np.ndarray | list[list[float]],
    omega: float = 1.0,
    *,
    cos_forcing: np.ndarray | None = None,
    sin_forcing: np.ndarray | None = None,
) -> System:
    """y' = A y + f cos Ωτ + g sin Ωτ."""
    a = _real_array("matrix", matrix)
    if a.ndim != 2 or a.shape[0] != a.shape[1] or a.shape[0] < 1:
        raise ParameterError(f"matrix must be square and non-empty: got shape {a.shape}")
    n = a.shape[0]
    f = np.zeros(n) if cos_forcing is None else _real_array("cos_forcing", cos_forcing)
    g = np.zeros(n) if sin_forcing is None else _real_array("sin_forcing", sin_forcing)
    for name, v in (("cos_forcing", f), ("sin_forcing", g)):
        if v.shape != (n,):
            raise ParameterError(f"{name} must have shape ({n},): got {v.shape}")
    model = LinearSystem(
        tuple(tuple(float(x) for x in row) for row in a),
        tuple(float(x) for x in f),
        tuple(float(x) for x in g),
    )
    return System(model, omega)


def linear_oscillator(omega: float = 1.0, *, zeta: float = 0.05, force: float = 0.0) -> System:
    """x'' + 2ζx' + x = F cos Ωτ as a first-order linear system."""
    zeta, force = _check("zeta", zeta, ""), _check("force", force, "")
    return linear_system(
        [[0.0, 1.0], [-1.0, -2.0 * zeta]], omega, cos_forcing=np.array([0.0, force])
    )


def duffing(
    omega: float, *, delta: float = 0.1, alpha: float = 1.0, beta: float = 1.0, gamma: float = 0.5
) -> System:
    """Forced Duffing oscillator at Ω."""
    return System(Duffing(delta, alpha, beta, gamma), omega)


def lorenz(
    *, sigma: float = 10.0, rho: float = 28.0, beta: float = 8.0 / 3.0, sample_interval: float = 1.0
) -> System:
    """Lorenz system; samples are taken every ``sample_interval`` time units."""
    interval = _check("sample_interval", sample_interval, ">0")
    return System(Lorenz(sigma, rho, beta), 2.0 * math.pi / interval)
