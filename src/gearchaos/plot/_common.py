"""Shared helpers of the plotting layer: symbols and labels (from the parameter registry),
variables of results, axes, cell edges, clearance and resonance lines."""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._text import escape_text
from ..errors import ParameterError
from ..gearset.schema import MODULE_BOUNDED, OMEGA, describe
from ..model.contract import Capabilities
from ..model.planetary import PlanetaryModel

#: ``gid`` of the vertical lines where a mesh harmonic meets a natural frequency.
RESONANCE_GID = "resonance"

# symbols of the reference systems' parameters (gearchaos.model.library): the backlash
# oscillator's, the Duffing oscillator's (x'' + δx' + αx + βx³ = γ cos Ωτ), the Lorenz system's
_REFERENCE_TEX: dict[str, str] = {
    "zeta": r"\zeta",
    "eps": r"\varepsilon",
    "b": "b",
    "f_mean": "F_m",
    "f_alt": "F_a",
    "delta": r"\delta",
    "alpha": r"\alpha",
    "beta": r"\beta",
    "gamma": r"\gamma",
    "sigma": r"\sigma",
    "rho": r"\rho",
}
# definitions shown after a symbol on axes
_DEFINITIONS: dict[str, str] = {OMEGA: r"\omega/\omega_n"}

# section variable -> mathtext symbol (%d: planet); derivatives get a prime
#: Symbols of the planetary model's variables (its own table, for figures drawn from stores).
_VAR_SYMBOLS: dict[str, str] = {k: v[0] for k, v in PlanetaryModel.symbols.items()}


# --------------------------------------------------------------------------- names and labels
def _tex(name: str, symbols: Mapping[str, str] | None = None) -> str | None:
    if symbols and name in symbols:
        return str(symbols[name])
    field = describe(name)
    if field is not None:
        return field.tex
    return _REFERENCE_TEX.get(name)


def axis_symbol(name: str, symbols: Mapping[str, str] | None = None) -> str:
    """Mathtext symbol (with ``$``) of a parameter, e.g. ``$\\xi$``; else the name.
    ``symbols``: a model's own parameter symbols (:func:`parameter_symbols`), which come
    first."""
    sym = _tex(name, symbols)
    return f"${sym}$" if sym is not None else figure_text(name)


def axis_label(name: str, symbols: Mapping[str, str] | None = None) -> str:
    """Axis label of a parameter from the registry: ``omega`` → ``$\\Omega = \\omega/\\omega_n$``,
    ``backlash.sun_planet`` → ``$\\bar b_{sp}$``, ``torque.input`` → ``$T_D$ [N m]``; a
    parameter of a model's own ``symbols`` (:func:`parameter_symbols`) → its symbol; an
    unknown name labels itself."""
    if symbols and name in symbols:
        return f"${symbols[name]}$"
    sym = _tex(name)
    if sym is None:
        return figure_text(name)  # a name read from a file: printable, no mathtext
    if name in _DEFINITIONS:
        return f"${sym} = {_DEFINITIONS[name]}$"
    field = describe(name)
    unit = field.unit_label if field is not None else ""
    return f"${sym}$ {unit}" if unit else f"${sym}$"


def given(name: str, value: Any, symbols: Mapping[str, str] | None = None) -> str:
    """``symbol = value`` of a parameter for titles and legends: ``$\\Omega$ = 1.2``,
    ``$\\delta$ = 0.25``; an unknown name as it is, a value that is no number as written.
    ``symbols`` as for :func:`axis_symbol`."""
    number = isinstance(value, int | float | np.number) and not isinstance(value, bool)
    field = describe(name)
    unit = f" {field.unit}" if number and field is not None and field.unit in _SPEED_UNITS else ""
    return f"{axis_symbol(name, symbols)} = {fmt(value) if number else figure_text(value)}{unit}"


#: Units written after a value in titles (a speed: ``$n_s$ = 7500 rpm``).
_SPEED_UNITS = ("rpm", "Hz")


def subject(attrs: Any, gearset: Any = None) -> str:
    """What a figure of a store or file is of, as its title names it: the model's title
    (:func:`~gearchaos.model.record.model_title`: the gear set's name, ``sheng2016``, for a
    model built from one — ``gearset`` when given, else the one the attributes record — else
    the model's, ``backlash_oscillator``), not the record's ``planetary[sheng2016]``; the
    recorded name when the model cannot be built again."""
    model = stored_model(attrs, gearset)
    if model is None:
        return figure_text(attrs.get("model", "") or "")
    from ..model.record import model_title

    return figure_text(model_title(model)[1])


def gearset_title(gearset: Any) -> str:
    """A gear set's name as a figure names it: the name it carries, except that a gear set
    named after a built-in preset whose values are another preset's is named by those
    (a store written with the default before issue 34 says ``sheng2016-v1``, not
    ``sheng2016``)."""
    from ..model.record import model_title

    return model_title(PlanetaryModel.from_gearset(gearset))[1]


def figure_text(text: Any) -> str:
    """Text read from a file (a name, a title) as figure text that only prints: control
    characters as escapes (:func:`~gearchaos._text.escape_text`), a ``$`` kept literal (no
    mathtext from a file)."""
    return escape_text(text).replace("$", r"\$")


def stored_gearset(attrs: Any) -> Any:
    """The gear set a store, branch or curve file records (the fields of its planetary model,
    or ``gearset_toml`` in an older file: :func:`~gearchaos.model.record.recorded_gearset`),
    or ``None`` (any other model). A damaged record is refused
    (:class:`~gearchaos.errors.ParameterError`)."""
    from ..model.record import recorded_gearset

    return recorded_gearset(attrs)


def stored_fixed(attrs: Any) -> dict[str, Any]:
    """The fixed values a branch or curve file records (attribute ``fixed``, JSON); ``{}``
    when it has none or they cannot be read."""
    raw = attrs.get("fixed", "{}")
    try:
        data = json.loads(raw) if isinstance(raw, str) else dict(raw)
    except (TypeError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


_DAMPING = frozenset({"xi", "damping.sun_planet", "damping.planet_ring", "damping.sun_bearing"})


def given_values(
    attrs: Any,
    *,
    fixed: Mapping[str, Any],
    gearset: Any = None,
    leave_out: Any = (),
) -> list[str]:
    """``symbol = value`` of what a figure holds fixed, for its title's ``at …`` line: the
    numeric ``fixed`` values, then b̄_sp, b̄_rp, b̄_s and ξ of ``gearset`` (with the fixed
    values applied) or, for a reference system, its parameters that have a symbol (from the
    attribute ``model_parameters``, the model's repr); the names in ``leave_out`` (the swept
    or continued parameters) are left out. One helper for the titles of sweeps, branches
    and stability charts."""
    shown = {str(n) for n in leave_out}
    out: list[str] = []
    symbols = parameter_symbols(attrs)  # a gear set's model has none: the registry's
    metres = clearances_in_metres(gearset)
    model = stored_model(attrs, gearset)
    for k, v in fixed.items():
        number = isinstance(v, int | float | np.number) and not isinstance(v, bool)
        if number and k not in shown and k not in metres:  # those: b̄ and µm from the gear set
            out.append(given(k, v, symbols) + (speed_text(v, model) if k == OMEGA else ""))
            shown.add(k)
    # gear-set switch: a gear set's fixed values are its registry's clearances (b̄ and µm) and ξ
    if gearset is None:  # a reference system or a user model: its parameters with a symbol
        text = str(attrs.get("model_parameters", "") or "")
        for k, v in re.findall(r"(\w+)=([-+0-9.eE]+)[,)]", text):
            if k not in shown and axis_symbol(k, symbols) != k:
                out.append(given(k, float(v), symbols))
                shown.add(k)
        return out
    bsp, brp = gearset.backlash_bar()
    for key, value in (
        ("backlash.sun_planet", bsp),
        ("backlash.planet_ring", brp),
        ("clearance.sun_bearing", gearset.sun_bearing_clearance_bar()),
    ):
        if key not in shown:  # b̄, and the µm the gear set gives it in (units "m")
            um = f" ({fmt(metres[key] * 1e6, '.4g')} µm)" if key in metres else ""
            out.append(given(key, value) + um)
    d = gearset.damping
    if not _DAMPING & shown and d.sun_planet == d.planet_ring == d.sun_bearing:
        out.append(given("xi", d.sun_planet))
    return out


def speed_text(omega: Any, model: Any) -> str:
    """`` (7589 rpm)``: the sun speed at Ω of ``model`` (built from a gear set with its fixed
    values applied: :func:`~gearchaos.model.target.speeds_at`), written beside Ω in titles;
    ``""`` for a model without speeds (or ``None``)."""
    from ..model.target import speeds_at

    rpm = None if model is None else speeds_at(model, float(omega)).get("sun_rpm")
    return "" if rpm is None else f" ({fmt(rpm, '.5g')} rpm)"


def clearances_in_metres(gearset: Any) -> dict[str, float]:
    """The clearances that ``gearset`` gives in metres (their ``units`` field ``m``), by
    name, in metres; ``{}`` without a gear set."""
    # gear-set switch: clearances in metres are a gear set's input setting (backlash.units)
    if gearset is None:
        return {}
    from ..gearset.mapping import get_value

    return {
        name: float(get_value(gearset, name))  # type: ignore[arg-type]
        for name, units in MODULE_BOUNDED.items()
        if units is not None and get_value(gearset, units) == "m"
    }


def at_line(values: list[str], width: int = 80) -> str:
    """The title's ``at …`` line of ``values`` (:func:`given_values`), broken after a comma
    where it would run past ``width`` visible characters (mathtext counted as drawn: ``$``,
    braces and ``_`` none, ``\\zeta`` one), so that a model with many parameters keeps its
    title inside the figure; ``""`` for no values."""
    lines: list[str] = []
    line, used = "at", 2
    for k, v in enumerate(values):
        text = v + ("," if k < len(values) - 1 else "")
        n = len(re.sub(r"[${}_^]", "", re.sub(r"\\[A-Za-z]+ ?", "x", text)))
        if k and used + 1 + n > width:
            lines.append(line)
            line, used = text, n
        else:
            line, used = f"{line} {text}", used + 1 + n
    return "\n".join([*lines, line]) if values else ""


def model_symbols(attrs: Any) -> Mapping[str, Any]:
    """The figure symbols of the variables of what a store or branch file records (its
    attributes): the ``symbols`` (the optional member of the model contract) of its model
    (:func:`stored_model`: the planetary model of its gear set, or the model built again
    from ``model_class`` and ``model_fields``); none when it has none or can no longer be
    built (its file moved)."""
    model = stored_model(attrs)
    return {} if model is None else dict(Capabilities.of(model).symbols)


def parameter_symbols(attrs: Any) -> Mapping[str, str]:
    """The figure symbols of the parameters of the model a store, branch or curve file
    records (its attributes): the model's own ``parameter_symbols`` (the optional member of
    the model contract; field name → mathtext without ``$``), the model of
    :func:`stored_model`; none for a gear set (the registry names its parameters), a model
    without them or one that can no longer be built. For ``symbols=`` of
    :func:`axis_label`, :func:`axis_symbol` and :func:`given`."""
    model = stored_model(attrs)
    table = {} if model is None else Capabilities.of(model).parameter_symbols
    return {str(k): str(v) for k, v in table.items()}


def stored_target(attrs: Any, gearset: Any = None) -> Any:
    """What a store's, branch file's or curve file's attributes record as computed on
    (:func:`~gearchaos.model.record.recorded_target`: ``gearset`` when given, else the gear
    set it records, else a :class:`~gearchaos.model.System` of the model of
    ``model_class``/``model_fields``), built once per record; ``None`` when they record
    neither, when it is the user's own model and the user has not named it (``--model``: a
    file's record never imports anything) or when it cannot be built."""
    from ..model.record import recorded_target

    key = (*(str(attrs.get(k, "") or "") for k in _RECORD_KEYS), str(id(gearset)))
    hit = _REBUILT.get(key)
    if hit is not None and hit[0] is gearset:
        return hit[1]
    try:  # only a model the user named or gearchaos's own: never an import by the record
        target = recorded_target(attrs, gearset)
    except ParameterError:
        return None  # not named (yet): the figure draws names, not symbols
    if len(_REBUILT) >= 16:
        _REBUILT.pop(next(iter(_REBUILT)))
    _REBUILT[key] = (gearset, target)
    return target


def stored_model(attrs: Any, gearset: Any = None) -> Any:
    """The model of :func:`stored_target` (``gearset`` when given, else what the attributes
    record), or ``None``."""
    from ..model.target import model_for

    target = stored_target(attrs, gearset)
    return None if target is None else model_for(target, {})


#: The attributes that record what a file was computed on.
_RECORD_KEYS = ("gearset_toml", "model_class", "model_fields")
#: Targets built again for figures, by (gearset_toml, model_class, model_fields, the given
#: gear set's id), with the given gear set: at most 16.
_REBUILT: dict[tuple[str, ...], tuple[Any, Any]] = {}


def var_symbol(var: str, planet: int | None, symbols: Mapping[str, Any] | None = None) -> str:
    """Mathtext symbol (without ``$``) of a section variable from ``symbols`` (a model's
    table, :func:`model_symbols`; default the planetary model's): ``delta_sp`` →
    ``\\bar{X}_{sp1}``, ``delta_sp_dot`` → ``\\bar{X}'_{sp1}``; other names become
    ``head_{tail}``."""
    table = _VAR_SYMBOLS if symbols is None else {k: v[0] for k, v in symbols.items()}
    base, prime = (var[:-4], "'") if var.endswith("_dot") else (var, "")
    if base in table:
        sym = table[base]
        if "%d" in sym:
            sym = sym % (planet if planet is not None else 1)
        # prime before the subscript: \bar{X}'_{sp1}
        head, sep, tail = sym.partition("_")
        return f"{head}{prime}{sep}{tail}" if sep else sym + prime
    return _generic_symbol(base) + prime


def fmt(v: Any, spec: str = "g") -> str:
    """A value for figure text (titles, legends, notes): strings as they are, numbers with
    ``spec`` (default ``%g``) and a true minus (U+2212), not a hyphen: ``−1``, ``1e−08``."""
    if isinstance(v, str):
        return v
    return format(float(v), spec).replace("-", "\N{MINUS SIGN}")


def edges(v: np.ndarray) -> np.ndarray:
    """Cell edges around (possibly non-uniform) centres."""
    v = np.asarray(v, dtype=np.float64)
    if v.size == 1:
        d = 0.5 * abs(v[0]) if v[0] != 0 else 0.5
        return np.array([v[0] - d, v[0] + d])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]])


def no_offset(*axes: Any) -> None:
    """Turn off axis offsets (“1e-6 + 3.49”) on the given matplotlib axes."""
    for axis in axes:
        formatter = axis.get_major_formatter()
        if hasattr(formatter, "set_useOffset"):
            formatter.set_useOffset(False)


_HARMONIC_STYLES = {1: "-", 2: "--", 3: ":"}


def resonance_lines(ax: Any, gearset: Any, lo: float, hi: float) -> int:
    """Vertical lines at Ω = ω_k/(h ω_n) inside [lo, hi], where the h-th mesh harmonic meets a
    natural frequency ω_k of the linear model; returns how many were drawn."""
    # gear-set switch: natural frequencies come from a gear set's linear model (gearset_info)
    if gearset is None:
        raise ParameterError(
            "resonances need the gear set of the sweep (attribute gearset_toml); "
            "this dataset has none (a reference system?)"
        )
    from ..model.derived import gearset_info

    found = sorted(
        gearset_info(gearset)["omega_at_resonances"],
        key=lambda r: (int(r["harmonic"]), float(r["omega"])),
    )
    drawn = 0
    labelled: set[int] = set()
    for r in found:
        om, h = float(r["omega"]), int(r["harmonic"])
        if not lo <= om <= hi:
            continue
        ax.axvline(
            om,
            color="tab:green",
            linestyle=_HARMONIC_STYLES.get(h, "-."),
            linewidth=0.7,
            alpha=0.55,
            zorder=0.5,
            gid=RESONANCE_GID,
            label=(
                rf"${'' if h == 1 else h}\Omega = \omega_k/\omega_n$" if h not in labelled else None
            ),
        )
        labelled.add(h)
        drawn += 1
    return drawn


#: Line style of clearance markers (±b̄), so tests and users can find them by ``gid``.
CLEARANCE_GID = "clearance"
_CLEARANCE_STYLE: dict[str, Any] = {"color": "0.35", "linestyle": "--", "linewidth": 0.9}


@dataclass(frozen=True)
class VarInfo:
    """A variable of a result with its derivative, mathtext symbols and clearance."""

    name: str
    dot: str | None
    symbol: str  # mathtext without $
    definition: str | None
    clearance: float | None
    clearance_symbol: str | None

    @property
    def label(self) -> str:
        if self.definition:
            return f"${self.symbol} = {self.definition}$"
        return f"${self.symbol}$"

    @property
    def dot_symbol(self) -> str:
        return f"{self.symbol}'"

    @property
    def dot_label(self) -> str:
        thin = r"\," if len(self.symbol) > 1 and self.symbol[0].isalpha() else ""
        return rf"${self.dot_symbol} = \mathrm{{d}}{thin}{self.symbol}/\mathrm{{d}}\tau$"


def period_name(result: Any) -> str:
    """What the model calls its forcing period (``mesh`` for gear trains, else ``forcing``)."""
    return result.system.capabilities.period_name


def frequency_axis(result: Any) -> tuple[str, str]:
    """(mathtext symbol, words) of a spectrum's frequency axis, in multiples of the frequency
    2π/T of the model's forcing period T = ``period_factor``·2π/Ω, so that the harmonics of
    its period lie at the integers: ω/ω_m (the mesh frequency), ω/Ω for a period 2π/Ω, else
    ωT/2π (a period of 5·2π/Ω: multiples of Ω/5)."""
    caps = result.system.capabilities
    name, factor = caps.period_name, caps.period_factor
    if name == "mesh":
        return r"\omega/\omega_m", "multiples of the mesh frequency $f_m$"
    if factor == 1.0:
        return r"\omega/\Omega", f"multiples of the {name} frequency"
    words = rf"multiples of the {name} frequency $2\pi/T = {omega_times(1.0 / factor)}$"
    return r"\omega T/2\pi", words


def omega_times(ratio: float) -> str:
    """``ratio``·Ω in mathtext without ``$``: ``\\Omega``, ``2\\Omega``, ``3\\Omega/5`` for a
    fraction of small terms, else ``0.417\\Omega``."""
    from fractions import Fraction

    fr = Fraction(ratio).limit_denominator(1000)
    if not math.isclose(float(fr), ratio, rel_tol=1e-9):
        return rf"{ratio:.3g}\Omega"
    num = "" if fr.numerator == 1 else str(fr.numerator)
    return rf"{num}\Omega" + ("" if fr.denominator == 1 else f"/{fr.denominator}")


def has_physical_scales(result: Any) -> bool:
    """Whether the model converts to SI units (a gear set's ω_n, b_c …)."""
    return result.system.capabilities.has_scales


def _generic_symbol(name: str) -> str:
    base, dot = (name[:-4], "'") if name.endswith("_dot") else (name, "")
    if base.count("_") > 1:  # a long name: upright, as written (contact_force_1)
        return r"\mathrm{" + base.replace("_", r"\_") + "}" + dot
    if "_" not in base and len(base) > 1:  # a word (delta, theta): upright, not a product
        return r"\mathrm{" + base + "}" + dot
    head, sep, tail = base.partition("_")
    sym = f"{head}_{{{tail}}}" if sep else head
    return sym + dot


def variable(result: Any, var: str | None = None, planet: int = 1) -> VarInfo:
    """Resolve ``var`` (and ``planet``) into a :class:`VarInfo` for ``result``.

    Any state or observable name, or a group of the model's ``symbols`` (the planetary
    model's ``delta_sp`` (default), ``delta_rp``, ``force_sp``, ``force_rp``, ``p`` per planet;
    ``x_s``, ``y_s``, ``sigma``) drawn with its symbol and clearance; the default is the model's
    default observable, else the first state.
    """
    system = result.system
    names = tuple(system.state_names) + tuple(system.obs_names)
    caps = system.capabilities
    clearances, symbols = caps.clearances, caps.symbols
    if var is None:
        var = system.default_observables[0]
    if var in symbols:
        sym, definition, ckey, csym = symbols[var]
        clearance = None if ckey is None else float(clearances[ckey])
        if "%d" not in sym:
            dot = f"{var}_dot"
            return VarInfo(var, dot if dot in names else None, sym, definition, clearance, csym)
        name = system.member(var, planet)
        if name is None:
            raise ParameterError(f"var {var!r} is no per-planet variable of {system.name}")
        member_dot = system.member(f"{var}_dot", planet)
        return VarInfo(
            name, member_dot, sym % planet, None if definition is None else definition % planet,
            clearance, csym,
        )  # fmt: skip
    member = system.member(var, planet)  # a group without a symbol: its member
    if member is not None:
        member_dot = system.member(f"{var}_dot", planet)
        member_dot = member_dot or (f"{member}_dot" if f"{member}_dot" in names else None)
        return VarInfo(member, member_dot, _generic_symbol(member), None, None, None)
    if var not in names:
        raise ParameterError(
            f"var must name a variable of {system.name} ({', '.join(names)}): got {var!r}"
        )
    dot = f"{var}_dot"
    b = clearances.get(var)
    return VarInfo(
        var,
        dot if dot in names else None,
        _generic_symbol(var),
        None,
        None if b is None else float(b),
        None if b is None else r"\bar{b}" if symbols else "b",
    )


def get_ax(ax: Any) -> Any:
    """``ax`` or a new Axes on a new pyplot figure."""
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    _, ax = plt.subplots()
    return ax


def period_axis_label(result: Any) -> str:
    if period_name(result) == "mesh":
        return r"$t\,/\,T_m$ (mesh periods)"
    return rf"$t\,/\,T$ ({period_name(result)} periods)"


def to_periods(result: Any, tau: np.ndarray) -> np.ndarray:
    """τ in the model's forcing periods: τ/T, T = :attr:`~gearchaos.model.System.period`
    (τΩ/2π for a forcing of one frequency, τΩ/(2π·``period_factor``) for several)."""
    return np.asarray(tau) / result.system.period


def sample_window(result: Any, periods: float | None) -> slice:
    """Slice of the samples covering the last ``periods`` recorded periods (all if None)."""
    if periods is None:
        return slice(None)
    if not (math.isfinite(periods) and periods > 0):
        raise ParameterError(f"periods must be a number > 0 or None: got {periods!r}")
    n = round(periods * result.samples_per_period)
    return slice(max(result.tau.size - n, 0), None)


def clearance_lines(ax: Any, info: VarInfo, *, vertical: bool = False) -> None:
    """Dashed lines at ±b̄ of ``info`` (horizontal, or vertical when the variable is on x)."""
    if info.clearance is None:
        return
    b = info.clearance
    draw = ax.axvline if vertical else ax.axhline
    for k, v in enumerate((b, -b)):
        draw(
            v,
            gid=CLEARANCE_GID,
            label=rf"$\pm {info.clearance_symbol} = \pm {b:g}$" if k == 0 else None,
            zorder=1,
            **_CLEARANCE_STYLE,
        )


def corner_note(ax: Any, text: str) -> Any:
    """A small grey note in the lower right corner of ``ax`` (points left out, and why)."""
    return ax.text(
        0.99,
        0.01,
        text,
        ha="right",
        va="bottom",
        fontsize="x-small",
        color="0.3",
        transform=ax.transAxes,
    )


def message(ax: Any, text: str) -> Any:
    """Show ``text`` in the middle of an otherwise empty Axes."""
    ax.text(0.5, 0.5, text, ha="center", va="center", transform=ax.transAxes, wrap=True)
    ax.set_xticks([])
    ax.set_yticks([])
    return ax
