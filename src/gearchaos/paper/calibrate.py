"""Calibrate the seed's lost Table 1 against the landmarks of its own text.

The seed (Sheng et al. 2016) lost the table of its gear set. What survives are its quantitative
statements — "1T for 0 ≤ Ω ≤ 1.35", "2T at Ω = 1.875", "chaos within b̄_rp ∈ 11.3–11.6" — kept
as data in ``paper/landmarks.toml`` (:mod:`gearchaos.paper.landmarks`). This module searches
the quantities Table 1 would have fixed, inside physically plausible ranges, for the gear set
whose coarse sweeps reproduce the most landmarks.

Objective
    For a candidate gear set g, the landmarks are grouped by figure; each figure gets one short
    sweep (:func:`gearchaos.bifurcation`, zero initial state, ``points`` values spread over the
    landmarks' own ranges, the panels they name, 60 + 60 mesh periods, rtol 1e-7, largest
    Lyapunov exponent on so that chaos and quasi-periodic motion get told apart). Then
    ``J(g) = score(evaluate_all(landmarks, stores))`` — the number of landmarks reproduced, each
    scoring in [0, 1].

Search space (:data:`DEFAULT_SPACE`)
    N ∈ {3, 4, 5} with standard tooth numbers near the default's (z_r = z_s + 2 z_p,
    (z_s + z_r)/N an integer, neighbouring planets clear), input torque T_D, transmission-error
    amplitude A_sp = A_rp, stiffness ratios ε_sp = k_a,sp/k_m,sp and ε_rp, the ratio
    k_m,rp/k_m,sp, scale factors of the sun, planet and carrier inertia (equivalent masses), the
    characteristic length b_c and the load mode (constant torque or constant power). The
    dimensionless clearances b̄ are the seed's, so b_c scales the physical clearances and the
    ratios A/b_c, and with T_D sets T̄_D = T_D/(r_bs k_m,sp b_c).

Method
    A seeded Latin-hypercube sample (the first candidate is the unchanged base gear set), then a
    local refinement: each round perturbs one coordinate of each of the best few candidates by
    ± a step in the unit cube (a neighbouring tooth combination, or the other load mode, for the
    discrete ones) and halves the step after a round without improvement. The sequence depends
    only on the seed and on the scores, so it is deterministic and a restart reproduces it.

Resumability
    Every evaluated candidate is appended to a JSON-lines file (one line, flushed and fsynced),
    keyed by a hash of its variables; a restart reads the file, re-uses the stored scores
    instead of evaluating again, and continues the same sequence.

Limits: coarse sweeps mis-label points near bifurcations (transients of 60 periods), so scores
are noisy by about a landmark; the search is a heuristic, not a global optimiser.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from .._checks import check_bool, check_int, check_real
from .._files import MissingFileError, check_path, read_text_file
from ..errors import ParameterError, StoreError
from ..integrate.settings import SolverSettings
from .search_space import (
    BASE_PRESET,
    DEFAULT_SPACE,
    Candidate,
    Range,
    SearchSpace,
    TeethChoice,
    _base,
    _History,
    base_candidate,
    build_gearset,
    candidate_from_record,
    candidate_key,
    enumerate_teeth,
    gearset_changes,
    plausibility,
    propose,
    record_gearset,
)

__all__ = [
    "BASE_PRESET",
    "DEFAULT_SPACE",
    "CalibrationResult",
    "Candidate",
    "Evaluation",
    "Range",
    "SearchSpace",
    "SweepSettings",
    "TeethChoice",
    "base_candidate",
    "best_record",
    "build_gearset",
    "calibrate",
    "candidate_from_record",
    "candidate_key",
    "enumerate_teeth",
    "gearset_changes",
    "landmark_objective",
    "plausibility",
    "propose",
    "ranked",
    "read_results",
    "record_gearset",
    "sweep_plan",
]


# --------------------------------------------------------------------------- objective
@dataclass(frozen=True)
class Evaluation:
    """The outcome of one candidate: total score, per-landmark scores by id, seconds spent."""

    score: float
    landmarks: Mapping[str, float]
    seconds: float = 0.0


@dataclass(frozen=True)
class SweepSettings:
    """Coarseness of the calibration sweeps: points per landmark range and the solver settings
    (checked on construction, with the same messages as every other entry point)."""

    points: int = 48
    transient_periods: int = 60
    periods: int = 60
    rtol: float = 1e-7
    atol: float = 1e-9
    lyapunov: bool = True

    def __post_init__(self) -> None:
        check_int("points", self.points, lo=1, hi=10**6)
        check_bool("lyapunov", self.lyapunov)
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
        return cls(points=6, transient_periods=20, periods=16)


def _landmark_interval(lm: Any) -> tuple[float, float]:
    lo = getattr(lm, "lo", None)
    hi = getattr(lm, "hi", None)
    at = getattr(lm, "at", None)
    tol = float(getattr(lm, "tolerance", 0.0) or 0.0)
    if lo is not None and hi is not None:
        return float(lo) - tol, float(hi) + tol
    where = at if at is not None else lo if lo is not None else hi
    if where is None:
        raise ParameterError(f"landmark {getattr(lm, 'id', lm)!r} has neither lo/hi nor at")
    x = float(where)
    return x - tol, x + tol


def _grid(intervals: Sequence[tuple[float, float]], points: int, floor: float) -> np.ndarray:
    """``points`` values over the union of ``intervals`` (≥ 3 per merged interval), every
    interval's ends included, spread in proportion to length."""
    iv = sorted((max(a, floor), max(b, floor)) for a, b in intervals)
    merged: list[list[float]] = []
    for a, b in iv:
        if merged and a <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], b)
        else:
            merged.append([a, b])
    total = sum(b - a for a, b in merged) or 1.0
    vals: list[float] = []
    for a, b in merged:
        n = max(3, round(points * (b - a) / total)) if b > a else 1
        vals.extend(np.linspace(a, b, n).tolist())
    return np.unique(np.round(np.asarray(vals), 10))


def sweep_plan(
    landmarks: Sequence[Any],
    settings: SweepSettings,
    recipe_for: Callable[[Any], str] | None = None,
) -> dict[str, dict[str, Any]]:
    """Keyword arguments of :func:`gearchaos.bifurcation` for each figure the landmarks need:
    the recipe's swept parameter over the union of the landmarks' ranges (± tolerance), the
    panels they name, the recipe's fixed values updated by the landmarks' own.
    ``recipe_for`` maps a landmark to its covering recipe (default
    :func:`gearchaos.paper.landmarks.recipe_for`)."""
    from .recipes import get_recipe

    if recipe_for is None:
        from .landmarks import recipe_for as default_recipe_for

        recipe_for = default_recipe_for

    by_fig: dict[str, list[Any]] = {}
    for lm in landmarks:
        by_fig.setdefault(recipe_for(lm), []).append(lm)
    plan: dict[str, dict[str, Any]] = {}
    for fig, lms in by_fig.items():
        rec = get_recipe(fig)
        fam_name = rec.family.name
        fixed = dict(rec.fixed)
        families: list[float] = []
        intervals = []
        for lm in lms:
            extra = dict(getattr(lm, "fixed", None) or {})
            if fam_name in extra:
                families.append(float(extra.pop(fam_name)))
            else:
                families.extend(_panel_values(rec, getattr(lm, "panel", None)))
            extra.pop(rec.vary.name, None)
            fixed.update(extra)
            intervals.append(_landmark_interval(lm))
        floor = rec.vary.start if rec.vary.name == "omega" else 0.0
        plan[fig] = {
            "vary": {rec.vary.name: _grid(intervals, settings.points, floor)},
            "family": {fam_name: sorted(set(families))},
            "params": fixed,
            "observe": rec.observe,
            "planets": (1,),
            "initial_conditions": "fresh",
            "settings": settings.solver,
            "lyapunov": settings.lyapunov,
        }
    return plan


def _panel_values(rec: Any, panel: Any) -> list[float]:
    """Family values of a landmark's panel: a mapping ``{family name: value}``, a letter
    ``a``–``d`` (index), a number (the value itself) or nothing (every panel)."""
    vals = list(rec.family.values)
    if panel is None or panel == "":
        return vals
    if isinstance(panel, Mapping):
        if rec.family.name in panel:
            return [float(panel[rec.family.name])]
        return vals
    if isinstance(panel, str) and len(panel.strip()) == 1 and panel.strip().isalpha():
        k = ord(panel.strip().lower()) - ord("a")
        if 0 <= k < len(vals):
            return [vals[k]]
    with contextlib.suppress(TypeError, ValueError):
        return [float(panel)]
    return vals


def _result_id(r: Any) -> str:
    for attr in ("id", "landmark_id"):
        if getattr(r, attr, None) is not None:
            return str(getattr(r, attr))
    lm = getattr(r, "landmark", None)
    return str(getattr(lm, "id", lm))


def landmark_objective(
    landmarks: Sequence[Any], settings: SweepSettings | None = None
) -> Callable[[Any], Evaluation]:
    """The calibration objective: gear set → :class:`Evaluation` (sum of landmark scores of its
    coarse sweeps, see the module docstring)."""
    from ..sweep.run import bifurcation
    from .landmarks import evaluate_all, score

    settings = settings or SweepSettings()
    plan = sweep_plan(landmarks, settings)

    def objective(gs: Any) -> Evaluation:
        t0 = time.perf_counter()
        stores = {fig: bifurcation(gs, progress=False, **kw) for fig, kw in plan.items()}
        results = evaluate_all(landmarks, stores)
        per = {_result_id(r): float(r.score) for r in results}
        return Evaluation(float(score(results)), per, time.perf_counter() - t0)

    return objective


# --------------------------------------------------------------------------- driver
def read_results(path: str | os.PathLike[str]) -> dict[str, dict[str, Any]]:
    """Finished evaluations of a calibration file by candidate key (a torn last line, left by
    a kill during a write, is ignored)."""
    out: dict[str, dict[str, Any]] = {}
    try:  # a regular UTF-8 file of bounded size: never a FIFO, a device or a directory
        text = read_text_file(path, what="calibration file", max_bytes=MAX_RESULTS_BYTES)
    except MissingFileError:
        return out
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        try:
            rec = json.loads(line)
        except (json.JSONDecodeError, RecursionError):
            continue
        if not _is_record(rec):
            raise StoreError(
                f"calibration file '{path}': line {number} is not a calibration record "
                "(key, index, score, variables); use another --out file"
            )
        out[rec["key"]] = rec
    return out


#: Largest calibration file read (a record is about 2 KB: 100 000 candidates).
MAX_RESULTS_BYTES = 256 * 2**20


def _is_record(rec: Any) -> bool:
    """A line this module wrote: a key, an index, a numeric score and the variables."""
    if not isinstance(rec, dict) or not isinstance(rec.get("key"), str):
        return False
    index, score = rec.get("index"), rec.get("score")
    if isinstance(index, bool) or not isinstance(index, int):
        return False
    if isinstance(score, bool) or not isinstance(score, int | float) or math.isnan(score):
        return False
    return isinstance(rec.get("variables"), dict)


_R = TypeVar("_R", bound=Mapping[str, Any])


def _rank_key(record: Mapping[str, Any]) -> tuple[float, int]:
    return -float(record["score"]), int(record["index"])


def ranked(records: Iterable[_R]) -> list[_R]:
    """Calibration records best first: highest score, the earlier candidate on a tie."""
    return sorted(records, key=_rank_key)


def best_record(records: Iterable[_R]) -> _R | None:
    """The best of ``records`` (highest score, the earliest on a tie), or ``None``."""
    return min(records, key=_rank_key, default=None)


def _append(path: Path, record: Mapping[str, Any]) -> None:
    # a torn line from an earlier kill must not glue onto this one
    needs_newline = path.exists() and path.stat().st_size > 0
    if needs_newline:
        with path.open("rb") as fh:
            fh.seek(-1, os.SEEK_END)
            needs_newline = fh.read(1) != b"\n"
    with path.open("a", encoding="utf-8") as fh:
        if needs_newline:
            fh.write("\n")
        fh.write(json.dumps(record, sort_keys=True) + "\n")
        fh.flush()
        os.fsync(fh.fileno())


@dataclass
class CalibrationResult:
    """What :func:`calibrate` did: every record in sequence order (resumed ones included), how
    many were evaluated now, whether it stopped on the budget or an interrupt, and the best."""

    records: list[dict[str, Any]]
    evaluated: int
    reused: int
    stopped: str
    best: dict[str, Any] | None
    best_toml: Path | None
    problems: list[str]

    @property
    def plausible(self) -> bool:
        return self.best is not None and not self.problems

    def top(self, k: int = 3) -> list[dict[str, Any]]:
        return ranked(self.records)[:k]


def calibrate(
    landmarks: Sequence[Any] | str | os.PathLike[str] | None = None,
    out: str | os.PathLike[str] = "calibration.jsonl",
    *,
    budget_minutes: float = 110.0,
    max_candidates: int | None = None,
    seed: int = 0,
    quick: bool = False,
    n_initial: int | None = None,
    space: SearchSpace = DEFAULT_SPACE,
    objective: Callable[[Any], Evaluation] | None = None,
    settings: SweepSettings | None = None,
    on_record: Callable[[dict[str, Any], bool], None] | None = None,
) -> CalibrationResult:
    """Search ``space`` for the gear set that reproduces the most landmarks.

    Parameters
    ----------
    landmarks
        Landmark list or the path of ``landmarks.toml`` (``None``: the packaged default); not
        needed when ``objective`` is given.
    out
        JSON-lines file, one line per evaluated candidate: ``key``, ``index``, ``origin``,
        ``variables`` (search variables), ``params`` (dotted gear-set changes), ``score``,
        ``landmarks`` (score per landmark id), ``seconds``. Existing lines are re-used.
    budget_minutes, max_candidates
        Stop after this much wall time spent evaluating (this call), or when the sequence
        (resumed candidates included) reaches ``max_candidates``.
    seed
        Seed of the candidate sequence.
    quick
        3 candidates on tiny sweeps (CI).
    n_initial
        Latin-hypercube candidates before refinement (default 48; quick 3).
    objective
        Gear set → :class:`Evaluation`; default :func:`landmark_objective`.
    on_record
        Called with each record and whether it was evaluated now (progress display).

    Returns
    -------
    CalibrationResult
        The best candidate's gear set is written to ``best.toml`` next to ``out``. Ctrl-C stops
        after the last finished candidate (``stopped == "interrupted"``).
    """
    if max_candidates is not None:
        check_int("max_candidates", max_candidates, lo=1)
    check_real("budget_minutes", budget_minutes, lo=0.0, lo_open=True)
    check_int("seed", seed, lo=0)
    quick = check_bool("quick", quick)
    check_path(out, f"out must be the path of a JSON-lines file: got {out!r}")
    out_path = Path(out)
    if quick:
        max_candidates = 3 if max_candidates is None else min(max_candidates, 3)
        n_initial = n_initial or 3
        settings = settings or SweepSettings.quick()
    n_initial = n_initial or 48
    if objective is None:
        from .landmarks import load_landmarks

        lms = (
            load_landmarks(None if landmarks is None else Path(landmarks))
            if landmarks is None or isinstance(landmarks, (str, os.PathLike))
            else list(landmarks)
        )
        objective = landmark_objective(lms, settings)
    done = read_results(out_path)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    base = _base()
    history = _History()
    records: list[dict[str, Any]] = []
    stream = propose(space, seed, n_initial, history, base=base_candidate(base, space))
    evaluated = reused = 0
    stopped = "max_candidates"
    t_start = time.monotonic()
    try:
        for cand in stream:
            if max_candidates is not None and len(history.scores) >= max_candidates:
                break
            variables = cand.variables()
            key = candidate_key(variables)
            if key in history.seen:  # a duplicate proposal: counts, never re-evaluated
                history.candidates.append(cand)
                history.scores.append(-math.inf)
                continue
            history.seen.add(key)
            if key in done:
                rec = done[key]
                reused += 1
                now = False
            else:
                if time.monotonic() - t_start > 60.0 * budget_minutes:
                    stopped = "budget"
                    break
                try:
                    gs = build_gearset(cand, base)
                except ParameterError:
                    history.candidates.append(cand)
                    history.scores.append(-math.inf)
                    continue
                ev = objective(gs)
                rec = {
                    "key": key,
                    "index": len(history.scores),
                    "seed": seed,
                    "origin": cand.origin,
                    "variables": variables,
                    "params": gearset_changes(cand, base),
                    "score": ev.score,
                    "landmarks": dict(ev.landmarks),
                    "seconds": round(ev.seconds, 3),
                }
                _append(out_path, rec)
                evaluated += 1
                now = True
            history.candidates.append(cand)
            history.scores.append(float(rec["score"]))
            records.append(rec)
            if on_record is not None:
                on_record(rec, now)
    except KeyboardInterrupt:
        stopped = "interrupted"
    best = best_record(records)
    best_toml: Path | None = None
    problems: list[str] = []
    if best is not None:
        cand = candidate_from_record(best, space)
        problems = plausibility(cand, space)
        gs = build_gearset(cand, base)
        best_toml = out_path.with_name("best.toml")
        best_toml.write_text(gs.to_toml(), encoding="utf-8")
    return CalibrationResult(records, evaluated, reused, stopped, best, best_toml, problems)
