"""Defining test functions of two-parameter boundary curves, and their codimension-2 points.

A boundary curve (:mod:`gearchaos.dynamics.curves.tracing`) is the set of (y, λ₁, λ₂) where

    Pⁿ(y) − y = 0    and    g(y, λ₁, λ₂) = 0,

g a scalar test function that vanishes at the event being continued:

=====================  ==========================================================================
kind                   g
=====================  ==========================================================================
``fold``               the bordered (minimally augmented) test function of A = M − I: the last
                       component of the solution of [[A, b], [cᵀ, 0]] (v, g) = (0, 1), with b
                       and c the left and right singular vectors of A's smallest singular value
                       at the previous curve point (Govaerts, *Numerical Methods for
                       Bifurcations of Dynamical Equilibria*, SIAM 2000, §4.4). g is a smooth
                       function that changes sign where A turns singular, as well-scaled as
                       σ_min(A) (det(M − I) is not: it scales with every other multiplier).
``period_doubling``    the same with A = M + I (a real multiplier at −1).
``neimark_sacker``     |μ_c|² − 1 of the complex multiplier μ_c (Im μ_c > 0) nearest the one of
                       the previous curve point (followed by continuity, not by modulus).
``grazing``            the contact gap of the event's contact over the orbit, from the extrema
                       the kernel tracks: δ_min − b̄ (drive flank) or δ_min + b̄ (back flank) of
                       a mesh, x_max − b̄ or x_min + b̄ of a bearing
                       (:func:`gearchaos.dynamics.continuation.events.contact_tests`).
=====================  ==========================================================================

Codimension-2 points are sign changes, between two consecutive curve points, of the functions
of :func:`codim2_tests` (each located by the Illinois iteration on the curve, see
:mod:`gearchaos.dynamics.curves.tracing`), and the cusp of a fold curve, where the curve's tangent
projected on the parameter plane (dλ₁/ds, dλ₂/ds) reverses (the projection has a cusp there: the
tangent is purely in the state directions):

=================  ==========================  ==================================================
curve              codimension-2 point         test that changes sign
=================  ==========================  ==================================================
fold               ``cusp``                    (λ₁', λ₂')ₖ · (λ₁', λ₂')ₖ₊₁ (projected tangent)
fold               ``fold_flip``               Π(μ + 1) (another multiplier through −1)
fold               ``resonance_1_1``           Π(μ − 1) over the non-critical multipliers (a
                                               second multiplier through +1: Bogdanov–Takens
                                               of the map)
period_doubling    ``fold_flip``               Π(μ − 1) (a multiplier through +1)
period_doubling    ``resonance_1_2``           Π(μ + 1) over the non-critical multipliers
period_doubling    ``flip_neimark_sacker``     |μ_c| − 1 of the complex pair nearest the circle
neimark_sacker     ``resonance_1_1``/``1_2``   the pair turns real at +1 / −1 (Im μ_c → 0)
neimark_sacker     ``resonance_1_3``/``1_4``   arg μ_c − 2π/3, arg μ_c − π/2
neimark_sacker     ``fold_neimark_sacker``     Π(μ − 1)
neimark_sacker     ``flip_neimark_sacker``     Π(μ + 1)
grazing            ``grazing_fold``            Π(μ − 1) (grazing meets a fold)
grazing            ``grazing_period_doubling`` Π(μ + 1)
grazing            ``grazing_neimark_sacker``  |μ_c| − 1 of the complex pair nearest the circle
=================  ==========================  ==================================================

Limits: degenerate period doublings and Neimark–Sacker points (a zero of the normal form's cubic
coefficient, where the bifurcation turns from super- to subcritical) need third derivatives of
the map and are not detected; the grazing curve of a piecewise-smooth map is continued like the
smooth ones (the map is C¹ there, so Newton's method converges, more slowly than quadratically).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import ParameterError
from ..continuation import events as ev

__all__ = ["CODIM2_KINDS", "CURVE_KINDS", "TestFunction", "codim2_tests"]

#: Event kinds whose boundary curves can be continued.
CURVE_KINDS = ("fold", "period_doubling", "neimark_sacker", "grazing")

#: Codimension-2 points each curve kind reports (see the module table).
CODIM2_KINDS: dict[str, tuple[str, ...]] = {
    "fold": ("cusp", "fold_flip", "resonance_1_1"),
    "period_doubling": ("fold_flip", "resonance_1_2", "flip_neimark_sacker"),
    "neimark_sacker": (
        "resonance_1_1",
        "resonance_1_2",
        "resonance_1_3",
        "resonance_1_4",
        "fold_neimark_sacker",
        "flip_neimark_sacker",
    ),
    "grazing": ("grazing_fold", "grazing_period_doubling", "grazing_neimark_sacker"),
}


def _bordered(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
    m = a.shape[0]
    k = np.zeros((m + 1, m + 1))
    k[:m, :m] = a
    k[:m, m] = b
    k[m, :m] = c
    rhs = np.zeros(m + 1)
    rhs[m] = 1.0
    try:
        return float(np.linalg.solve(k, rhs)[m])
    except np.linalg.LinAlgError:
        return math.nan


@dataclass
class TestFunction:
    """The defining test function g of one curve kind (module table), with the data it carries
    from point to point (the borders b, c; the followed complex multiplier; the contact)."""

    kind: str
    contact: tuple[str, str] | None = None
    b: np.ndarray = field(default_factory=lambda: np.zeros(0))
    c: np.ndarray = field(default_factory=lambda: np.zeros(0))
    mu_ref: complex = complex(math.nan, math.nan)

    def __post_init__(self) -> None:
        if self.kind not in CURVE_KINDS:
            raise ParameterError(
                f"event kind must be one of {', '.join(CURVE_KINDS)} to continue its boundary "
                f"curve: got {self.kind!r}"
            )

    def shift(self) -> float:
        return 1.0 if self.kind == "fold" else -1.0

    def adapt(self, monodromy: np.ndarray, mu: np.ndarray) -> None:
        """Borders and reference multiplier at an accepted curve point (kept fixed while the
        next point is corrected: the zero set of g does not depend on them)."""
        if self.kind in ("fold", "period_doubling"):
            a = monodromy - self.shift() * np.eye(monodromy.shape[0])
            u, _, vt = np.linalg.svd(a)
            self.b, self.c = u[:, -1].copy(), vt[-1].copy()
        elif self.kind == "neimark_sacker":
            self.mu_ref = ev.critical_multiplier("neimark_sacker", mu)

    def value(
        self, monodromy: np.ndarray, mu: np.ndarray | None, tests: dict[tuple[str, str], float]
    ) -> float:
        """g at one point: its monodromy (and multipliers) and its grazing tests."""
        if self.kind in ("fold", "period_doubling"):
            a = monodromy - self.shift() * np.eye(monodromy.shape[0])
            return _bordered(a, self.b, self.c)
        if self.kind == "grazing":
            assert self.contact is not None
            return float(tests[self.contact])
        if mu is None:
            mu = np.linalg.eigvals(monodromy)
        mu_c = self.critical(mu)
        return float(abs(mu_c) ** 2 - 1.0) if np.isfinite(mu_c) else math.nan

    def critical(self, mu: np.ndarray) -> complex:
        """The critical multiplier at a curve point: nearest +1, −1, the followed complex one,
        or NaN for grazing."""
        mu = np.asarray(mu, dtype=complex)
        if self.kind == "neimark_sacker":
            cplx = ev._is_complex(mu) & (mu.imag > 0)
            if not np.any(cplx):
                return complex(math.nan, math.nan)
            cand = mu[cplx]
            ref = self.mu_ref if np.isfinite(self.mu_ref) else cand[0]
            return complex(cand[np.argmin(np.abs(cand - ref))])
        return ev.critical_multiplier(self.kind, mu)


def _others(mu: np.ndarray, crit: complex) -> np.ndarray:
    """The multipliers without the critical one (and its conjugate)."""
    mu = np.asarray(mu, dtype=complex)
    if not np.isfinite(crit):
        return mu
    keep = np.ones(mu.size, dtype=bool)
    keep[int(np.argmin(np.abs(mu - crit)))] = False
    if abs(crit.imag) > 0:
        rest = np.where(keep)[0]
        keep[rest[int(np.argmin(np.abs(mu[rest] - np.conj(crit))))]] = False
    return mu[keep]


def _pair_modulus(mu: np.ndarray) -> float:
    cplx = ev._is_complex(mu)
    if not np.any(cplx):
        return math.nan
    mods = np.abs(mu[cplx]) - 1.0
    return float(mods[np.argmin(np.abs(mods))])


def codim2_tests(fn: TestFunction, mu: np.ndarray) -> dict[str, float]:
    """The multiplier tests of the codimension-2 points of ``fn.kind`` at one curve point
    (module table; the cusp is tested on the tangents instead). NaN: not defined here."""
    mu = np.asarray(mu, dtype=complex)
    crit = fn.critical(mu)
    rest = _others(mu, crit)
    fold = float(np.prod(mu - 1.0).real)
    flip = float(np.prod(mu + 1.0).real)
    if fn.kind == "fold":
        return {"fold_flip": flip, "resonance_1_1": float(np.prod(rest - 1.0).real)}
    if fn.kind == "period_doubling":
        return {
            "fold_flip": fold,
            "resonance_1_2": float(np.prod(rest + 1.0).real),
            "flip_neimark_sacker": _pair_modulus(rest),
        }
    if fn.kind == "neimark_sacker":
        theta = float(abs(np.angle(crit))) if np.isfinite(crit) else math.nan
        return {
            "resonance_1_1": theta if theta < 0.5 else math.nan,
            "resonance_1_2": math.pi - theta if theta > math.pi - 0.5 else math.nan,
            "resonance_1_3": theta - 2.0 * math.pi / 3.0,
            "resonance_1_4": theta - 0.5 * math.pi,
            "fold_neimark_sacker": float(np.prod(rest - 1.0).real),
            "flip_neimark_sacker": float(np.prod(rest + 1.0).real),
        }
    return {
        "grazing_fold": fold,
        "grazing_period_doubling": flip,
        "grazing_neimark_sacker": _pair_modulus(mu),
    }


def changes(fn: TestFunction, mu_a: np.ndarray, mu_b: np.ndarray) -> list[tuple[str, float, float]]:
    """(codimension-2 kind, test at a, test at b) for each test that changes sign from a to b."""
    ta, tb = codim2_tests(fn, mu_a), codim2_tests(fn, mu_b)
    out = []
    for key, va in ta.items():
        vb = tb[key]
        if math.isfinite(va) and math.isfinite(vb) and va * vb < 0:
            out.append((key, va, vb))
    return out


def grazing_contact(levels: Any, lo: np.ndarray, hi: np.ndarray, detail: str) -> tuple[str, str]:
    """The contact (name, side) of a grazing event: the one whose gap is nearest 0 at the
    event's orbit, among the contacts its ``detail`` names (all when it names none)."""
    tests = ev.contact_tests(levels, lo, hi)
    named = [k for k in tests if k[0] in detail.split(":")[0].split(",")]
    keys = named or list(tests)
    if not keys:
        raise ParameterError("a grazing curve needs a model with contacts: this one has none")
    return min(keys, key=lambda k: abs(tests[k]))
