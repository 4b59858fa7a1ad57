"""Validation of gear sets against the rules of the parameter registry.

:func:`validate` runs from ``GearSet.__post_init__``, so every gear set that exists has passed
it. Each violation raises :class:`~gearchaos.errors.ParameterError` with a message that names
the dotted parameter, the rule and the offending value, e.g.::

    backlash.sun_planet must be >= 0: got -3.0
    teeth.ring must equal teeth.sun + 2*teeth.planet (34 + 2*31 = 96): got 95
    geometry.module must lie in the plausible range [1e-06, 1] m: got 1e+308

The rules themselves (kinds, signs, choices, plausible ranges, which lengths are bounded by the
module) are data of :mod:`gearchaos.gearset.schema`; this module applies them. It knows the
records of the tables (:mod:`gearchaos.gearset.tables`) but not the ``GearSet`` class, which
calls it: a gear set is anything with the twelve table attributes, ``name`` and
``description`` and the derived properties of :class:`~gearchaos.gearset.records.GearSet`.
The edges of a valid gear set are explained in ``docs/gearset-rules.md``.

:func:`warn_if_eccentric` is a separate, non-fatal check for analyses that sample the response at
the mesh-period Poincaré section; :func:`warn_if_clearance_in_metres`, run with
:func:`validate`, warns of a clearance in units of b_c so small that it is most likely a value
in metres.
"""

from __future__ import annotations

import math
import numbers
import unicodedata
import warnings
from collections.abc import Callable
from types import MappingProxyType
from typing import Any, Final

from ..errors import ParameterError
from .fieldtypes import Field, Rule
from .schema import CHOICES, FIELDS, MAX_HARMONICS, META, MODULE_BOUNDED
from .tables import RECORD_CLASSES

__all__ = [
    "CHOICES",
    "FIELD_KINDS",
    "POINCARE_ANALYSES",
    "RECORD_CLASSES",
    "SMALL_CLEARANCE_BAR",
    "show",
    "validate",
    "warn_if_clearance_in_metres",
    "warn_if_eccentric",
]

#: A clearance in units of b_c below this (and above 0) is most likely a value in metres: b_c
#: is some µm, so 1e-3 b_c is some nm, far below any manufactured backlash.
SMALL_CLEARANCE_BAR: Final = 1e-3

#: Kind of every dotted field: ``"int"``, ``"float"``, ``"str"`` or ``"floats"`` (tuple of floats).
FIELD_KINDS: Final = MappingProxyType({name: f.kind for name, f in FIELDS.items()})

_MAX_SHOWN = 120  # characters of a value's repr in a message


def show(value: object) -> str:
    """``repr(value)``, shortened for messages: never longer than about 120 characters, never
    an exception (huge integers, failing ``__repr__``)."""
    if isinstance(value, numbers.Integral) and not isinstance(value, bool):
        bits = int(value).bit_length()
        if bits > 256:  # more than 77 digits; beyond 4300 digits repr() itself fails
            return f"<an integer of about {int(bits * math.log10(2)) + 1} digits>"
    try:
        text = repr(value)
    except Exception:  # a message must not fail on a hostile object
        text = object.__repr__(value)
    if len(text) > _MAX_SHOWN:
        text = f"{text[: _MAX_SHOWN - 20]}…{text[-15:]} ({len(text)} characters)"
    return text


def _got(value: object) -> str:
    return f"got {show(value)} ({type(value).__name__})"


def _is_int(value: object) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def _is_number(value: object) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _check_number(name: str, value: object) -> float:
    """Type and finiteness of one real number; returns it as a float."""
    if not _is_number(value):
        raise ParameterError(f"{name} must be a number: {_got(value)}")
    try:
        x = float(value)  # type: ignore[arg-type]
    except (OverflowError, ValueError, TypeError):
        raise ParameterError(f"{name} must be finite: got {show(value)}") from None
    if not math.isfinite(x):
        raise ParameterError(f"{name} must be finite: got {show(value)}")
    return x


def _check_text(name: str, value: object) -> str:
    if not isinstance(value, str):
        raise ParameterError(f"{name} must be a string: {_got(value)}")
    try:
        value.encode("utf-8")
    except UnicodeEncodeError:
        raise ParameterError(
            f"{name} must be valid Unicode text (no lone surrogates): got {show(value)}"
        ) from None
    return value


def _unit_words(unit: str) -> str:
    if unit in ("", "1"):
        return ""
    return " degrees" if unit == "deg" else f" {unit}"


def _check_range(name: str, f: Field, x: float, value: object) -> None:
    """The field's rule (sign or interval), then its plausible range."""
    rule = f.rule
    if rule is not None and not rule.holds(x):
        if rule.lo is not None and rule.hi is not None:
            kind = "open interval" if rule.lo_open and rule.hi_open else "interval"
            raise ParameterError(
                f"{name} must lie in the {kind} {rule.text()[3:]}{_unit_words(f.unit)}: "
                f"got {show(value)}"
            )
        raise ParameterError(f"{name} must be {rule.text()}: got {show(value)}")
    _check_limits(name, f.limits, f.unit, x, value)


def _check_limits(name: str, limits: Rule | None, unit: str, x: float, value: object) -> None:
    if limits is not None and not limits.holds(x):
        raise ParameterError(
            f"{name} must lie in the plausible range {limits.text()[3:]}{_unit_words(unit)}: "
            f"got {show(value)}"
        )


def _check_field(f: Field, value: object) -> None:
    name, kind = f.name, f.kind
    if kind == "int":
        if not _is_int(value):
            raise ParameterError(f"{name} must be an integer: {_got(value)}")
        # compared as an exact integer: a huge one never becomes a float
        _check_range(name, f, int(value), value)  # type: ignore[call-overload]
    elif kind == "float":
        _check_range(name, f, _check_number(name, value), value)
    elif kind == "str":
        text = _check_text(name, value)
        if name in CHOICES and text not in CHOICES[name]:
            allowed = ", ".join(repr(c) for c in CHOICES[name])
            raise ParameterError(f"{name} must be one of {allowed}: got {show(value)}")
    elif kind == "floats":
        if not isinstance(value, tuple):
            raise ParameterError(f"{name} must be a tuple of numbers: {_got(value)}")
        if len(value) > MAX_HARMONICS:
            raise ParameterError(
                f"{name} must list at most {MAX_HARMONICS} harmonics: got {len(value)}"
            )
        for i, item in enumerate(value):
            x = _check_number(f"{name}[{i}]", item)
            _check_limits(f"{name}[{i}]", f.limits, f.unit, x, item)
    else:  # pragma: no cover - the registry only holds the kinds above
        raise AssertionError(kind)


def _check_stiffness_positive(gs: Any, mesh: str) -> None:
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


def _value(gs: Any, dotted: str) -> Any:
    table, attr = dotted.split(".", 1)
    return getattr(getattr(gs, table), attr)


def _check_within_module(gs: Any) -> None:
    """Clearances, transmission errors and eccentricities, in metres, are at most one module."""
    module = float(gs.geometry.module)
    bc = float(gs.clearance.characteristic_length)
    for dotted, units_field in MODULE_BOUNDED.items():
        value = float(_value(gs, dotted))
        if units_field is not None and _value(gs, units_field) == "dimensionless":
            metres = value * bc
            shown = f"{value!r} × b_c = {value!r} × {bc!r} m = {metres!r} m"
        else:
            metres, shown = value, f"{value!r} m"
        if metres > module:
            raise ParameterError(
                f"{dotted} must be <= geometry.module = {module!r} m (one module, the addendum "
                "of a standard tooth: a larger clearance, transmission error or eccentricity "
                f"would disengage the teeth): got {shown}"
            )


def _derived(gs: Any) -> list[tuple[str, Callable[[], float], bool]]:
    """(symbol = formula, value, must be positive) of every derived quantity (MODEL.md §1, §4,
    §7); the values are computed lazily so that one failing formula is reported by name."""
    st, tq = gs.stiffness, gs.torque

    def me() -> float:
        return float(gs.equivalent_mass_mesh)

    def bar(x: float) -> float:
        return x / gs.clearance.characteristic_length

    return [
        ("r_s = m z_s / 2", lambda: gs.radius_sun, True),
        ("r_p = m z_p / 2", lambda: gs.radius_planet, True),
        ("r_r = m z_r / 2", lambda: gs.radius_ring, True),
        ("r_bs = r_s cos α_s", lambda: gs.base_radius_sun, True),
        ("r_bp = r_p cos α_s", lambda: gs.base_radius_planet, True),
        ("m_s* = J_s / r_bs²", lambda: gs.equivalent_mass_sun, True),
        ("m_p* = J_p / r_bp²", lambda: gs.equivalent_mass_planet, True),
        ("m_c* = J_c / r_c² + N m_p", lambda: gs.equivalent_mass_carrier, True),
        ("m_e = m_s* m_p* / (m_s* + m_p*)", me, True),
        ("ω_n = √(k_m,sp / m_e)", lambda: gs.omega_n, True),
        ("c_sp = 2 ξ_sp √(k_m,sp m_e)", lambda: gs.damping_sun_planet, False),
        ("c_rp = 2 ξ_rp √(k_m,rp m_p*)", lambda: gs.damping_planet_ring, False),
        ("c_s = 2 ξ_s √(k_s m_s)", lambda: gs.damping_sun_bearing, False),
        ("T_L = T_D r_c (cos α_s + cos α_r) / r_bs", lambda: gs.output_torque, False),
        ("μ_s = m_s / m_e", lambda: gs.mass.sun / me(), True),
        ("μ_s* = m_s* / m_e", lambda: gs.equivalent_mass_sun / me(), True),
        ("μ_p* = m_p* / m_e", lambda: gs.equivalent_mass_planet / me(), True),
        ("μ_c* = m_c* / m_e", lambda: gs.equivalent_mass_carrier / me(), True),
        ("κ_b = k_s / k_m,sp", lambda: st.sun_bearing / st.sun_planet_mean, True),
        ("k_m,rp / k_m,sp", lambda: st.planet_ring_mean / st.sun_planet_mean, True),
        (
            "T̄_D = T_D / (r_bs k_m,sp b_c)",
            lambda: bar(tq.input / (gs.base_radius_sun * st.sun_planet_mean)),
            False,
        ),
        (
            "T̄_L = T_L / (r_c k_m,sp b_c)",
            lambda: bar(gs.output_torque / (gs.radius_carrier * st.sun_planet_mean)),
            False,
        ),
        ("b̄_sp, b̄_rp", lambda: max(gs.backlash_bar()), False),
        ("b̄_s", lambda: gs.sun_bearing_clearance_bar(), False),
        ("Ā_sp = A_sp / b_c", lambda: bar(gs.transmission_error.sun_planet), False),
        ("Ā_rp = A_rp / b_c", lambda: bar(gs.transmission_error.planet_ring), False),
        ("Ē = max(E_s, E_p, E_r) / b_c", lambda: bar(max(_eccentricities(gs))), False),
        ("φ_sp, φ_rp (mesh phases)", lambda: _largest_phase(gs), False),
    ]


def _eccentricities(gs: Any) -> tuple[float, float, float]:
    e = gs.eccentricity
    return e.sun, e.planet, e.ring


def _largest_phase(gs: Any) -> float:
    sp, rp = gs.mesh_phases()
    return max((abs(p) for p in (*sp, *rp)), default=0.0)


def _check_derived(gs: Any) -> None:
    """Every derived quantity is finite, and positive where the model divides by it."""
    for label, compute, positive in _derived(gs):
        try:
            x = float(compute())
        except (ArithmeticError, ValueError):
            x = math.nan
        if not math.isfinite(x) or (positive and not x > 0.0):
            rule = "finite and > 0" if positive else "finite"
            raise ParameterError(
                f"derived quantity {label} must be {rule}: got {x!r}; the gear set's values "
                "are outside what the model can represent (docs/gearset-rules.md)"
            )


def validate(gs: Any) -> None:
    """Check every field of a gear set and the relations between them.

    Parameters
    ----------
    gs : GearSet
        The gear set to check (``GearSet.__post_init__`` calls this on every construction).

    Raises
    ------
    TypeError
        If ``gs`` has not the attributes of a gear set.
    ParameterError
        At the first violated rule, with a message naming the dotted parameter, the rule and
        the value. The checks run in this order (symbols of MODEL.md; the plausible ranges and
        their reasons are in ``docs/gearset-rules.md``):

        1. records: each nested field is its record class; ``name``, ``description`` strings
           of valid Unicode;
        2. per field, in registry order: type (integer, number, string or tuple of numbers;
           ``bool`` is never a number, integral floats such as ``34.0`` are not integers,
           ``int`` is accepted for floats), finiteness, the rule the model needs, then the
           plausible range:

           - z_s, z_p, z_r integers > 0 and <= 10000; N integer >= 1 and <= 100 (one planet
             is allowed: the model holds for any N, e.g. a single-planet test rig);
           - module m > 0, in [1e-6, 1] m (below MEMS gears to ten times the largest
             mill-drive modules);
           - 0 < α_s, α_r < 45 degrees;
           - masses m_s, m_p > 0, in [1e-12, 1e6] kg; inertias J_s, J_p, J_c > 0, in
             [1e-24, 1e6] kg m²;
           - k_m,sp, k_m,rp, k_s > 0, in [1e-3, 1e13] N/m; k_a >= 0 and <= 1e13 N/m;
             harmonics: at most 64 finite numbers of any sign, each |k_h| <= 1e13 N/m;
           - damping ratios ξ >= 0 and <= 10;
           - T_D any sign, |T_D| <= 1e9 N m; ``torque.reference_omega`` Ω_ref > 0, in
             [1e-6, 1e6];
           - b_c > 0, in [1e-9, 1] m; half clearances b_sp, b_rp, b_s, transmission-error
             amplitudes A and eccentricities E >= 0;
           - phases (degrees) and γ_rs (mesh cycles) of any sign, |value| <= 1e6;
           - ``torque.mode`` in {constant_torque, constant_power}; ``backlash.units`` and
             ``clearance.units`` in {dimensionless, m}; ``mesh_phasing.model`` in
             {parker, in_phase};
        3. relations: z_r = z_s + 2 z_p (standard gears); (z_s + z_r)/N an integer (equally
           spaced planets); N ≥ 2 planets clear each other, (z_s + z_p)·sin(π/N) > z_p + 2
           (centre spacing beyond the tip diameter, in modules); k_a + Σ_h |k_h| < k_m for
           each mesh (positive mesh stiffness);
           b_sp, b_rp, b_s, A_sp, A_rp, E_s, E_p, E_r, converted to metres (× b_c when their
           ``units`` is ``dimensionless``), at most one module m — the addendum of a standard
           tooth: a larger clearance or error disengages the teeth;
        4. every derived quantity — radii, equivalent masses, m_e, ω_n, damping coefficients,
           T_L and the dimensionless groups μ, κ, T̄_D, T̄_L, b̄, Ā, Ē, mesh phases — is finite,
           and positive where the model divides by it. The ranges above guarantee this; the
           check guards against a rule relaxed later.
    """
    if not all(hasattr(gs, t) for t in (*RECORD_CLASSES, *META)):
        raise TypeError(f"validate() expects a GearSet: got {type(gs).__name__}")
    for table, cls in RECORD_CLASSES.items():
        record = getattr(gs, table)
        if not isinstance(record, cls):
            raise ParameterError(f"{table} must be a {cls.__name__} record: {_got(record)}")
    _check_text("name", gs.name)
    _check_text("description", gs.description)

    for f in FIELDS.values():
        _check_field(f, _value(gs, f.name))

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
    _check_planets_fit(gs)
    _check_stiffness_positive(gs, "sun_planet")
    _check_stiffness_positive(gs, "planet_ring")
    _check_within_module(gs)
    _check_derived(gs)


def _check_planets_fit(gs: Any) -> None:
    """N ≥ 2 equally spaced planets must clear each other: their centres, on the circle of
    radius a = m (z_s + z_p)/2, lie 2a·sin(π/N) apart, which must exceed a planet's tip
    diameter m (z_p + 2) (standard addendum m)."""
    z, n, m = gs.teeth, gs.geometry.planets, gs.geometry.module
    if n < 2:
        return
    apart = (z.sun + z.planet) * math.sin(math.pi / n)
    tip = z.planet + 2
    if apart <= tip:
        raise ParameterError(
            f"geometry.planets = {n}: the planets do not fit around the sun: neighbouring "
            f"planet centres are (teeth.sun + teeth.planet)·m·sin(π/N) = {apart:.4g} modules "
            f"= {apart * m * 1e3:.4g} mm apart, not more than a planet's tip diameter "
            f"(teeth.planet + 2)·m = {tip} modules = {tip * m * 1e3:.4g} mm (teeth.sun = "
            f"{z.sun}, teeth.planet = {z.planet}); use fewer planets or other teeth"
        )


#: Analyses that sample the response at the mesh-period section t_k = kT (case-insensitive;
#: ``-`` and spaces count as ``_``, accents are ignored).
POINCARE_ANALYSES: Final = frozenset(
    {"poincare", "poincare_map", "bifurcation", "periodicity", "period", "classify", "map"}
)


def warn_if_clearance_in_metres(gs: Any) -> list[str]:
    """Warn for every clearance given in units of b_c (its ``units`` field ``dimensionless``)
    whose value lies in (0, :data:`SMALL_CLEARANCE_BAR`): a value in metres given for a
    parameter in units of b_c (``--set backlash.sun_planet=60e-6`` on a gear set in b_c means
    6×10⁻⁵ b_c, about a nanometre) is the likely mistake, and the warning says so, with the
    value in units of b_c that the metres would be. Returns the names warned about."""
    bc = gs.clearance.characteristic_length
    warned = []
    for name, units_field in MODULE_BOUNDED.items():
        if units_field is None or _value(gs, units_field) != "dimensionless":
            continue
        v = float(_value(gs, name))
        if not 0.0 < v < SMALL_CLEARANCE_BAR:
            continue
        warned.append(name)
        warnings.warn(
            f"{name} = {v:g} is in units of b_c ({units_field} = 'dimensionless'), so it is "
            f"{v * bc * 1e9:.3g} nm (b_c = {bc * 1e6:.4g} µm): is it a value in metres given "
            f"for a parameter in units of b_c? {v:g} m is {v / bc:.4g} b_c (give {name} = "
            f"{v / bc:.4g}), or set {units_field} = 'm' to give clearances in metres",
            UserWarning,
            stacklevel=4,  # the code that built the gear set (through GearSet.__init__)
        )
    return warned


def _normalise_analysis(analysis: str) -> str:
    text = unicodedata.normalize("NFKD", analysis).encode("ascii", "ignore").decode("ascii")
    return text.strip().lower().replace("-", "_").replace(" ", "_")


def warn_if_eccentric(gs: Any, analysis: str) -> bool:
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

    Raises
    ------
    ParameterError
        If ``analysis`` is not a string.
    """
    if not isinstance(analysis, str):
        raise ParameterError(f"analysis must be a string: {_got(analysis)}")
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
