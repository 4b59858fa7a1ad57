"""Spur gear pair on two radial bearings with clearances (Kahraman & Singh 1991), a model
written outside gearchaos.

The three-degree-of-freedom gear–rotor–bearing model of

    A. Kahraman and R. Singh, "Interactions between time-varying mesh stiffness and clearance
    non-linearities in a geared system", Journal of Sound and Vibration 146(1), 135–156 (1991)

(the model of their companion paper "Non-linear dynamics of a geared rotor-bearing system
with multiple clearances", J. Sound Vib. 144(3), 469–506, 1991, with a time-varying mesh
stiffness), reference [1] of the seed paper (Sheng et al. 2016). The equations below are
written from the model's description by Newton's second law, in the paper's coordinates
(the two transverse displacements and the dynamic transmission error); the names of the
dimensionless groups are this file's. A pinion (p) and a gear (g), rigid discs
of masses m_p, m_g, polar moments I_p, I_g and base radii r_p, r_g, move along the line of
action (transverse displacements y_p, y_g) on radial rolling-element bearings of stiffness
k_p, k_g with radial clearances 2b_p, 2b_g, and rotate (θ_p, θ_g), meshing with backlash 2b_h
through a mesh of time-varying stiffness k_h(t) = k_m (1 + ε cos Ωt) and viscous damping c_h.
A torque T_p drives the pinion and T_g loads the gear. The dynamic mesh deflection (dynamic
transmission error)

    δ = y_p − y_g + r_p θ_p − r_g θ_g − e(t),    e(t) = e_a cos Ωt

(e: the static transmission error) carries the mesh force W = c_h δ̇ + k_h(t) f(δ; b_h), and

    m_p ÿ_p + c_p ẏ_p + k_p f(y_p; b_p) + W = 0
    m_g ÿ_g + c_g ẏ_g + k_g f(y_g; b_g) − W = 0
    I_p θ̈_p + r_p W = T_p,      I_g θ̈_g − r_g W = −T_g.

The two rotations enter only through r_p θ_p − r_g θ_g, so the rigid-body mode drops out
and δ replaces them: with the equivalent mass m_c = (r_p²/I_p + r_g²/I_g)⁻¹ and the mean
mesh force F_m = T_p/r_p = T_g/r_g, the two torsional equations become
m_c(δ̈ − ÿ_p + ÿ_g) + W = F_m − m_c ë(t). Lengths are scaled by a characteristic length b_c
and time by the mesh natural frequency ω_n = √(k_m/m_c): τ = ω_n t, Ω ← Ω/ω_n,
q̄1 = y_p/b_c, q̄2 = y_g/b_c, q̄3 = δ/b_c and ′ = d/dτ. The dimensionless equations are

    q̄1″ + 2ζ_p q̄1′ + μ_p κ_p f(q̄1; b̄_p) + μ_p w̄ = 0
    q̄2″ + 2ζ_g q̄2′ + μ_g κ_g f(q̄2; b̄_g) − μ_g w̄ = 0
    q̄3″ − q̄1″ + q̄2″ + w̄ = F̄_m + F̄_a Ω² cos Ωτ
    w̄ = 2ζ_h q̄3′ + (1 + ε cos Ωτ) f(q̄3; b̄_h)

with the dead zone (clearance) function of half clearance b

    f(x; b) = x − b (x > b),   0 (|x| ≤ b),   x + b (x < −b).

Parameters (the fields of :class:`KahramanSingh1991`, all dimensionless):

=========  ====================  =====================================================
field      symbol                meaning
=========  ====================  =====================================================
zeta_h     ζ_h = c_h/(2m_cω_n)   mesh damping ratio
zeta_p     ζ_p = c_p/(2m_pω_n)   pinion bearing damping ratio
zeta_g     ζ_g = c_g/(2m_gω_n)   gear bearing damping ratio
mu_p       μ_p = m_c/m_p         equivalent (torsional) mass over pinion mass
mu_g       μ_g = m_c/m_g         equivalent (torsional) mass over gear mass
kappa_p    κ_p = k_p/k_m         pinion bearing stiffness over mean mesh stiffness
kappa_g    κ_g = k_g/k_m         gear bearing stiffness over mean mesh stiffness
b_h        b̄_h = b_h/b_c         half backlash of the gear mesh
b_p        b̄_p = b_p/b_c         half radial clearance of the pinion bearing
b_g        b̄_g = b_g/b_c         half radial clearance of the gear bearing
eps        ε                     amplitude of the mesh stiffness variation, in [0, 1)
f_mean     F̄_m = F_m/(k_m b_c)   mean mesh force (static load)
f_alt      F̄_a = e_a/b_c         amplitude of the static transmission error
=========  ====================  =====================================================

and the forcing (mesh) frequency Ω = ω_mesh/ω_n, the :class:`~gearchaos.model.System`'s
``omega``. In static equilibrium (ε = 0, F̄_a = 0) the mesh carries w̄ = F̄_m, so
q̄3 = b̄_h + F̄_m, q̄1 = −(b̄_p + F̄_m/κ_p) and q̄2 = b̄_g + F̄_m/κ_g: the load pushes the
pinion to one side of its bearing and the gear to the other.

The defaults are a representative gear pair, not one taken from the paper: b_c = b_h;
equal bearings as stiff as the mesh, with clearances half the backlash; the mass ratios of
two solid discs of the same width with a 3:2 gear ratio (m_c = (2/m_p + 2/m_g)⁻¹); 5 %
damping; a mean load of a tenth of the backlash, ε = 0.3 and a transmission error a quarter
of the backlash. Contact then is lost at the mesh (0.9 ≲ Ω ≲ 2.1 and Ω ≳ 2.2: min q̄3 < b̄_h)
and at the pinion bearing near Ω = 1.5, with subharmonic, quasi-periodic and chaotic motion
between periodic windows, as Kahraman & Singh describe.

State, observables and contacts (the model contract, :mod:`gearchaos.model.contract`): the
state is (q̄1, q̄2, q̄3, q̄1′, q̄2′, q̄3′); the three *tracked* observables are the dead-zone
arguments q̄1, q̄2, q̄3 (the integrator lands its steps on q̄_i = ±b̄_i, where the vector
field has a kink), followed by their derivatives and by the mesh force w̄, the bearing
forces κ_p f(q̄1; b̄_p) + 2ζ_p q̄1′/μ_p and κ_g f(q̄2; b̄_g) + 2ζ_g q̄2′/μ_g (in units of
k_m b_c), and the mesh stiffness 1 + ε cos Ωτ.

Run it::

    gearchaos simulate --model examples/kahraman_singh_1991.py:KahramanSingh1991 --omega 0.8

or, in Python, ``gc.simulate(System(KahramanSingh1991(), 0.8))``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numba
import numpy as np

from gearchaos.errors import ParameterError
from gearchaos.model.contract import Contact, UserModel
from gearchaos.model.kernels import OBS_ALL, dead_zone, engaged

# The packed parameter vector p that the compiled functions read.
OMEGA, ZETA_H, ZETA_P, ZETA_G, MU_P, MU_G, KAPPA_P, KAPPA_G = range(8)
B_H, B_P, B_G, EPS, F_MEAN, F_ALT = range(8, 14)
N_PARAMS = 14


@numba.njit(cache=True)
def rhs(t, y, p, dydt, obs, level):  # pragma: no cover - compiled
    """dy/dτ of y = (q̄1, q̄2, q̄3, q̄1′, q̄2′, q̄3′) and the observables (module docstring)."""
    om = p[OMEGA]
    c = math.cos(om * t)
    k = 1.0 + p[EPS] * c  # mesh stiffness 1 + ε cos Ωτ
    f1 = dead_zone(y[0], p[B_P])
    f2 = dead_zone(y[1], p[B_G])
    f3 = dead_zone(y[2], p[B_H])
    w = 2.0 * p[ZETA_H] * y[5] + k * f3  # mesh force w̄
    a1 = -2.0 * p[ZETA_P] * y[3] - p[MU_P] * (p[KAPPA_P] * f1 + w)
    a2 = -2.0 * p[ZETA_G] * y[4] - p[MU_G] * (p[KAPPA_G] * f2 - w)
    a3 = a1 - a2 - w + p[F_MEAN] + p[F_ALT] * om * om * c
    dydt[0] = y[3]
    dydt[1] = y[4]
    dydt[2] = y[5]
    dydt[3] = a1
    dydt[4] = a2
    dydt[5] = a3
    # tracked observables (the dead-zone arguments), then their τ-derivatives
    obs[0] = y[0]
    obs[1] = y[1]
    obs[2] = y[2]
    obs[3] = y[3]
    obs[4] = y[4]
    obs[5] = y[5]
    if level >= OBS_ALL:
        obs[6] = w
        obs[7] = p[KAPPA_P] * f1 + 2.0 * p[ZETA_P] * y[3] / p[MU_P]
        obs[8] = p[KAPPA_G] * f2 + 2.0 * p[ZETA_G] * y[4] / p[MU_G]
        obs[9] = k


@numba.njit(cache=True)
def tangent(t, y, p, obs, dydt, n, k):  # pragma: no cover - compiled
    """dydt[n:] = J(τ, y[:n]) v for the k tangent vectors v stored after the state in y: the
    Jacobian of :func:`rhs` (piecewise constant in the state: f′(x; b) = 1 outside the
    clearance, 0 inside)."""
    kh = (1.0 + p[EPS] * math.cos(p[OMEGA] * t)) * engaged(y[2], p[B_H])
    k1 = p[MU_P] * p[KAPPA_P] * engaged(y[0], p[B_P])
    k2 = p[MU_G] * p[KAPPA_G] * engaged(y[1], p[B_G])
    for r in range(k):
        o = n + r * n
        dw = 2.0 * p[ZETA_H] * y[o + 5] + kh * y[o + 2]
        d1 = -2.0 * p[ZETA_P] * y[o + 3] - k1 * y[o] - p[MU_P] * dw
        d2 = -2.0 * p[ZETA_G] * y[o + 4] - k2 * y[o + 1] + p[MU_G] * dw
        dydt[o] = y[o + 3]
        dydt[o + 1] = y[o + 4]
        dydt[o + 2] = y[o + 5]
        dydt[o + 3] = d1
        dydt[o + 4] = d2
        dydt[o + 5] = d1 - d2 - dw


@dataclass(frozen=True)
class KahramanSingh1991(UserModel):
    """Spur gear pair with backlash on two radial bearings with clearances (module
    docstring): the fields are the dimensionless parameters."""

    zeta_h: float = 0.05
    zeta_p: float = 0.05
    zeta_g: float = 0.05
    mu_p: float = 0.35
    mu_g: float = 0.15
    kappa_p: float = 1.0
    kappa_g: float = 1.0
    b_h: float = 1.0
    b_p: float = 0.5
    b_g: float = 0.5
    eps: float = 0.3
    f_mean: float = 0.1
    f_alt: float = 0.25

    name = "kahraman_singh_1991"
    state_names = ("y_p", "y_g", "delta", "y_p_dot", "y_g_dot", "delta_dot")
    obs_names = (
        "y_p",
        "y_g",
        "delta",
        "y_p_dot",
        "y_g_dot",
        "delta_dot",
        "mesh_force",
        "bearing_force_p",
        "bearing_force_g",
        "stiffness",
    )
    n_track = 3
    default_observables = ("delta", "delta_dot")
    rhs = rhs
    tangent = tangent
    #: Figure symbols: variable → (symbol, definition, clearance name, clearance symbol).
    symbols: ClassVar[dict[str, tuple[str, str | None, str | None, str | None]]] = {
        "delta": (r"\bar{\delta}", r"\delta/b_c", "mesh", r"\bar{b}_h"),
        "y_p": (r"\bar{y}_p", r"y_p/b_c", "bearing_p", r"\bar{b}_p"),
        "y_g": (r"\bar{y}_g", r"y_g/b_c", "bearing_g", r"\bar{b}_g"),
    }
    #: Figure symbols of the parameters (the module docstring's): field → mathtext symbol.
    parameter_symbols: ClassVar[dict[str, str]] = {
        "zeta_h": r"\zeta_h",
        "zeta_p": r"\zeta_p",
        "zeta_g": r"\zeta_g",
        "mu_p": r"\mu_p",
        "mu_g": r"\mu_g",
        "kappa_p": r"\kappa_p",
        "kappa_g": r"\kappa_g",
        "b_h": r"\bar{b}_h",
        "b_p": r"\bar{b}_p",
        "b_g": r"\bar{b}_g",
        "eps": r"\varepsilon",
        "f_mean": r"\bar{F}_m",
        "f_alt": r"\bar{F}_a",
    }

    def __post_init__(self) -> None:
        for name in ("zeta_h", "zeta_p", "zeta_g", "b_h", "b_p", "b_g"):
            _check(name, getattr(self, name), 0.0, False)
        for name in ("mu_p", "mu_g", "kappa_p", "kappa_g"):
            _check(name, getattr(self, name), 0.0, True)
        _check("f_mean", self.f_mean, -math.inf, False)
        _check("f_alt", self.f_alt, -math.inf, False)
        eps = _check("eps", self.eps, 0.0, False)
        if eps >= 1.0:
            raise ParameterError(
                f"eps must be in [0, 1) (stiffness would turn negative): got {eps}"
            )

    @property
    def switch_widths(self) -> np.ndarray:
        """The half clearances of the three dead zones, in the order of the tracked
        observables (q̄1: pinion bearing, q̄2: gear bearing, q̄3: mesh)."""
        return np.array([self.b_p, self.b_g, self.b_h])

    @property
    def contacts(self) -> tuple[Contact, ...]:
        return (
            Contact("mesh", 2, self.b_h, "mesh"),
            Contact("bearing_p", 0, self.b_p, "bearing"),
            Contact("bearing_g", 1, self.b_g, "bearing"),
        )

    def pack(self, omega: float) -> np.ndarray:
        p = np.empty(N_PARAMS)
        p[OMEGA] = omega
        p[ZETA_H], p[ZETA_P], p[ZETA_G] = self.zeta_h, self.zeta_p, self.zeta_g
        p[MU_P], p[MU_G] = self.mu_p, self.mu_g
        p[KAPPA_P], p[KAPPA_G] = self.kappa_p, self.kappa_g
        p[B_H], p[B_P], p[B_G] = self.b_h, self.b_p, self.b_g
        p[EPS], p[F_MEAN], p[F_ALT] = self.eps, self.f_mean, self.f_alt
        return p

    def static_equilibrium(self) -> np.ndarray:
        """The state at rest under the mean load (ε = 0, F̄_a = 0; module docstring): the
        mesh carries w̄ = F̄_m, the pinion bearing −F̄_m and the gear bearing F̄_m."""
        f = self.f_mean
        return np.array(
            [
                -_deflected(f / self.kappa_p, self.b_p),
                _deflected(f / self.kappa_g, self.b_g),
                _deflected(f, self.b_h),
                0.0,
                0.0,
                0.0,
            ]
        )


def _deflected(force_over_stiffness: float, b: float) -> float:
    """The x with f(x; b) = force/stiffness (the middle of the clearance for no force)."""
    return (
        math.copysign(b, force_over_stiffness) + force_over_stiffness
        if force_over_stiffness
        else 0.0
    )


def _check(name: str, value: float, lo: float, lo_open: bool) -> float:
    """A finite real number above ``lo`` (or at it, unless ``lo_open``)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise ParameterError(f"{name} must be a number: got {value!r}")
    v = float(value)
    if not math.isfinite(v) or v < lo or (lo_open and v == lo):
        rule = f"> {lo}" if lo_open else f">= {lo}"
        raise ParameterError(f"{name} must be a finite number {rule}: got {value!r}")
    return v
