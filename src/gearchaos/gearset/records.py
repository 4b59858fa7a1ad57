"""Frozen records that describe a 2K-H planetary gear set in SI units.

Every field is addressed by a stable dotted name (``teeth.sun``, ``backlash.sun_planet``,
``damping.sun_bearing`` ...) that is the same in Python, TOML, the CLI, sweep stores and plot
labels. Units live in the parameter registry (:mod:`gearchaos.gearset.schema`; :data:`UNITS`),
not in the field names. The records of the tables (:class:`Teeth` …) are defined in
:mod:`gearchaos.gearset.tables` and importable from here.

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
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Final

from .._files import read_text_file
from ..errors import ParameterError
from .mapping import apply_changes, check_changes, get_value, records_from_data, to_dict
from .schema import UNITS
from .tables import (
    RECORD_CLASSES,
    Backlash,
    Clearance,
    Damping,
    Eccentricity,
    Geometry,
    Inertia,
    Mass,
    MeshPhasing,
    Stiffness,
    Teeth,
    Torque,
    TransmissionError,
)
from .tomltext import MAX_FILE_BYTES, parse, to_toml
from .validation import validate, warn_if_clearance_in_metres

__all__ = ["MAX_FILE_BYTES", "UNITS", "GearSet"]


_NO_CHANGES: Final[Mapping[str, object]] = MappingProxyType({})


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
        validate(self)
        warn_if_clearance_in_metres(self)  # a value in metres for one in units of b_c?

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

    def speed(self, name: str, omega: float) -> float:
        """The operating speed ``name`` at Ω: ``sun_rpm``, the sun speed n_s [rpm]
        (:meth:`sun_speed_rpm`), or ``mesh_hz``, the mesh frequency f_m = Ω ω_n/2π [Hz]. The
        one conversion between Ω and the speeds (its inverse is :meth:`omega_at`)."""
        if name == "sun_rpm":
            return self.sun_speed_rpm(omega)
        if name == "mesh_hz":
            return omega * self.omega_n / (2.0 * math.pi)
        raise ParameterError(f"a speed is sun_rpm or mesh_hz: got {name!r}")

    def omega_at(self, name: str, value: float) -> float:
        """Ω = ω/ω_n at the operating speed ``name`` = ``value`` (the inverse of
        :meth:`speed`): ω = 2π n_s z_s z_r / (60 (z_s + z_r)) for ``sun_rpm`` (MODEL.md §2,
        :meth:`mesh_frequency`), ω = 2π f_m for ``mesh_hz``."""
        if name == "sun_rpm":
            return self.mesh_frequency(value) / self.omega_n
        if name == "mesh_hz":
            return 2.0 * math.pi * value / self.omega_n
        raise ParameterError(f"a speed is sun_rpm or mesh_hz: got {name!r}")

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
    def __getitem__(self, name: str) -> object:
        """One parameter by the dotted name :meth:`evolve` and ``--set`` take:
        ``gs["backlash.sun_planet"]``, ``gs["xi"]`` (while the three damping ratios are
        equal), ``gs["name"]``. Unknown names raise :class:`~gearchaos.errors.ParameterError`
        with the closest valid name."""
        return get_value(self, name)

    def evolve(self, changes: Mapping[str, object] = _NO_CHANGES, /, **kwargs: object) -> GearSet:
        """A validated copy with some parameters changed.

        Parameters
        ----------
        changes : mapping of str to object, optional
            New values by dotted name (``{"backlash.sun_planet": 4.0}``), ``"name"``,
            ``"description"``, a table name (``"backlash"``) with a record instance or a
            mapping of some of its fields, or the alias ``"xi"`` that sets
            ``damping.sun_planet``, ``damping.planet_ring`` and ``damping.sun_bearing`` at once
            (a dotted damping name in the same call overrides the alias for that ratio).
            Integers are accepted for float fields and sequences for the harmonics; they are
            converted to float and tuple. Leave it out for an unchanged copy: anything but a
            mapping, ``None`` included, is refused (a ``None`` where changes were meant is a
            bug, not a request for no change).
        **kwargs
            More changes, with ``__`` for the dot: ``gs.evolve(backlash__sun_planet=4.0)``;
            they override ``changes``.

        Returns
        -------
        GearSet
            The new gear set, validated as a whole (so a change of ``teeth.planet`` must come
            with a consistent ``teeth.ring``).

        Raises
        ------
        ParameterError
            If ``changes`` is not a mapping (the message names ``changes``), for an unknown
            name (suggesting the closest valid one) or an invalid resulting set.
        """
        merged: dict[object, object] = dict(check_changes(changes))
        merged.update({k.replace("__", "."): v for k, v in kwargs.items()})
        tables, meta = apply_changes(self, merged)
        records = {table: cls(**tables[table]) for table, cls in RECORD_CLASSES.items()}
        return GearSet(**records, **meta)  # type: ignore[arg-type]

    @classmethod
    def from_dict(cls, data: Mapping[str, object]) -> GearSet:
        """Build a gear set from a nested mapping in TOML layout (the inverse of
        :meth:`to_dict`); see :func:`gearchaos.gearset.io.from_dict`."""
        records, meta = records_from_data(data)
        return GearSet(**records, **meta)  # type: ignore[arg-type]

    @classmethod
    def from_toml_string(cls, text: str) -> GearSet:
        """Parse a gear set from TOML text (``ParameterError`` for invalid TOML or values)."""
        return cls.from_dict(parse(text))

    @classmethod
    def from_toml(cls, path: str | os.PathLike[str]) -> GearSet:
        """Read a gear set from a TOML file (see ``gearchaos init-gearset`` for a template).

        Only a regular UTF-8 file of at most :data:`MAX_FILE_BYTES` bytes is read (see
        :func:`gearchaos.gearset.io.from_toml` for the errors): a directory, FIFO, device,
        link loop or huge file is refused with a ``StoreError``, a missing file with a
        ``FileNotFoundError`` (that is also a ``StoreError``), invalid contents with a
        ``ParameterError`` whose message starts with the path.
        """
        text = read_text_file(path, what="gear-set file", max_bytes=MAX_FILE_BYTES)
        try:
            return cls.from_toml_string(text)
        except ParameterError as exc:
            raise ParameterError(f"{Path(path)}: {exc}") from exc

    def to_toml(self) -> str:
        """TOML text that :meth:`from_toml_string` reads back to an equal gear set."""
        return to_toml(self)

    def to_dict(self) -> dict[str, object]:
        """Nested plain dictionary (TOML layout)."""
        return to_dict(self)
