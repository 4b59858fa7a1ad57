"""The parameter registry: every dotted name a user can address, described once.

For each gear-set field (``teeth.sun`` … ``mesh_phasing.ring_sun``) :data:`FIELDS` holds a
:class:`Field`: its kind (``int``, ``float``, ``str`` or ``floats``), unit, plain and TeX
symbol, meaning, allowed choices, its rule (the sign or interval the model needs) and its
plausible range (``limits``: where a value stops describing a gear set; docs/gearset-rules.md).
The operating point ``omega`` (Ω = ω/ω_n), the speeds that set it through a gear set
(``sun_rpm``, ``mesh_hz``: :data:`SPEEDS`) and the alias ``xi`` (the three damping ratios) are
described in :data:`EXTRA`. :data:`CLEARANCES` says which clearance belongs to which
observable, :data:`MODULE_BOUNDED` which lengths may not exceed one module. Validation, TOML
I/O, the command line's ``--set`` parsing, plot labels and the paper's tables all read this
module; it imports only its types (:mod:`~gearchaos.gearset.fieldtypes`).
"""

from __future__ import annotations

from dataclasses import replace
from types import MappingProxyType
from typing import Final

from .fieldtypes import ANGLE, AT_LEAST_ONE, NON_NEGATIVE, POSITIVE, Field, Rule

__all__ = [
    "ALIASES",
    "CHOICES",
    "CLEARANCES",
    "EXTRA",
    "FIELDS",
    "MAX_HARMONICS",
    "MESH_HZ",
    "META",
    "MODULE_BOUNDED",
    "OMEGA",
    "SPEEDS",
    "SUN_RPM",
    "TABLES",
    "UNITS",
    "XI",
    "Field",
    "Rule",
    "describe",
    "display_symbol",
    "symbol",
    "tex",
]

# Plausible ranges (docs/gearset-rules.md): from below MEMS gears to beyond mill drives, chosen
# so that every derived quantity (radii, equivalent masses, ω_n, damping coefficients, the
# dimensionless groups of MODEL.md §7) stays finite and positive.
_TEETH: Final = Rule(1, 10_000)
_PLANETS: Final = Rule(1, 100)
_MODULE: Final = Rule(1e-6, 1.0)
_MASS: Final = Rule(1e-12, 1e6)
_INERTIA: Final = Rule(1e-24, 1e6)
_STIFFNESS: Final = Rule(1e-3, 1e13)
_STIFFNESS_ALT: Final = Rule(0.0, 1e13)
_HARMONIC: Final = Rule(-1e13, 1e13)
_DAMPING: Final = Rule(0.0, 10.0)
_TORQUE: Final = Rule(-1e9, 1e9)
_OMEGA: Final = Rule(1e-6, 1e6)
# Ω of an operating point: a mesh frequency 50 times the first mesh mode's is no gearbox's
# (an rpm typed as Ω, 7000, is 34 million rpm for sheng2016: refused, with a hint at sun_rpm)
_OMEGA_POINT: Final = Rule(1e-6, 50.0)
_LENGTH_SCALE: Final = Rule(1e-9, 1.0)
_PHASE: Final = Rule(-1e6, 1e6)

#: Most higher harmonics a mesh stiffness may list (``stiffness.*_harmonics``).
MAX_HARMONICS: Final = 64


_F = Field
_CLEAR_SP = "b_c or m (backlash.units)"
_CLEAR_S = "b_c or m (clearance.units)"

_LIMITS: Final = {
    **dict.fromkeys(("teeth.sun", "teeth.planet", "teeth.ring"), _TEETH),
    "geometry.planets": _PLANETS,
    "geometry.module": _MODULE,
    **dict.fromkeys(("mass.sun", "mass.planet"), _MASS),
    **dict.fromkeys(("inertia.sun", "inertia.planet", "inertia.carrier"), _INERTIA),
    **dict.fromkeys(
        ("stiffness.sun_planet_mean", "stiffness.planet_ring_mean", "stiffness.sun_bearing"),
        _STIFFNESS,
    ),
    **dict.fromkeys(
        ("stiffness.sun_planet_alternating", "stiffness.planet_ring_alternating"), _STIFFNESS_ALT
    ),
    **dict.fromkeys(
        ("stiffness.sun_planet_harmonics", "stiffness.planet_ring_harmonics"), _HARMONIC
    ),
    **dict.fromkeys(("damping.sun_planet", "damping.planet_ring", "damping.sun_bearing"), _DAMPING),
    "torque.input": _TORQUE,
    "torque.reference_omega": _OMEGA,
    "clearance.characteristic_length": _LENGTH_SCALE,
    **dict.fromkeys(
        (
            "transmission_error.sun_planet_phase",
            "transmission_error.planet_ring_phase",
            "eccentricity.sun_phase",
            "eccentricity.planet_phase",
            "eccentricity.ring_phase",
            "mesh_phasing.ring_sun",
        ),
        _PHASE,
    ),
}

#: Every gear-set field by dotted name, table by table in record order.
FIELDS: Final = MappingProxyType(
    {
        f.name: replace(f, limits=_LIMITS.get(f.name))
        for f in (
            _F("teeth.sun", "int", "1", "z_s", "z_s", "number of sun teeth", POSITIVE),
            _F(
                "teeth.planet", "int", "1", "z_p", "z_p", "number of teeth of each planet", POSITIVE
            ),
            _F(
                "teeth.ring",
                "int",
                "1",
                "z_r",
                "z_r",
                "number of ring teeth (internal gear); must equal z_s + 2 z_p",
                POSITIVE,
            ),
            _F(
                "geometry.planets",
                "int",
                "1",
                "N",
                "N",
                "number of equally spaced planets; (z_s + z_r)/N must be an integer",
                AT_LEAST_ONE,
            ),
            _F(
                "geometry.module",
                "float",
                "m",
                "m",
                "m",
                "module; pitch radius r = m z / 2",
                POSITIVE,
            ),
            _F(
                "geometry.pressure_angle_sun",
                "float",
                "deg",
                "α_s",
                r"\alpha_s",
                "pressure angle of the sun–planet meshes, in (0, 45)",
                ANGLE,
            ),
            _F(
                "geometry.pressure_angle_ring",
                "float",
                "deg",
                "α_r",
                r"\alpha_r",
                "pressure angle of the ring–planet meshes, in (0, 45)",
                ANGLE,
            ),
            _F(
                "mass.sun",
                "float",
                "kg",
                "m_s",
                "m_s",
                "translational mass of the sun (moves in x and y on its bearing)",
                POSITIVE,
            ),
            _F(
                "mass.planet",
                "float",
                "kg",
                "m_p",
                "m_p",
                "mass of each planet (rides on the carrier)",
                POSITIVE,
            ),
            _F(
                "inertia.sun",
                "float",
                "kg m^2",
                "J_s",
                "J_s",
                "polar moment of inertia of the sun; m_s* = J_s / r_bs²",
                POSITIVE,
            ),
            _F(
                "inertia.planet",
                "float",
                "kg m^2",
                "J_p",
                "J_p",
                "polar moment of inertia of each planet; m_p* = J_p / r_bp²",
                POSITIVE,
            ),
            _F(
                "inertia.carrier",
                "float",
                "kg m^2",
                "J_c",
                "J_c",
                "polar moment of inertia of the carrier; m_c* = J_c / r_c² + N m_p",
                POSITIVE,
            ),
            _F(
                "stiffness.sun_planet_mean",
                "float",
                "N/m",
                "k_m,sp",
                "k_{m,sp}",
                "mean sun–planet mesh stiffness",
                POSITIVE,
            ),
            _F(
                "stiffness.sun_planet_alternating",
                "float",
                "N/m",
                "k_a,sp",
                "k_{a,sp}",
                "amplitude of its mesh-frequency variation; needs k_a + Σ|k_h| < k_m",
                NON_NEGATIVE,
            ),
            _F(
                "stiffness.planet_ring_mean",
                "float",
                "N/m",
                "k_m,rp",
                "k_{m,rp}",
                "mean planet–ring mesh stiffness",
                POSITIVE,
            ),
            _F(
                "stiffness.planet_ring_alternating",
                "float",
                "N/m",
                "k_a,rp",
                "k_{a,rp}",
                "amplitude of its mesh-frequency variation; needs k_a + Σ|k_h| < k_m",
                NON_NEGATIVE,
            ),
            _F(
                "stiffness.sun_bearing",
                "float",
                "N/m",
                "k_s",
                "k_s",
                "sun bearing (support) stiffness, along x and along y",
                POSITIVE,
            ),
            _F(
                "stiffness.sun_planet_harmonics",
                "floats",
                "N/m",
                "k_2, k_3, …",
                "k_{h,sp}",
                "optional higher harmonics of the sun–planet mesh stiffness (any sign)",
            ),
            _F(
                "stiffness.planet_ring_harmonics",
                "floats",
                "N/m",
                "k_2, k_3, …",
                "k_{h,rp}",
                "optional higher harmonics of the planet–ring mesh stiffness (any sign)",
            ),
            _F(
                "damping.sun_planet",
                "float",
                "1",
                "ξ_sp",
                r"\xi_{sp}",
                "sun–planet mesh damping ratio; c_sp = 2 ξ_sp √(k_m,sp m_e)",
                NON_NEGATIVE,
            ),
            _F(
                "damping.planet_ring",
                "float",
                "1",
                "ξ_rp",
                r"\xi_{rp}",
                "planet–ring mesh damping ratio; c_rp = 2 ξ_rp √(k_m,rp m_p*)",
                NON_NEGATIVE,
            ),
            _F(
                "damping.sun_bearing",
                "float",
                "1",
                "ξ_s",
                r"\xi_{s}",
                "sun bearing damping ratio; c_s = 2 ξ_s √(k_s m_s)",
                NON_NEGATIVE,
            ),
            _F(
                "torque.input",
                "float",
                "N m",
                "T_D",
                "T_D",
                "input torque on the sun; output torque T_L = T_D (1 + z_r/z_s)",
            ),
            _F(
                "torque.mode",
                "str",
                "",
                "",
                r"\mathrm{load\ mode}",
                "constant_torque: T_D fixed; constant_power: T_D Ω_ref / Ω",
                choices=("constant_torque", "constant_power"),
            ),
            _F(
                "torque.reference_omega",
                "float",
                "1",
                "Ω_ref",
                r"\Omega_{ref}",
                "dimensionless mesh frequency at which T_D applies (constant_power only)",
                POSITIVE,
            ),
            _F(
                "backlash.sun_planet",
                "float",
                _CLEAR_SP,
                "b_sp",
                r"\bar b_{sp}",
                "half backlash of the sun–planet meshes (total 2 b_sp)",
                NON_NEGATIVE,
            ),
            _F(
                "backlash.planet_ring",
                "float",
                _CLEAR_SP,
                "b_rp",
                r"\bar b_{rp}",
                "half backlash of the planet–ring meshes (total 2 b_rp)",
                NON_NEGATIVE,
            ),
            _F(
                "backlash.units",
                "str",
                "",
                "",
                r"\mathrm{backlash\ units}",
                "units of the two half backlashes below: b/b_c or metres",
                choices=("dimensionless", "m"),
            ),
            _F(
                "clearance.sun_bearing",
                "float",
                _CLEAR_S,
                "b_s",
                r"\bar b_s",
                "sun bearing half clearance, along x and along y",
                NON_NEGATIVE,
            ),
            _F(
                "clearance.characteristic_length",
                "float",
                "m",
                "b_c",
                "b_c",
                "length scale of the dimensionless model (always in metres)",
                POSITIVE,
            ),
            _F(
                "clearance.units",
                "str",
                "",
                "",
                r"\mathrm{clearance\ units}",
                "units of clearance.sun_bearing: b/b_c or metres",
                choices=("dimensionless", "m"),
            ),
            _F(
                "transmission_error.sun_planet",
                "float",
                "m",
                "A_sp",
                "A_{sp}",
                "sun–planet static transmission-error amplitude",
                NON_NEGATIVE,
            ),
            _F(
                "transmission_error.planet_ring",
                "float",
                "m",
                "A_rp",
                "A_{rp}",
                "planet–ring static transmission-error amplitude",
                NON_NEGATIVE,
            ),
            _F(
                "transmission_error.sun_planet_phase",
                "float",
                "deg",
                "",
                r"\varphi_{A,sp}",
                "phase of A_sp relative to the sun–planet mesh-stiffness phase",
            ),
            _F(
                "transmission_error.planet_ring_phase",
                "float",
                "deg",
                "",
                r"\varphi_{A,rp}",
                "phase of A_rp relative to the planet–ring mesh-stiffness phase",
            ),
            _F(
                "eccentricity.sun",
                "float",
                "m",
                "E_s",
                "E_s",
                "sun eccentricity; any E ≠ 0 makes the forcing lcm(z_s, z_p, z_r)-periodic",
                NON_NEGATIVE,
            ),
            _F(
                "eccentricity.planet",
                "float",
                "m",
                "E_p",
                "E_p",
                "planet eccentricity",
                NON_NEGATIVE,
            ),
            _F("eccentricity.ring", "float", "m", "E_r", "E_r", "ring eccentricity", NON_NEGATIVE),
            _F(
                "eccentricity.sun_phase",
                "float",
                "deg",
                "β_s",
                r"\beta_s",
                "phase of the sun eccentricity",
            ),
            _F(
                "eccentricity.planet_phase",
                "float",
                "deg",
                "β_p",
                r"\beta_p",
                "phase of the planet eccentricity",
            ),
            _F(
                "eccentricity.ring_phase",
                "float",
                "deg",
                "β_r",
                r"\beta_r",
                "phase of the ring eccentricity",
            ),
            _F(
                "mesh_phasing.model",
                "str",
                "",
                "",
                r"\mathrm{mesh\ phasing}",
                "parker (the default): Parker & Lin (2004) phases; "
                "in_phase: all φ = 0 (as sheng2016, MODEL.md §9)",
                choices=("parker", "in_phase"),
            ),
            _F(
                "mesh_phasing.ring_sun",
                "float",
                "mesh cycles",
                "γ_rs",
                r"\gamma_{rs}",
                "ring-mesh phase of planet 1 relative to its sun mesh (parker only)",
            ),
        )
    }
)

#: The tables of a gear-set file (= the records of a GearSet), in order.
TABLES: Final = tuple(dict.fromkeys(f.table for f in FIELDS.values()))

#: Top-level keys of a gear-set file besides the tables.
META: Final = ("name", "description")

#: Names that set several fields at once: alias -> the fields it sets.
ALIASES: Final = MappingProxyType(
    {"xi": ("damping.sun_planet", "damping.planet_ring", "damping.sun_bearing")}
)

#: The operating point: Ω is a simulation setting, not a gear-set field, but it is addressed
#: by name like one (``--set omega=1.5``, ``--vary omega=0.1:4:800``).
OMEGA: Final = "omega"
XI: Final = "xi"
#: The sun (input) speed n_s [rpm] and the mesh frequency f_m [Hz]: the operating point in a
#: drivetrain engineer's units, each setting Ω through the gear set's ω_n (and tooth numbers)
#: (:meth:`~gearchaos.gearset.GearSet.omega_at`). Addressed like Ω (``--set sun_rpm=7500``,
#: ``--vary sun_rpm=1000:20000:200``); at most one of Ω and these per point.
SUN_RPM: Final = "sun_rpm"
MESH_HZ: Final = "mesh_hz"
SPEEDS: Final = (SUN_RPM, MESH_HZ)

#: Names that are not gear-set fields: Ω, the speeds that set it and the alias ξ.
EXTRA: Final = MappingProxyType(
    {
        OMEGA: Field(
            OMEGA,
            "float",
            "1",
            "Ω",
            r"\Omega",
            "dimensionless mesh frequency Ω = ω/ω_n",
            POSITIVE,
            limits=_OMEGA_POINT,
        ),
        SUN_RPM: Field(
            SUN_RPM,
            "float",
            "rpm",
            "n_s",
            "n_s",
            "sun (input) speed; sets Ω = 2π n_s z_s z_r / (60 (z_s + z_r) ω_n)",
            POSITIVE,
        ),
        MESH_HZ: Field(
            MESH_HZ,
            "float",
            "Hz",
            "f_m",
            "f_m",
            "mesh frequency; sets Ω = 2π f_m / ω_n",
            POSITIVE,
        ),
        XI: Field(
            XI,
            "float",
            "1",
            "ξ",
            r"\xi",
            "all three damping ratios ξ_sp = ξ_rp = ξ_s",
            NON_NEGATIVE,
        ),
    }
)

#: Allowed values of the string fields.
CHOICES: Final = MappingProxyType({n: f.choices for n, f in FIELDS.items() if f.choices})

#: Units of every dotted field (degrees for angles; clearances follow their ``units`` field).
UNITS: Final = MappingProxyType({n: f.unit for n, f in FIELDS.items()})

#: Lengths that may not exceed one module m (the addendum of a standard tooth), each with the
#: field giving its units (``None``: always metres).
MODULE_BOUNDED: Final = MappingProxyType(
    {
        "backlash.sun_planet": "backlash.units",
        "backlash.planet_ring": "backlash.units",
        "clearance.sun_bearing": "clearance.units",
        "transmission_error.sun_planet": None,
        "transmission_error.planet_ring": None,
        "eccentricity.sun": None,
        "eccentricity.planet": None,
        "eccentricity.ring": None,
    }
)

#: Which clearance acts on which observable: observable -> (clearance field, its units field,
#: the model's clearance key).
CLEARANCES: Final = MappingProxyType(
    {
        "delta_sp": ("backlash.sun_planet", "backlash.units", "sun_planet"),
        "delta_rp": ("backlash.planet_ring", "backlash.units", "planet_ring"),
        "x_s": ("clearance.sun_bearing", "clearance.units", "sun_bearing"),
        "y_s": ("clearance.sun_bearing", "clearance.units", "sun_bearing"),
    }
)


def describe(name: str) -> Field | None:
    """The :class:`Field` of a gear-set field, ``omega``, a speed or ``xi``; ``None`` for other
    names."""
    return FIELDS.get(name) or EXTRA.get(name)


def symbol(name: str) -> str:
    """Plain symbol of a parameter (``Ω``, ``ξ``, ``b_sp``); the name itself when it has none."""
    f = describe(name)
    return f.symbol if f is not None and f.symbol else name


def tex(name: str) -> str | None:
    """Mathtext symbol (without ``$``) of a parameter, or ``None`` for unknown names."""
    f = describe(name)
    return None if f is None else f.tex


def display_symbol(name: str) -> str:
    """Plain symbol for tables and captions: ``Ω``, ``ξ``, ``b̄_sp`` (the clearances are shown
    dimensionless, as the seed quotes them), ``T_D``; the name itself when it has none."""
    if any(name == parameter for parameter, _, _ in CLEARANCES.values()):
        return "b̄_" + FIELDS[name].symbol.split("_", 1)[1]
    return symbol(name)
