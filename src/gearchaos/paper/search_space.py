"""The search space of the calibration (:mod:`gearchaos.paper.calibrate`): the quantities the
seed's lost Table 1 would have fixed, their plausible ranges, candidates as gear sets, and how
an Optuna trial draws a candidate (:func:`suggest`).

Ranges, and why (module 4 mm, z_s ≈ 33, d_s ≈ 132 mm, centre distance a ≈ 130 mm)
    ``transmission_error.amplitude`` A = A_sp = A_rp, 1–40 µm (log)
        The static transmission error of a spur mesh is of the size of its profile and pitch
        deviations. ISO 1328-1 (grade 5 values, a factor √2 per grade) gives for m = 4 mm,
        d = 132 mm: single pitch f_pt = 0.3(m + 0.4√d) + 4 ≈ 6.6 µm, total profile
        F_α = 3.2√m + 0.22√d + 0.7 ≈ 9.6 µm; so f_pt ≈ 3.3 µm at grade 3 (ground), ≈ 19 µm at
        grade 8 and ≈ 37 µm at grade 10 (hobbed, not finished). 1 µm is a ground mesh with
        profile modification at its design load. The range was 1–20 µm (grades ≲ 8); the
        issue-34 optimum sat on its upper edge, so it reaches grade 10 now.
    ``clearance.characteristic_length`` b_c, 2–50 µm (log)
        The seed's clearances are b̄ = b/b_c with b̄_sp = 3, b̄_rp = 3.5 in its figures and
        b̄ = 1–16 along its sweeps, so b_sp = 3 b_c. The minimum normal backlash that ISO/TR
        10064-2 (and AGMA) recommend, j_bn,min = (2/3)(0.06 + 0.0005 a + 0.03 m) mm ≈ 160 µm
        at a = 130 mm, is a rated industrial fit (DIN 3967 fits c–d); DIN 3967's fits reach
        from large allowances (a, ab: several hundred µm) down to h (zero upper tooth
        thickness allowance), where only the tooth-thickness tolerances leave backlash, of the
        order of 10–30 µm for precision (low-backlash) planetary gearboxes. b_c = 2 µm makes
        b_sp = 6 µm (a full backlash of 12 µm: a fit h at tight tolerances), b_c = 50 µm makes
        it 150 µm (≈ the ISO/TR minimum above, and 800 µm at b̄ = 16). The range was 5–50 µm;
        the optimum sat on its lower edge, so it reaches the fit-h precision limit now.
    ``torque.input`` T_D, 200–3000 N·m (log)
        Light to rated load of a 4 mm-module sun of ≈ 130 mm (tooth root stress ≲ 300 MPa).
    ``stiffness.epsilon_sp``, ``stiffness.epsilon_rp`` ε = k_a/k_m, 0.05–0.4
        Spur meshes of contact ratio 1.4–1.9 alternate between one and two tooth pairs; the
        fundamental of that square wave is 5–40 % of the mean (internal meshes, of higher
        contact ratio, at the low end).
    ``stiffness.rp_sp_ratio`` k_m,rp/k_m,sp, 0.8–2
        Concave–convex internal contact is stiffer (Lin & Parker: 1–1.6).
    ``inertia.sun_scale``, ``inertia.planet_scale``, ``inertia.carrier_scale``, 0.5–2 (log)
        Equivalent masses × factor: face width, rim thickness, hollow shafts, single- or
        double-walled carrier.
    teeth: N ∈ {3, 4, 5}, 28 ≤ z_s ≤ 40, 25 ≤ z_p ≤ 37
        Standard 2K-H sets that assemble with equally spaced planets (:func:`enumerate_teeth`).
    ``torque.mode``: constant torque or constant power.

The dimensionless clearances b̄ are the seed's, so b_c scales the physical clearances, the
ratio A/b_c and, with T_D, T̄_D = T_D/(r_bs k_m,sp b_c).
"""

from __future__ import annotations

import hashlib
import json
import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
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
    "candidate_from_params",
    "candidate_from_record",
    "candidate_key",
    "candidate_of",
    "candidate_params",
    "enumerate_teeth",
    "gearset_changes",
    "nearest_teeth",
    "plausibility",
    "record_gearset",
    "suggest",
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
            40e-6,
            True,
            "m",
            "A_sp = A_rp: ISO 1328-1 single pitch / profile deviations of a 4 mm module, "
            "grades 3 (ground) to 10 (hobbed); was 1-20 µm, the optimum sat on its upper edge",
        ),
        Range(
            "stiffness.epsilon_sp",
            0.05,
            0.4,
            False,
            "1",
            "k_a/k_m of spur meshes with contact ratio 1.4-1.9 (one/two tooth pairs: the "
            "fundamental of that square wave is 5-40 % of the mean)",
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
            2e-6,
            50e-6,
            True,
            "m",
            "b_c: b_sp = 3 b_c from 6 µm (DIN 3967 fit h, precision) to 150 µm (ISO/TR 10064-2 "
            "minimum at a = 130 mm); was 5-50 µm, the optimum sat on its lower edge",
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
    c = candidate_of(gs, gs, space)
    return Candidate(c.values, c.teeth, c.mode, origin="base")


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


# --------------------------------------------------------------------------- Optuna trials
#: Trial parameters of the tooth combination and the load mode (besides the ranges').
TEETH_PARAMS = ("geometry.planets", "teeth.sun", "teeth.planet")
MODE_PARAM = "torque.mode"


def _bounds(space: SearchSpace) -> tuple[list[int], tuple[int, int], tuple[int, int]]:
    planets = sorted({t.planets for t in space.teeth})
    suns = [t.sun for t in space.teeth]
    plans = [t.planet for t in space.teeth]
    return planets, (min(suns), max(suns)), (min(plans), max(plans))


def nearest_teeth(planets: int, sun: int, planet: int, space: SearchSpace) -> TeethChoice:
    """The valid tooth combination of ``space`` closest to (z_s, z_p) = (``sun``, ``planet``):
    with N = ``planets`` when one exists, smallest |Δz_s| + |Δz_p|, then the smaller z_s and
    z_p (deterministic)."""
    same = [t for t in space.teeth if t.planets == planets] or list(space.teeth)
    if not same:
        raise ParameterError("the search space has no tooth combination")
    return min(
        same,
        key=lambda t: (abs(t.sun - sun) + abs(t.planet - planet), t.planets != planets, t.sun,
                       t.planet),
    )  # fmt: skip


def suggest(trial: Any, space: SearchSpace = DEFAULT_SPACE) -> Candidate:
    """The candidate an Optuna ``trial`` draws from ``space``: a float per range (log-uniform
    where the range says so), N as a category, z_s and z_p as integers snapped to the nearest
    valid combination (:func:`nearest_teeth`; the snapped teeth are the candidate's), the load
    mode as a category. Values keep :data:`DIGITS` significant digits."""
    values = tuple(
        (r.name, min(max(_round(trial.suggest_float(r.name, r.lo, r.hi, log=r.log)), r.lo), r.hi))
        for r in space.ranges
    )
    planets, suns, plans = _bounds(space)
    n = int(trial.suggest_categorical("geometry.planets", planets))
    zs = int(trial.suggest_int("teeth.sun", suns[0], suns[1]))
    zp = int(trial.suggest_int("teeth.planet", plans[0], plans[1]))
    mode = str(trial.suggest_categorical(MODE_PARAM, list(space.modes)))
    return Candidate(values, nearest_teeth(n, zs, zp, space), mode, origin="trial")


def candidate_params(candidate: Candidate) -> dict[str, Any]:
    """The trial parameters that make :func:`suggest` return ``candidate`` (for
    ``study.enqueue_trial``)."""
    out: dict[str, Any] = dict(candidate.values)
    out["geometry.planets"] = candidate.teeth.planets
    out["teeth.sun"] = candidate.teeth.sun
    out["teeth.planet"] = candidate.teeth.planet
    out[MODE_PARAM] = candidate.mode
    return out


def candidate_from_params(
    params: Mapping[str, Any], space: SearchSpace = DEFAULT_SPACE, origin: str = "trial"
) -> Candidate:
    """The candidate of a finished trial's parameters (the inverse of :func:`candidate_params`,
    teeth snapped as :func:`suggest` does)."""
    missing = [k for k in (*space.names[:-2], *TEETH_PARAMS, MODE_PARAM) if k not in params]
    if missing:
        raise ParameterError(f"trial parameters lack {', '.join(missing)}")
    teeth = nearest_teeth(
        int(params["geometry.planets"]), int(params["teeth.sun"]), int(params["teeth.planet"]),
        space,
    )  # fmt: skip
    values = tuple((r.name, _round(float(params[r.name]))) for r in space.ranges)
    return Candidate(values, teeth, str(params[MODE_PARAM]), origin=origin)


def candidate_of(gearset: Any, base: Any = None, space: SearchSpace = DEFAULT_SPACE) -> Candidate:
    """A gear set built on ``base`` (default :data:`BASE_PRESET`) as a candidate: its
    variables read back (the inertia scales as ratios of equivalent masses, of J_c/r_c² for the
    carrier), so ``build_gearset(candidate_of(gs))`` is ``gs`` to the rounding of the
    variables. ``candidate_of(preset("sheng2016"))`` starts a study from today's default."""
    b = base if base is not None else _base()
    gs = gearset
    st = gs.stiffness
    vals = {
        "torque.input": gs.torque.input,
        "transmission_error.amplitude": gs.transmission_error.sun_planet,
        "stiffness.epsilon_sp": st.sun_planet_alternating / st.sun_planet_mean,
        "stiffness.epsilon_rp": st.planet_ring_alternating / st.planet_ring_mean,
        "stiffness.rp_sp_ratio": st.planet_ring_mean / st.sun_planet_mean,
        "inertia.sun_scale": gs.equivalent_mass_sun / b.equivalent_mass_sun,
        "inertia.planet_scale": gs.equivalent_mass_planet / b.equivalent_mass_planet,
        "inertia.carrier_scale": (gs.inertia.carrier / gs.radius_carrier**2)
        / (b.inertia.carrier / b.radius_carrier**2),
        "clearance.characteristic_length": gs.clearance.characteristic_length,
    }
    t = TeethChoice(gs.n_planets, gs.teeth.sun, gs.teeth.planet, gs.teeth.ring)
    return Candidate(
        tuple((r.name, _round(vals[r.name])) for r in space.ranges),
        t,
        gs.torque.mode,
        origin=str(gs.name),
    )
