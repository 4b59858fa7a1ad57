"""The structural term of the calibration: do the seed's clearances act?

The seed studies how the backlashes shape the motion: "tooth separation, single-sided and
double-sided impact occur in the most area of chaotic and multiple periodic motion state", and
its Figs. 6–11 sweep b̄_sp and b̄_rp. A gear set whose meshes never reach their back flanks has
backlash sweeps that are constants (issue 34). Two measurements say whether they act:

double-sided impact (``double_sided``)
    Over the points of the backlash sweeps (axes b̄_sp, b̄_rp) labelled chaos or nT with
    n ≥ 2 — the chaotic and multi-periodic regions — the fraction where some mesh reaches its
    back flank: a stored contact regime ``contact_sp`` or ``contact_rp`` (:func:`gearchaos.
    sweep.classify`'s codes from the tracked minimum deflections: 2 = double-sided) equals 2
    on some planet. 0 when the sweeps have no such point.
multipliers that change (``multipliers``)
    The period-1 branch continued over b̄_sp ∈ [1, 10] (Fig. 8's recipe) and over
    b̄_rp ∈ [1, 11] (Fig. 11's), at ξ = 0.11 and Ω = 1 and 1.5
    (:func:`gearchaos.continuation`, coarse steps, no cascade). A branch scores 1 when an event
    lies on it or its largest multiplier modulus max|μ| changes by ≥ :data:`MU_CHANGE` = 10⁻³
    along it; below, ``log10(Δ/10⁻⁶)/3`` clipped to [0, 1] (a change of 10⁻⁶ — solver noise —
    scores 0). A branch that cannot start at either end scores 0.

``structure = (double_sided + mean branch score) / 2`` in [0, 1].

Cost: four branches of at most :data:`BRANCH_POINTS` points, a few seconds in all; the contact
regimes come with the sweeps.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..analysis.motion import Motion, MotionKind
from ..model.target import Target

__all__ = [
    "BACKLASH_AXES",
    "BRANCHES",
    "MU_CHANGE",
    "branch_score",
    "clearance_problems",
    "double_sided_share",
    "multiplier_change",
    "structure_term",
]

#: Swept axes that are backlashes.
BACKLASH_AXES = ("backlash.sun_planet", "backlash.planet_ring")
#: (recipe, Ω) of the continued branches: Fig. 8 over b̄_sp and Fig. 11 over b̄_rp, ξ = 0.11.
BRANCHES = (("fig8", 1.0), ("fig8", 1.5), ("fig11", 1.0), ("fig11", 1.5))
#: A change of max|μ| along a branch at least this large says the backlash acts (issue 34).
MU_CHANGE = 1e-3
#: Change of max|μ| that scores 0 (the continuation's own noise).
MU_NOISE = 1e-6
#: Largest step (range / this) and most points of each branch.
BRANCH_STEPS = 20
BRANCH_POINTS = 60
#: Code of double-sided contact in the stored contact regimes (MODEL.md §8).
DOUBLE_SIDED = 2


def _region(label: str) -> bool:
    """Chaotic or multi-periodic (nT, n ≥ 2)."""
    motion = Motion.parse(label)
    return motion.kind is MotionKind.CHAOS or motion.period >= 2


def double_sided_share(stores: Mapping[str, Any]) -> tuple[float, int, int]:
    """(fraction, double-sided points, points) over the chaotic and multi-periodic points of
    the backlash sweeps among ``stores`` (see the module docstring); (0, 0, 0) without such
    points. A store without stored contact regimes counts no double-sided point."""
    region = double = 0
    for ds in stores.values():
        motion = ds["motion"]
        if not any(a in motion.dims for a in BACKLASH_AXES):
            continue
        labels = np.asarray(motion.values).astype(str)
        inside = np.vectorize(_region, otypes=[bool])(labels) if labels.size else labels
        hit = np.zeros(labels.shape, dtype=bool)
        for var in ("contact_sp", "contact_rp"):
            if var not in ds.data_vars:
                continue
            code = np.asarray(ds[var].transpose(*motion.dims, "planet_all").values)
            hit |= np.any(code == DOUBLE_SIDED, axis=-1)
        region += int(np.count_nonzero(inside))
        double += int(np.count_nonzero(inside & hit))
    return (double / region if region else 0.0), double, region


def branch_score(change: float, events: int) -> float:
    """Score of one continued branch: 1 with an event or a change of max|μ| ≥ :data:`MU_CHANGE`,
    else ``log10(change / MU_NOISE) / 3`` clipped to [0, 1]; 0 for a NaN change."""
    if events > 0:
        return 1.0
    if not math.isfinite(change) or change <= MU_NOISE:
        return 0.0
    return float(min(1.0, math.log10(change / MU_NOISE) / math.log10(MU_CHANGE / MU_NOISE)))


def multiplier_change(
    target: Target, axis: str, lo: float, hi: float, fixed: Mapping[str, Any], settings: Any = None
) -> dict[str, Any]:
    """The period-1 branch over ``axis`` ∈ [lo, hi] at ``fixed``, continued from ``lo`` (from
    ``hi`` when no orbit starts there): ``{"change": max − min of max|μ|, "events": count,
    "kinds": [...], "from": start, "reached": [min, max] of the parameter, "reason": why it
    failed, or ""}``."""
    from ..dynamics.continuation.arclength import continuation
    from ..errors import IntegrationError, ParameterError

    span = hi - lo
    kw: dict[str, Any] = {
        "params": dict(fixed),
        "period": 1,
        "max_step": span / BRANCH_STEPS,
        "step": span / (2 * BRANCH_STEPS),
        "max_points": BRANCH_POINTS,
    }
    if settings is not None:
        kw["settings"] = settings
    reasons = []
    for a, b in ((lo, hi), (hi, lo)):
        try:
            br = continuation(target, (axis, a, b), **kw)
        except (IntegrationError, ParameterError) as exc:
            reasons.append(f"from {a:g}: {exc}")
            continue
        mu = np.asarray(br["max_multiplier"].values, dtype=float)
        mu = mu[np.isfinite(mu)]
        lam = np.asarray(br[axis].values, dtype=float)
        kinds = (
            [str(k) for k in br["event_kind"].values] if "event" in br.dims else []
        )  # fmt: skip
        return {
            "change": float(mu.max() - mu.min()) if mu.size else math.nan,
            "events": len(kinds),
            "kinds": kinds,
            "from": a,
            "reached": [float(lam.min()), float(lam.max())],
            "reason": "",
        }
    return {
        "change": math.nan,
        "events": 0,
        "kinds": [],
        "from": None,
        "reached": None,
        "reason": "; ".join(reasons),
    }


def structure_term(
    target: Target, stores: Mapping[str, Any], settings: Any = None
) -> tuple[float, dict[str, Any]]:
    """(structure in [0, 1], its parts) of gear set ``target`` whose objective sweeps are
    ``stores`` (see the module docstring)."""
    from .recipes import get_recipe

    share, double, region = double_sided_share(stores)
    branches = []
    for fig, omega in BRANCHES:
        rec = get_recipe(fig)
        fixed = {**rec.fixed, rec.family.name: omega}
        found = multiplier_change(
            target, rec.vary.name, rec.vary.start, rec.vary.stop, fixed, settings
        )
        found.update(
            axis=rec.vary.name, omega=omega, score=branch_score(found["change"], found["events"])
        )
        branches.append(found)
    mean = float(np.mean([b["score"] for b in branches]))
    parts = {
        "double_sided": share,
        "double_sided_points": double,
        "region_points": region,
        "multipliers": mean,
        "branches": branches,
    }
    return 0.5 * (share + mean), parts


def clearance_problems(record: Mapping[str, Any]) -> list[str]:
    """Why the clearances of a calibration record's gear set do not act everywhere the seed
    says they do (issue 34): a continued branch of :data:`BRANCHES` along which max|μ| changes
    by less than :data:`MU_CHANGE` with no event, or no double-sided impact in the chaotic and
    multi-periodic regions of the backlash sweeps. Empty when they act; a record without the
    structural parts (a calibration before issue 34) gives one reason saying so."""
    parts = record.get("parts")
    if not isinstance(parts, Mapping) or not isinstance(parts.get("branches"), list):
        return ["no structural measurements in the record (a calibration before issue 34)"]
    why = []
    for b in parts["branches"]:
        if b.get("score", 0.0) < 1.0:
            why.append(
                f"{b.get('axis')} at Ω = {b.get('omega')}: max|μ| changes by "
                f"{float(b.get('change', math.nan)):.2g} with no event"
                + (f" ({b['reason']})" if b.get("reason") else "")
            )
    if not parts.get("double_sided_points"):
        why.append(
            "no double-sided impact in the backlash sweeps' chaotic and multi-periodic points"
        )
    return why
