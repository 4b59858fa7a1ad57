"""Does the swept parameter act? The test behind ``holds (constant)``.

A landmark that holds along an axis on which nothing changes agrees with the seed only because
nothing changes (issue 34: in the ``sheng2016-v1`` set no mesh reaches its back flank and the
sun never reaches its bearing clearance, so the backlash and b̄_s sweeps are constants). For
every panel a landmark is read on (a recipe at one family value) :func:`panel_action` decides
whether the swept parameter acts there:

1. **The clearance is reached on the sweep** (clearance axes only;
   :func:`gearchaos.paper.evidence.clearance_reach`): some mesh of the swept kind reaches its
   back flank (double-sided impact) at some point, or the sun reaches its bearing clearance.
   Then the parameter enters the motion: it *acts*.
2. **A continued branch along the axis** (:func:`branch_action`): the period-1 orbit at a
   representative point — the panel's fixed values and the seed's value of the swept
   parameter (:data:`REPRESENTATIVE`: Ω = 1.5, b̄_sp = 3, b̄_rp = 3.5, b̄_s = 2, the values the
   other figures hold it at) — continued to both ends of the recipe's range
   (:func:`gearchaos.continuation`). It *acts* when its largest multiplier modulus max|μ|
   changes by more than :data:`ACT_THRESHOLD` = 10⁻³ along the branch, or when the branch
   has an event (period doubling, fold, Neimark–Sacker, grazing …); events located on the
   report's own branches of the panel (:mod:`.routes`) count too. Otherwise it is *constant*.
3. **Without a branch** (no period-1 orbit converges at the representative point): a direct
   test on the sweep. A clearance that is never reached and leaves every point's section
   values unchanged (beyond :data:`NOISE` of the panel's largest |X̄_sp1|; for a backlash
   the values less their mean, since a backlash that is never crossed only shifts the
   mesh coordinate) is *constant*; Ω or ξ that change them *act*; anything else is
   *undecided*.

:func:`apply_actions` attaches the answer to every landmark result and turns ``holds`` on a
constant panel into ``holds (constant)``.

Cost: two short branches per panel (at most :data:`BRANCH_POINTS` points each), a few seconds
per panel; the panels run in threads (the kernels release the GIL).
"""

from __future__ import annotations

import concurrent.futures as cf
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from ..model.target import Target
from .evidence import clearance_reach, panels
from .landmark_data import AxisAction, Landmark, LandmarkResult, recipe_for
from .structure import MU_CHANGE

__all__ = [
    "ACT_THRESHOLD",
    "NOISE",
    "REPRESENTATIVE",
    "apply_actions",
    "axis_action",
    "branch_action",
    "landmark_actions",
    "panel_action",
    "section_change",
]

#: A change of max|μ| along the branch larger than this says the parameter acts (issue 34).
ACT_THRESHOLD = MU_CHANGE
#: Section values that differ by less than this fraction of the panel's largest |X̄_sp1| are
#: the same (the integrator's tolerances are 10⁻⁸).
NOISE = 1e-6
#: The value each swept parameter is held at in the seed's other figures: where a panel's
#: branch starts.
REPRESENTATIVE = {
    "omega": 1.5,
    "xi": 0.05,
    "backlash.sun_planet": 3.0,
    "backlash.planet_ring": 3.5,
    "clearance.sun_bearing": 2.0,
}
#: (range / largest step, most points) of each half branch: full and quick reports.
BRANCH_STEPS = {False: (20, 60), True: (8, 16)}
BRANCH_POINTS = BRANCH_STEPS[False][1]
_BACKLASHES = ("backlash.sun_planet", "backlash.planet_ring")
_CLEARANCES = (*_BACKLASHES, "clearance.sun_bearing")


def branch_action(
    target: Target,
    axis: str,
    lo: float,
    hi: float,
    start: float,
    fixed: Mapping[str, Any],
    *,
    quick: bool = False,
    settings: Any = None,
) -> dict[str, Any]:
    """The period-1 branch from ``start`` to ``lo`` and to ``hi`` along ``axis`` at ``fixed``:
    ``{"change": max − min of max|μ| over both halves, "mu": [min, max], "events": count,
    "kinds": [...], "reached": [min, max] of the parameter, "reason": why none started, or
    ""}``."""
    from ..dynamics.continuation.arclength import continuation
    from ..errors import IntegrationError, ParameterError

    steps, points = BRANCH_STEPS[bool(quick)]
    span = hi - lo
    kw: dict[str, Any] = {
        "params": dict(fixed),
        "period": 1,
        "max_step": span / steps,
        "step": span / (2 * steps),
        "max_points": points,
    }
    if settings is not None:
        kw["settings"] = settings
    mus: list[np.ndarray] = []
    lams: list[np.ndarray] = []
    kinds: list[str] = []
    reasons: list[str] = []
    for end in (lo, hi):
        if math.isclose(start, end):
            continue
        try:
            br = continuation(target, (axis, start, end), **kw)
        except (IntegrationError, ParameterError) as exc:
            reasons.append(f"towards {end:g}: {exc}")
            continue
        mus.append(np.asarray(br["max_multiplier"].values, dtype=float))
        lams.append(np.asarray(br[axis].values, dtype=float))
        if "event" in br.dims:
            kinds.extend(str(k) for k in br["event_kind"].values)
    mu = np.concatenate(mus) if mus else np.zeros(0)
    mu = mu[np.isfinite(mu)]
    if mu.size == 0:
        return {
            "change": math.nan,
            "mu": None,
            "events": 0,
            "kinds": [],
            "reached": None,
            "reason": "; ".join(reasons) or "no branch point",
        }
    lam = np.concatenate(lams)
    return {
        "change": float(mu.max() - mu.min()),
        "mu": [float(mu.min()), float(mu.max())],
        "events": len(kinds),
        "kinds": kinds,
        "reached": [float(lam.min()), float(lam.max())],
        "reason": "",
    }


def section_change(
    x: np.ndarray, labels: np.ndarray, sections: np.ndarray, *, centred: bool
) -> float:
    """Largest difference between any computed point's section values (sorted; less their mean
    when ``centred``) and the first point's, relative to the panel's largest |value|: 0 when
    the parameter changes nothing on the recorded motion."""
    lab = np.asarray(labels).astype(str)
    sec = np.asarray(sections, dtype=float)
    keep = (lab != "failed") & np.isfinite(sec).all(axis=1)
    s = np.sort(sec[keep], axis=1)
    if s.shape[0] < 2:
        return math.nan
    if centred:
        s = s - s.mean(axis=1, keepdims=True)
    scale = float(np.max(np.abs(sec[keep])))
    diff = float(np.max(np.abs(s - s[0])))
    return diff / scale if scale > 0 else diff


def _panel_sections(ds: Any, family_value: float | None) -> tuple[Any, Any, Any] | None:
    for fv, x, lab, sec in panels(ds):
        same = (
            fv is None
            if family_value is None
            else fv is not None and math.isclose(fv, family_value)
        )
        if same:
            return (x, lab, sec) if sec is not None else None
    return None


def _event_text(rows: Sequence[Mapping[str, Any]]) -> str:
    shown = ", ".join(f"{r['kind']} at {float(r['value']):.4g}" for r in rows[:4])
    more = f" (+{len(rows) - 4} more)" if len(rows) > 4 else ""
    return shown + more


def panel_action(
    target: Target,
    recipe: str,
    family_value: float | None,
    ds: Any = None,
    *,
    events: Sequence[Mapping[str, Any]] = (),
    quick: bool = False,
    settings: Any = None,
) -> AxisAction:
    """Whether the swept parameter of ``recipe`` acts on its panel ``family_value`` for gear set
    ``target`` (:func:`axis_action` over the recipe's range at the panel's fixed values)."""
    from .recipes import get_recipe

    rec = get_recipe(recipe)
    fixed = dict(rec.fixed)
    if family_value is not None:
        fixed[rec.family.name] = family_value
    return axis_action(
        target,
        rec.vary.name,
        rec.vary.start,
        rec.vary.stop,
        fixed,
        ds=ds,
        family_value=family_value,
        events=events,
        quick=quick,
        settings=settings,
    )


def axis_action(
    target: Target,
    axis: str,
    lo: float,
    hi: float,
    fixed: Mapping[str, Any],
    *,
    ds: Any = None,
    family_value: float | None = None,
    events: Sequence[Mapping[str, Any]] = (),
    start: float | None = None,
    quick: bool = False,
    settings: Any = None,
) -> AxisAction:
    """Whether ``axis`` acts over [``lo``, ``hi``] at ``fixed`` for ``target`` (a gear set or any
    model; see the module docstring). ``ds`` is the sweep (panel ``family_value``) checked for
    contact and used for the direct test; ``events`` the event rows of branches already
    continued along the axis on this panel (:func:`gearchaos.paper.routes.event_rows`);
    ``start`` the branch's start (default :data:`REPRESENTATIVE`, else the middle)."""
    measured: dict[str, Any] = {"axis": axis, "panel": family_value}
    reach = clearance_reach(ds, axis, family_value) if ds is not None else None
    measured["reach"] = reach
    if reach is not None and reach["reached"] > 0:
        what = "a back flank" if axis in _BACKLASHES else "the bearing clearance"
        return AxisAction(
            True,
            f"{what} is reached at {reach['reached']} of {reach['points']} points of the sweep",
            measured,
        )
    found = [r for r in events if r.get("kind") != "branch"]
    if found:
        measured["events"] = [float(r["value"]) for r in found]
        return AxisAction(
            True, f"events on the panel's continued branches: {_event_text(found)}", measured
        )
    if start is None:
        start = REPRESENTATIVE.get(axis, 0.5 * (lo + hi))
    start = min(max(start, lo), hi)
    br = branch_action(target, axis, lo, hi, start, fixed, quick=quick, settings=settings)
    measured["branch"] = {**br, "from": start}
    never = (
        ""
        if reach is None
        else (
            f"; the clearance is never reached on the sweep ({reach['points']} points, "
            f"deepest {reach['depth']:.3g} of it)"
        )
    )
    if not br["reason"]:
        mu_lo, mu_hi = br["mu"]
        head = (
            f"1T branch from {start:g} over [{br['reached'][0]:.4g}, {br['reached'][1]:.4g}]: "
            f"max|μ| {mu_lo:.8g}–{mu_hi:.8g} (change {br['change']:.2g}, threshold "
            f"{ACT_THRESHOLD:g}), {br['events']} event(s)"
        )
        if br["events"]:
            return AxisAction(True, f"{head}: {', '.join(sorted(set(br['kinds'])))}", measured)
        if br["change"] > ACT_THRESHOLD:
            return AxisAction(True, head, measured)
        return AxisAction(False, head + never, measured)
    # no branch: the direct test on the sweep
    got = _panel_sections(ds, family_value) if ds is not None else None
    if got is None:
        why = f"no 1T branch from {start:g} ({br['reason']}) and no section values"
        return AxisAction(None, why, measured)
    x, lab, sec = got
    change = section_change(x, lab, sec, centred=axis in _BACKLASHES)
    measured["section_change"] = change
    head = f"no 1T branch from {start:g} ({br['reason']}); section values change by {change:.2g}"
    if axis not in _CLEARANCES:
        acts = bool(change > NOISE) if math.isfinite(change) else None
        return AxisAction(acts, head, measured)
    if reach is not None and math.isfinite(change) and change <= NOISE:
        return AxisAction(False, head + never, measured)
    return AxisAction(None, head + never, measured)


def _panel_key(mark: Landmark) -> tuple[str, float | None]:
    vals = list(mark.panel.values())
    return recipe_for(mark), (float(vals[0]) if vals else None)


def landmark_actions(
    target: Target,
    landmarks: Iterable[Landmark],
    stores: Mapping[str, Any],
    *,
    branches: Mapping[str, Sequence[Mapping[str, Any]]] | None = None,
    quick: bool = False,
    settings: Any = None,
) -> dict[str, AxisAction]:
    """:func:`panel_action` of every landmark's panel (each panel once, in threads), by
    landmark id. ``stores`` maps recipe names to their sweeps, ``branches`` recipe names to
    the event rows of the report's continued branches. A panel whose test raises is
    ``undecided`` with the error."""
    marks = list(landmarks)
    keys = sorted({_panel_key(m) for m in marks}, key=lambda k: (k[0], k[1] or 0.0))

    def one(key: tuple[str, float | None]) -> AxisAction:
        recipe, fv = key
        rows = [
            r for r in (branches or {}).get(recipe, ())
            if fv is None or r.get("panel") is None or math.isclose(float(r["panel"]), fv)
        ]  # fmt: skip
        try:
            return panel_action(
                target, recipe, fv, stores.get(recipe), events=rows, quick=quick, settings=settings
            )
        except Exception as exc:  # one panel's failure never hides the others
            return AxisAction(None, f"test failed: {type(exc).__name__}: {exc}", {})

    width = max(1, min(len(keys), os.cpu_count() or 1))
    with cf.ThreadPoolExecutor(width, thread_name_prefix="gearchaos-action") as pool:
        found = dict(zip(keys, pool.map(one, keys), strict=True))
    return {m.id: found[_panel_key(m)] for m in marks}


def apply_actions(
    results: Iterable[LandmarkResult], actions: Mapping[str, AxisAction]
) -> list[LandmarkResult]:
    """``results`` with each landmark's :class:`AxisAction` attached, and ``holds`` turned into
    ``holds (constant)`` where the swept parameter does not act (``acts`` False). The score is
    left as it is (it measures agreement with the labels)."""
    out = []
    for r in results:
        a = actions.get(r.landmark.id)
        verdict = r.verdict
        if a is not None and a.acts is False and verdict == "holds":
            verdict = "holds (constant)"
        out.append(replace(r, verdict=verdict, action=a))
    return out
