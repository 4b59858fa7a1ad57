"""Frozen records that describe a 2K-H planetary gear set in SI units.

Every field is addressed by a stable dotted name (``teeth.sun``, ``backlash.sun_planet``,
``damping.sun_bearing`` ...) that is the same in Python, TOML, the CLI, sweep stores and plot
labels. Units live in one table, :data:`UNITS`, not in the field names.

Angles are stored in degrees (as gear designers quote them); everything else is SI. Clearances
may be stored dimensionless (relative to ``clearance.characteristic_length`` b_c, as the seed
paper quotes them) or in metres; :meth:`GearSet.backlash_bar` and friends always return the
dimensionless values the model uses.

Symbols follow ``MODEL.md``: z_s, z_p, z_r teeth; N planets; α_s, α_r pressure angles;
m_s, m_p translational masses; J_s, J_p, J_c inertias; k_m/k_a mean/alternating mesh stiffness;
k_s sun support stiffness; ξ damping ratios; T_D input torque; A transmission-error amplitudes;
E eccentricities; b half clearances.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

__all__ = [
    "UNITS",
    "Backlash",
    "Clearance",
    "Damping",
    "Eccentricity",
    "GearSet",
    "Geometry",
    "Inertia",
    "Mass",
    "MeshPhasing",
    "Stiffness",
    "Teeth",
    "Torque",
    "TransmissionError",
]


@dataclass(frozen=True)
class Teeth:
    """Tooth numbers z_s (sun), z_p (planet), z_r (ring, internal)."""

    sun: int
    planet: int
    ring: int


@dataclass(frozen=True)
class Geometry:
    """Planets N, module m [m], pressure angles α_s (sun–planet), α_r (ring–planet) [deg]."""

    planets: int
    module: float
    pressure_angle_sun: float = 20.0
    pressure_angle_ring: float = 20.0


@dataclass(frozen=True)
class Mass:
    """Translational masses [kg]: the sun's m_s (moves in x, y) and each planet's m_p
    (rides on the carrier)."""

    sun: float
    planet: float


@dataclass(frozen=True)
class Inertia:
    """Polar moments of inertia [kg m²] J_s, J_p (each planet) and J_c (carrier)."""

    sun: float
    planet: float
    carrier: float


@dataclass(frozen=True)
class Stiffness:
    """Mesh and support stiffness [N/m].

    k_sp(t) = k_m,sp + k_a,sp cos(ωt + φ) + Σ_h k_h cos(h(ωt + φ)), h = 2, 3, …
    (``sun_planet_harmonics`` lists k_2, k_3, …); likewise for the planet–ring mesh.
    """

    sun_planet_mean: float
    sun_planet_alternating: float
    planet_ring_mean: float
    planet_ring_alternating: float
    sun_bearing: float
    sun_planet_harmonics: tuple[float, ...] = ()
    planet_ring_harmonics: tuple[float, ...] = ()


@dataclass(frozen=True)
class Damping:
    """Viscous damping ratios ξ_sp, ξ_rp, ξ_s (MODEL.md §4)."""

    sun_planet: float
    planet_ring: float
    sun_bearing: float


@dataclass(frozen=True)
class Torque:
    """Input torque T_D on the sun [N m] and load mode.

    ``constant_torque``: T_D fixed. ``constant_power``: T_D is the torque at the dimensionless
    mesh frequency Ω = ``reference_omega`` and scales as T_D Ω_ref/Ω. The output torque on the
    carrier is always the loss-free balance (:attr:`GearSet.output_torque`).
    """

    input: float
    mode: str = "constant_torque"
    reference_omega: float = 1.0


@dataclass(frozen=True)
class TransmissionError:
    """Static transmission-error amplitudes A_sp, A_rp [m] and their phase offsets [deg]
    relative to the mesh-stiffness phase of the same mesh."""

    sun_planet: float = 0.0
    planet_ring: float = 0.0
    sun_planet_phase: float = 0.0
    planet_ring_phase: float = 0.0


@dataclass(frozen=True)
class Eccentricity:
    """Geometric eccentricities E_s, E_p, E_r [m] and phases β_s, β_p, β_r [deg] (MODEL.md §3)."""

    sun: float = 0.0
    planet: float = 0.0
    ring: float = 0.0
    sun_phase: float = 0.0
    planet_phase: float = 0.0
    ring_phase: float = 0.0


@dataclass(frozen=True)
class Backlash:
    """Half backlashes b_sp, b_rp of the sun–planet and planet–ring meshes (total 2b).

    ``units`` is ``"dimensionless"`` (values are b̄ = b/b_c, as in the seed) or ``"m"``.
    """

    sun_planet: float
    planet_ring: float
    units: str = "dimensionless"


@dataclass(frozen=True)
class Clearance:
    """Sun bearing half clearance b_s and the characteristic length b_c [m].

    ``units`` applies to ``sun_bearing`` only (``"dimensionless"`` or ``"m"``);
    ``characteristic_length`` is always in metres.
    """

    sun_bearing: float
    characteristic_length: float
    units: str = "dimensionless"


@dataclass(frozen=True)
class MeshPhasing:
    """Mesh phasing model: ``parker`` (Parker & Lin 2004) or ``in_phase`` (all φ = 0).

    ``ring_sun`` is γ_rs, the ring-mesh phase of planet 1 relative to its sun mesh, as a
    fraction of one mesh cycle (used by ``parker`` only).
    """

    model: str = "parker"
    ring_sun: float = 0.0


def _frac(x: float) -> float:
    return x - math.floor(x)


@dataclass(frozen=True)
class GearSet:
    """A complete 2K-H planetary gear set (sun input, carrier output, fixed ring).

    Build it with :meth:`from_toml`, :func:`gearchaos.gearset.preset` or :meth:`evolve`;
    constructing it directly validates every field as well.
    """

    teeth: Teeth
    geometry: Geometry
    mass: Mass
    inertia: Inertia
    stiffness: Stiffness
    damping: Damping
    torque: Torque
    backlash: Backlash
    clearance: Clearance
    transmission_error: TransmissionError = field(default_factory=TransmissionError)
    eccentricity: Eccentricity = field(default_factory=Eccentricity)
    mesh_phasing: MeshPhasing = field(default_factory=MeshPhasing)
    name: str = "custom"
    description: str = ""

    def __post_init__(self) -> None:
        from .validation import validate

        validate(self)

    # ------------------------------------------------------------------ geometry
    @property
    def n_planets(self) -> int:
        """N."""
        return self.geometry.planets

    @property
    def alpha_s(self) -> float:
        """α_s [rad]."""
        return math.radians(self.geometry.pressure_angle_sun)

    @property
    def alpha_r(self) -> float:
        """α_r [rad]."""
        return math.radians(self.geometry.pressure_angle_ring)

    @property
    def radius_sun(self) -> float:
        """Pitch radius r_s = m z_s / 2 [m]."""
        return self.geometry.module * self.teeth.sun / 2.0

    @property
    def radius_planet(self) -> float:
        """Pitch radius r_p = m z_p / 2 [m]."""
        return self.geometry.module * self.teeth.planet / 2.0

    @property
    def radius_ring(self) -> float:
        """Pitch radius r_r = m z_r / 2 [m]."""
        return self.geometry.module * self.teeth.ring / 2.0

    @property
    def radius_carrier(self) -> float:
        """Planet-centre radius r_c = r_s + r_p [m]."""
        return self.radius_sun + self.radius_planet

    @property
    def base_radius_sun(self) -> float:
        """r_bs = r_s cos α_s [m]."""
        return self.radius_sun * math.cos(self.alpha_s)

    @property
    def base_radius_planet(self) -> float:
        """r_bp = r_p cos α_s [m] (the planet's base circle of its sun mesh)."""
        return self.radius_planet * math.cos(self.alpha_s)

    @property
    def planet_angles(self) -> tuple[float, ...]:
        """ψ_i = 2π(i−1)/N [rad]."""
        n = self.n_planets
        return tuple(2.0 * math.pi * i / n for i in range(n))

    # ------------------------------------------------------------------ masses
    @property
    def equivalent_mass_sun(self) -> float:
        """m_s* = J_s / r_bs² [kg]."""
        return self.inertia.sun / self.base_radius_sun**2

    @property
    def equivalent_mass_planet(self) -> float:
        """m_p* = J_p / r_bp² [kg]."""
        return self.inertia.planet / self.base_radius_planet**2

    @property
    def equivalent_mass_carrier(self) -> float:
        """m_c* = J_c / r_c² + N m_p [kg]."""
        return self.inertia.carrier / self.radius_carrier**2 + self.n_planets * self.mass.planet

    @property
    def equivalent_mass_mesh(self) -> float:
        """m_e = m_s* m_p* / (m_s* + m_p*) [kg], the sun–planet mesh's equivalent mass."""
        ms, mp = self.equivalent_mass_sun, self.equivalent_mass_planet
        return ms * mp / (ms + mp)

    # ------------------------------------------------------------------ dynamics
    @property
    def omega_n(self) -> float:
        """ω_n = √(k_m,sp / m_e) [rad/s], the time scale of the dimensionless model."""
        return math.sqrt(self.stiffness.sun_planet_mean / self.equivalent_mass_mesh)

    @property
    def damping_sun_planet(self) -> float:
        """c_sp = 2 ξ_sp √(k_m,sp m_e) [N s/m]."""
        return (
            2.0
            * self.damping.sun_planet
            * math.sqrt(self.stiffness.sun_planet_mean * self.equivalent_mass_mesh)
        )

    @property
    def damping_planet_ring(self) -> float:
        """c_rp = 2 ξ_rp √(k_m,rp m_p*) [N s/m] (fixed ring)."""
        return (
            2.0
            * self.damping.planet_ring
            * math.sqrt(self.stiffness.planet_ring_mean * self.equivalent_mass_planet)
        )

    @property
    def damping_sun_bearing(self) -> float:
        """c_s = 2 ξ_s √(k_s m_s) [N s/m]."""
        k_s, m_s = self.stiffness.sun_bearing, self.mass.sun
        return 2.0 * self.damping.sun_bearing * math.sqrt(k_s * m_s)

    @property
    def output_torque(self) -> float:
        """T_L [N m]: the loss-free static balance T_D r_c (cos α_s + cos α_r) / r_bs.

        For equal pressure angles this is T_D (1 + z_r/z_s) (MODEL.md §2); for unequal angles it
        is the value that keeps the carrier in static equilibrium with equal mesh forces.
        """
        return (
            self.torque.input
            * self.radius_carrier
            * (math.cos(self.alpha_s) + math.cos(self.alpha_r))
            / self.base_radius_sun
        )

    def mesh_frequency(self, sun_speed_rpm: float) -> float:
        """Mesh frequency ω = ω_s z_s z_r / (z_s + z_r) [rad/s] for a sun speed in rpm."""
        ws = sun_speed_rpm * 2.0 * math.pi / 60.0
        z = self.teeth
        return ws * z.sun * z.ring / (z.sun + z.ring)

    def sun_speed_rpm(self, omega: float) -> float:
        """Sun speed [rpm] at dimensionless mesh frequency Ω = ω/ω_n."""
        z = self.teeth
        w = omega * self.omega_n
        ws = w * (z.sun + z.ring) / (z.sun * z.ring)
        return ws * 60.0 / (2.0 * math.pi)

    # ------------------------------------------------------------------ clearances
    def _bar(self, value: float, units: str) -> float:
        if units == "m":
            return value / self.clearance.characteristic_length
        return value

    def backlash_bar(self) -> tuple[float, float]:
        """(b̄_sp, b̄_rp), half backlashes in units of b_c."""
        b = self.backlash
        return self._bar(b.sun_planet, b.units), self._bar(b.planet_ring, b.units)

    def sun_bearing_clearance_bar(self) -> float:
        """b̄_s, the sun bearing half clearance in units of b_c."""
        return self._bar(self.clearance.sun_bearing, self.clearance.units)

    # ------------------------------------------------------------------ phasing
    def mesh_phases(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """Mesh phase angles (φ_spi, φ_rpi) [rad], φ = −2πγ (Parker & Lin 2004; MODEL.md §3)."""
        n, z = self.n_planets, self.teeth
        if self.mesh_phasing.model == "in_phase":
            return (0.0,) * n, (0.0,) * n
        gsp = [_frac(z.sun * i / n) for i in range(n)]
        grp = [_frac(-z.ring * i / n) + self.mesh_phasing.ring_sun for i in range(n)]
        return tuple(-2.0 * math.pi * g for g in gsp), tuple(-2.0 * math.pi * g for g in grp)

    @property
    def phasing_class(self) -> str:
        """Planet phasing class from k = z_r mod N: ``in_phase`` (k = 0), ``sequential``
        (k = 1 or N−1) or ``counter_phase`` — a property of the tooth numbers, whatever the
        :class:`MeshPhasing` model."""
        n = self.n_planets
        k = self.teeth.ring % n
        if k == 0:
            return "in_phase"
        if k in (1, n - 1):
            return "sequential"
        return "counter_phase"

    @property
    def has_eccentricity(self) -> bool:
        """Whether any eccentricity E_s, E_p, E_r is non-zero (forcing no longer 1T-periodic)."""
        e = self.eccentricity
        return any(v != 0.0 for v in (e.sun, e.planet, e.ring))

    # ------------------------------------------------------------------ copies and I/O
    def evolve(self, changes: dict[str, object] | None = None, /, **kwargs: object) -> GearSet:
        """A validated copy with some fields changed.

        Fields are addressed by dotted name: ``gs.evolve({"backlash.sun_planet": 4.0})`` or,
        as keywords, with ``__`` for the dot: ``gs.evolve(backlash__sun_planet=4.0)``.
        The alias ``xi`` sets all three damping ratios.
        """
        from .io import evolve

        merged: dict[str, object] = dict(changes or {})
        merged.update({k.replace("__", "."): v for k, v in kwargs.items()})
        return evolve(self, merged)

    @classmethod
    def from_toml(cls, path: str | os.PathLike[str]) -> GearSet:
        """Read a gear set from a TOML file (see ``gearchaos init-gearset`` for a template)."""
        from .io import from_toml

        return from_toml(path)

    @classmethod
    def from_toml_string(cls, text: str) -> GearSet:
        """Parse a gear set from TOML text."""
        from .io import from_toml_string

        return from_toml_string(text)

    def to_toml(self) -> str:
        """TOML text that :meth:`from_toml_string` reads back to an equal gear set."""
        from .io import to_toml

        return to_toml(self)

    def to_dict(self) -> dict[str, object]:
        """Nested plain dictionary (TOML layout)."""
        from .io import to_dict

        return to_dict(self)


#: Units of every dotted field (degrees for angles; clearances follow their ``units`` field).
UNITS: dict[str, str] = {
    "teeth.sun": "1",
    "teeth.planet": "1",
    "teeth.ring": "1",
    "geometry.planets": "1",
    "geometry.module": "m",
    "geometry.pressure_angle_sun": "deg",
    "geometry.pressure_angle_ring": "deg",
    "mass.sun": "kg",
    "mass.planet": "kg",
    "inertia.sun": "kg m^2",
    "inertia.planet": "kg m^2",
    "inertia.carrier": "kg m^2",
    "stiffness.sun_planet_mean": "N/m",
    "stiffness.sun_planet_alternating": "N/m",
    "stiffness.planet_ring_mean": "N/m",
    "stiffness.planet_ring_alternating": "N/m",
    "stiffness.sun_bearing": "N/m",
    "stiffness.sun_planet_harmonics": "N/m",
    "stiffness.planet_ring_harmonics": "N/m",
    "damping.sun_planet": "1",
    "damping.planet_ring": "1",
    "damping.sun_bearing": "1",
    "torque.input": "N m",
    "torque.mode": "",
    "torque.reference_omega": "1",
    "transmission_error.sun_planet": "m",
    "transmission_error.planet_ring": "m",
    "transmission_error.sun_planet_phase": "deg",
    "transmission_error.planet_ring_phase": "deg",
    "eccentricity.sun": "m",
    "eccentricity.planet": "m",
    "eccentricity.ring": "m",
    "eccentricity.sun_phase": "deg",
    "eccentricity.planet_phase": "deg",
    "eccentricity.ring_phase": "deg",
    "backlash.sun_planet": "b_c or m (backlash.units)",
    "backlash.planet_ring": "b_c or m (backlash.units)",
    "backlash.units": "",
    "clearance.sun_bearing": "b_c or m (clearance.units)",
    "clearance.characteristic_length": "m",
    "clearance.units": "",
    "mesh_phasing.model": "",
    "mesh_phasing.ring_sun": "mesh cycles",
}
