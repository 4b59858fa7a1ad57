"""The calibration objective: a candidate gear set scored by the report's own evaluation.

For a gear set g the objective runs, for every panel that a landmark of ``landmarks.toml``
names (a figure's recipe at one family value, e.g. Fig. 4 at ξ = 0.03), one sweep of the
recipe's swept parameter (:func:`gearchaos.bifurcation`) with the report's protocol: the recipe's
fixed values, the start at rest perturbed by the default 10⁻⁶ (:class:`SolverSettings`), 100
transient and 100 recorded periods, the default tolerances, λ₁ on and every point decided by
the motion verdict (:mod:`gearchaos.dynamics.verdict.decide`). Every landmark is checked with
:func:`gearchaos.paper.landmarks.evaluate` (the report's tolerances); the landmarks that name a
bifurcation are then scored from the events of continued branches of their panel
(:func:`~gearchaos.paper.routes.follow_branches`,
:func:`~gearchaos.paper.routes.landmarks_from_events`), as the report does, with coarser steps.
Two numbers come out:

``score``
    the sum of the landmark scores (each in [0, 1]; :func:`gearchaos.paper.landmarks.score`);
``structure``
    the structural term of :mod:`gearchaos.paper.structure` in [0, 1]: double-sided impact in
    the chaotic and multi-periodic regions of the backlash sweeps, and Floquet multipliers
    that change along b̄_sp and b̄_rp.

The grid
    Only the swept values the landmarks look at are run, but every landmark is guaranteed
    points where it is read (:func:`panel_grid`): ``inside`` points strictly inside the
    interval it is evaluated on ([lo, hi], or ± tolerance around ``at``), two points half a
    tolerance either side of every value where a change is expected (a transition's ``at``,
    a window's edges), so a change there is located within its tolerance, and ``points``
    more spread over the union of the panel's intervals, widened by three tolerances, for the
    context a transition or a window edge is read against.

Limits: the grid is denser near the landmarks than elsewhere, so the fractions of the
structural term are over those points; the branches of event landmarks are followed with
coarse steps (:data:`BRANCH_STEPS`), so an event can be missed that the report's finer
continuation finds.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from .._checks import check_bool, check_int
from ..integrate.settings import SolverSettings

__all__ = [
    "BRANCH_STEPS",
    "Evaluation",
    "PanelRun",
    "SweepSettings",
    "evaluation_interval",
    "landmark_objective",
    "panel_grid",
    "sweep_plan",
]

#: (range / largest step, most points per branch, highest period, most branches per panel)
#: of the branches that score the event landmarks in every trial (the quick report's).
BRANCH_STEPS = (20, 40, 4, 4)


@dataclass(frozen=True)
class Evaluation:
    """The outcome of one candidate: landmark score, per-landmark scores by id, seconds
    spent, the structural term and its parts (JSON-ready)."""

    score: float
    landmarks: Mapping[str, float]
    seconds: float = 0.0
    structure: float = 0.0
    parts: Mapping[str, Any] = field(default_factory=dict)


_DEFAULT_SOLVER = SolverSettings()


@dataclass(frozen=True)
class SweepSettings:
    """The objective's configuration (checked on construction, with the same messages as every
    other entry point). The defaults are the report's protocol (:data:`gearchaos.paper.recipes.
    FULL_PERIODS`, the default tolerances and perturbation, λ₁ and verdicts on).

    Attributes
    ----------
    points
        Grid points per panel spread over its landmarks' (widened) intervals.
    inside
        Grid points strictly inside every landmark's evaluation interval (≥ 1).
    transient_periods, periods, rtol, atol, lyapunov
        The sweeps' protocol.
    branches
        Score the event landmarks from continued branches (:data:`BRANCH_STEPS`).
    structure
        Compute the structural term (:mod:`gearchaos.paper.structure`).
    loads
        Measure the peak dynamic mesh loads (:mod:`gearchaos.paper.loads`): a candidate whose
        teeth would break is not plausible, whatever it scores.
    """

    points: int = 12
    inside: int = 2
    transient_periods: int = 100
    periods: int = 100
    rtol: float = _DEFAULT_SOLVER.rtol
    atol: float = _DEFAULT_SOLVER.atol
    lyapunov: bool = True
    branches: bool = True
    structure: bool = True
    loads: bool = True

    def __post_init__(self) -> None:
        check_int("points", self.points, lo=0, hi=10**6)
        check_int("inside", self.inside, lo=1, hi=10**4)
        for name in ("lyapunov", "branches", "structure", "loads"):
            check_bool(name, getattr(self, name))
        _ = self.solver

    @property
    def solver(self) -> SolverSettings:
        """The solver settings of every calibration sweep."""
        return SolverSettings(
            transient_periods=self.transient_periods,
            periods=self.periods,
            rtol=self.rtol,
            atol=self.atol,
        )

    @classmethod
    def quick(cls) -> SweepSettings:
        """Tiny sweeps for CI: 1 point inside each interval, 20 + 16 periods, no branches."""
        return cls(points=2, inside=1, transient_periods=20, periods=16, branches=False)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


# --------------------------------------------------------------------------- the grid
def evaluation_interval(mark: Any) -> tuple[float, float]:
    """The interval a landmark is read on by :func:`gearchaos.paper.landmarks.evaluate`:
    [lo, hi] of a label or a window, ``at`` ± tolerance of a label or a transition at a value,
    [lo − tolerance, hi + tolerance] of a transition anywhere in [lo, hi]."""
    lo, hi = mark.span
    tol = float(mark.tolerance)
    if mark.at is not None or mark.kind == "transition":
        return lo - tol, hi + tol
    return lo, hi


def _edges(mark: Any) -> tuple[float, ...]:
    """Values where the landmark expects a change: a transition's ``at`` (or [lo, hi]'s
    ends), a window's edges."""
    if mark.kind == "transition" or mark.kind == "window":
        lo, hi = mark.span
        return (lo,) if lo == hi else (lo, hi)
    return ()


def panel_grid(
    marks: Sequence[Any], settings: SweepSettings, bounds: tuple[float, float]
) -> np.ndarray:
    """The swept values of one panel (see the module docstring), inside ``bounds``."""
    lo_b, hi_b = bounds
    vals: list[float] = []
    widened: list[tuple[float, float]] = []
    for m in marks:
        a, b = evaluation_interval(m)
        k = settings.inside
        vals.extend(a + (i + 0.5) * (b - a) / k for i in range(k))
        tol = float(m.tolerance)
        for e in _edges(m):
            vals.extend((e - 0.5 * tol, e + 0.5 * tol))
        widened.append((a - 3 * tol, b + 3 * tol))
    merged: list[list[float]] = []
    for a, b in sorted((max(a, lo_b), min(b, hi_b)) for a, b in widened):
        if merged and a <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], b)
        elif b > a:
            merged.append([a, b])
    total = sum(b - a for a, b in merged)
    if settings.points and total > 0:
        for a, b in merged:
            n = max(2, round(settings.points * (b - a) / total))
            vals.extend(np.linspace(a, b, n).tolist())
    arr = np.asarray(vals, dtype=float)
    arr = arr[(arr >= lo_b) & (arr <= hi_b)]
    return np.unique(np.round(arr, 10))


@dataclass(frozen=True)
class PanelRun:
    """One sweep of the objective: a recipe's swept parameter at one family value."""

    figure: str
    family: str
    value: float
    vary: str
    grid: tuple[float, ...]
    params: Mapping[str, float]

    @property
    def key(self) -> str:
        return f"{self.figure}:{self.family}={self.value:g}"

    def sweep_kwargs(self, settings: SweepSettings, observe: tuple[str, ...]) -> dict[str, Any]:
        """Keyword arguments of :func:`gearchaos.bifurcation` (all but the target)."""
        return {
            "vary": {self.vary: np.asarray(self.grid)},
            "family": {self.family: [self.value]},
            "params": dict(self.params),
            "observe": observe,
            "planets": (1,),
            "initial_conditions": "fresh",
            "settings": settings.solver,
            "lyapunov": settings.lyapunov,
        }


def _bounds(rec: Any) -> tuple[float, float]:
    """The values a panel may sweep: the recipe's range widened by the 2 % slack that
    :func:`~gearchaos.paper.landmarks.recipe_for` allows, never below Ω's start or 0."""
    slack = 0.02 * (rec.vary.stop - rec.vary.start)
    if rec.vary.name == "omega":
        return rec.vary.start, rec.vary.stop + slack
    return max(rec.vary.start - slack, 1e-3), rec.vary.stop + slack


def sweep_plan(
    landmarks: Sequence[Any],
    settings: SweepSettings,
    recipe_for: Callable[[Any], str] | None = None,
) -> dict[str, PanelRun]:
    """The panels the landmarks need, by :attr:`PanelRun.key`, each with its grid
    (:func:`panel_grid`) and the recipe's fixed values. ``recipe_for`` maps a landmark to its
    recipe (default :func:`gearchaos.paper.landmarks.recipe_for`)."""
    from .recipes import get_recipe

    if recipe_for is None:
        from .landmarks import recipe_for as default_recipe_for

        recipe_for = default_recipe_for
    groups: dict[tuple[str, float], list[Any]] = {}
    for m in landmarks:
        rec = get_recipe(recipe_for(m))
        value = float(m.fixed[rec.family.name])
        groups.setdefault((rec.name, value), []).append(m)
    plan: dict[str, PanelRun] = {}
    for (fig, value), marks in groups.items():
        rec = get_recipe(fig)
        params = dict(rec.fixed)
        for m in marks:
            params.update({k: v for k, v in m.fixed.items() if k not in (rec.vary.name,)})
        params.pop(rec.family.name, None)
        grid = panel_grid(marks, settings, _bounds(rec))
        run = PanelRun(fig, rec.family.name, value, rec.vary.name, tuple(grid.tolist()), params)
        plan[run.key] = run
    return plan


def panel_key(mark: Any, recipe_for: Callable[[Any], str] | None = None) -> str:
    """The :attr:`PanelRun.key` of the panel a landmark is read on."""
    from .landmarks import recipe_for as default_recipe_for
    from .recipes import get_recipe

    rec = get_recipe((recipe_for or default_recipe_for)(mark))
    return f"{rec.name}:{rec.family.name}={float(mark.fixed[rec.family.name]):g}"


# --------------------------------------------------------------------------- objective
def _event_rows(
    gs: Any, plan: Mapping[str, PanelRun], stores: Mapping[str, Any], marks: Sequence[Any]
) -> dict[str, list[dict[str, Any]]]:
    """Event rows (:func:`gearchaos.paper.routes.event_rows`) by figure, from the branches
    continued on every panel that an event landmark names."""
    from .routes import event_rows, follow_branches

    steps, max_points, max_period, max_branches = BRANCH_STEPS
    wanted = {panel_key(m) for m in marks if m.event}
    rows: dict[str, list[dict[str, Any]]] = {}
    for key in sorted(wanted):
        run = plan[key]
        ds = stores[key]
        x = np.asarray(ds[run.vary].values, dtype=float)
        labels = np.asarray(ds["motion"].values).astype(str).reshape(-1)
        fixed = {**run.params, run.family: run.value}
        branches = follow_branches(
            gs, run.vary, x, labels, fixed,
            max_period=max_period, max_points=max_points, steps=steps, max_branches=max_branches,
        )  # fmt: skip
        mine = rows.setdefault(run.figure, [])
        for b in branches:
            mine.extend(event_rows(b, run.value, marker=True))
    return rows


def landmark_objective(
    landmarks: Sequence[Any], settings: SweepSettings | None = None
) -> Callable[[Any], Evaluation]:
    """The calibration objective: gear set → :class:`Evaluation` (see the module docstring)."""
    from ..sweep.run import bifurcation
    from .landmarks import evaluate, score
    from .recipes import get_recipe
    from .routes import BRANCH_ROW, landmarks_from_events

    settings = settings or SweepSettings()
    marks = list(landmarks)
    plan = sweep_plan(marks, settings)

    def objective(gs: Any) -> Evaluation:
        t0 = time.perf_counter()
        stores = {
            key: bifurcation(
                gs, progress=False, **run.sweep_kwargs(settings, get_recipe(run.figure).observe)
            )
            for key, run in plan.items()
        }
        results = [evaluate(m, stores[panel_key(m)]) for m in marks]
        parts: dict[str, Any] = {}
        if settings.branches and any(m.event for m in marks):
            rows = _event_rows(gs, plan, stores, marks)
            results = landmarks_from_events(results, rows)
            found_rows = [row for r in rows.values() for row in r]
            parts["events"] = sum(1 for row in found_rows if row["kind"] != BRANCH_ROW)
        structure = 0.0
        if settings.structure:
            from .structure import structure_term

            structure, found = structure_term(gs, stores, settings.solver)
            parts.update(found)
        if settings.loads:
            from .loads import load_factors

            parts["loads"] = load_factors(gs)
        per = {str(r.landmark.id): float(r.score) for r in results}
        held = sum(1 for r in results if r.verdict == "holds")
        parts["holds"] = held
        parts["points"] = int(sum(len(run.grid) for run in plan.values()))
        return Evaluation(
            float(score(results)), per, time.perf_counter() - t0, float(structure), parts
        )

    return objective
