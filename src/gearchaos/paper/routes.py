"""Routes to chaos from bifurcation events along continued branches, not from label changes.

The seed's conclusions 4–6 name routes to chaos: period doubling, crisis, "Hopf"
(Neimark–Sacker) and a 3T channel. A brute-force sweep shows *that* the motion label changes;
a continued branch of periodic orbits (:func:`gearchaos.continuation`) says *why*: its Floquet
multipliers cross the unit circle at a located event. Here

* :func:`follow_branches` continues, on one panel of a figure's sweep, the period-1 orbit from
  every stretch of 1T points (and a period-3 orbit from every stretch of 3T points) across the
  swept range, and switches at every period doubling to the period-2n branch (up to
  ``max_period``), so a cascade 1T → 2T → 4T is followed; its :func:`event_rows` are the table
  the verdicts read (kind, value, period of the branch, stability on either side);
* :func:`route_of` names the route of one onset of chaos (a ``chaos`` label whose previous
  labelled point is not chaotic) from the events within ``window`` of it — between the last
  non-chaotic point and the onset, widened by ``window`` on both sides — on the side where the
  branch loses stability: ``period doubling`` (a PD event; cites its value), ``Hopf`` (an NS
  event), ``3T channel`` (any event of a period-3 or period-6 branch), ``fold`` (a fold: a
  saddle-node, the start of intermittency), ``grazing`` (a contact change of a stable
  branch, the non-smooth bifurcation of gear rattle), else ``crisis``: the chaos appears with
  no bifurcation of a followed branch nearby — the attractor collides with something the
  branches do not show.

Priority when several events lie in the window: period doubling, Hopf, 3T channel, fold,
grazing.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..gearset import GearSet
from ..model.target import Target

__all__ = [
    "BRANCH_ROW",
    "ROUTE_OF_EVENT",
    "event_rows",
    "follow_branches",
    "onset_text",
    "panel_routes",
    "route_of",
    "routes_from_events",
]

#: The route an event names, in priority order.
ROUTE_OF_EVENT = (
    ("period_doubling", "period doubling"),
    ("neimark_sacker", "Hopf"),
    ("three", "3T channel"),
    ("fold", "fold"),
    ("grazing", "grazing"),
)


#: ``kind`` of the row that marks a followed branch (no event): a panel with such rows had
#: branches, so an onset there with no event nearby is a crisis.
BRANCH_ROW = "branch"


def event_rows(
    branch: Any, panel: float | None = None, *, marker: bool = False
) -> list[dict[str, Any]]:
    """The events of one branch dataset as plain rows: ``kind``, ``value``, ``period`` (of
    the branch), ``stable_below`` / ``stable_above`` (the branch on the side of smaller and of
    larger parameter values), ``panel`` (the family value) and ``multiplier``; with ``marker``
    first a row of kind :data:`BRANCH_ROW` (value NaN) that says the branch was followed."""
    head: list[dict[str, Any]] = []
    if marker:
        head.append(
            {
                "kind": BRANCH_ROW,
                "value": math.nan,
                "period": int(branch.attrs.get("period", 1)),
                "stable_below": False,
                "stable_above": False,
                "panel": panel,
                "multiplier": complex(math.nan, 0.0),
            }
        )
    if "event" not in branch.dims:
        return head
    name = str(branch.attrs["parameter"])
    stable = np.asarray(branch["stable"].values, dtype=bool)
    lam = np.asarray(branch[name].values, dtype=float)
    rows = head
    for k in range(branch.sizes["event"]):
        i = int(branch["event_point"].values[k])
        j = min(i + 1, stable.size - 1)
        rows.append(
            {
                "kind": str(branch["event_kind"].values[k]),
                "value": float(branch["event_value"].values[k]),
                "period": int(branch.attrs.get("period", 1)),
                # stable on the side of smaller / larger parameter values
                "stable_below": bool(stable[i] if lam[i] <= lam[j] else stable[j]),
                "stable_above": bool(stable[j] if lam[i] <= lam[j] else stable[i]),
                "panel": panel,
                "multiplier": complex(
                    float(branch["event_multiplier_re"].values[k]),
                    float(branch["event_multiplier_im"].values[k]),
                ),
            }
        )
    return rows


def _event_key(row: Mapping[str, Any]) -> str:
    if row["kind"] == BRANCH_ROW:
        return BRANCH_ROW
    if int(row.get("period", 1)) in (3, 6):
        return "three"
    return str(row["kind"])


def route_of(
    onset: float,
    before: float,
    rows: Sequence[Mapping[str, Any]],
    window: float,
) -> tuple[str, Mapping[str, Any] | None]:
    """(route, the event it rests on or None) of an onset of chaos at ``onset`` whose last
    non-chaotic labelled point is at ``before`` (see the module doc)."""
    lo, hi = min(onset, before) - window, max(onset, before) + window
    rising = onset >= before
    near = []
    for r in rows:
        v = float(r["value"])
        if not lo <= v <= hi:
            continue
        # the followed branch was stable on the non-chaotic side of the event
        if not r.get("stable_below" if rising else "stable_above", True):
            continue
        near.append(r)
    for key, route in ROUTE_OF_EVENT:
        hits = [r for r in near if _event_key(r) == key]
        if hits:
            return route, min(hits, key=lambda r: abs(float(r["value"]) - onset))
    return "crisis", None


def routes_from_events(
    onsets: Sequence[Mapping[str, Any]],
    x: np.ndarray,
    labels: np.ndarray,
    rows: Sequence[Mapping[str, Any]],
    *,
    window_steps: float = 1.0,
) -> list[dict[str, Any]]:
    """Each onset (``at``: the swept value of :func:`~gearchaos.paper.evidence.chaos_onsets`)
    of one panel with its route from ``rows`` (the events of that panel's branches):
    ``{"at", "route", "event": value or None, "event_kind", "event_period",
    "label_route"}``. ``window_steps`` grid steps widen the window on both sides."""
    xs = np.asarray(x, dtype=float)
    lab = np.asarray(labels).astype(str)
    keep = ~np.isin(lab, ("unresolved", "failed", ""))
    xk, lk = xs[keep], lab[keep]
    step = float(np.median(np.abs(np.diff(xs)))) if xs.size > 1 else 0.0
    out = []
    for o in onsets:
        at = float(o["at"])
        j = int(np.argmin(np.abs(xk - at)))
        before = float(xk[j - 1]) if j > 0 and lk[j - 1] != "chaos" else at
        route, ev = route_of(at, before, rows, window_steps * step)
        out.append(
            {
                "at": at,
                "route": route,
                "event": None if ev is None else float(ev["value"]),
                "event_kind": None if ev is None else str(ev["kind"]),
                "event_period": None if ev is None else int(ev["period"]),
                "label_route": o.get("route"),
                "panel": o.get("panel"),
            }
        )
    return out


def _stretch_starts(x: np.ndarray, labels: np.ndarray, label: str) -> list[float]:
    """The middle point of every maximal run of ``label`` along the swept axis."""
    lab = np.asarray(labels).astype(str)
    out, k = [], 0
    while k < lab.size:
        if lab[k] != label:
            k += 1
            continue
        e = k
        while e + 1 < lab.size and lab[e + 1] == label:
            e += 1
        out.append(float(x[(k + e) // 2]))
        k = e + 1
    return out


def follow_branches(
    target: Target,
    name: str,
    x: np.ndarray,
    labels: np.ndarray,
    fixed: Mapping[str, Any],
    *,
    max_period: int = 4,
    max_points: int = 400,
    max_branches: int = 24,
    steps: int = 100,
    settings: Any = None,
    cache: str | os.PathLike[str] | None = None,
) -> list[Any]:
    """Continue the branches of one panel: from the middle of every 1T (and 3T) stretch of the
    sweep's labels, in both directions to the ends of the swept range, each with its
    period-doubling cascade (``continuation(..., cascade=depth)``,
    :mod:`gearchaos.dynamics.continuation.cascade`: at every period doubling of a branch that is
    stable on
    one side of it — the attractor doubles — the period-2n branch, over the whole swept range)
    up to period ``max_period``, at most ``max_branches`` branches in all (breadth first within
    a cascade), each of at most ``max_points`` points. ``steps`` sets the largest step
    (range/steps); ``cache`` is a directory where each cascade is saved in one file and, when
    present, read back (so a report run twice continues nothing twice). Branches that fail to
    start are skipped.

    Returns the branch datasets (:func:`gearchaos.continuation`).
    """
    from ..dynamics.continuation.arclength import continuation
    from ..dynamics.continuation.cascade import open_cascade
    from ..errors import IntegrationError, ParameterError

    xs = np.asarray(x, dtype=float)
    lo, hi = float(xs.min()), float(xs.max())
    span = hi - lo
    kw: dict[str, Any] = {
        "params": dict(fixed),
        "max_step": span / steps,
        "step": span / (2 * steps),
        "max_points": max_points,
        # the period-2n branches cover the whole swept range, heading where their parent heads
        "cascade_range": (lo, hi),
    }
    if settings is not None:
        kw["settings"] = settings
    out: list[Any] = []
    counter = [0]

    def run(vary: tuple[str, float, float], period: int, limit: int) -> list[Any]:
        """The cascade of the period-n branch over ``vary``: doubled while the period stays
        at most ``max_period`` (a cascade file in ``cache``, read back when present)."""
        counter[0] += 1
        depth = 0
        while period * 2 ** (depth + 1) <= max_period:
            depth += 1
        path = None
        if cache is not None:
            Path(cache).mkdir(parents=True, exist_ok=True)
            path = Path(cache) / f"cascade{counter[0]:03d}.nc"
            if path.exists():
                return open_cascade(path)
        try:
            found: list[Any] = continuation(
                target, vary, period=period, store=path, overwrite=True, cascade=depth,
                max_branches=limit, **kw,
            )  # fmt: skip
        except (IntegrationError, ParameterError):
            return []
        return found

    starts = [(s, 1) for s in _stretch_starts(xs, labels, "1T")]
    starts += [(s, 3) for s in _stretch_starts(xs, labels, "3T")]
    for s, n in starts:
        for end in (lo, hi):
            if not math.isclose(s, end) and len(out) < max_branches:
                out.extend(run((name, s, end), n, max_branches - len(out)))
    return out


def panel_routes(ds: Any, rows: Sequence[Mapping[str, Any]] | None = None) -> list[dict[str, Any]]:
    """Onsets of chaos of every panel with their routes: from the events of the panel's
    continued branches when ``rows`` is given (:mod:`.routes`; the label route kept as
    ``label_route``), else from the labels alone."""
    from .evidence import chaos_onsets, panels

    out = []
    for fv, x, lab, sec in panels(ds):
        found = [{**o, "panel": fv} for o in chaos_onsets(x, lab, sec)]
        if rows is None:
            out.extend(found)
            continue
        mine = [
            r for r in rows
            if (fv is None and r.get("panel") is None)
            or (fv is not None and r.get("panel") is not None and math.isclose(r["panel"], fv))
        ]  # fmt: skip
        if not mine:  # no branch was followed on this panel: the labels' routes stand
            out.extend(found)
            continue
        for o, routed in zip(found, routes_from_events(found, x, lab, mine), strict=True):
            out.append({**o, **routed})
    return out


def onset_text(onsets: list[dict[str, Any]], family: str, limit: int = 8) -> str:
    items = []
    for o in onsets[:limit]:
        ev = o.get("event")
        cite = "" if ev is None else f" ({_EVENT_SHORT.get(o['event_kind'], o['event_kind'])} "
        if ev is not None:
            cite += f"of the period-{o['event_period']} branch at {ev:.4g})"
        panel = "" if o["panel"] is None else f" ({family}={o['panel']:g})"
        items.append(f"{o['route']} at {o['at']:.3g}{cite}{panel}")
    more = f" … (+{len(onsets) - limit})" if len(onsets) > limit else ""
    return "; ".join(items) + more


_EVENT_SHORT = {
    "period_doubling": "PD",
    "neimark_sacker": "NS",
    "fold": "fold",
    "grazing": "grazing",
    "branch_point": "branch point",
}


def _panel_value(mark: Any) -> float | None:
    vals = list(mark.panel.values())
    return float(vals[0]) if vals else None


def _wanted(row: Mapping[str, Any], event: str) -> bool:
    if row["kind"] == BRANCH_ROW:
        return False
    if event == "period_3":
        return int(row.get("period", 1)) in (3, 6)
    return str(row["kind"]) == event


_EVENT_NAME = {
    "period_doubling": "period doubling (PD)",
    "neimark_sacker": 'Neimark–Sacker ("Hopf")',
    "period_3": "event of a period-3 branch (3T channel)",
}


def landmarks_from_events(results: Sequence[Any], branches: Mapping[str, Any]) -> list[Any]:
    """Landmark results with the verdicts of the landmarks that name a bifurcation
    (``event``) taken from the located events of the continued branches of their panel
    (``branches``: recipe name → event rows): *holds* when such an event lies within the
    landmark's tolerance of ``at`` (or of [lo, hi]), *partly* within three tolerances, else
    *does not hold*; the label check stays in the evidence as "brute-force labels say".
    A landmark without ``event``, or whose recipe has no branches, is returned unchanged."""
    from .landmarks import LandmarkResult, Verdict, recipe_for

    out = []
    for r in results:
        mark = r.landmark
        rows = branches.get(recipe_for(mark))
        if not mark.event or rows is None:
            out.append(r)
            continue
        pv = _panel_value(mark)
        panel_rows = [
            row for row in rows
            if pv is None or row.get("panel") is None or math.isclose(row["panel"], pv)
        ]  # fmt: skip
        if not panel_rows:  # no branch was followed on this panel
            out.append(r)
            continue
        mine = [row for row in panel_rows if _wanted(row, mark.event)]
        lo, hi = mark.span
        what = _EVENT_NAME[mark.event]
        label_side = f"brute-force labels say: {r.evidence} ({r.verdict})"
        if not mine:
            out.append(
                LandmarkResult(
                    mark,
                    "does not hold",
                    0.0,
                    f"no {what} on the continued branches of this panel; {label_side}",
                    {"events": [], "label_verdict": r.verdict},
                )
            )
            continue

        dists = [max(lo - float(row["value"]), float(row["value"]) - hi, 0.0) for row in mine]
        k = int(np.argmin(dists))
        best, d = mine[k], dists[k]
        tol = mark.tolerance
        verdict: Verdict = "holds" if d <= tol else ("partly" if d <= 3 * tol else "does not hold")
        score = {"holds": 1.0, "partly": 0.5, "does not hold": 0.0}[verdict]
        evidence = (
            f"{what} of the period-{best['period']} branch at {mark.axis} = "
            f"{float(best['value']):.4g}, {d:.3g} from {mark.where()} (tolerance {tol:g}); "
            f"{label_side}"
        )
        out.append(
            LandmarkResult(
                mark,
                verdict,
                score,
                evidence,
                {
                    "events": [float(row["value"]) for row in mine],
                    "distance": d,
                    "label_verdict": r.verdict,
                },
            )
        )
    return out


#: Figures whose routes to chaos are read from continued branches (conclusions 4–6).
ROUTE_FIGURES = ("fig4", "fig6", "fig8", "fig9", "fig11")
#: Panels continued in a quick report: one per figure, those its landmarks name.
QUICK_PANELS = {"fig4": 0.03, "fig6": 0.05, "fig9": 0.05}
#: (range / largest step, most points per branch, highest period, most branches per panel):
#: full and quick reports.
BRANCH_STEPS = {False: (100, 300, 8, 8), True: (20, 40, 4, 4)}


def report_branches(
    stores: Mapping[str, Any],
    outdir: str | os.PathLike[str],
    *,
    quick: bool = False,
    gearset: GearSet | None = None,
) -> tuple[dict[str, list[dict[str, Any]]], dict[str, Any]]:
    """Continue the branches of the route figures' panels (:func:`follow_branches`, saved
    under ``outdir/branches`` and read back on a second run) and return their event rows by
    figure, and what was done (``{figure: {"panels", "branches", "events", "seconds"}}`` or
    ``{figure: {"error": ...}}``). A quick report continues one panel per figure
    (:data:`QUICK_PANELS`) with coarse steps."""
    import concurrent.futures as cf
    import time

    from .evidence import panels
    from .recipes import RECIPES, seed_gearset

    target = seed_gearset(gearset)
    steps, max_points, max_period, max_branches = BRANCH_STEPS[bool(quick)]
    rows: dict[str, list[dict[str, Any]]] = {}
    done: dict[str, Any] = {}
    for fig in ROUTE_FIGURES:
        if fig not in stores or (quick and fig not in QUICK_PANELS):
            continue
        t0 = time.perf_counter()
        recipe = RECIPES[fig]
        try:
            mine: list[dict[str, Any]] = []
            n_branches = n_panels = 0
            jobs = []
            for fv, x, lab, _ in panels(stores[fig]):
                if quick and (fv is None or not math.isclose(fv, QUICK_PANELS[fig])):
                    continue
                fixed = dict(recipe.fixed)
                if fv is not None:
                    fixed[recipe.family.name] = fv
                cache = (
                    Path(os.fspath(outdir))
                    / "branches"
                    / (f"{fig}-{recipe.family.name}={fv:g}" + ("-quick" if quick else ""))
                )
                jobs.append((fv, recipe.vary.name, x, lab, fixed, cache))

            def panel(job: tuple[Any, ...]) -> list[Any]:
                _, name, x, lab, fixed, cache = job
                return follow_branches(
                    target, name, x, lab, fixed,
                    max_period=max_period, max_points=max_points, steps=steps, cache=cache,
                    max_branches=max_branches,
                )  # fmt: skip

            # the panels are independent: one thread each on up to every core (the kernels
            # release the GIL; processes would re-import a user's unguarded script), the
            # results in panel order whatever finishes first
            width = max(1, min(len(jobs), os.cpu_count() or 1))
            with cf.ThreadPoolExecutor(width, thread_name_prefix="gearchaos-branches") as pool:
                found = list(pool.map(panel, jobs))
            for (fv, *_), brs in zip(jobs, found, strict=True):
                n_panels += 1
                n_branches += len(brs)
                for b in brs:
                    mine.extend(event_rows(b, fv, marker=True))
            if n_branches:
                rows[fig] = mine
            done[fig] = {
                "panels": n_panels,
                "branches": n_branches,
                "events": sum(1 for r in mine if r["kind"] != BRANCH_ROW),
                "seconds": time.perf_counter() - t0,
            }
        except Exception as exc:  # one failing figure never hides the others
            done[fig] = {"error": f"{type(exc).__name__}: {exc}"}
    return rows, done
