"""The records of a gear set's tables: :class:`Teeth`, :class:`Geometry` … :class:`MeshPhasing`.

Each is a frozen dataclass whose fields are the keys of one TOML table (and the second part of
the dotted names: ``backlash.sun_planet`` is ``Backlash.sun_planet``); :data:`RECORD_CLASSES`
maps table names to them in the order of :data:`gearchaos.gearset.schema.TABLES`. They hold
values only: a :class:`~gearchaos.gearset.records.GearSet` validates them as a whole.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType
from typing import Final

__all__ = [
    "Backlash",
    "Clearance",
    "Damping",
    "Eccentricity",
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


#: The nested records of a gear set: GearSet field (= TOML table) name -> record class.
RECORD_CLASSES: Final = MappingProxyType(
    {
        "teeth": Teeth,
        "geometry": Geometry,
        "mass": Mass,
        "inertia": Inertia,
        "stiffness": Stiffness,
        "damping": Damping,
        "torque": Torque,
        "backlash": Backlash,
        "clearance": Clearance,
        "transmission_error": TransmissionError,
        "eccentricity": Eccentricity,
        "mesh_phasing": MeshPhasing,
    }
)
