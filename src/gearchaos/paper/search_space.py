"""The search space of the calibration (:mod:`gearchaos.paper.calibrate`): the quantities the
seed's lost Table 1 would have fixed, their plausible ranges, candidates as gear sets, and the
deterministic proposal sequence (a seeded Latin hypercube, then local refinement).
"""

from __future__ import annotations

import hashlib
import json
import math
import warnings
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ParameterError

__all__ = [
    "BASE_PRESET",
    "DEFAULT_SPACE",
    "Candidate",
    "Range",
    "SearchSpace",
    "TeethChoice",
    "base_candidate",
    "build_gearset",
    "candidate_from_record",
    "candidate_key",
    "enumerate_teeth",
    "gearset_changes",
    "plausibility",
    "propose",
    "record_gearset",
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
