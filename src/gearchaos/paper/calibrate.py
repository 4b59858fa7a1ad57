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
import hashlib
import json
import math
import os
import time
import warnings
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from .._checks import check_bool, check_int
from ..errors import ParameterError
from ..integrate.settings import SolverSettings

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

#: The gear set every candidate starts from (MODEL.md §9). Fixed by name so that a calibration
#: log stays valid whatever the default preset becomes.
BASE_PRESET = "hindawi2021"

#: Significant digits kept of every continuous variable (keys and TOML stay clean).
DIGITS = 6


# --------------------------------------------------------------------------- search space
@dataclass(frozen=True)
class Range:
    """One continuous search variable: ``lo`` ≤ value ≤ ``hi``, sampled uniformly in the value or,
    with ``log``, in its logarithm."""

    name: str
    lo: float
    hi: float
    log: bool
    unit: str
    why: str

    def to_unit(self, value: float) -> float:
        if self.log:
            return (math.log(value) - math.log(self.lo)) / (math.log(self.hi) - math.log(self.lo))
        return (value - self.lo) / (self.hi - self.lo)

    def from_unit(self, u: float) -> float:
        u = min(max(float(u), 0.0), 1.0)
        if self.log:
            v = math.exp(math.log(self.lo) + u * (math.log(self.hi) - math.log(self.lo)))
        else:
            v = self.lo + u * (self.hi - self.lo)
        return min(max(_round(v), self.lo), self.hi)


@dataclass(frozen=True)
class TeethChoice:
    """A valid standard 2K-H tooth combination: N planets, z_s, z_p, z_r = z_s + 2 z_p."""

    planets: int
    sun: int
    planet: int
    ring: int


def _round(v: float, digits: int = DIGITS) -> float:
    return float(f"{v:.{digits}g}")


def enumerate_teeth(
    planets: Sequence[int] = (3, 4, 5),
    sun: tuple[int, int] = (28, 40),
    planet: tuple[int, int] = (25, 37),
) -> tuple[TeethChoice, ...]:
    """Every standard tooth combination with z_s, z_p in the given inclusive ranges that can be
    assembled with N equally spaced planets: z_r = z_s + 2 z_p, (z_s + z_r)/N an integer, and
    neighbouring planet tip circles clear, (z_s + z_p) sin(π/N) > z_p + 2."""
    out = []
    for n in planets:
        for zs in range(sun[0], sun[1] + 1):
            for zp in range(planet[0], planet[1] + 1):
                zr = zs + 2 * zp
                if (zs + zr) % n:
                    continue
                if (zs + zp) * math.sin(math.pi / n) <= zp + 2:
                    continue
                out.append(TeethChoice(n, zs, zp, zr))
    return tuple(out)


#: Load modes searched.
MODES = ("constant_torque", "constant_power")


@dataclass(frozen=True)
class SearchSpace:
    """Continuous ranges, tooth combinations and load modes searched (see ``docs/reproduction.md``
    for the justification of each range)."""

    ranges: tuple[Range, ...]
    teeth: tuple[TeethChoice, ...]
    modes: tuple[str, ...] = MODES

    @property
    def names(self) -> tuple[str, ...]:
        return (*(r.name for r in self.ranges), "teeth", "torque.mode")

    def range(self, name: str) -> Range:
        for r in self.ranges:
            if r.name == name:
                return r
        raise KeyError(name)


DEFAULT_SPACE = SearchSpace(
    ranges=(
        Range(
            "torque.input",
            200.0,
            3000.0,
            True,
            "N m",
            "light to rated load of a 4 mm-module sun of ~130 mm (root stress ≲ 300 MPa)",
        ),
        Range(
            "transmission_error.amplitude",
            1e-6,
            20e-6,
            True,
            "m",
            "A_sp = A_rp: ISO 1328 grades 3-8 profile/pitch errors of a 4 mm module",
        ),
        Range(
            "stiffness.epsilon_sp",
            0.05,
            0.4,
            False,
            "1",
            "k_a/k_m of spur meshes with contact ratio 1.4-1.9 (single/double tooth zones)",
        ),
        Range(
            "stiffness.epsilon_rp",
            0.05,
            0.4,
            False,
            "1",
            "as ε_sp; internal meshes have higher contact ratio, so lower ε is common",
        ),
        Range(
            "stiffness.rp_sp_ratio",
            0.8,
            2.0,
            False,
            "1",
            "k_m,rp/k_m,sp: concave-convex internal contact is stiffer (Lin & Parker: 1-1.6)",
        ),
        Range(
            "inertia.sun_scale",
            0.5,
            2.0,
            True,
            "1",
            "m_s* (and m_s) × factor: face width / hollow-shaft design of the sun",
        ),
        Range(
            "inertia.planet_scale",
            0.5,
            2.0,
            True,
            "1",
            "m_p* (and m_p) × factor: face width, rim thickness, bearing inside the planet",
        ),
        Range(
            "inertia.carrier_scale",
            0.5,
            2.0,
            True,
            "1",
            "J_c/r_c² × factor: single- vs double-walled carrier",
        ),
        Range(
            "clearance.characteristic_length",
            5e-6,
            50e-6,
            True,
            "m",
            "b_c: with b̄ = 2-16 gives backlash 10-800 µm, the range of DIN 3967 fits",
        ),
    ),
    teeth=enumerate_teeth(),
)


@dataclass(frozen=True)
class Candidate:
    """A point of the search space: continuous variables by name, a tooth combination and a load
    mode. ``values`` is a tuple of (name, value) pairs in the space's order."""

    values: tuple[tuple[str, float], ...]
    teeth: TeethChoice
    mode: str
    origin: str = "lhs"

    def variables(self) -> dict[str, Any]:
        """The search variables as a flat JSON-ready mapping (what the key hashes)."""
        out: dict[str, Any] = dict(self.values)
        out["geometry.planets"] = self.teeth.planets
        out["teeth.sun"] = self.teeth.sun
        out["teeth.planet"] = self.teeth.planet
        out["teeth.ring"] = self.teeth.ring
        out["torque.mode"] = self.mode
        return out

    def unit(self, space: SearchSpace) -> np.ndarray:
        d = dict(self.values)
        return np.array([r.to_unit(d[r.name]) for r in space.ranges])


def candidate_key(variables: Mapping[str, Any]) -> str:
    """Stable hash of a candidate's variables (sorted JSON, 16 hex digits)."""
    text = json.dumps(dict(variables), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _base() -> Any:
    from ..gearset import preset

    return preset(BASE_PRESET)


def base_candidate(base: Any = None, space: SearchSpace = DEFAULT_SPACE) -> Candidate:
    """The base gear set (MODEL.md §9) expressed as a candidate of ``space``."""
    gs = base if base is not None else _base()
    st = gs.stiffness
    vals = {
        "torque.input": gs.torque.input,
        "transmission_error.amplitude": gs.transmission_error.sun_planet,
        "stiffness.epsilon_sp": st.sun_planet_alternating / st.sun_planet_mean,
        "stiffness.epsilon_rp": st.planet_ring_alternating / st.planet_ring_mean,
        "stiffness.rp_sp_ratio": st.planet_ring_mean / st.sun_planet_mean,
        "inertia.sun_scale": 1.0,
        "inertia.planet_scale": 1.0,
        "inertia.carrier_scale": 1.0,
        "clearance.characteristic_length": gs.clearance.characteristic_length,
    }
    t = TeethChoice(gs.n_planets, gs.teeth.sun, gs.teeth.planet, gs.teeth.ring)
    return Candidate(
        tuple((r.name, _round(vals[r.name])) for r in space.ranges),
        t,
        gs.torque.mode,
        origin="base",
    )


def gearset_changes(candidate: Candidate, base: Any = None) -> dict[str, Any]:
    """The dotted-name changes that turn the base gear set into ``candidate``.

    Equivalent masses are kept as masses when the tooth numbers change: J_s = s_s m_s* r_bs²,
    J_p = s_p m_p* r_bp², J_c = s_c (J_c/r_c²)₀ r_c², and the translational masses m_s, m_p
    scale with the same factors (a solid disc keeps m*/m); k_m,sp and k_s stay the base's.
    """
    gs = base if base is not None else _base()
    v = dict(candidate.values)
    t = candidate.teeth
    alpha_s = math.radians(gs.geometry.pressure_angle_sun)
    module = gs.geometry.module
    r_bs = module * t.sun / 2 * math.cos(alpha_s)
    r_bp = module * t.planet / 2 * math.cos(alpha_s)
    r_c = module * (t.sun + t.planet) / 2
    kmsp = gs.stiffness.sun_planet_mean
    kmrp = _round(v["stiffness.rp_sp_ratio"] * kmsp, 4)
    m_c_rot = gs.inertia.carrier / gs.radius_carrier**2
    amp = v["transmission_error.amplitude"]
    return {
        "geometry.planets": t.planets,
        "teeth.sun": t.sun,
        "teeth.planet": t.planet,
        "teeth.ring": t.ring,
        "torque.input": v["torque.input"],
        "torque.mode": candidate.mode,
        "transmission_error.sun_planet": amp,
        "transmission_error.planet_ring": amp,
        "stiffness.sun_planet_alternating": _round(v["stiffness.epsilon_sp"] * kmsp, 4),
        "stiffness.planet_ring_mean": kmrp,
        "stiffness.planet_ring_alternating": _round(v["stiffness.epsilon_rp"] * kmrp, 4),
        "inertia.sun": v["inertia.sun_scale"] * gs.equivalent_mass_sun * r_bs**2,
        "mass.sun": _round(v["inertia.sun_scale"] * gs.mass.sun),
        "inertia.planet": v["inertia.planet_scale"] * gs.equivalent_mass_planet * r_bp**2,
        "mass.planet": _round(v["inertia.planet_scale"] * gs.mass.planet),
        "inertia.carrier": v["inertia.carrier_scale"] * m_c_rot * r_c**2,
        "clearance.characteristic_length": v["clearance.characteristic_length"],
    }


CALIBRATED_DESCRIPTION = (
    "2K-H planetary gear set calibrated against the seed paper's landmarks (gearchaos calibrate)"
)


def build_gearset(
    candidate: Candidate,
    base: Any = None,
    name: str = "calibrated",
    description: str = CALIBRATED_DESCRIPTION,
) -> Any:
    """The validated :class:`~gearchaos.gearset.GearSet` of ``candidate`` (raises
    :class:`~gearchaos.errors.ParameterError` for an invalid combination)."""
    gs = base if base is not None else _base()
    changes = gearset_changes(candidate, gs)
    changes["name"] = name
    changes["description"] = description
    return gs.evolve(changes)


def record_gearset(
    record: Mapping[str, Any],
    *,
    name: str = "calibrated",
    description: str = CALIBRATED_DESCRIPTION,
    space: SearchSpace = DEFAULT_SPACE,
) -> Any:
    """The gear set of one line of a calibration log (see :func:`read_results`)."""
    return build_gearset(candidate_from_record(record, space), None, name, description)


def plausibility(candidate: Candidate, space: SearchSpace = DEFAULT_SPACE) -> list[str]:
    """Reasons ``candidate`` is not physically plausible: outside a range, an invalid tooth
    combination, a validation error or a warning while building its gear set and model. Empty
    when it is plausible."""
    problems: list[str] = []
    for name, value in candidate.values:
        r = space.range(name)
        if not (r.lo <= value <= r.hi):
            problems.append(f"{name} = {value:g} outside [{r.lo:g}, {r.hi:g}]")
    if candidate.teeth not in space.teeth:
        problems.append(f"teeth {candidate.teeth} not a valid combination of the space")
    if candidate.mode not in space.modes:
        problems.append(f"torque.mode {candidate.mode!r} not one of {space.modes}")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            gs = build_gearset(candidate)
            from ..model import nondimensionalise

            nondimensionalise(gs)
        except ParameterError as exc:
            problems.append(f"invalid gear set: {exc}")
    problems.extend(f"warning: {w.message}" for w in caught)
    return problems


# --------------------------------------------------------------------------- proposals
@dataclass
class _History:
    """Scores in sequence order, shared between the driver and :func:`propose`."""

    candidates: list[Candidate] = field(default_factory=list)
    scores: list[float] = field(default_factory=list)
    seen: set[str] = field(default_factory=set)


def _lhs(rng: np.random.Generator, n: int, d: int) -> np.ndarray:
    u = np.empty((n, d))
    for j in range(d):
        u[:, j] = (rng.permutation(n) + rng.random(n)) / n
    return u


def _neighbour_teeth(
    rng: np.random.Generator, t: TeethChoice, teeth: Sequence[TeethChoice]
) -> TeethChoice:
    """A tooth combination close to ``t``: the nearest few by |Δz_s| + |Δz_p| (any N)."""
    others = [c for c in teeth if c != t]
    others.sort(key=lambda c: (abs(c.sun - t.sun) + abs(c.planet - t.planet), c.planets, c.sun))
    pool = others[:6]
    return pool[int(rng.integers(len(pool)))]


def propose(
    space: SearchSpace,
    seed: int,
    n_initial: int,
    history: _History,
    *,
    base: Candidate | None = None,
    elites: int = 3,
    step: float = 0.15,
    min_step: float = 0.02,
) -> Iterator[Candidate]:
    """The deterministic candidate sequence for ``seed``.

    First ``n_initial`` Latin-hypercube points (``base`` replaces the first when given), then
    rounds of coordinate perturbations of the ``elites`` best scored candidates in ``history``
    (which the caller fills in after each candidate). Perturbations already in
    ``history.seen`` are redrawn (20 tries). The sequence is infinite; the caller stops it.
    """
    rng = np.random.default_rng(seed)
    d = len(space.ranges)
    u = _lhs(rng, n_initial, d + 2)
    for i in range(n_initial):
        if i == 0 and base is not None:
            yield base
            continue
        values = tuple((r.name, r.from_unit(u[i, j])) for j, r in enumerate(space.ranges))
        teeth = space.teeth[min(int(u[i, d] * len(space.teeth)), len(space.teeth) - 1)]
        mode = space.modes[min(int(u[i, d + 1] * len(space.modes)), len(space.modes) - 1)]
        yield Candidate(values, teeth, mode, origin="lhs")
    best = max(history.scores, default=-math.inf)
    round_no = 0
    while True:
        round_no += 1
        order = sorted(range(len(history.scores)), key=lambda k: (-history.scores[k], k))
        top = [history.candidates[k] for k in order[:elites] if math.isfinite(history.scores[k])]
        if not top:
            top = [history.candidates[0]] if history.candidates else []
        if not top:  # pragma: no cover - nothing to refine
            return
        for parent in top:
            for _ in range(20):
                which = int(rng.integers(d + 2))
                sign = 1.0 if rng.random() < 0.5 else -1.0
                uu = parent.unit(space)
                teeth, mode = parent.teeth, parent.mode
                if which < d:
                    uu[which] = min(max(uu[which] + sign * step, 0.0), 1.0)
                elif which == d:
                    teeth = _neighbour_teeth(rng, teeth, space.teeth)
                else:
                    mode = space.modes[(space.modes.index(mode) + 1) % len(space.modes)]
                values = tuple((r.name, r.from_unit(uu[j])) for j, r in enumerate(space.ranges))
                cand = Candidate(values, teeth, mode, origin=f"refine{round_no}")
                if candidate_key(cand.variables()) not in history.seen:
                    break
            yield cand
        new_best = max(history.scores, default=-math.inf)
        if not new_best > best:
            step = max(step / 2, min_step)
        best = new_best


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


_VARY_NAMES = (
    "omega",
    "xi",
    "backlash.sun_planet",
    "backlash.planet_ring",
    "clearance.sun_bearing",
)


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
            "fixed": fixed,
            "observe": rec.observe,
            "planets": (1,),
            "initial_conditions": "fresh",
            "solver": settings.solver,
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
    p = Path(path)
    if not p.exists():
        return out
    for line in p.read_text(encoding="utf-8").splitlines():
        if not line.strip():
            continue
        try:
            rec = json.loads(line)
        except json.JSONDecodeError:
            continue
        out[rec["key"]] = rec
    return out


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


def candidate_from_record(rec: Mapping[str, Any], space: SearchSpace = DEFAULT_SPACE) -> Candidate:
    """The :class:`Candidate` of one line of a calibration log."""
    v = rec["variables"]
    return Candidate(
        tuple((r.name, float(v[r.name])) for r in space.ranges),
        TeethChoice(
            int(v["geometry.planets"]),
            int(v["teeth.sun"]),
            int(v["teeth.planet"]),
            int(v["teeth.ring"]),
        ),
        str(v["torque.mode"]),
        origin=str(rec.get("origin", "")),
    )


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
    out_path = Path(out)
    if quick:
        max_candidates = 3 if max_candidates is None else min(max_candidates, 3)
        n_initial = n_initial or 3
        settings = settings or SweepSettings.quick()
    n_initial = n_initial or 48
    if max_candidates is not None and max_candidates < 1:
        raise ParameterError(f"max_candidates must be >= 1: got {max_candidates}")
    if not budget_minutes > 0:
        raise ParameterError(f"budget_minutes must be > 0: got {budget_minutes}")
    if objective is None:
        from .landmarks import load_landmarks

        lms = (
            load_landmarks(None if landmarks is None else Path(landmarks))
            if landmarks is None or isinstance(landmarks, (str, os.PathLike))
            else list(landmarks)
        )
        objective = landmark_objective(lms, settings)
    done = read_results(out_path)
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
