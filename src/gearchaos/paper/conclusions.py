"""The seed paper's conclusions (Sheng et al. 2016, Section 4, items 1–8) as checks on our runs.

Every verdict is computed from sweep datasets (the stores :func:`gearchaos.paper.reproduce`
writes, with their ``motion`` labels and section values), never written by hand. Each check
returns a :class:`Verdict`: ``holds``, ``partly``, ``does not hold`` or ``not evaluated`` (the
runs needed are missing, or too few of their points could be labelled), with the numbers it
rests on in ``evidence`` (text) and ``measured`` (a JSON-able dict).

A sweep dataset here is any :class:`xarray.Dataset` with a ``motion`` variable of dimensions
``(family, vary)`` or ``(vary,)`` (labels ``1T`` … ``nT``, ``QP``, ``chaos``, ``unresolved``,
``failed``) and, for the checks that need them, section values ``delta_sp`` with a ``section``
dimension (and optionally ``planet``). The helpers work on synthetic datasets built that way,
which is how the tests check each verdict against a known answer.

Conventions
-----------
* ``unresolved`` and ``failed`` points carry no information about the motion; the route and
  window checks drop them from the sequence along the swept axis, and a sweep with fewer than
  :data:`MIN_RESOLVED` of its points labelled is not used.
* A *route to chaos* of conclusions 4–6 is read from the bifurcation events of continued
  branches when they are given (``branches``; :mod:`gearchaos.paper.routes`, which the report
  computes): a PD event gives ``period doubling`` (citing its value), an NS event ``Hopf``, an
  event of a period-3 branch ``3T channel``, no event of a followed branch near the onset
  ``crisis``; the label reading below stays as a secondary line ("brute-force labels say").
  Without branches, the route is read at every onset of chaos along the swept axis (a
  ``chaos`` point whose previous labelled point is not chaotic), from the labels just before
  it:
  ``period doubling`` (the periodic points before it double their period at least twice, or
  once to ≥ 4T, e.g. 1T → 2T → 4T), ``3T channel`` (a 3T or 6T window just before),
  ``Hopf`` (quasi-periodic motion just before — a Neimark–Sacker bifurcation), ``crisis``
  (the attractor — the spread of the section values — at least doubles at the onset and grows
  by at least 5 % of the sweep's largest attractor), else ``abrupt`` (no jump, no precursor).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..gearset.schema import display_symbol
from .evidence import (
    MIN_RESOLVED,
    _dims,
    _family_name,
    _fmt,
    _informative,
    _labels,
    _nonperiodic,
    _resolved,
    attractor_change,
    attractor_size,
    chaos_onsets,
    chaotic_fraction,
    clearance_reach,
    label_fraction,
    panels,
    point_statistics,
    qp_near_3t,
    section_spread,
)
from .routes import onset_text, panel_routes

__all__ = [
    "CONCLUSIONS",
    "MIN_RESOLVED",
    "VERDICTS",
    "Verdict",
    "attractor_size",
    "chaos_onsets",
    "chaotic_fraction",
    "evaluate_conclusions",
    "label_fraction",
    "panels",
    "qp_near_3t",
    "section_spread",
]

VERDICTS = ("holds", "partly", "does not hold", "not evaluated")
#: Ratio of the change of the per-point attractors along b̄_s to that along b̄_rp below which
#: b̄_s "couples weakly" (:func:`conclusion_7`).
WEAK_COUPLING_RATIO = 0.2

Stores = Mapping[str, Any]
#: Event rows of the continued branches by figure (:func:`gearchaos.paper.routes.event_rows`).
Branches = Mapping[str, Sequence[Mapping[str, Any]]]


@dataclass(frozen=True)
class Verdict:
    """The check of one conclusion of the seed's Section 4."""

    conclusion_id: int
    statement: str
    verdict: str
    evidence: str
    measured: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.verdict not in VERDICTS:
            raise ValueError(f"verdict must be one of {VERDICTS}: got {self.verdict!r}")


# --------------------------------------------------------------------------- statements
STATEMENTS: dict[int, str] = {
    1: (
        "A transverse-torsional model with backlash and bearing clearance is proposed; bifurcation "
        "and chaos are obtained with variable-step Runge-Kutta integration under the bifurcation "
        "parameters Ω, b̄_sp, b̄_rp and b̄_s."
    ),
    2: (
        "The model takes time-varying mesh stiffness, transverse displacements and radial "
        "clearance of the sun, comprehensive transmission error and sun-planet and planet-ring "
        "backlash into account."
    ),
    3: (
        "Increasing damping suppresses the non-periodic motion effectively (the chaotic fraction "
        "of every ξ sweep shrinks as ξ grows)."
    ),
    4: "The route of crisis to chaos is observed under the meshing frequency Ω (Fig. 4).",
    5: (
        "The routes of crisis and period doubling to chaos are identified under the sun-planet "
        "backlash b̄_sp (Figs. 6, 8)."
    ),
    6: (
        "Several routes to chaos coexist under the planet-ring backlash b̄_rp — period doubling, "
        "crisis, Hopf bifurcation and 3T-periodic channel (Figs. 9, 11)."
    ),
    7: (
        "The sun's bearing clearance b̄_s couples weakly: no bifurcation and no chaos under b̄_s "
        "(Fig. 12), while b̄_rp couples strongly."
    ),
    8: (
        "Quasi-periodic motion is found under all the bifurcation parameters and is closely "
        "related to 3T-periodic motion."
    ),
}


def _verdict(cid: int, verdict: str, evidence: str, measured: dict[str, Any]) -> Verdict:
    return Verdict(cid, STATEMENTS[cid], verdict, evidence, measured)


def _missing(cid: int, names: Sequence[str]) -> Verdict:
    return _verdict(cid, "not evaluated", f"needs the run(s) {', '.join(names)}", {})


# --------------------------------------------------------------------------- conclusions
#: The seed's four bifurcation parameters.
_BIFURCATION_PARAMS = (
    "omega",
    "backlash.sun_planet",
    "backlash.planet_ring",
    "clearance.sun_bearing",
)


def conclusion_1(stores: Stores) -> Verdict:
    """All four bifurcation parameters swept with a variable-step integrator, points succeed."""
    swept: dict[str, list[str]] = {}
    total = failed = 0
    steps: list[float] = []
    for name, ds in stores.items():
        _, vary = _dims(ds)
        if vary in _BIFURCATION_PARAMS:
            swept.setdefault(display_symbol(vary), []).append(name)
        lab = _labels(ds)
        total += lab.size
        failed += int(np.count_nonzero(lab == "failed"))
        if "steps_accepted" in ds.data_vars:
            steps.extend(np.asarray(ds["steps_accepted"].values, dtype=float).ravel().tolist())
    if not stores:
        return _missing(1, ["fig4", "fig6", "fig9", "fig12"])
    frac_failed = failed / total if total else math.nan
    n = len(swept)
    measured: dict[str, Any] = {
        "parameters_swept": sorted(swept),
        "points": total,
        "failed_fraction": frac_failed,
        "steps_per_point_median": float(np.median(steps)) if steps else None,
    }
    evidence = (
        f"{n} of 4 bifurcation parameters swept ({', '.join(sorted(swept)) or 'none'}); "
        f"{total} points, {_fmt(100 * frac_failed)} % failed; adaptive Dormand–Prince 5(4), "
        f"median {_fmt(measured['steps_per_point_median'])} accepted steps per point"
    )
    if n == 4 and frac_failed <= 0.01:
        verdict = "holds"
    elif n >= 1 and frac_failed <= 0.1:
        verdict = "partly"
    else:
        verdict = "does not hold"
    return _verdict(1, verdict, evidence, measured)


def conclusion_2(stores: Stores) -> Verdict:
    """Every model ingredient is present in the gear set and excited in the runs."""
    from ..sweep.result import SweepResult

    recorded = (SweepResult.of(d).base_gearset for d in stores.values())
    # gear-set switch: a seed's conclusion on gear sets
    gs = next((gs for gs in recorded if gs is not None), None)
    if gs is None:  # gear-set switch: a seed's conclusion on gear sets
        return _missing(2, ["any figure with its gear set"])
    st, te, bl = gs.stiffness, gs.transmission_error, gs.backlash
    parts = {
        "time-varying mesh stiffness": st.sun_planet_alternating > 0
        and st.planet_ring_alternating > 0,
        "sun transverse displacement (bearing stiffness)": st.sun_bearing > 0,
        "sun radial clearance": gs.clearance.sun_bearing > 0,
        "transmission error": te.sun_planet > 0 or te.planet_ring > 0,
        "sun-planet and planet-ring backlash": bl.sun_planet > 0 and bl.planet_ring > 0,
    }
    xs = 0.0
    for d in stores.values():
        for v in ("x_s_max", "x_s_min", "y_s_max", "y_s_min"):
            if v in d.data_vars:
                with np.errstate(all="ignore"):
                    m = float(np.nanmax(np.abs(np.asarray(d[v].values, dtype=float))))
                if math.isfinite(m):
                    xs = max(xs, m)
    bs = float(gs.sun_bearing_clearance_bar())
    excited = xs > 1e-6 * max(bs, 1.0)
    measured = {
        "ingredients": parts,
        "max_sun_translation": xs,
        "sun_translation_excited": excited,
        "mesh_phasing": gs.mesh_phasing.model,
    }
    have = [k for k, v in parts.items() if v]
    evidence = (
        f"{len(have)} of {len(parts)} ingredients in the gear set ({', '.join(have)}); "
        f"largest sun translation |x̄_s|, |ȳ_s| over all runs = {_fmt(xs)} "
        f"(mesh phasing {gs.mesh_phasing.model}"
        + (
            ": in-phase meshes cancel the net mesh force on the sun, so its translation and "
            "bearing clearance stay idle)"
            if not excited
            else ")"
        )
    )
    if len(have) == len(parts) and excited:
        verdict = "holds"
    elif len(have) >= len(parts) - 1:
        verdict = "partly"
    else:
        verdict = "does not hold"
    return _verdict(2, verdict, evidence, measured)


DAMPING_FIGURES = ("fig4", "fig6", "fig9")


def conclusion_3(stores: Stores, figures: Sequence[str] = DAMPING_FIGURES) -> Verdict:
    """Chaotic fraction per ξ in every ξ-family sweep: monotone non-increasing?"""
    present = [f for f in figures if f in stores and _family_name(stores[f]) == "xi"]
    if not present:
        return _missing(3, list(figures))
    measured: dict[str, Any] = {}
    ok = used = 0
    parts = []
    for f in present:
        ds = stores[f]
        frac = chaotic_fraction(ds)
        xi = sorted(frac)
        chaos = [frac[k] for k in xi]
        metric, what = chaos, "chaotic"
        if all(not (c > 0) for c in chaos):  # no chaos at all: use QP + chaos
            metric = [
                label_fraction(lab, _nonperiodic) for _, _, lab, _ in sorted(panels(ds), key=_k0)
            ]
            what = "non-periodic (QP + chaos)"
        finite = [m for m in metric if math.isfinite(m)]
        informative = len(finite) >= 2 and any(m > 0 for m in finite) and _informative(ds)
        mono = all(b <= a + 1e-12 for a, b in itertools.pairwise(finite))
        measured[f] = {
            "xi": xi,
            "chaotic_fraction": chaos,
            "metric": what,
            "fraction": metric,
            "monotone": mono,
            "informative": informative,
        }
        fr = ", ".join(f"ξ={k:g}: {_fmt(m)}" for k, m in zip(xi, metric, strict=True))
        if informative:
            used += 1
            ok += int(mono)
            parts.append(
                f"{f} {what} fraction {fr} → {'non-increasing' if mono else 'NOT monotone'}"
            )
        else:
            parts.append(f"{f}: too few labelled or no non-periodic points ({fr}), not used")
    evidence = "; ".join(parts)
    if used == 0:
        verdict = "not evaluated"
    elif ok == used:
        verdict = "holds"
    elif ok > used / 2:
        verdict = "partly"
    else:
        verdict = "does not hold"
    measured["sweeps_used"] = used
    measured["sweeps_monotone"] = ok
    return _verdict(3, verdict, evidence, measured)


def _k0(p: tuple[Any, ...]) -> float:
    return -math.inf if p[0] is None else float(p[0])


def _route_counts(onsets: list[dict[str, Any]]) -> dict[str, int]:
    counts: dict[str, int] = {}
    for o in onsets:
        counts[o["route"]] = counts.get(o["route"], 0) + 1
    return counts


def _gather_routes(
    stores: Stores, figures: Sequence[str], branches: Branches | None = None
) -> tuple[list[Any], list[str], bool]:
    onsets: list[dict[str, Any]] = []
    texts = []
    informative = True  # every sweep of the group must be mostly labelled
    for f in figures:
        if f not in stores:
            continue
        ds = stores[f]
        informative = informative and _informative(ds)
        rows = None if branches is None else branches.get(f)
        o = panel_routes(ds, rows)
        for item in o:
            item["figure"] = f
        onsets.extend(o)
        fam = _family_name(ds)
        if rows is None:
            texts.append(
                f"{f}: {len(o)} onset(s) of chaos, routes from labels only (no continued "
                "branches)" + (f" — {onset_text(o, fam)}" if o else "")
            )
            continue
        label_side = [{**x, "route": x.get("label_route", x["route"]), "event": None} for x in o]
        texts.append(
            f"{f}: {len(o)} onset(s) of chaos, routes from "
            f"{sum(1 for r in rows if r['kind'] != 'branch')} event(s) of the continued branches"
            + (f" — {onset_text(o, fam)}" if o else "")
            + (f"; brute-force labels say: {onset_text(label_side, fam)}" if o else "")
        )
    return onsets, texts, informative


def _route_conclusion(
    number: int,
    stores: Stores,
    figures: Sequence[str],
    branches: Branches | None,
    judge: Callable[[dict[str, int]], tuple[bool, bool, dict[str, Any], str]],
) -> Verdict:
    """A conclusion about the routes to chaos along the sweeps of ``figures``.

    ``judge(route counts)`` gives (claim met in full, met in part, what it measured, the end
    of the evidence). Without onsets the verdict is "does not hold" when the stores could have
    shown one and "not evaluated" when not; with onsets "holds", "partly" or "does not hold".
    """
    if not any(f in stores for f in figures):
        return _missing(number, list(figures))
    onsets, texts, informative = _gather_routes(stores, figures, branches)
    counts = _route_counts(onsets)
    full, some, extra, tail = judge(counts)
    if not onsets:
        verdict = "does not hold" if informative else "not evaluated"
    else:
        verdict = "holds" if full else ("partly" if some else "does not hold")
    measured = {"route_counts": counts, "onsets": onsets, **extra}
    return _verdict(number, verdict, "; ".join(texts) + tail, measured)


def conclusion_4(
    stores: Stores, figures: Sequence[str] = ("fig4",), branches: Branches | None = None
) -> Verdict:
    """Onsets of chaos along Ω: is crisis (a jump of the attractor) among their routes?"""

    def judge(counts: dict[str, int]) -> tuple[bool, bool, dict[str, Any], str]:
        crisis = counts.get("crisis", 0)
        full = bool(crisis) and crisis >= max(counts.values())
        return full, bool(crisis), {}, f"; routes: {counts or 'none'}"

    return _route_conclusion(4, stores, figures, branches, judge)


def conclusion_5(
    stores: Stores, figures: Sequence[str] = ("fig6", "fig8"), branches: Branches | None = None
) -> Verdict:
    """Onsets of chaos along b̄_sp: both crisis and period doubling found?"""

    def judge(counts: dict[str, int]) -> tuple[bool, bool, dict[str, Any], str]:
        found = [r for r in ("crisis", "period doubling") if counts.get(r)]
        return len(found) == 2, bool(found), {"found": found}, f"; routes: {counts or 'none'}"

    return _route_conclusion(5, stores, figures, branches, judge)


ROUTE_TYPES = ("period doubling", "crisis", "Hopf", "3T channel")


def conclusion_6(
    stores: Stores, figures: Sequence[str] = ("fig9", "fig11"), branches: Branches | None = None
) -> Verdict:
    """Onsets of chaos along b̄_rp: how many of the paper's four route types coexist?"""

    def judge(counts: dict[str, int]) -> tuple[bool, bool, dict[str, Any], str]:
        kinds = [r for r in ROUTE_TYPES if counts.get(r)]
        tail = f"; {len(kinds)} of the paper's 4 route types found ({', '.join(kinds) or 'none'})"
        return len(kinds) >= 3, len(kinds) == 2, {"route_types": kinds}, tail

    return _route_conclusion(6, stores, figures, branches, judge)


def conclusion_7(
    stores: Stores, weak: str = "fig12", strong: str = "fig9", strong_panel: float = 0.05
) -> Verdict:
    """b̄_s sweep: no bifurcation, no chaos, and its attractors change along b̄_s much less than
    along b̄_rp.

    The coupling of an axis is the change of the per-point attractor along it
    (:func:`~gearchaos.paper.evidence.attractor_change`): per labelled point the centre and
    the size of its X̄_sp1 section values, their ranges over the points, the larger of the two.
    Pooled section spreads are not used: they grow with every point's own attractor (or a
    transient left in its record) even when nothing changes from point to point. b̄_s couples
    weakly when its change is below :data:`WEAK_COUPLING_RATIO` of b̄_rp's (Fig. 9's ξ =
    ``strong_panel`` panel); distinct section points and λ₁ along both axes are evidence."""
    if weak not in stores:
        return _missing(7, [weak])
    ds = stores[weak]
    lab = _labels(ds).ravel()
    res = lab[_resolved(lab)]
    kinds = sorted(set(res.tolist()))
    no_chaos = "chaos" not in kinds and "QP" not in kinds
    no_bif = len(kinds) <= 1
    w_stats = point_statistics(ds)
    w = attractor_change(w_stats) if w_stats is not None and w_stats["x"].size else None
    s: dict[str, Any] | None = None
    if strong in stores:
        sds = stores[strong]
        st = point_statistics(sds, strong_panel if _family_name(sds) else None)
        if st is None:  # no such panel: the first one
            st = point_statistics(sds)
        s = attractor_change(st) if st is not None and st["x"].size else None
    c_weak = w["change"] if w else math.nan
    c_strong = s["change"] if s else math.nan
    ratio = c_weak / c_strong if c_strong and math.isfinite(c_strong) else math.nan
    weakly = math.isfinite(ratio) and ratio < WEAK_COUPLING_RATIO
    reach = clearance_reach(ds, "clearance.sun_bearing", panels(ds)[0][0])
    measured = {
        "labels_bs": kinds,
        "change_bs": w,
        "change_brp": s,
        "ratio": ratio,
        "no_chaos": no_chaos,
        "no_bifurcation": no_bif,
        "bearing_reach": reach,
    }

    def side(c: dict[str, Any] | None) -> str:
        if c is None:
            return "no labelled points"
        lle = c["lle"]
        lle_text = (
            f"λ₁ {_fmt(lle[0])} to {_fmt(lle[1])} (error ≤ {_fmt(c['lle_error'])})"
            if lle is not None
            else "no λ₁"
        )
        return (
            f"per-point centre moves by {_fmt(c['centre'])}, size by {_fmt(c['size'])} over "
            f"{c['points']} points; distinct section points {c['distinct'][:6]}; {lle_text}"
        )

    evidence = (
        f"{weak} (b̄_s sweep) motion types {kinds or ['none labelled']}; along b̄_s: {side(w)}; "
        f"along b̄_rp ({strong}, ξ={strong_panel:g}): {side(s)}; change ratio {_fmt(ratio)} "
        f"(weak if < {WEAK_COUPLING_RATIO:g})"
    )
    if reach is not None and reach["reached"] == 0:
        evidence += (
            f"; the sun never reaches its bearing clearance (largest |x̄_s|, |ȳ_s| "
            f"{_fmt(reach['depth'])} of b̄_s): b̄_s does not act at all"
        )
    if res.size < MIN_RESOLVED * max(lab.size, 1) or not math.isfinite(ratio):
        verdict = "not evaluated"
    elif no_chaos and no_bif and weakly:
        verdict = "holds"
    elif (no_chaos and no_bif) or weakly:
        verdict = "partly"
    else:
        verdict = "does not hold"
    return _verdict(7, verdict, evidence, measured)


QP_GROUPS: dict[str, tuple[str, ...]] = {
    "Ω": ("fig4",),
    "b̄_sp": ("fig6", "fig8"),
    "b̄_rp": ("fig9", "fig11"),
}


def conclusion_8(
    stores: Stores, groups: Mapping[str, Sequence[str]] = QP_GROUPS, tol_fraction: float = 0.05
) -> Verdict:
    """QP under every bifurcation parameter, near (within 5 % of the range, at least one grid
    step) a 3T window."""
    measured: dict[str, Any] = {}
    parts = []
    with_qp = near = used = 0
    for param, figs in groups.items():
        have = [f for f in figs if f in stores]
        if not have:
            continue
        used += 1
        n_qp = n_near = 0
        for f in have:
            for _, x, lab, _ in panels(stores[f]):
                # near: within tol_fraction of the range, and never less than one grid step
                step = float(np.median(np.abs(np.diff(x)))) if x.size > 1 else 0.0
                tol = max(tol_fraction * float(np.ptp(x)), 1.01 * step) if x.size > 1 else 0.0
                q, n = qp_near_3t(x, lab, tol)
                n_qp += q
                n_near += n
        measured[param] = {"figures": have, "qp_points": n_qp, "qp_near_3t": n_near}
        with_qp += int(n_qp > 0)
        near += int(n_near > 0)
        parts.append(f"{param} ({', '.join(have)}): {n_qp} QP point(s), {n_near} near a 3T/6T")
    if not used:
        return _missing(8, [f for g in groups.values() for f in g])
    evidence = (
        "; ".join(parts)
        + f" (near: within {tol_fraction:.0%} of the swept range or one grid step). "
        "b̄_s is left out: the paper's own conclusion 7 and Fig. 12 report no non-periodic "
        "motion under b̄_s"
    )
    measured["parameters"] = used
    if near == used:
        verdict = "holds"
    elif with_qp:
        verdict = "partly"
    else:
        informative = all(
            _informative(stores[f]) for g in groups.values() for f in g if f in stores
        )
        verdict = "does not hold" if informative else "not evaluated"
    return _verdict(8, verdict, evidence, measured)


CONCLUSIONS: dict[int, Callable[[Stores], Verdict]] = {
    1: conclusion_1,
    2: conclusion_2,
    3: conclusion_3,
    4: conclusion_4,
    5: conclusion_5,
    6: conclusion_6,
    7: conclusion_7,
    8: conclusion_8,
}


def evaluate_conclusions(stores: Stores, branches: Branches | None = None) -> list[Verdict]:
    """Every conclusion of the seed's Section 4 checked on ``stores`` (figure name → dataset).

    ``branches`` (figure name → event rows of its continued branches, see :mod:`.routes`)
    makes the routes to chaos of conclusions 4–6 come from detected bifurcation events; a
    figure without rows falls back to the labels (and says so in the evidence).

    A check that raises gives ``not evaluated`` with the error as evidence, so one broken store
    never hides the other verdicts.
    """
    out = []
    for cid, fn in CONCLUSIONS.items():
        try:
            if cid in (4, 5, 6):
                out.append(fn(stores, branches=branches))  # type: ignore[call-arg]
            else:
                out.append(fn(stores))
        except Exception as exc:
            out.append(
                _verdict(cid, "not evaluated", f"check failed: {type(exc).__name__}: {exc}", {})
            )
    return out
