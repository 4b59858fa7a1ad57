"""Sweep specification: axes addressed by stable dotted names.

An axis is a dotted parameter name and its values: ``omega`` (the dimensionless mesh frequency
Ω), ``xi`` (all three damping ratios), any gear-set field (``backlash.sun_planet``,
``backlash.planet_ring``, ``clearance.sun_bearing``, ``torque.input``,
``transmission_error.sun_planet`` …; see :func:`gearchaos.gearset.io.field_names`) or, for a
reference system, any field of its model (``zeta``, ``f_alt`` …).

Value syntax (CLI and Python alike):

* ``start:stop:count`` — ``count`` linearly spaced values including both ends;
* ``log:start:stop:count`` — logarithmically spaced;
* ``a,b,c`` — an explicit list.

A :class:`SweepSpec` holds up to two varied axes (``vary``; two make a 2-D map), an optional
``family`` axis (one diagram per value, like the seed's panels a–d), fixed overrides
(``fixed``), the observed variables and planets, the initial-condition protocol and the solver
settings. It serialises to TOML (stored in every sweep store as ``sweep_toml``) so a store can
be checked against the command that would resume it.
"""

from __future__ import annotations

import difflib
import math
import numbers
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from .._checks import check_bool, check_choice, check_int
from ..errors import ParameterError, StoreError
from ..integrate.settings import SolverSettings, check_keyword, check_params, renamed_keyword
from ..model.target import OMEGA, Target, check_omega
from .execute import EXECUTION_OPTIONS

__all__ = ["Axis", "SweepSpec", "parse_axis", "parse_values"]

INITIAL_CONDITIONS = ("fresh", "continuation")
DIRECTIONS = ("up", "down", "both")
DEFAULT_OBSERVE = ("delta_sp", "delta_sp_dot")


#: Most values one axis may have (a 2-D map of 10⁶ × 10⁶ points is refused by memory).
MAX_AXIS_VALUES = 10**6


def _syntax(name: str, text: Any) -> ParameterError:
    return ParameterError(
        f"{name} must be start:stop:count, log:start:stop:count or a,b,c: got {text!r}"
    )


def _count(name: str, raw: str, text: str) -> int:
    try:
        n = int(raw)
    except ValueError:
        raise _syntax(name, text) from None
    if not 1 <= n <= MAX_AXIS_VALUES:
        raise ParameterError(
            f"{name}: the count must be an integer in [1, {MAX_AXIS_VALUES}]: got {text!r}"
        )
    return n


def _finite_bounds(name: str, lo: float, hi: float, text: str) -> None:
    """A range's bounds must be finite, whatever the count (``log:1:inf:1`` is one value, 1,
    but no meaningful spec)."""
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise ParameterError(f"{name}: the start and stop of a range must be finite: got {text!r}")


def parse_values(name: str, text: str | float | Sequence[float] | np.ndarray) -> tuple[float, ...]:
    """Values of an axis from ``start:stop:count``, ``log:start:stop:count``, ``a,b,c``, a
    number or a one-dimensional sequence. Errors name the axis, the rule and the value."""
    if isinstance(text, str):
        t = text.strip()
        try:
            if t.startswith("log:"):
                parts = t[4:].split(":")
                if len(parts) != 3:
                    raise _syntax(name, text)
                lo, hi, cnt = float(parts[0]), float(parts[1]), _count(name, parts[2], text)
                _finite_bounds(name, lo, hi, text)
                if not (lo > 0 and hi > 0):
                    raise ParameterError(f"{name}: log spacing needs positive bounds: got {text!r}")
                vals = np.geomspace(lo, hi, cnt)
            elif ":" in t:
                parts = t.split(":")
                if len(parts) != 3:
                    raise _syntax(name, text)
                a, b = float(parts[0]), float(parts[1])
                _finite_bounds(name, a, b, text)
                vals = np.linspace(a, b, _count(name, parts[2], text))
            else:
                items = t.split(",")
                if len(items) > 1 and not all(v.strip() for v in items):
                    raise ParameterError(f"{name}: an empty value in the list: got {text!r}")
                vals = np.array([float(v) for v in items if v.strip()])
        except ValueError as exc:
            if isinstance(exc, ParameterError):
                raise
            raise _syntax(name, text) from None
    elif isinstance(text, bool) or text is None:
        raise _syntax(name, text)
    elif isinstance(text, int | float | np.floating | np.integer):
        try:
            vals = np.array([float(text)])
        except OverflowError:
            raise ParameterError(f"{name} values must be finite: got {_shown(text)}") from None
    else:
        try:
            if isinstance(text, list | tuple) and any(
                isinstance(v, bool | np.bool_) or not isinstance(v, numbers.Real) for v in text
            ):
                raise TypeError("not numbers")
            raw = np.asarray(text)
            if raw.dtype.kind not in "fiu":  # complex, bool, text, objects: not values
                raise TypeError(raw.dtype)
            vals = raw.astype(float)
        except (TypeError, ValueError, OverflowError):
            raise _syntax(name, _shown(text)) from None
        if vals.ndim != 1:
            raise ParameterError(
                f"{name} values must be a one-dimensional sequence: got an array of shape "
                f"{vals.shape}"
            )
        if vals.size > MAX_AXIS_VALUES:
            raise ParameterError(
                f"{name} may have at most {MAX_AXIS_VALUES} values: got {vals.size}"
            )
    if vals.size < 1:
        raise ParameterError(f"{name} needs at least one value: got {text!r}")
    if not np.all(np.isfinite(vals)):
        raise ParameterError(f"{name} values must be finite: got {vals.tolist()}")
    return tuple(float(v) for v in vals)


def _shown(value: Any, limit: int = 60) -> Any:
    """A value as shown in messages: long reprs shortened."""
    r = repr(value)
    return value if len(r) <= limit else f"{r[: limit - 3]}..."


@dataclass(frozen=True)
class Axis:
    """A swept parameter: dotted ``name`` and its ``values``."""

    name: str
    values: tuple[float, ...]

    def __post_init__(self) -> None:
        if not self.name or not isinstance(self.name, str):
            raise ParameterError(f"axis name must be a non-empty string: got {self.name!r}")
        if len(self.values) < 1:
            raise ParameterError(f"axis {self.name} needs at least one value")

    def __len__(self) -> int:
        return len(self.values)


def parse_axis(item: str | tuple[str, Any] | Axis) -> Axis:
    """``"omega=0.1:4:800"`` or ``("omega", values)`` or an :class:`Axis`."""
    if isinstance(item, Axis):
        return item
    if isinstance(item, str):
        if "=" not in item:
            raise ParameterError(
                f"an axis must be NAME=VALUES (e.g. omega=0.1:4:800): got {item!r}"
            )
        name, _, text = item.partition("=")
        name = name.strip()
        if not name:
            raise ParameterError(f"an axis must be NAME=VALUES: the name is missing in {item!r}")
        return Axis(name, parse_values(name, text))
    if not isinstance(item, tuple | list) or len(item) != 2 or not isinstance(item[0], str):
        raise ParameterError(
            "an axis must be NAME=VALUES, a (name, values) pair or a mapping "
            f"{{name: values}}: got {_shown(item)}"
        )
    name, vals = item
    return Axis(name, parse_values(name, vals))


def _axes(items: Any, what: str = "vary") -> tuple[Axis, ...]:
    if items is None:
        return ()
    if isinstance(items, Mapping):
        return tuple(parse_axis((k, v)) for k, v in items.items())
    if isinstance(items, str | Axis):
        return (parse_axis(items),)
    if not isinstance(items, list | tuple):
        raise ParameterError(
            f"{what} must be NAME=VALUES (e.g. omega=0.1:4:800), a list of them or a mapping "
            f"{{name: values}}: got {_shown(items)} ({type(items).__name__})"
        )
    return tuple(parse_axis(i) for i in items)


#: Solver settings of a sweep when none are given: the seed's 100 + 100 periods.
SWEEP_SOLVER = SolverSettings(transient_periods=100, periods=100)

#: Solver settings of a frequency-response sweep when none are given: 100 transient and 50
#: recorded periods, 32 samples per period for the RMS values.
RESPONSE_SOLVER = SolverSettings(transient_periods=100, periods=50, samples_per_period=32)

#: The options of :meth:`SweepSpec.build` besides the axes and the fixed values.
SPEC_OPTIONS = (
    "observe",
    "planets",
    "initial_conditions",
    "direction",
    "lyapunov",
    "orbits",
    "verdicts",
    "response",
)


def sweep_keywords(
    door: str, target: Target, keywords: Mapping[str, Any], params: Any
) -> tuple[dict[str, Any], dict[str, Any]]:
    """A sweep door's keywords in the front doors' vocabulary
    (:func:`~gearchaos.integrate.settings.split_keywords`): the parameter values — ``params``
    and every keyword that is neither a sweep option nor a solver setting, by name — and the
    sweep options and settings. A name that is none of these is refused with the closest
    (:func:`check_keyword`)."""
    known = {*SPEC_OPTIONS, *SolverSettings.field_names()}
    values = dict(check_params("params", params) or {})
    options: dict[str, Any] = {}
    for key, value in keywords.items():
        if key in known:
            options[key] = value
            continue
        check_keyword(door, target, key, {*known, *EXECUTION_OPTIONS})
        if key in values:
            raise ParameterError(f"parameter {key!r} is given twice (keyword and params)", name=key)
        values[key] = value
    return values, options


def _names(what: str, items: Any) -> tuple[str, ...]:
    if isinstance(items, str):
        items = (items,)
    try:
        names = tuple(items)
    except TypeError:
        raise ParameterError(f"{what} must be a list of variable names: got {items!r}") from None
    return names


def _planets(items: Any) -> tuple[int, ...]:
    if isinstance(items, str | bytes) or not hasattr(items, "__iter__"):
        raise ParameterError(
            f"planets must be a list of planet numbers such as [1, 2]: got {items!r}"
        )
    return tuple(items)


@dataclass(frozen=True)
class SweepSpec:
    """Everything that defines a sweep's numbers (not how it is executed).

    Parameters
    ----------
    vary
        One or two axes (two give a 2-D map).
    family
        Optional family axis: one diagram per value; becomes the first dimension.
    fixed
        Fixed overrides by dotted name (``omega`` too, when it is not swept).
    observe
        Variables of :func:`gearchaos.simulate`'s dataset whose section values are stored.
    planets
        Observed planets (1-based) of the per-planet variables.
    initial_conditions
        ``fresh`` (zero state at every point, the seed's protocol) or ``continuation`` (each
        point starts from the previous point's final state along the first varied axis).
    direction
        For continuation: ``up``, ``down`` or ``both`` (an extra ``direction`` dimension).
    solver
        Transient and recorded periods, tolerances (one sample per period: the section).
    lyapunov
        Also integrate the largest Lyapunov exponent of every point.
    orbits
        Confirm every label nT (n ≤ 8) by a converged period-n orbit shot from the point's
        final state, and store its residual, largest multiplier modulus and a status flag
        (:mod:`gearchaos.sweep.orbits`).
    verdicts
        Decide every point's motion with the verdict (:mod:`gearchaos.dynamics.verdict.decide`):
        nT confirmed by shooting, chaos and QP by λ₁ ± its error, transients finished by
        extending the run (the stored section record is then the finished one). False
        labels the points from their records alone (faster, heuristic).
    response
        Also store the frequency-response quantities of every point
        (:mod:`gearchaos.model.response`): RMS and peak contact force of every mesh, dynamic
        load factor and RMS dynamic transmission error. Only a response sweep may record more
        than one sample per period (the RMS values come from the samples; the sections are
        every ``samples_per_period``-th sample).
    """

    # the fields after ``fixed`` are written to TOML in this order (:meth:`to_toml`)
    vary: tuple[Axis, ...]
    family: Axis | None = None
    fixed: tuple[tuple[str, Any], ...] = ()
    initial_conditions: str = "fresh"
    direction: str = "up"
    solver: SolverSettings = SWEEP_SOLVER
    lyapunov: bool = False
    observe: tuple[str, ...] = DEFAULT_OBSERVE
    planets: tuple[int, ...] = (1,)
    orbits: bool = False
    verdicts: bool = True
    response: bool = False

    def __post_init__(self) -> None:
        if not 1 <= len(self.vary) <= 2:
            raise ParameterError(
                f"vary must have one or two axes (two make a 2-D map): got {len(self.vary)}"
            )
        names = [a.name for a in self.axes]
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise ParameterError(f"each parameter may be swept once: {sorted(dup)} repeated")
        for k, v in self.fixed:
            if k in names:
                raise ParameterError(f"{k} is both swept and fixed (--set); choose one")
            if k == OMEGA:
                check_omega(v)
        for a in self.axes:
            if a.name == OMEGA:
                for v in a.values:
                    check_omega(v)
        check_choice("initial_conditions", self.initial_conditions, INITIAL_CONDITIONS)
        check_choice("direction", self.direction, DIRECTIONS)
        if self.direction != "up" and self.initial_conditions == "fresh":
            raise ParameterError(
                f"direction={self.direction!r} needs initial_conditions='continuation' "
                "(fresh starts do not depend on the sweep direction)"
            )
        if not self.observe:
            raise ParameterError("observe must name at least one variable")
        for name in self.observe:
            if not isinstance(name, str) or not name:
                raise ParameterError(f"observe must hold variable names: got {name!r}")
        twice = sorted({n for n in self.observe if self.observe.count(n) > 1})
        if twice:
            raise ParameterError(f"observe names each variable once: {twice} repeated")
        if not self.planets:
            raise ParameterError(f"planets must be 1-based planet numbers: got {self.planets}")
        for p in self.planets:
            check_int("planets", p, lo=1)
        if len(set(self.planets)) != len(self.planets):
            raise ParameterError(f"planets must not repeat a planet: got {list(self.planets)}")
        if not isinstance(self.solver, SolverSettings):
            raise ParameterError(
                f"solver must be a SolverSettings: got {type(self.solver).__name__}"
            )
        check_bool("response", self.response)
        if self.solver.samples_per_period != 1 and not self.response:
            raise ParameterError(
                "a sweep records one sample per period (the section), a response sweep more: "
                f"got samples_per_period={self.solver.samples_per_period}"
            )
        check_bool("lyapunov", self.lyapunov)
        check_bool("orbits", self.orbits)
        check_bool("verdicts", self.verdicts)

    @property
    def recorded_lyapunov(self) -> bool:
        """Whether the kernel integrates λ₁ over the recorded window (``lyapunov`` without
        ``verdicts``: with verdicts, the verdict supplies every point's λ₁ and its error)."""
        return bool(self.lyapunov and not self.verdicts)

    @classmethod
    def build(
        cls,
        vary: Any,
        *,
        family: Any = None,
        params: Mapping[str, Any] | None = None,
        settings: SolverSettings | None = None,
        fixed: Mapping[str, Any] | None = None,
        solver: SolverSettings | None = None,
        **options: Any,
    ) -> SweepSpec:
        """A spec from strings, mappings or sequences (see the module doc).

        ``params`` are the fixed values by dotted name (the field ``fixed``); ``settings`` a
        :class:`~gearchaos.integrate.settings.SolverSettings` (the field ``solver``; default
        :data:`SWEEP_SOLVER`, :data:`RESPONSE_SOLVER` for a response sweep). ``options`` are
        the spec's own (``observe``, ``planets``, ``initial_conditions``, ``direction``,
        ``lyapunov``, ``orbits``, ``verdicts``, ``response``) and solver settings by name
        (``transient_periods``, ``periods``, ``rtol``, ``atol``, ``max_steps`` …), which
        override ``settings``. ``fixed=`` and ``solver=`` are the deprecated spellings of
        ``params=`` and ``settings=``."""
        if fixed is not None:
            fixed = check_params("fixed", fixed)
            params = renamed_keyword("SweepSpec.build", "fixed", "params", fixed, params)
        if solver is not None:
            settings = renamed_keyword("SweepSpec.build", "solver", "settings", solver, settings)
        return cls._build(vary, family, params, settings, options)

    @classmethod
    def _build(
        cls,
        vary: Any,
        family: Any,
        params: Mapping[str, Any] | None,
        settings: SolverSettings | None,
        options: dict[str, Any],
    ) -> SweepSpec:
        fam = _axes(family, "family")
        if len(fam) > 1:
            raise ParameterError(f"family must be a single axis: got {len(fam)}", name="family")
        params = check_params("params", params)
        own = {k: v for k, v in options.items() if k in SPEC_OPTIONS}
        changes = {k: v for k, v in options.items() if k not in SPEC_OPTIONS}
        for key in changes:
            if key not in SolverSettings.field_names():
                valid = [*SPEC_OPTIONS, *SolverSettings.field_names()]
                close = difflib.get_close_matches(key, valid, n=1)
                hint = f"; did you mean {close[0]!r}?" if close else ""
                raise ParameterError(f"unknown sweep option {key!r}{hint}", name=key)
        if "observe" in own:
            own["observe"] = _names("observe", own["observe"])
        if "planets" in own:
            own["planets"] = _planets(own["planets"])
        if settings is None:
            settings = RESPONSE_SOLVER if own.get("response") else SWEEP_SOLVER
        return cls(
            vary=_axes(vary),
            family=fam[0] if fam else None,
            fixed=tuple(sorted((params or {}).items())),
            solver=SolverSettings.build(settings, **changes),
            **own,
        )

    # ------------------------------------------------------------------ grid
    @property
    def axes(self) -> tuple[Axis, ...]:
        """Family first (if any), then the varied axes: the leading store dimensions."""
        return ((self.family,) if self.family is not None else ()) + self.vary

    @property
    def directions(self) -> tuple[str, ...]:
        if self.initial_conditions == "continuation" and self.direction == "both":
            return ("up", "down")
        return (self.direction,)

    @property
    def dims(self) -> tuple[str, ...]:
        """Leading dimensions of the store: (``direction``,) when both, then the axes."""
        lead = ("direction",) if len(self.directions) > 1 else ()
        return lead + tuple(a.name for a in self.axes)

    @property
    def shape(self) -> tuple[int, ...]:
        lead = (len(self.directions),) if len(self.directions) > 1 else ()
        return lead + tuple(len(a) for a in self.axes)

    @property
    def n_points(self) -> int:
        return int(np.prod(self.shape))

    # ------------------------------------------------------------------ TOML
    def to_toml(self) -> str:
        """Canonical TOML text (values written with ``repr``: exact), generated from the
        fields: the options in field order, the solver settings in their place
        (:meth:`~gearchaos.integrate.settings.SolverSettings.to_record`), then the tables
        ``[[vary]]``, ``[family]`` and ``[fixed]``. An option or setting whose value is what
        its absence means (:data:`UNRECORDED`) is left out, so the text of a sweep stored
        before it existed is the same text, and :meth:`from_toml` reads every value back
        exactly."""
        lines = []
        for name, value in self._options():
            if name == "solver":
                lines += [f"{k} = {_toml(v)}" for k, v in self.solver.to_record().items()]
            elif not (name in UNRECORDED and value == UNRECORDED[name]):
                lines.append(f"{name} = {_toml(value)}")
        lines.append("")
        for a in self.vary:
            lines += ["[[vary]]", f"name = {_toml(a.name)}", f"values = {_toml(a.values)}", ""]
        if self.family is not None:
            lines += [
                "[family]",
                f"name = {_toml(self.family.name)}",
                f"values = {_toml(self.family.values)}",
                "",
            ]
        if self.fixed:
            lines.append("[fixed]")
            lines += [f'"{k}" = {_toml(v)}' for k, v in self.fixed]
            lines.append("")
        return "\n".join(lines)

    def _options(self) -> list[tuple[str, Any]]:
        """The fields that are not tables, by name, in field order."""
        return [(f.name, getattr(self, f.name)) for f in fields(self) if f.name not in _TABLES]

    @classmethod
    def from_toml(cls, text: str) -> SweepSpec:
        """The spec written by :meth:`to_toml`; unreadable text is a :class:`StoreError`."""
        import tomllib

        try:
            d = tomllib.loads(text)
            fam = d.get("family")
            options: dict[str, Any] = {}
            for f in fields(cls):
                if f.name == "solver":
                    options["solver"] = SolverSettings.from_record(d)
                elif f.name in _TABLES:
                    continue
                elif f.name in d:
                    value = d[f.name]
                    options[f.name] = tuple(value) if isinstance(value, list) else value
                elif f.name in UNRECORDED:
                    options[f.name] = UNRECORDED[f.name]
                else:
                    raise KeyError(f.name)
            return cls(
                vary=tuple(
                    Axis(a["name"], tuple(float(x) for x in a["values"])) for a in d["vary"]
                ),
                family=Axis(fam["name"], tuple(float(x) for x in fam["values"])) if fam else None,
                fixed=tuple(sorted(d.get("fixed", {}).items())),
                **options,
            )
        except (tomllib.TOMLDecodeError, KeyError, TypeError, ValueError, AttributeError) as exc:
            if isinstance(exc, ParameterError):
                raise StoreError(f"the stored sweep specification is invalid: {exc}") from None
            raise StoreError(
                f"the stored sweep specification is not readable ({type(exc).__name__}: {exc})"
            ) from None


#: The fields of a :class:`SweepSpec` written as TOML tables, not as options.
_TABLES = ("vary", "family", "fixed")

#: What a specification without an option means: sweeps stored before the option existed
#: neither confirmed orbits nor ran verdicts nor stored response quantities.
UNRECORDED = {"orbits": False, "verdicts": False, "response": False}


def _toml(v: Any) -> str:
    """A value as TOML (floats with ``repr``: exact)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int | np.integer):
        return str(int(v))
    if isinstance(v, float | np.floating):
        return repr(float(v))
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_toml(x) for x in v) + "]"
    raise TypeError(f"cannot write {v!r} to TOML")
