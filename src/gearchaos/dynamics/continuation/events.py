"""Bifurcation and grazing events along a continued branch of periodic orbits.

Between two consecutive branch points the Floquet multipliers μ and the contact regimes are
compared through test functions that change sign at an event:

=====================  ==========================================  ===========================
kind                   test function                               meaning
=====================  ==========================================  ===========================
``fold``               det(M − I) = Π(μ − 1), and dλ/ds changes    a real μ through +1 where
                       sign                                        the branch turns back
``branch_point``       det(M − I), dλ/ds keeps its sign            a real μ through +1 without
                                                                   a turn: a pitchfork or
                                                                   transcritical (symmetry
                                                                   breaking) branch point
``period_doubling``    det(M + I) = Π(μ + 1)                       a real μ through −1
``neimark_sacker``     |μ_c| − 1 for the complex μ_c nearest the   a complex pair through the
                       unit circle, when the number of unstable    unit circle (the seed's
                       complex μ changes with the number of        "Hopf")
                       unstable μ
``grazing``            δ_min ∓ b of a mesh, x_max − b or x_min + b  a contact regime changes:
                       of the sun bearing                          a tooth pair or the bearing
                                                                   starts (or stops) touching
=====================  ==========================================  ===========================

Each sign change is located by the Illinois (modified regula falsi) iteration on the arclength
between the two points, every trial point corrected onto the branch
(:mod:`gearchaos.dynamics.continuation.locate` does that), to a tolerance in arclength; every event
carries its location uncertainty in the parameter.
Grazing makes the stroboscopic map only C¹, so the multipliers may change steeply (not
smoothly) across a grazing event; a multiplier test that changes sign in the same step as a
grazing is still reported, with ``detail`` saying so.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import ParameterError

__all__ = [
    "EVENT_KINDS",
    "Event",
    "critical_multiplier",
    "events",
    "illinois",
    "multiplier_tests",
]

#: Event kinds, in the order of the module table.
EVENT_KINDS = ("fold", "branch_point", "period_doubling", "neimark_sacker", "grazing")

#: A multiplier counts as complex when |Im μ| exceeds this fraction of |μ| (and 1e-12).
COMPLEX_TOL = 1e-7


@dataclass(frozen=True, eq=False)
class Event:
    """One located event of a branch.

    Attributes
    ----------
    kind
        One of :data:`EVENT_KINDS`.
    parameter
        The continued parameter's name.
    value
        The parameter value where the test function vanishes.
    point
        Index of the branch point just before the event.
    arclength
        The branch's arclength at the event.
    multiplier
        The critical multiplier (+1, −1 or the complex one at the unit circle);
        NaN for grazing.
    state
        The orbit's section state at the event.
    vector
        A real eigenvector of the monodromy matrix for the critical multiplier (the real
        part of the complex one for Neimark–Sacker; zeros for grazing).
    period
        The period n of the branch (in forcing periods).
    detail
        Contacts and regimes that change (grazing), or remarks.
    located
        Whether the location converged to the tolerance.
    uncertainty
        The location uncertainty in the parameter: the final bracket's half-width and the
        shift the integrator's error of the test function causes
        (:mod:`gearchaos.dynamics.continuation.locate`); NaN for branch files written before it was
        stored.
    values
        The branch's fixed numeric parameter values by dotted name (its store's ``fixed``).
    """

    kind: str
    parameter: str
    value: float
    point: int
    arclength: float
    multiplier: complex
    state: np.ndarray
    vector: np.ndarray
    period: int
    detail: str = ""
    located: bool = True
    uncertainty: float = math.nan
    values: dict[str, float] = field(default_factory=dict)

    def __repr__(self) -> str:
        mu = "" if self.kind == "grazing" else f", μ={self.multiplier:.4g}"
        extra = f", {self.detail}" if self.detail else ""
        pm = f" ± {self.uncertainty:.1g}" if math.isfinite(self.uncertainty) else ""
        return (
            f"Event({self.kind} at {self.parameter}={self.value:.10g}{pm}, "
            f"period {self.period}{mu}{extra})"
        )


# ------------------------------------------------------------------------------ test functions
def _is_complex(mu: np.ndarray) -> np.ndarray:
    return np.abs(mu.imag) > np.maximum(COMPLEX_TOL * np.abs(mu), 1e-12)


def multiplier_tests(mu: np.ndarray) -> dict[str, float]:
    """The multiplier test functions of one point: ``fold`` det(M − I), ``period_doubling``
    det(M + I) (both as products of the multipliers), ``neimark_sacker`` |μ_c| − 1 of the
    complex multiplier nearest the unit circle (NaN without complex ones), and the counts
    ``unstable`` and ``unstable_complex`` of multipliers outside the unit circle."""
    mu = np.asarray(mu, dtype=complex)
    cplx = _is_complex(mu)
    out = {
        "fold": float(np.prod(mu - 1.0).real),
        "period_doubling": float(np.prod(mu + 1.0).real),
        "unstable": float(np.sum(np.abs(mu) > 1.0)),
        "unstable_complex": float(np.sum(cplx & (np.abs(mu) > 1.0))),
        "neimark_sacker": math.nan,
    }
    if np.any(cplx):
        mods = np.abs(mu[cplx]) - 1.0
        out["neimark_sacker"] = float(mods[np.argmin(np.abs(mods))])
    return out


def critical_multiplier(kind: str, mu: np.ndarray) -> complex:
    """The multiplier of ``kind`` (the nearest to +1, to −1 or, for Neimark–Sacker, the
    complex one with Im μ > 0 nearest the unit circle)."""
    mu = np.asarray(mu, dtype=complex)
    if kind in ("fold", "branch_point"):
        return complex(mu[np.argmin(np.abs(mu - 1.0))])
    if kind == "period_doubling":
        return complex(mu[np.argmin(np.abs(mu + 1.0))])
    if kind == "neimark_sacker":
        cplx = _is_complex(mu) & (mu.imag > 0)
        if not np.any(cplx):
            return complex(math.nan, math.nan)
        cand = mu[cplx]
        return complex(cand[np.argmin(np.abs(np.abs(cand) - 1.0))])
    return complex(math.nan, math.nan)


def eigenvector(monodromy: np.ndarray, mu: complex) -> np.ndarray:
    """A real unit eigenvector of ``monodromy`` for the eigenvalue nearest ``mu`` (the real
    part, normalised, of a complex one)."""
    if not np.isfinite(mu):
        return np.zeros(monodromy.shape[0])
    w, v = np.linalg.eig(monodromy)
    k = int(np.argmin(np.abs(w - mu)))
    vec = v[:, k]
    # rotate the complex vector so that its largest entry is real, then take the real part
    j = int(np.argmax(np.abs(vec)))
    vec = vec * np.exp(-1j * np.angle(vec[j]))
    r = np.real(vec)
    nrm = float(np.linalg.norm(r))
    return r / nrm if nrm > 0 else r


def multiplier_changes(
    mu_a: np.ndarray, mu_b: np.ndarray, tlam_a: float, tlam_b: float
) -> list[tuple[str, str]]:
    """Multiplier events between two points: (kind, test function name)."""
    a, b = multiplier_tests(mu_a), multiplier_tests(mu_b)
    out = []
    if a["fold"] * b["fold"] < 0:
        kind = "fold" if tlam_a * tlam_b < 0 else "branch_point"
        out.append((kind, "fold"))
    if a["period_doubling"] * b["period_doubling"] < 0:
        out.append(("period_doubling", "period_doubling"))
    dc = b["unstable_complex"] - a["unstable_complex"]
    du = b["unstable"] - a["unstable"]
    if dc != 0 and dc == du and a["neimark_sacker"] * b["neimark_sacker"] < 0:
        out.append(("neimark_sacker", "neimark_sacker"))
    return out


def contact_tests(
    levels: Sequence[tuple[str, int, float, str]],
    lo: np.ndarray,
    hi: np.ndarray,
) -> dict[tuple[str, str], float]:
    """Grazing test functions of one point: for a mesh δ_min − b (``drive``) and δ_min + b
    (``back``); for a bearing x_max − b (``positive``) and x_min + b (``negative``)."""
    out = {}
    for name, k, b, what in levels:
        if what == "mesh":
            out[(name, "drive")] = float(lo[k] - b)
            out[(name, "back")] = float(lo[k] + b)
        else:
            out[(name, "positive")] = float(hi[k] - b)
            out[(name, "negative")] = float(lo[k] + b)
    return out


def contact_changes(
    ta: dict[tuple[str, str], float], tb: dict[tuple[str, str], float]
) -> list[list[tuple[str, str]]]:
    """Grazing crossings between two points, grouped: contacts whose test values agree at
    both points (symmetric planets) form one group, located once."""
    crossed = [key for key in ta if ta[key] * tb[key] < 0 or (ta[key] != 0 and tb[key] == 0)]
    groups: list[list[tuple[str, str]]] = []
    for key in crossed:
        for grp in groups:
            ref = grp[0]
            same = ref[1] == key[1] and all(
                abs(t[ref] - t[key]) <= 1e-9 * (1.0 + abs(t[ref])) for t in (ta, tb)
            )
            if same:
                grp.append(key)
                break
        else:
            groups.append([key])
    return groups


# ------------------------------------------------------------------------------ location
def illinois(
    fn: Callable[[float], float | None],
    lo: float,
    hi: float,
    f_lo: float,
    f_hi: float,
    tol: float,
    max_evaluations: int = 40,
) -> tuple[float, bool, tuple[float, float]]:
    """A root of ``fn`` in [lo, hi] (f_lo·f_hi < 0) by the Illinois iteration, stopping when
    the bracket is shorter than ``tol``; ``fn`` returning None (a failed evaluation) falls
    back to bisection. Returns (root, converged, final bracket): the root is the bracket's
    midpoint, or a trial point where ``fn`` is exactly 0."""
    side = 0
    for _ in range(max_evaluations):
        if hi - lo <= tol:
            return 0.5 * (lo + hi), True, (lo, hi)
        if f_hi != f_lo and math.isfinite(f_hi - f_lo):
            x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
        else:
            x = 0.5 * (lo + hi)
        # keep the trial strictly inside, away from the ends by a fraction of the tolerance
        x = min(max(x, lo + 0.25 * tol), hi - 0.25 * tol)
        fx = fn(x)
        if fx is None or not math.isfinite(fx):
            fx2 = fn(0.5 * (lo + hi))
            if fx2 is None or not math.isfinite(fx2):
                return 0.5 * (lo + hi), False, (lo, hi)
            x, fx = 0.5 * (lo + hi), fx2
        if fx == 0.0:
            return x, True, (x, x)
        if (fx > 0) == (f_hi > 0):
            hi, f_hi = x, fx
            if side == -1:
                f_lo *= 0.5
            side = -1
        else:
            lo, f_lo = x, fx
            if side == 1:
                f_hi *= 0.5
            side = 1
    return 0.5 * (lo + hi), hi - lo <= tol, (lo, hi)


# ------------------------------------------------------------------------------ reading
def events(ds: Any) -> list[Event]:
    """The events of a continuation dataset (or of a file opened with
    :func:`gearchaos.dynamics.open_branch`) as :class:`Event` objects, in the
    order of the ``event`` dimension."""
    if "event" not in ds.dims:
        return []
    name = str(ds.attrs.get("parameter", ""))
    if not name:
        raise ParameterError("ds is not a continuation dataset: it has no 'parameter' attribute")
    out = []
    for k in range(ds.sizes["event"]):
        row = ds.isel(event=k)
        out.append(
            Event(
                kind=str(row["event_kind"].values),
                parameter=name,
                value=float(row["event_value"].values),
                point=int(row["event_point"].values),
                arclength=float(row["event_arclength"].values),
                multiplier=complex(
                    float(row["event_multiplier_re"].values),
                    float(row["event_multiplier_im"].values),
                ),
                state=np.asarray(row["event_state"].values, dtype=np.float64),
                vector=np.asarray(row["event_vector"].values, dtype=np.float64),
                period=int(ds.attrs.get("period", 1)),
                detail=str(row["event_detail"].values),
                located=bool(int(row["event_located"].values)),
                uncertainty=(
                    float(row["event_uncertainty"].values)
                    if "event_uncertainty" in ds
                    else math.nan
                ),
                values=_fixed_values(ds),
            )
        )
    return out


def _fixed_values(ds: Any) -> dict[str, float]:
    import json

    try:
        fixed = json.loads(str(ds.attrs.get("fixed", "{}")))
    except ValueError:
        return {}
    return {str(k): float(v) for k, v in fixed.items() if isinstance(v, int | float)}
