"""Validation of :class:`~gearchaos.gearset.records.GearSet` records.

:func:`validate` runs from ``GearSet.__post_init__``, so every gear set that exists has passed
it. Each violation raises :class:`~gearchaos.errors.ParameterError` with a message that names
the dotted parameter, the rule and the offending value, e.g.::

    backlash.sun_planet must be >= 0: got -3.0
    teeth.ring must equal teeth.sun + 2*teeth.planet (34 + 2*31 = 96): got 95

The checks run in a fixed order and the first violation is reported:

1. every nested field holds the right record class; ``name`` and ``description`` are strings;
2. per field, in the order of :data:`FIELD_KINDS`: type (integer, number, string or tuple of
   numbers; ``bool`` is never a number), finiteness, then the field's own rule (sign, open
   interval or allowed choices);
3. relations between fields: standard tooth numbers z_r = z_s + 2 z_p, equal planet spacing
   ((z_s + z_r)/N an integer, MODEL.md §1) and positive mesh stiffness
   (k_a + Σ|k_h| < k_m for each mesh, so that k(t) > 0 whatever the phases, MODEL.md §3).

:func:`warn_if_eccentric` is a separate, non-fatal check for analyses that sample the response at
the mesh-period Poincaré section.
"""

from __future__ import annotations

import math
import numbers
import typing
import unicodedata
import warnings
from dataclasses import fields
from typing import Final

from ..errors import ParameterError
from .records import GearSet

__all__ = [
    "CHOICES",
    "FIELD_KINDS",
    "POINCARE_ANALYSES",
    "RECORD_CLASSES",
    "validate",
    "warn_if_eccentric",
]


def _record_classes() -> dict[str, type]:
    hints = typing.get_type_hints(GearSet)
    return {f.name: hints[f.name] for f in fields(GearSet) if f.name not in ("name", "description")}


#: The nested records of a gear set: GearSet field (= TOML table) name -> record class.
RECORD_CLASSES: Final[dict[str, type]] = _record_classes()


def _kind(tp: object) -> str:
    if tp is int:
        return "int"
    if tp is float:
        return "float"
    if tp is str:
        return "str"
    if tp == tuple[float, ...]:
        return "floats"
    raise TypeError(f"unsupported record field type {tp!r}")  # pragma: no cover


def _field_kinds() -> dict[str, str]:
    kinds: dict[str, str] = {}
    for table, cls in RECORD_CLASSES.items():
        hints = typing.get_type_hints(cls)
        for f in fields(cls):
            kinds[f"{table}.{f.name}"] = _kind(hints[f.name])
    return kinds


#: Kind of every dotted field: ``"int"``, ``"float"``, ``"str"`` or ``"floats"`` (tuple of floats).
FIELD_KINDS: Final[dict[str, str]] = _field_kinds()

#: Allowed values of the string fields.
CHOICES: Final[dict[str, tuple[str, ...]]] = {
    "torque.mode": ("constant_torque", "constant_power"),
    "backlash.units": ("dimensionless", "m"),
    "clearance.units": ("dimensionless", "m"),
    "mesh_phasing.model": ("parker", "in_phase"),
}

# Sign rules of scalar fields; a float field not listed may take any finite value.
_POSITIVE: Final = frozenset(
    {
        "teeth.sun",
        "teeth.planet",
        "teeth.ring",
        "geometry.module",
        "mass.sun",
        "mass.planet",
        "inertia.sun",
        "inertia.planet",
        "inertia.carrier",
        "stiffness.sun_planet_mean",
        "stiffness.planet_ring_mean",
        "stiffness.sun_bearing",
        "torque.reference_omega",
        "clearance.characteristic_length",
    }
)
_AT_LEAST_ONE: Final = frozenset({"geometry.planets"})
_NON_NEGATIVE: Final = frozenset(
    {
        "stiffness.sun_planet_alternating",
        "stiffness.planet_ring_alternating",
        "damping.sun_planet",
        "damping.planet_ring",
        "damping.sun_bearing",
        "transmission_error.sun_planet",
        "transmission_error.planet_ring",
        "eccentricity.sun",
        "eccentricity.planet",
        "eccentricity.ring",
        "backlash.sun_planet",
        "backlash.planet_ring",
        "clearance.sun_bearing",
    }
)
_OPEN_INTERVAL: Final[dict[str, tuple[float, float]]] = {
    "geometry.pressure_angle_sun": (0.0, 45.0),
    "geometry.pressure_angle_ring": (0.0, 45.0),
}


def _is_int(value: object) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def _is_number(value: object) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _got(value: object) -> str:
    return f"got {value!r} ({type(value).__name__})"


def _check_number(name: str, value: object) -> float:
    """Type and finiteness of one real number; returns it as a float."""
    if not _is_number(value):
        raise ParameterError(f"{name} must be a number: {_got(value)}")
    try:
        x = float(value)  # type: ignore[arg-type]
    except OverflowError:
        raise ParameterError(f"{name} must be finite: got {value!r}") from None
    if not math.isfinite(x):
        raise ParameterError(f"{name} must be finite: got {value!r}")
    return x


def _check_text(name: str, value: object) -> str:
    if not isinstance(value, str):
        raise ParameterError(f"{name} must be a string: {_got(value)}")
    try:
        value.encode("utf-8")
    except UnicodeEncodeError:
        raise ParameterError(
            f"{name} must be valid Unicode text (no lone surrogates): got {value!r}"
        ) from None
    return value


def _check_field(name: str, kind: str, value: object) -> None:
    if kind == "int":
        if not _is_int(value):
            raise ParameterError(f"{name} must be an integer: {_got(value)}")
        n = int(value)  # type: ignore[call-overload]
        if name in _POSITIVE and n <= 0:
            raise ParameterError(f"{name} must be > 0: got {value!r}")
        if name in _AT_LEAST_ONE and n < 1:
            raise ParameterError(f"{name} must be >= 1: got {value!r}")
    elif kind == "float":
        x = _check_number(name, value)
        if name in _POSITIVE and not x > 0.0:
            raise ParameterError(f"{name} must be > 0: got {value!r}")
        if name in _NON_NEGATIVE and not x >= 0.0:
            raise ParameterError(f"{name} must be >= 0: got {value!r}")
        if name in _OPEN_INTERVAL:
            lo, hi = _OPEN_INTERVAL[name]
            if not lo < x < hi:
                raise ParameterError(
                    f"{name} must lie in the open interval ({lo:g}, {hi:g}) degrees: got {value!r}"
                )
    elif kind == "str":
        text = _check_text(name, value)
        if name in CHOICES and text not in CHOICES[name]:
            allowed = ", ".join(repr(c) for c in CHOICES[name])
            raise ParameterError(f"{name} must be one of {allowed}: got {value!r}")
    elif kind == "floats":
        if not isinstance(value, tuple):
            raise ParameterError(f"{name} must be a tuple of numbers: {_got(value)}")
        for i, item in enumerate(value):
            _check_number(f"{name}[{i}]", item)
    else:  # pragma: no cover - FIELD_KINDS only holds the kinds above
        raise AssertionError(kind)


def _check_stiffness_positive(gs: GearSet, mesh: str) -> None:
    s = gs.stiffness
    km = float(getattr(s, f"{mesh}_mean"))
    ka = float(getattr(s, f"{mesh}_alternating"))
    harmonics = tuple(float(h) for h in getattr(s, f"{mesh}_harmonics"))
    sum_h = math.fsum(abs(h) for h in harmonics)
    total = ka + sum_h
    if total < km:
        return
    if harmonics:
        raise ParameterError(
            f"stiffness.{mesh}_alternating + sum(|stiffness.{mesh}_harmonics|) must be < "
            f"stiffness.{mesh}_mean = {km!r} (stiffness would turn negative): "
            f"got {ka!r} + {sum_h!r} = {total!r}"
        )
    raise ParameterError(
        f"stiffness.{mesh}_alternating must be < stiffness.{mesh}_mean = {km!r} "
        f"(stiffness would turn negative): got {ka!r}"
    )


def validate(gs: GearSet) -> None:
    """Check every field of a gear set and the relations between them.

    Parameters
    ----------
    gs : GearSet
        The gear set to check (``GearSet.__post_init__`` calls this on every construction).

    Raises
    ------
    ParameterError
        At the first violated rule, with a message naming the dotted parameter, the rule and
        the value. The rules are (symbols of MODEL.md):

        - records: each nested field is its record class; ``name``, ``description`` strings;
        - integers (``bool`` and integral floats such as ``34.0`` are rejected):
          z_s, z_p, z_r > 0, N >= 1;
        - every float field is a finite real number (``bool`` rejected, ``int`` accepted);
        - > 0: module m, masses m_s, m_p, inertias J_s, J_p, J_c, mean mesh stiffnesses
          k_m,sp and k_m,rp, sun bearing stiffness k_s, b_c, ``torque.reference_omega``;
        - >= 0: alternating stiffnesses k_a, damping ratios ξ, transmission-error amplitudes
          A, eccentricities E, half clearances b_sp, b_rp, b_s;
        - 0 < α_s, α_r < 45 degrees;
        - ``torque.mode`` in {constant_torque, constant_power}; ``backlash.units`` and
          ``clearance.units`` in {dimensionless, m}; ``mesh_phasing.model`` in {parker, in_phase};
        - harmonics are tuples of finite numbers of any sign;
        - z_r = z_s + 2 z_p (standard gears);
        - (z_s + z_r)/N is an integer (equally spaced planets);
        - k_a + Σ_h |k_h| < k_m for each mesh, so the mesh stiffness stays positive.
    """
    if not isinstance(gs, GearSet):
        raise TypeError(f"validate() expects a GearSet: got {type(gs).__name__}")
    for table, cls in RECORD_CLASSES.items():
        record = getattr(gs, table)
        if not isinstance(record, cls):
            raise ParameterError(f"{table} must be a {cls.__name__} record: {_got(record)}")
    _check_text("name", gs.name)
    _check_text("description", gs.description)

    for dotted, kind in FIELD_KINDS.items():
        table, attr = dotted.split(".", 1)
        _check_field(dotted, kind, getattr(getattr(gs, table), attr))

    z = gs.teeth
    if z.ring != z.sun + 2 * z.planet:
        raise ParameterError(
            "teeth.ring must equal teeth.sun + 2*teeth.planet "
            f"({z.sun} + 2*{z.planet} = {z.sun + 2 * z.planet}): got {z.ring}"
        )
    n = gs.geometry.planets
    if (z.sun + z.ring) % n != 0:
        raise ParameterError(
            f"geometry.planets = {n}: planets cannot be equally spaced, "
            "(teeth.sun + teeth.ring)/geometry.planets must be an integer: "
            f"got ({z.sun} + {z.ring})/{n} = {(z.sun + z.ring) / n:g}"
        )
    _check_stiffness_positive(gs, "sun_planet")
    _check_stiffness_positive(gs, "planet_ring")


#: Analyses that sample the response at the mesh-period section t_k = kT (case-insensitive;
#: ``-`` and spaces count as ``_``, accents are ignored).
POINCARE_ANALYSES: Final = frozenset(
    {"poincare", "poincare_map", "bifurcation", "periodicity", "period", "classify", "map"}
)


def _normalise_analysis(analysis: str) -> str:
    text = unicodedata.normalize("NFKD", analysis).encode("ascii", "ignore").decode("ascii")
    return text.strip().lower().replace("-", "_").replace(" ", "_")


def warn_if_eccentric(gs: GearSet, analysis: str) -> bool:
    """Warn when a Poincaré-section analysis is asked of a gear set with eccentricities.

    With any eccentricity E_s, E_p or E_r non-zero the transmission errors contain the
    frequencies ω/z_s, ω/z_p and ω/z_r (MODEL.md §3), so the forcing repeats only every
    lcm(z_s, z_p, z_r) mesh periods. No orbit is then strictly 1T-periodic at the mesh-period
    section t_k = kT, and section-based classifications (nT-periodic, quasi-periodic) describe
    the slow eccentricity modulation as much as the gear dynamics.

    Parameters
    ----------
    gs : GearSet
        The gear set to be analysed.
    analysis : str
        Name of the requested analysis. Only the names in :data:`POINCARE_ANALYSES`
        (e.g. ``"poincare"``, ``"bifurcation"``) and names starting with ``"poincare"`` trigger
        the warning.

    Returns
    -------
    bool
        Whether a :class:`UserWarning` was issued.
    """
    key = _normalise_analysis(analysis)
    if not gs.has_eccentricity:
        return False
    if key not in POINCARE_ANALYSES and not key.startswith("poincare"):
        return False
    z = gs.teeth
    e = gs.eccentricity
    period = math.lcm(z.sun, z.planet, z.ring)
    warnings.warn(
        f"{analysis}: gear set {gs.name!r} has non-zero eccentricity "
        f"(eccentricity.sun = {e.sun!r}, eccentricity.planet = {e.planet!r}, "
        f"eccentricity.ring = {e.ring!r}); the forcing is then periodic only over "
        f"lcm(z_s, z_p, z_r) = lcm({z.sun}, {z.planet}, {z.ring}) = {period} mesh periods, "
        "so no orbit is strictly 1T-periodic at the mesh-period Poincaré section "
        "(MODEL.md §3); set the eccentricities to 0 for section-based classification",
        UserWarning,
        stacklevel=2,
    )
    return True
