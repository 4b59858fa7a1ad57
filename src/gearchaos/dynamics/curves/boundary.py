"""The front door of two-parameter boundary curves: :func:`boundary_curve`.

The method is in :mod:`gearchaos.dynamics.curves.tracing`, the test functions and codimension-2
points
in :mod:`gearchaos.dynamics.curves.defining`, the file layout in
:mod:`gearchaos.dynamics.curves.file`.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable, Mapping
from dataclasses import replace
from typing import Any

import numpy as np

from ..._checks import check_bool, check_int, check_real
from ...errors import IntegrationError, ParameterError, StoreError
from ...integrate.settings import SolverSettings, split_keywords
from ...model.record import parameter_value
from ...model.target import Target
from ..continuation import events as ev
from ..continuation.arclength import parse_vary
from ..orbits.orbit import ORBIT_SETTINGS, check_tol, contact_levels
from ..orbits.shooting import multipliers_of
from .defining import CURVE_KINDS, TestFunction, grazing_contact
from .file import RESUMABLE, curve_dataset, open_curve
from .tracing import Curve, CurvePoint, CurveSteps

__all__ = ["boundary_curve"]


def boundary_curve(
    target: Target,
    event: ev.Event,
    vary: Any,
    *,
    within: Any = None,
    settings: SolverSettings | None = None,
    params: Mapping[str, Any] | None = None,
    step: float | None = None,
    min_step: float | None = None,
    max_step: float | None = None,
    max_points: int = 200,
    max_corrector: int = 10,
    tol: float | None = None,
    at: Any = None,
    assess: str = "landed",
    store: str | os.PathLike[str] | None = None,
    resume: bool = False,
    overwrite: bool = False,
    progress: Callable[[int, CurvePoint], None] | None = None,
    **values_and_settings: Any,
) -> Any:
    """Continue a fold, period-doubling, Neimark–Sacker or grazing event in a second parameter.

    Parameters
    ----------
    target
        The gear set or :class:`~gearchaos.model.System` of the branch the event was found on.
    event
        An :class:`~gearchaos.dynamics.Event` of kind ``fold``, ``period_doubling``,
        ``neimark_sacker`` or ``grazing`` (:func:`gearchaos.dynamics.events` of a branch). Its
        parameter is the curve's first parameter λ₁, its fixed values are kept fixed.
    vary
        The second parameter λ₂ and its range, ``"xi=0.02:0.1"`` (as for
        :func:`~gearchaos.continuation`). The curve starts at the event (λ₂ at its fixed value
        there, which must lie inside the range) and is followed both ways until it leaves the
        range.
    within
        The range of λ₁ (``"omega=2:5"`` or (lo, hi); default: unbounded, the range of λ₂ sets
        the arclength's units of λ₁ too).
    settings, params, **values_and_settings
        Solver settings and further fixed values, as for :func:`~gearchaos.continuation`
        (the branch's settings: use the same ones).
    step, min_step, max_step
        Arclength steps in units of the ranges (defaults 0.01, 1e-6, 0.02).
    max_points
        Most new points per direction (per run: a resumed run adds as many again).
    max_corrector
        Chord Newton corrections per point.
    tol
        Residual tolerance of ‖Pⁿ(y) − y‖ (default as for periodic orbits: rtol/10).
    at
        Values of λ₂ to land on exactly (a point computed there, flagged ``on_grid``): to compare
        with one-parameter branches at fixed λ₂.
    assess
        Which points state their uncertainty (variables ``uncertainty``, ``uncertainty2``: the
        shift of λ₁ and λ₂ when the point is corrected again with rtol, atol and the
        corrector's tolerance 100 times tighter): ``"landed"`` (default) the points landed on
        ``at`` (on their own λ₂, so λ₂ shifts by 0), ``"all"`` every point (the others on their
        own tangent hyperplane; about doubles the cost), ``"none"``.
    store
        A ``.nc`` (or ``.zarr``) path: the curve is written there, every
        :data:`CHECKPOINT_EVERY` points too.
    resume
        When ``store`` exists: extend its ends that stopped at ``max_points`` or were
        interrupted (the file must hold a curve of the same event kind, parameters, period
        and gear set); ends that stopped for good stay.
    overwrite
        Replace an existing ``store`` (without ``resume``).
    progress
        Called as progress(points so far, point) after every new point.

    Returns
    -------
    xarray.Dataset
        The curve (layout: :mod:`gearchaos.dynamics.curves.file`): per point both parameters,
        the orbit, its multipliers and the test value; the codimension-2 points met
        (``event_*``); the stop reason of each end.
    """
    from ..continuation.branch import check_store, save_branch

    if not isinstance(event, ev.Event):
        raise ParameterError(
            f"event must be an Event of a branch (gearchaos.dynamics.events(branch)): got "
            f"{type(event).__name__}"
        )
    if event.kind not in CURVE_KINDS:
        raise ParameterError(
            f"event kind must be one of {', '.join(CURVE_KINDS)} to continue its boundary: got "
            f"{event.kind!r}"
        )
    name2, a2, b2 = parse_vary(vary)
    name1 = event.parameter
    if name2 == name1:
        raise ParameterError(
            f"vary must name a second parameter, not the event's {name1}", name="vary"
        )
    if a2 > b2:  # the curve is continued both ways from the event: a direction means nothing
        raise ParameterError(
            f"vary {name2}={a2:g}:{b2:g} is reversed: a boundary curve is continued both ways "
            f"from the event, within the range from low to high; give {name2}={b2:g}:{a2:g}",
            name="vary",
        )
    lo1, hi1 = (-math.inf, math.inf) if within is None else _within(within, name1)
    check_bool("resume", resume)
    check_bool("overwrite", overwrite)
    if store is not None and not (resume and os.path.exists(os.fspath(store))):
        check_store(store, overwrite)
    values, cfg = split_keywords(
        values_and_settings, settings, params, ORBIT_SETTINGS, door=boundary_curve, target=target
    )
    fixed = {**event.values, **values}
    fixed.pop(name1, None)
    lam2 = float(fixed.pop(name2)) if name2 in fixed else parameter_value(target, name2)
    lo2, hi2 = a2, b2
    if not lo2 <= lam2 <= hi2:
        raise ParameterError(
            f"vary {name2}={lo2:g}:{hi2:g}: the event's {name2}={lam2:g} lies outside it; "
            "the range must hold the event",
            name="vary",
        )
    steps = CurveSteps(
        initial=_pos("step", step, 0.01),
        minimum=_pos("min_step", min_step, 1e-6),
        maximum=_pos("max_step", max_step, 0.02),
        max_points=check_int("max_points", max_points, lo=1, hi=1_000_000),
        max_corrector=check_int("max_corrector", max_corrector, lo=2, hi=1000),
    )
    if not steps.minimum <= steps.initial <= steps.maximum:
        raise ParameterError(
            "the steps must satisfy min_step <= step <= max_step: got "
            f"{steps.minimum:g}, {steps.initial:g}, {steps.maximum:g}"
        )
    if assess not in ASSESS:
        raise ParameterError(f"assess must be one of {', '.join(ASSESS)}: got {assess!r}")
    grid = _landing_values(at, name2, lo2, hi2)
    fn = TestFunction(event.kind)
    curve = Curve(
        target, (name1, name2), fixed, cfg, int(event.period), check_tol(tol, cfg), fn,
        ((lo1, hi1), (lo2, hi2)), steps,
    )  # fmt: skip
    y0 = np.asarray(event.state, dtype=float)
    span1 = hi1 - lo1 if math.isfinite(hi1 - lo1) else max(abs(event.value), 1e-9)
    curve.scale = np.array(
        [max(1.0, float(np.max(np.abs(y0)))) * math.sqrt(y0.size)] * y0.size + [span1, hi2 - lo2]
    )
    extra = {
        "vary": f"{name2}={a2:.10g}:{b2:.10g}",
        "within": "" if within is None else f"{name1}={lo1:.10g}:{hi1:.10g}",
        "start": f"{event.kind} at {name1}={event.value:.10g} (period {event.period})",
        "start_value2": lam2,
    }
    if store is not None and resume and os.path.exists(os.fspath(store)):
        backward, forward, reasons = _resume(curve, open_curve(store), extra)
    else:
        backward, forward, reasons = _start(curve, event, y0, lam2, bool(np.any(grid == lam2)))

    count = [0]
    written = [False]

    def save(reason_b: str, reason_f: str) -> Any:
        for p in backward[1:]:
            p.s = -abs(p.s)
        ds = curve_dataset(curve, backward, forward, (reason_b, reason_f), extra)
        for p in backward[1:]:
            p.s = abs(p.s)
        if store is not None:  # a checkpoint of this run (or the resumed file) is replaced
            save_branch(ds, store, overwrite=resume or overwrite or written[0])
            written[0] = True
        return ds

    def step_done(q: CurvePoint) -> None:
        count[0] += 1
        if progress is not None:
            progress(count[0], q)
        if store is not None and count[0] % CHECKPOINT_EVERY == 0:
            save(*(r if not r.startswith("running") else "interrupted" for r in reasons))

    for k, pts in ((1, forward), (0, backward)):
        if not reasons[k].startswith((*RESUMABLE, "running")):
            continue
        end = pts[-1]
        shot, _ = curve.shots(end.z[None])  # M and the borders at the end point, then DF
        if shot is not None and shot.monodromy is not None:
            fn.adapt(shot.monodromy[0], multipliers_of(shot.monodromy[0]))
        got = None if shot is None else curve.jacobian(end.z)
        if got is None:
            reasons[k] = "the map failed at the end point"
            continue
        end.jac, end.monodromy = got[0], got[1].monodromy
        curve.direction = 1 if k == 1 else -1
        reasons[k] = "running"
        reasons[k] = curve.run(pts, grid, step_done)
    for e in curve.events:
        if e["direction"] < 0:
            e["s"] = -abs(e["s"])
    if assess != "none":
        _assess(curve, [*backward[1:], *forward], everywhere=assess == "all")
    extra["assessed"] = assess
    return save(reasons[0], reasons[1])


def _assess(curve: Curve, pts: list[CurvePoint], everywhere: bool) -> None:
    """The uncertainty in λ₁ and λ₂ of the points landed on a value of ``at`` (and of all
    the others when ``everywhere``), and of the codimension-2 points located on the way.

    A point is corrected again with rtol, atol and the corrector's tolerance 100 times tighter
    — a landed point on the same λ₂, any other on its own tangent hyperplane (the shift is then
    across the curve) — and the shifts of λ₁ and λ₂ are its uncertainties. The curve's test
    function is built from a monodromy matrix accurate to about rtol, so at the default rtol
    1e-8 a period-doubling point can be a few 1e-9 off; tests compare curves with events
    through this. A codimension-2 point is located again on the tighter curve
    (:func:`_relocate`) and its shift is added to half its bracket. Every shift is taken
    :func:`fine_margin` times, for the tighter solution's own error, plus the tighter
    corrector's convergence bound (:func:`_shift`). Where the 100 times
    tighter solution fails, one 10 times tighter is used (:data:`TIGHTER`)."""
    todo = [
        p for p in pts
        if (p.landed or everywhere) and p.tangent is not None and math.isnan(p.uncertainty)
    ]  # fmt: skip
    found = [e for e in curve.events if "bracket" in e and e["located"] and e["p"] is not None]
    if not todo and not found:
        return
    fines = [_tighter(curve, f) for f in TIGHTER]
    for p in todo:
        for fine in fines:
            _adapt(fine, p)
            q = fine.land(p, -1, float(p.z[-1])) if p.landed else fine.on_hyperplane(p, 0.0)
            if q is not None:
                u = _shift(fine, curve, q.z, p.z)
                p.uncertainty, p.uncertainty2 = u[0], 0.0 if p.landed else u[1]
                break
        else:
            p.uncertainty = p.uncertainty2 = math.inf
    for e in found:
        for fine in fines:
            z = _relocate(fine, e)
            if z is not None:
                shift = np.array(_shift(fine, curve, z, e["z"]))
                break
        else:
            shift = np.full(2, math.inf)
        e["uncertainty"] = tuple(float(u + d) for u, d in zip(e["uncertainty"], shift, strict=True))
        del e["bracket"]  # assessed once: a resumed run keeps the stored value
    curve.evals += sum(fine.evals for fine in fines)


def _adapt(fine: Curve, p: CurvePoint) -> None:
    """The test function's borders (fold, period doubling) or followed multiplier
    (Neimark–Sacker) at p, as the continuation had them there: those of the curve's last
    point may suit a point far from it badly. A point read back from a file holds no
    monodromy (the identity in its place): its map is evaluated once for it."""
    monodromy = p.monodromy
    if fine.fn.kind in ("fold", "period_doubling") and np.array_equal(
        monodromy, np.eye(monodromy.shape[0])
    ):
        shot, _ = fine.shots(p.z[None])
        if shot is None or shot.monodromy is None:
            return
        monodromy = shot.monodromy[0]
    fine.fn.adapt(monodromy, p.mu)


def _shift(fine: Curve, curve: Curve, z_fine: np.ndarray, z: np.ndarray) -> tuple[float, float]:
    """The uncertainties of λ₁ and λ₂ at z from the tighter solution z_fine: the shift times
    :func:`fine_margin`, plus the tighter corrector's own convergence bound (its last step
    was at most 10·tol of max(|λ|, the parameter's scale))."""
    margin = fine_margin(fine.cfg.rtol, curve.cfg.rtol)
    floor = 10.0 * fine.tol * np.maximum(np.abs(z_fine[-2:]), curve.scale[-2:])
    u = margin * np.abs(z_fine[-2:] - z[-2:]) + floor
    return float(u[0]), float(u[1])


def _tighter(curve: Curve, factor: float) -> Curve:
    """The curve's continuation with rtol, atol and the corrector's tolerance ``factor`` times
    tighter."""
    cfg = curve.cfg.replace(rtol=curve.cfg.rtol / factor, atol=curve.cfg.atol / factor)
    fine = Curve(
        curve.target, curve.names, curve.fixed, cfg, curve.n, max(curve.tol / factor, 1e-14),
        replace(curve.fn), curve.bounds, curve.steps,
    )  # fmt: skip
    fine.scale = curve.scale
    return fine


def fine_margin(fine_rtol: float, rtol: float) -> float:
    """The factor on the shift to a solution at ``fine_rtol`` that makes it an uncertainty of
    the solution at ``rtol``: the global error of DOPRI5 scales about as rtol^(5/6), so the
    tighter solution's own error is about r = (fine_rtol/rtol)^(5/6) of the first one's (1/46
    at 100 times tighter); the shift, e(1 − r), is divided by 1 − 2r (twice r, to be safe):
    1.05 at 100 times, 1.42 at 10 times tighter."""
    r = (fine_rtol / rtol) ** (5.0 / 6.0)
    return 1.0 / (1.0 - 2.0 * r)


def _relocate(fine: Curve, e: dict[str, Any]) -> np.ndarray | None:
    """The codimension-2 point ``e`` located again on the tighter curve ``fine``: the Illinois
    iteration on the same tangent hyperplanes of the point before it, in a bracket around the
    first location widened until its test changes sign (None: no sign change up to the whole
    step, or a failed correction)."""
    from .defining import codim2_tests

    p, key, sigma = e["p"], e["kind"], float(e["sigma"])
    sign = 1.0 if sigma >= 0 else -1.0
    centre = abs(sigma)
    lo, hi = e["bracket"]
    half = max(0.5 * (hi - lo), 1e-12)
    _adapt(fine, p)
    if np.isfinite(e["mu"]):
        fine.fn.mu_ref = complex(e["mu"])

    def fn(x: float) -> float | None:
        pt = fine.on_hyperplane(p, sign * x)
        return None if pt is None else codim2_tests(fine.fn, pt.mu)[key]

    tol = max(half * 1e-2, 1e-14)
    for widen in (4.0, 40.0, 400.0):
        a, b = max(centre - widen * half, 0.0), centre + widen * half
        fa, fb = fn(a), fn(b)
        if fa is None or fb is None:
            return None
        if fa * fb < 0:
            x, _ok, _ = ev.illinois(fn, a, b, fa, fb, tol, max_evaluations=20)
            pt = fine.on_hyperplane(p, sign * x)
            return None if pt is None else pt.z
    return None


#: How much tighter the assessing solutions are, in order: the next is tried where the first
#: fails (its correction does not converge, or an integration runs out of its step budget).
TIGHTER = (100.0, 10.0)

#: The choices of ``assess``.
ASSESS = ("landed", "all", "none")

#: Points between checkpoints of the store.
CHECKPOINT_EVERY = 20


def _start(
    curve: Curve, event: ev.Event, y0: np.ndarray, lam2: float, landed: bool
) -> tuple[list[CurvePoint], list[CurvePoint], list[str]]:
    """The start point (corrected at the event's λ₂) and the two directions' point lists."""
    z0 = np.append(y0, [event.value, lam2])
    shot, why = curve.shots(z0[None])
    if shot is None or shot.monodromy is None:
        raise IntegrationError(f"the map failed at the event {event!r}: {why}")
    if event.kind == "grazing":
        levels = contact_levels(curve.system(event.value, lam2))
        curve.fn.contact = grazing_contact(levels, shot.obs_min[0], shot.obs_max[0], event.detail)
    curve.fn.adapt(shot.monodromy[0], multipliers_of(shot.monodromy[0]))
    e2 = np.zeros(z0.size)
    e2[-1] = 1.0
    p0, why = curve.correct(z0, e2, lam2)
    if p0 is None:
        raise IntegrationError(
            f"the {event.kind} curve could not start at {event!r} ({why}); continue the branch "
            "with a tighter tol or rtol so that the event is located more precisely"
        )
    left = curve._left(p0)
    if left:
        raise IntegrationError(f"the start point is no {event.kind}: {left}")
    t = curve.tangent(p0, e2)
    p0.tangent = t
    p0.landed = landed  # the event's λ₂ is a value of ``at``
    back = replace(p0, tangent=-t)
    return [back], [p0], ["running", "running"]


def _resume(
    curve: Curve, ds: Any, extra: dict[str, Any]
) -> tuple[list[CurvePoint], list[CurvePoint], list[str]]:
    """The point lists of a stored curve, after checking it is the same curve."""
    want = {
        "curve_kind": curve.fn.kind,
        "parameter": curve.names[0],
        "parameter2": curve.names[1],
        "period": curve.n,
        "vary": extra["vary"],
        "within": extra["within"],
        "start": extra["start"],
    }
    for key, value in want.items():
        got = ds.attrs.get(key)
        if str(got) != str(value):
            raise StoreError(
                f"cannot resume {ds.encoding.get('source', 'the store')}: its {key} is {got!r}, "
                f"this run's is {value!r}"
            )
    if json.loads(str(ds.attrs.get("fixed", "{}"))) != json.loads(_fixed(curve.fixed)):
        raise StoreError("cannot resume: the store's fixed values differ from this run's")
    contact = str(ds.attrs.get("contact", ""))
    if contact:
        a, b = contact.split(":")
        curve.fn.contact = (a, b)
    curve.scale = np.asarray(json.loads(str(ds.attrs["scale"])), dtype=float)
    n1, n2 = curve.names
    mu = np.asarray(ds.multiplier_re.values) + 1j * np.asarray(ds.multiplier_im.values)
    pts = []
    for k in range(ds.sizes["point"]):
        z = np.append(ds.orbit_state.values[k], [ds[n1].values[k], ds[n2].values[k]])
        pts.append(
            CurvePoint(
                z=z, monodromy=np.eye(z.size - 2), mu=mu[k], g=float(ds.test_value.values[k]),
                residual=float(ds.residual.values[k]), evals=int(ds.iterations.values[k]),
                sections=np.asarray(ds.orbit_sections.values[k]),
                obs_min=np.asarray(ds.obs_min.values[k]), obs_max=np.asarray(ds.obs_max.values[k]),
                tangent=np.asarray(ds.tangent.values[k]), s=abs(float(ds.arclength.values[k])),
                landed=bool(ds.on_grid.values[k]),
                uncertainty=(
                    float(ds.uncertainty.values[k]) if "uncertainty" in ds else math.nan
                ),
                uncertainty2=(
                    float(ds.uncertainty2.values[k]) if "uncertainty2" in ds else math.nan
                ),
            )
        )  # fmt: skip
    direction = np.asarray(ds.direction.values)
    k0 = int(np.flatnonzero(direction == 0)[0])
    forward = pts[k0:]
    backward = [replace(pts[k0], tangent=-np.asarray(pts[k0].tangent)), *pts[k0 - 1 :: -1]]
    if k0 == 0:
        backward = backward[:1]
    if curve.fn.kind == "neimark_sacker":
        curve.fn.mu_ref = complex(ds.critical_re.values[-1], ds.critical_im.values[-1])
    for k in range(ds.sizes.get("event", 0)):
        p = int(ds.event_point.values[k])
        s = float(ds.event_arclength.values[k])
        curve.events.append(
            {
                "kind": str(ds.event_kind.values[k]),
                "z": np.append(ds.event_state.values[k],
                               [ds.event_value.values[k], ds.event_value2.values[k]]),
                "s": s,
                "mu": complex(ds.event_multiplier_re.values[k], ds.event_multiplier_im.values[k]),
                "located": bool(ds.event_located.values[k]),
                "uncertainty": (float(ds.event_uncertainty.values[k]),
                                float(ds.event_uncertainty2.values[k])),
                "p": pts[p] if 0 <= p < len(pts) else None,
                "direction": -1 if s < 0 else 1,
            }
        )  # fmt: skip
    reasons = [str(ds.attrs["stop_reason_backward"]), str(ds.attrs["stop_reason_forward"])]
    return backward, forward, reasons


def _fixed(values: Mapping[str, Any]) -> str:
    from ..continuation.branch import fixed_json

    return fixed_json(values)


def _landing_values(at: Any, name2: str, lo2: float, hi2: float) -> np.ndarray:
    """The sorted distinct values of ``at`` (None: none), each a finite number inside the
    range [lo2, hi2] of ``vary``: a value outside it would never be landed on."""
    try:
        grid = np.unique(np.asarray([] if at is None else at, dtype=float).reshape(-1))
    except (TypeError, ValueError):
        raise ParameterError(
            f"at must be values of {name2} (numbers): got {at!r}", name="at"
        ) from None
    if not np.all(np.isfinite(grid)):
        raise ParameterError(f"at must be finite values of {name2}: got {at!r}", name="at")
    outside = grid[(grid < lo2) | (grid > hi2)]
    if outside.size:
        raise ParameterError(
            f"at {', '.join(f'{v:g}' for v in outside)} lie outside vary's range "
            f"{name2}={lo2:g}:{hi2:g}, so the curve would never land on them; give values "
            "inside it or widen vary",
            name="at",
        )
    return grid


def _within(within: Any, name1: str) -> tuple[float, float]:
    if isinstance(within, str):
        name, a, b = parse_vary(within, "within")
        if name != name1:
            raise ParameterError(
                f"within must range the event's parameter {name1}: got {name}", name="within"
            )
    elif isinstance(within, tuple | list) and len(within) == 2:
        a = check_real("within start", within[0])
        b = check_real("within stop", within[1])
    else:
        raise ParameterError(
            f"within must be '{name1}=LO:HI' or (lo, hi): got {within!r}", name="within"
        )
    if a == b:
        raise ParameterError(f"within's ends must differ: got {a!r} and {b!r}", name="within")
    return min(a, b), max(a, b)


def _pos(name: str, value: float | None, default: float) -> float:
    if value is None:
        return default
    return check_real(name, value, lo=0.0, lo_open=True)
