"""From a target and parameter values by dotted name to a :class:`System`: :func:`resolve`.

A *target* is what a user simulates, sweeps or continues: a
:class:`~gearchaos.gearset.GearSet` (parameters: the dotted gear-set names of
:mod:`gearchaos.gearset.schema`, the alias ``xi``) or a :class:`System` (a reference system or a
model built by hand; parameters: the fields of its model, ``zeta``, ``f_alt`` …). Both take
``omega``, the dimensionless forcing frequency Ω, or instead one of the speeds that set it
through a gear set (``sun_rpm``, the sun speed in rpm, and ``mesh_hz``, the mesh frequency in
Hz: :data:`~gearchaos.gearset.schema.SPEEDS`). This module is the one place that applies such
names: it splits Ω (or the speed, converted by the gear set's
:meth:`~gearchaos.gearset.GearSet.omega_at`) from the rest, applies the rest to the target, and
refuses unknown names with the closest valid one.
"""

from __future__ import annotations

import dataclasses
import difflib
import functools
import re
from collections.abc import Mapping
from typing import Any

from .._checks import check_real
from ..errors import ParameterError
from ..gearset import GearSet
from ..gearset.schema import ALIASES, EXTRA, FIELDS, SPEEDS
from .contract import Capabilities
from .planetary import PlanetaryModel
from .system import System

__all__ = [
    "DEFAULT_OMEGA",
    "MEMBER_WORD",
    "OMEGA",
    "SPEEDS",
    "Target",
    "check_names",
    "check_one_operating_point",
    "member_word",
    "model_for",
    "operating_omega",
    "parameter_names",
    "resolve",
    "scale_attrs",
    "speed_gearset",
    "speed_names",
    "speeds_at",
    "split_omega",
]

#: What a user simulates, sweeps or continues: a gear set (which builds a planetary model) or a
#: :class:`System` of any model.
Target = GearSet | System

#: The name of the dimensionless forcing frequency Ω = ω/ω_n among the parameters.
OMEGA = "omega"
#: Ω of the command line when it is neither swept nor set (the README's quick-start point).
DEFAULT_OMEGA = 1.5

#: Fields of a model dataclass that are members of the model contract (its layout, scales,
#: source gear set …), not parameters.
_LAYOUT_FIELDS = frozenset(f.name for f in dataclasses.fields(Capabilities))


def _check_target(target: Any) -> None:
    if not isinstance(target, GearSet | System):
        raise ParameterError(f"target must be a GearSet or a System: got {type(target).__name__}")


def parameter_names(target: Any) -> list[str]:
    """The names :func:`resolve` accepts for ``target`` (Ω and the speeds included: a target
    without a gear set refuses a speed when it is used, with the reason)."""
    _check_target(target)
    if isinstance(target, GearSet):
        return [*FIELDS, *ALIASES, OMEGA, *SPEEDS]
    model = target.model
    if not dataclasses.is_dataclass(model):
        return [OMEGA, *SPEEDS]
    own = [f.name for f in dataclasses.fields(model) if f.name not in _LAYOUT_FIELDS]
    return [*own, OMEGA, *(s for s in SPEEDS if s not in own)]


def check_names(target: Any, names: Any) -> None:
    """Refuse names ``target`` does not have, suggesting the closest valid one."""
    valid = parameter_names(target)
    for name in names:
        if not isinstance(name, str):
            raise ParameterError(f"parameter names must be strings: got {name!r}")
        if name not in valid:
            close = difflib.get_close_matches(name, sorted(valid), n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ParameterError(f"unknown parameter {name!r}{hint}")


def check_omega(value: Any) -> float:
    """Ω as a float: a finite number > 0 inside its plausible range (the registry's); a value
    outside is refused with a hint at the speeds (an rpm typed as Ω is the likely mistake)."""
    omega = check_real(OMEGA, value, lo=0.0, lo_open=True)
    limits = EXTRA[OMEGA].limits
    if limits is not None and not limits.holds(omega):
        raise ParameterError(
            f"omega must lie in the plausible range {limits.text()[3:]}: got {omega:g}; Ω = "
            f"ω/ω_n is dimensionless (a gear set's sun speed in rpm is sun_rpm={omega:g}, "
            f"its mesh frequency in Hz mesh_hz={omega:g}: --set sun_rpm=...)",
            name=OMEGA,
        )
    return omega


def split_omega(values: Mapping[str, Any]) -> tuple[float | None, dict[str, Any]]:
    """(Ω or None, the other values); Ω is checked by :func:`check_omega`. Speeds are left
    among the other values (:func:`operating_omega` converts them)."""
    rest = dict(values)
    if OMEGA not in rest:
        return None, rest
    return check_omega(rest.pop(OMEGA)), rest


def speed_names(target: Any, names: Any) -> list[str]:
    """The speeds among the parameter ``names`` of ``target`` (a model's own field of the same
    name is no speed)."""
    if isinstance(target, System) and dataclasses.is_dataclass(target.model):
        own = {f.name for f in dataclasses.fields(target.model)}
        return [n for n in names if n in SPEEDS and n not in own]
    return [n for n in names if n in SPEEDS]


def check_one_operating_point(target: Any, names: Any) -> None:
    """Refuse Ω and a speed, or two speeds, given together (each sets Ω)."""
    given = [n for n in names if n == OMEGA] + speed_names(target, names)
    if len(given) > 1:
        raise ParameterError(
            f"{' and '.join(given)} each set Ω (the operating point): give one of them",
            name=given[1],
        )


def speed_gearset(target: Any, name: str, changes: Mapping[str, Any] | None = None) -> GearSet:
    """The gear set through which the speed ``name`` sets Ω on ``target`` with ``changes``
    (no Ω): the target itself, evolved, or the gear set a planetary model was built from. A
    model without one (a reference system, your own model) has no physical scales: refused,
    naming the speed."""
    model = model_for(target, changes or {})
    gearset = Capabilities.of(model).gearset
    if gearset is not None:
        return gearset
    raise ParameterError(
        f"{name} sets Ω through a gear set's ω_n and tooth numbers, but {model.name} is not "
        "built from a gear set (it has no physical scales): give omega (Ω = ω/ω_n) instead",
        name=name,
    )


def _speed_omega(target: Any, name: str, value: Any, changes: Mapping[str, Any]) -> float:
    """Ω of the speed ``name`` = ``value`` on ``target`` with ``changes``, checked."""
    unit = EXTRA[name].unit
    v = check_real(name, value, lo=0.0, lo_open=True)
    omega = speed_gearset(target, name, changes).omega_at(name, v)
    limits = EXTRA[OMEGA].limits
    if limits is not None and not limits.holds(omega):
        raise ParameterError(
            f"{name} = {v:g} {unit} is Ω = {omega:.4g} for this gear set, outside Ω's "
            f"plausible range {limits.text()[3:]}",
            name=name,
        )
    return omega


def operating_omega(target: Any, values: Mapping[str, Any]) -> tuple[float | None, dict[str, Any]]:
    """(Ω or None, the other values) of ``values`` on ``target``: Ω given as ``omega`` or as a
    speed (``sun_rpm``, ``mesh_hz``), which is converted through the gear set with the other
    values applied (:func:`speed_gearset`, :meth:`~gearchaos.gearset.GearSet.omega_at`).
    More than one of them is refused."""
    check_one_operating_point(target, values)
    speeds = speed_names(target, values)
    if not speeds:
        return split_omega(values)
    rest = dict(values)
    value = rest.pop(speeds[0])
    return _speed_omega(target, speeds[0], value, rest), rest


def speeds_at(model: Any, omega: float) -> dict[str, float]:
    """The speeds (``sun_rpm``, ``mesh_hz``) at Ω of a model built from a gear set; ``{}``
    for a model without one. Tables and figures show them beside Ω."""
    gearset = Capabilities.of(model).gearset
    if gearset is not None:
        return {name: gearset.speed(name, float(omega)) for name in SPEEDS}
    return {}


def _gearset_model(gs: GearSet, changes: tuple[tuple[str, str, Any], ...]) -> Any:
    """The planetary model of ``gs`` evolved by ``changes`` ((name, type name, value), the
    cache's key; validated)."""
    return PlanetaryModel.from_gearset(gs.evolve({k: v for k, _, v in changes}) if changes else gs)


#: The models of the last gear sets and changes asked for: a continuation or a Newton
#: iteration resolves the same few points (Ω apart) thousands of times, and validating and
#: non-dimensionalising a gear set costs far more than a short integration. Both are
#: immutable, so a cached model is the one a fresh call would build.
_cached_gearset_model = functools.lru_cache(maxsize=256)(_gearset_model)


def model_for(target: Any, changes: Mapping[str, Any]) -> Any:
    """The model of ``target`` with ``changes`` (no Ω) applied.

    A gear set is evolved by dotted name and non-dimensionalised; a system's model gets the
    changed fields. Unknown names are refused with a suggestion.
    """
    _check_target(target)
    if isinstance(target, GearSet):
        # the values' types are part of the key: True == 1, but a bool is never a count
        key = tuple(sorted((k, type(v).__name__, v) for k, v in changes.items()))
        try:
            hash(key)
        except TypeError:  # an unhashable value (a list of harmonics): no cache
            return _gearset_model(target, key)
        return _cached_gearset_model(target, key)
    if not changes:
        return target.model
    check_names(target, changes)
    return dataclasses.replace(target.model, **changes)


def resolve(
    target: Any, values: Mapping[str, Any] | None = None, *, default_omega: float | None = None
) -> System:
    """The :class:`System` of ``target`` with parameter ``values`` by dotted name.

    Parameters
    ----------
    target
        A :class:`~gearchaos.gearset.GearSet` or a :class:`System`.
    values
        Parameters by name: ``omega`` (Ω) or a speed that sets it (``sun_rpm``, ``mesh_hz``:
        a gear set's, through its ω_n and tooth numbers), gear-set names
        (``backlash.sun_planet``, ``xi``) or model fields of a system (``zeta``).
    default_omega
        Ω when ``values`` has none: a gear set needs one (else :class:`ParameterError`); a
        system keeps its own Ω when neither is given.
    """
    if values is not None and not isinstance(values, Mapping):
        raise ParameterError(
            "parameter values must be a mapping of dotted names to values "
            f"(e.g. {{'omega': 1.5}}): got {type(values).__name__}"
        )
    if default_omega is not None:
        default_omega = check_omega(default_omega)
    omega, changes = operating_omega(target, values or {})
    if omega is None:
        if default_omega is not None:
            omega = check_omega(default_omega)
        elif isinstance(target, System):
            omega = target.omega
        else:
            _check_target(target)
            raise ParameterError(
                "omega is required for a gear set: sweep it, or fix it "
                "(omega=1.5 in Python, --set omega=1.5 on the command line)"
            )
    if isinstance(target, System) and not changes:
        return target if omega == target.omega else target.at(omega)
    return System(model_for(target, changes), omega)


def scale_attrs(model: Any) -> dict[str, float | str]:
    """A model's scales and clearances as store attributes: ``omega_n_rad_s`` (ω_n),
    ``characteristic_length_m`` (b_c) where the model has physical scales,
    ``clearance_<name>`` for each of its clearances, ``period_factor`` where its forcing
    period is not 2π/Ω, and ``member_name`` (a word: :func:`member_word`) where a member of
    its variable groups is not a planet (the stores' member dimensions are named ``planet``
    and ``planet_all`` for every model; tables name their columns by this word)."""
    caps = Capabilities.of(model)
    a: dict[str, float | str] = {}
    if caps.period_factor != 1.0:
        a["period_factor"] = caps.period_factor
    if caps.member_name != "planet":
        a["member_name"] = member_word(caps.member_name)
    if caps.scales is not None:
        a["omega_n_rad_s"] = float(caps.scales.omega_n)
        a["characteristic_length_m"] = float(caps.scales.length)
    for k, v in caps.clearances.items():
        a[f"clearance_{k}"] = float(v)
    return a


#: A member word as a store records it (and a table's column names use it).
MEMBER_WORD = re.compile(r"[A-Za-z][A-Za-z0-9]{0,31}")


def member_word(name: str) -> str:
    """``name`` as a word for column names: its letters and digits (``planet gear`` →
    ``planetgear``), at most 32, starting with a letter; ``member`` when none is left."""
    word = re.sub(r"[^A-Za-z0-9]", "", str(name)).lstrip("0123456789")[:32]
    return word if MEMBER_WORD.fullmatch(word) else "member"
