"""Finding and locating the events between two consecutive points of a continued branch.

The test functions of :mod:`gearchaos.dynamics.continuation.events` are compared at the two points;
every sign change is located by the Illinois iteration on the arclength σ from the first point,
each trial point corrected onto the branch, until the bracket is shorter than the event
tolerance (default: range × the corrector's residual tolerance — a state change of that
relative size counts as that much arclength in the weighted norm, so a shorter bracket would
resolve nothing the corrector resolves).

Every event carries its location **uncertainty** in the parameter,

    u = |dλ/ds| (h + 2 δs) + 2 |λ_c − λ_e|,    δs = |f(z_c) − f(z_e)| / |df/ds|,

h the half-width of the final bracket (the root-finding error); z_c = (y_c, λ_c) the event
point z_e corrected again onto the same hyperplane (normal to the tangent) with rtol and atol a
hundred times smaller, where the integrator's error is about 1 % of that at rtol. The
integrator's error moves the event two ways: along the branch, δs, the change of the test
function f divided by its slope between the two branch points; and the branch itself, λ_c −
λ_e (at a fold, where the hyperplane leaves λ free, this is the whole error: dλ/ds = 0 there).
The factors 2 cover the check's own error and a secant slope that differs from the slope at
the event. |dλ/ds| is bounded by the larger |dλ/ds| of the two points.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from ...integrate.settings import RTOL_RANGE
from ..orbits.corrector import Solution, Start, correct
from ..orbits.orbit import contact_levels, default_tol, orbit_contacts
from . import events as ev

__all__ = ["CHECK_FACTOR", "detect", "location_uncertainty"]

#: The integrator check of an event evaluates its test function again with rtol and atol
#: divided by this factor.
CHECK_FACTOR = 100.0


def contact_tests(br: Any, p: Solution) -> dict[tuple[str, str], float]:
    """Grazing test functions at p, against the clearances at p's parameter value (the
    continued parameter may be a clearance)."""
    levels = contact_levels(br.system(p.lam))
    return ev.contact_tests(levels, p.shot.obs_min[0], p.shot.obs_max[0])


def _regime(br: Any, p: Solution, key: tuple[str, str]) -> str:
    regimes = orbit_contacts(br.system(p.lam), p.shot.obs_min[0], p.shot.obs_max[0])
    return regimes[key[0]]


def detect(br: Any, p: Solution, q: Solution, index: int) -> list[ev.Event]:
    """The events between consecutive points p and q of ``br`` (a continuation's branch),
    located and with their uncertainty; ``index`` is p's index on the branch."""
    assert p.tangent is not None and q.tangent is not None
    found = []
    ta = contact_tests(br, p)
    tb = contact_tests(br, q)
    grazing = ev.contact_changes(ta, tb)
    for group in grazing:
        key = group[0]

        def fn(pt: Solution | None, key: tuple[str, str] = key) -> float | None:
            return None if pt is None else contact_tests(br, pt)[key]

        names = ",".join(k[0] for k in group)
        detail = f"{names}: {_regime(br, p, key)} → {_regime(br, q, key)}"
        found.append(locate(br, "grazing", fn, p, q, ta[key], tb[key], detail))
    changes = ev.multiplier_changes(p.mu, q.mu, float(p.tangent[-1]), float(q.tangent[-1]))
    if br.switched and index == 0:
        # a branch switched at a bifurcation starts where a multiplier is +1 (μ² of the
        # period-n orbit's −1, or the branch point's +1): that is where it came from
        changes = [c for c in changes if c[1] != "fold"]
    for kind, test in changes:

        def mfn(pt: Solution | None, test: str = test) -> float | None:
            return None if pt is None else ev.multiplier_tests(pt.mu)[test]

        fa = ev.multiplier_tests(p.mu)[test]
        fb = ev.multiplier_tests(q.mu)[test]
        note = "in the same step as a grazing" if grazing else ""
        found.append(locate(br, kind, mfn, p, q, fa, fb, note))
    return [ev.Event(**{**e, "point": index}) for e in found]


def locate(
    br: Any,
    kind: str,
    fn: Any,
    p: Solution,
    q: Solution,
    fa: float,
    fb: float,
    detail: str,
) -> dict[str, Any]:
    """The fields of the :class:`~gearchaos.dynamics.continuation.events.Event` where ``fn``
    (the test function of a corrected point) changes sign between p and q."""
    assert p.tangent is not None and q.tangent is not None
    span = q.s - p.s  # q's coordinate along p's tangent
    cache: dict[float, Solution | None] = {}

    def g(sigma: float) -> float | None:
        pt = br.at_arclength(p, sigma)
        cache[sigma] = pt
        return fn(pt)

    sigma, ok, (lo, hi) = ev.illinois(g, 0.0, span, fa, fb, br.steps.event_tol)
    pt = br.at_arclength(p, sigma)
    if pt is None:  # fall back to the nearest corrected trial point
        good = {s: v for s, v in cache.items() if v is not None}
        if not good:
            pt, sigma, ok, lo, hi = p, 0.0, False, 0.0, span
        else:
            sigma = min(good, key=lambda s: abs(s - sigma))
            pt = good[sigma]
            ok, lo, hi = False, min(lo, sigma), max(hi, sigma)
    assert pt is not None
    check = check_point(br, p, pt)
    f_e = fn(pt)
    f_check = fn(check) if check is not None else None
    dlam_ds = max(abs(float(p.tangent[-1])), abs(float(q.tangent[-1])))
    u = location_uncertainty(
        max(sigma - lo, hi - sigma),
        math.nan if f_e is None or f_check is None else abs(f_check - f_e),
        abs(fb - fa) / span if span > 0 else math.nan,
        dlam_ds,
        span,
    ) + (2.0 * abs(check.lam - pt.lam) if check is not None else 0.0)
    mu_c = ev.critical_multiplier(kind, pt.mu)
    vec = ev.eigenvector(pt.monodromy, mu_c) if kind != "grazing" else np.zeros(pt.y.size)
    return {
        "kind": kind,
        "parameter": br.name,
        "value": pt.lam,
        "arclength": p.s + sigma,
        "multiplier": mu_c,
        "state": pt.y.copy(),
        "vector": vec,
        "period": br.n,
        "detail": detail,
        "located": ok,
        "uncertainty": u,
        "values": {k: float(v) for k, v in br.fixed.items() if _is_number(v)},
    }


def check_point(br: Any, p: Solution, pt: Solution) -> Solution | None:
    """``pt`` corrected again on its hyperplane (normal to p's tangent: well posed at a fold,
    where a fixed parameter value is not) with rtol and atol divided by
    :data:`CHECK_FACTOR` (None when that fails; ``pt`` itself when rtol is already at its
    floor)."""
    cfg = br.cfg
    rtol = max(float(cfg.rtol) / CHECK_FACTOR, RTOL_RANGE[0])
    if rtol >= float(cfg.rtol):
        return pt
    fine = replace(cfg, rtol=rtol, atol=float(cfg.atol) / CHECK_FACTOR)
    prob = replace(br.prob, settings=fine, tol=default_tol(fine), fd_step=0.0)  # G_λ: pt's
    assert p.tangent is not None
    normal = br.weight(p.tangent)
    z = pt.z
    sol, _ = correct(prob, Start(br.system, z, normal, float(normal @ z), pt.monodromy, pt.g_lam))
    if sol is not None:
        br.evals += sol.evals
        br.jacobians += sol.jacobians
    return sol


def location_uncertainty(
    half_width: float, df: float, slope: float, dlam_ds: float, span: float
) -> float:
    """u = |dλ/ds| (h + 2 δs) of the module docstring: ``half_width`` h and the step ``span``
    in arclength, ``df`` the integrator's error of the test function at the event, ``slope``
    |df/ds| between the two points, ``dlam_ds`` the bound of |dλ/ds|. A missing check (NaN
    ``df``) or a flat test function counts 2 δs as the whole step."""
    if math.isfinite(df) and math.isfinite(slope) and slope > 0:
        ds = min(2.0 * df / slope, span)
    else:
        ds = span
    return float(dlam_ds * (half_width + ds))


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)
