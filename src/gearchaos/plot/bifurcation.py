"""Bifurcation diagrams and maps of sweep stores (:func:`gearchaos.bifurcation`).

A sweep dataset has leading dimensions (``direction`` when both directions were run, the
family axis, the varied axes — named by their dotted parameter names), then ``section`` (one
Poincaré point per recorded mesh period) and ``planet`` (the observed planets). These plots
read such a dataset (an open Zarr store or the return value of :func:`gearchaos.bifurcation`)
and never simulate:

* :func:`bifurcation` — section values of one variable against one swept parameter, the seed's
  bifurcation diagram (Fig. 4: X̄_sp1 against Ω);
* :func:`bifurcation_figure` — one panel per family value, titled ``(a) ξ = 0.03`` … like the
  seed's figures; up and down continuation branches overlaid in two colours;
* :func:`distinct_map` — a 2-D sweep coloured by the number of distinct section points of
  every grid point (1T, 2T, …, many);
* :func:`sweep_figure` — whichever of the two fits the dataset; with motion labels (every
  store has them) 1-D panels get a regime band and 2-D sweeps become regime maps
  (:mod:`gearchaos.plot.regimes`).
"""

from __future__ import annotations

import math
import string
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ParameterError, Status
from ._common import _CLEARANCE_STYLE, CLEARANCE_GID, get_ax

__all__ = [
    "RESONANCE_GID",
    "axis_label",
    "axis_symbol",
    "bifurcation",
    "bifurcation_figure",
    "distinct_counts",
    "distinct_map",
    "sweep_figure",
]

#: ``gid`` of the vertical lines where a mesh harmonic meets a natural frequency.
RESONANCE_GID = "resonance"

# dotted parameter name -> (mathtext symbol without $, definition or unit for the axis label)
_AXIS_SYMBOLS: dict[str, tuple[str, str | None]] = {
    "omega": (r"\Omega", r"= \omega/\omega_n"),
    "xi": (r"\xi", None),
    "damping.sun_planet": (r"\xi_{sp}", None),
    "damping.planet_ring": (r"\xi_{rp}", None),
    "damping.sun_bearing": (r"\xi_{s}", None),
    "backlash.sun_planet": (r"\bar b_{sp}", None),
    "backlash.planet_ring": (r"\bar b_{rp}", None),
    "clearance.sun_bearing": (r"\bar b_s", None),
    "torque.input": ("T_D", "[N m]"),
    "transmission_error.sun_planet": ("A_{sp}", "[m]"),
    "transmission_error.planet_ring": ("A_{rp}", "[m]"),
    "stiffness.sun_planet_mean": ("k_{m,sp}", "[N/m]"),
    "stiffness.sun_planet_alternating": ("k_{a,sp}", "[N/m]"),
    "stiffness.planet_ring_mean": ("k_{m,rp}", "[N/m]"),
    "stiffness.planet_ring_alternating": ("k_{a,rp}", "[N/m]"),
    "stiffness.sun_bearing": ("k_s", "[N/m]"),
    # reference systems (gearchaos.model.library)
    "zeta": (r"\zeta", None),
    "eps": (r"\varepsilon", None),
    "b": ("b", None),
    "f_mean": ("F_m", None),
    "f_alt": ("F_a", None),
}

# section variable -> mathtext symbol (%d: planet); derivatives get a prime
_VAR_SYMBOLS: dict[str, str] = {
    "delta_sp": r"\bar{X}_{sp%d}",
    "delta_rp": r"\bar{X}_{rp%d}",
    "force_sp": r"\bar{F}_{sp%d}",
    "force_rp": r"\bar{F}_{rp%d}",
    "p": r"\bar{p}_{%d}",
    "x_s": r"\bar{x}_s",
    "y_s": r"\bar{y}_s",
    "sigma": r"\bar{\sigma}",
}

# section variable -> (backlash/clearance parameter, dataset attribute with its b̄, symbol)
_CLEARANCES: dict[str, tuple[str, str, str]] = {
    "delta_sp": ("backlash.sun_planet", "clearance_sun_planet", r"\bar{b}_{sp}"),
    "delta_rp": ("backlash.planet_ring", "clearance_planet_ring", r"\bar{b}_{rp}"),
    "x_s": ("clearance.sun_bearing", "clearance_sun_bearing", r"\bar{b}_s"),
    "y_s": ("clearance.sun_bearing", "clearance_sun_bearing", r"\bar{b}_s"),
}

_NON_SWEEP_DIMS = ("section", "planet", "planet_all")
_DIRECTION_COLOURS = {"up": "C0", "down": "C3"}
_FAILED_COLOUR = "0.7"
_MANY_COLOUR = "0.1"


# --------------------------------------------------------------------------- names and labels
def axis_symbol(name: str) -> str:
    """Mathtext symbol (with ``$``) of a swept parameter, e.g. ``$\\xi$``; else the name."""
    if name in _AXIS_SYMBOLS:
        return f"${_AXIS_SYMBOLS[name][0]}$"
    return name


def axis_label(name: str) -> str:
    """Axis label of a swept parameter: ``omega`` → ``$\\Omega = \\omega/\\omega_n$``,
    ``backlash.sun_planet`` → ``$\\bar b_{sp}$``, ``torque.input`` → ``$T_D$ [N m]``; an
    unknown dotted name labels itself."""
    if name not in _AXIS_SYMBOLS:
        return name
    sym, extra = _AXIS_SYMBOLS[name]
    if extra is None:
        return f"${sym}$"
    if extra.startswith("="):
        return f"${sym} {extra}$"
    return f"${sym}$ {extra}"


def _var_symbol(var: str, planet: int | None) -> str:
    base, prime = (var[:-4], "'") if var.endswith("_dot") else (var, "")
    if base in _VAR_SYMBOLS:
        sym = _VAR_SYMBOLS[base]
        if "%d" in sym:
            sym = sym % (planet if planet is not None else 1)
        # prime before the subscript: \bar{X}'_{sp1}
        head, sep, tail = sym.partition("_")
        return f"{head}{prime}{sep}{tail}" if sep else sym + prime
    head, sep, tail = base.partition("_")
    sym = f"{head}_{{{tail}}}" if sep else head
    return sym + prime


def _fmt(v: Any) -> str:
    if isinstance(v, str):
        return v
    return f"{float(v):g}"


# --------------------------------------------------------------------------- dataset helpers
@dataclass(frozen=True)
class _Layout:
    """Which leading dimensions of a sweep dataset are what."""

    directions: tuple[str, ...]  # () when there is no direction dimension
    family: str | None
    vary: tuple[str, ...]


def _leading_dims(ds: Any, var: str) -> tuple[str, ...]:
    return tuple(d for d in ds[var].dims if d not in _NON_SWEEP_DIMS)


def _spec(ds: Any) -> Any:
    text = ds.attrs.get("sweep_toml")
    if not text:
        return None
    from ..sweep.spec import SweepSpec

    try:
        return SweepSpec.from_toml(str(text))
    except (tomllib.TOMLDecodeError, KeyError, TypeError, ValueError):
        return None


def _layout(ds: Any, var: str) -> _Layout:
    dims = _leading_dims(ds, var)
    directions: tuple[str, ...] = ()
    if "direction" in dims:
        directions = tuple(str(v) for v in np.asarray(ds["direction"].values))
        dims = tuple(d for d in dims if d != "direction")
    spec = _spec(ds)
    if spec is not None and spec.family is not None and spec.family.name in dims:
        family: str | None = spec.family.name
        vary = tuple(d for d in dims if d != family)
    else:
        vary = tuple(a.name for a in spec.vary if a.name in dims) if spec is not None else ()
        family = None
        if not vary or len(vary) != len(dims):
            # without a readable sweep spec: a family only when it is declared; all varied
            vary = dims
    return _Layout(directions, family, vary)


def _resolve_var(ds: Any, var: str | None) -> str:
    names = [str(n) for n in ds.data_vars if "section" in ds[n].dims]
    if var is None:
        if "delta_sp" in names:
            return "delta_sp"
        if not names:
            raise ParameterError("ds holds no section variable (dimension 'section')")
        return names[0]
    if var not in ds.data_vars or "section" not in ds[var].dims:
        raise ParameterError(
            f"var must name a section variable of the dataset ({', '.join(names)}): got {var!r}"
        )
    return var


def _select(ds: Any, select: Mapping[str, Any] | None) -> Any:
    """``ds`` with the dimensions in ``select`` fixed (nearest value for numeric axes)."""
    if not select:
        return ds
    for dim, value in select.items():
        if dim not in ds.dims:
            have = ", ".join(map(str, ds.dims))
            raise ParameterError(
                f"select names a dimension the dataset does not have ({have}): got {dim!r}"
            )
        coord = np.asarray(ds[dim].values)
        if coord.dtype.kind in "fiu":
            try:
                v = float(value)
            except (TypeError, ValueError):
                raise ParameterError(f"select[{dim!r}] must be a number: got {value!r}") from None
            i = int(np.argmin(np.abs(coord - v)))
            tol = 1e-9 * max(1.0, float(np.max(np.abs(coord))))
            if abs(float(coord[i]) - v) > tol:
                raise ParameterError(
                    f"select[{dim!r}] must be one of the swept values "
                    f"({', '.join(_fmt(c) for c in coord)}): got {value!r}"
                )
            ds = ds.isel({dim: i})
        else:
            values = [str(c) for c in coord]
            if str(value) not in values:
                raise ParameterError(f"select[{dim!r}] must be one of {values}: got {value!r}")
            ds = ds.isel({dim: values.index(str(value))})
    return ds


def _planet_sel(da: Any, planet: int) -> Any:
    if "planet" not in da.dims:
        return da
    planets = [int(p) for p in np.asarray(da["planet"].values)]
    if planet not in planets:
        raise ParameterError(
            f"planet must be one of the observed planets {planets}: got {planet!r}"
        )
    return da.sel(planet=planet)


#: ``status`` of a point not yet computed (an interrupted store); 1-3 are integration failures.
_NOT_RUN = int(Status.NOT_RUN)


def _status(ds: Any, dims: tuple[str, ...]) -> np.ndarray | None:
    """The ``status`` values over ``dims`` (None when the dataset has no status)."""
    if "status" not in ds:
        return None
    return np.asarray(ds["status"].transpose(*dims).values)


def _gearset(ds: Any) -> Any:
    text = ds.attrs.get("gearset_toml")
    if not text:
        return None
    from ..gearset import GearSet

    gs = GearSet.from_toml_string(str(text))
    spec = _spec(ds)
    if spec is not None:
        changes = {k: v for k, v in spec.fixed if k != "omega"}
        if changes:
            try:
                gs = gs.evolve(changes)
            except (ParameterError, TypeError, ValueError):
                pass
    return gs


def _to_bar(gs: Any, parameter: str, value: float) -> float:
    """b̄ of a backlash or clearance parameter value (in the gear set's units)."""
    if gs is None:
        return value
    units = gs.backlash.units if parameter.startswith("backlash.") else gs.clearance.units
    if units == "m":
        return value / gs.clearance.characteristic_length
    return value


def _fixed_value(ds: Any, name: str) -> float | None:
    spec = _spec(ds)
    if spec is None:
        return None
    for k, v in spec.fixed:
        if k == name:
            try:
                return float(v)
            except (TypeError, ValueError):
                return None
    return None


def _clearance_of(ds: Any, var: str, x_name: str, x: np.ndarray) -> tuple[np.ndarray, str] | None:
    """b̄ of ``var`` along the x axis (an array, constant unless x is that clearance)."""
    if var.endswith("_dot"):
        return None
    if var in _CLEARANCES:
        parameter, attr, sym = _CLEARANCES[var]
    elif f"clearance_{var}" in ds.attrs:  # reference systems, e.g. x of the backlash oscillator
        attr = f"clearance_{var}"
        if x_name == "b":
            return np.asarray(x, dtype=np.float64), "b"
        return np.full(np.shape(x), float(ds.attrs[attr])), "b"
    else:
        return None
    gs = None
    try:
        gs = _gearset(ds)
    except (ParameterError, OSError, ValueError):
        gs = None
    if x_name == parameter:
        return np.array([_to_bar(gs, parameter, float(v)) for v in x]), sym
    if parameter in ds.coords and ds[parameter].ndim == 0:  # selected family/axis value
        b = _to_bar(gs, parameter, float(ds[parameter].values))
    elif (fixed := _fixed_value(ds, parameter)) is not None:
        b = _to_bar(gs, parameter, fixed)
    elif attr in ds.attrs:
        b = float(ds.attrs[attr])
    elif gs is not None:
        b = {
            "backlash.sun_planet": gs.backlash_bar()[0],
            "backlash.planet_ring": gs.backlash_bar()[1],
            "clearance.sun_bearing": gs.sun_bearing_clearance_bar(),
        }[parameter]
    else:
        return None
    return np.full(np.shape(x), b), sym


def _resonance_omegas(ds: Any) -> list[dict[str, Any]]:
    gs = _gearset(ds)
    if gs is None:
        raise ParameterError(
            "resonances need the gear set of the sweep (attribute gearset_toml); "
            "this dataset has none (a reference system?)"
        )
    from ..analysis.derived import gearset_info

    return list(gearset_info(gs)["omega_at_resonances"])


_HARMONIC_STYLES = {1: "-", 2: "--", 3: ":"}


def _resonance_lines(ax: Any, ds: Any, lo: float, hi: float) -> int:
    """Vertical lines at Ω = ω_k/(h ω_n) inside [lo, hi]; returns how many were drawn."""
    drawn = 0
    labelled: set[int] = set()
    found = sorted(_resonance_omegas(ds), key=lambda r: (int(r["harmonic"]), float(r["omega"])))
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


def _scatter_points(x: np.ndarray, y: np.ndarray, rel: float = 1e-4) -> tuple[np.ndarray, ...]:
    """Flatten (x, section values) to scatter points, dropping non-finite values; at one x,
    sorted values less than ``rel`` of the overall y range apart are drawn once (a 1T point,
    spread by integration noise, is one dot)."""
    y = np.asarray(y, dtype=np.float64)
    finite = np.isfinite(y)
    if not finite.any():
        return np.empty(0), np.empty(0)
    span = float(np.max(y[finite]) - np.min(y[finite]))
    tol = rel * max(span, 1e-12 * float(np.max(np.abs(y[finite]))))
    ys = np.sort(np.where(finite, y, np.nan), axis=1)  # NaN last
    keep = np.isfinite(ys)
    keep[:, 1:] &= np.diff(ys, axis=1) > tol
    xs = np.broadcast_to(np.asarray(x, dtype=np.float64)[:, None], ys.shape)
    return xs[keep], ys[keep]


# --------------------------------------------------------------------------- bifurcation
def bifurcation(
    ds: Any,
    ax: Any = None,
    *,
    var: str | None = "delta_sp",
    planet: int = 1,
    select: Mapping[str, Any] | None = None,
    clearance_lines: bool = False,
    resonances: bool = False,
    color: Any = None,
    s: float = 0.3,
) -> Any:
    """Bifurcation diagram: the section values of ``var`` against the swept parameter.

    For every value of the swept parameter, the recorded Poincaré section values
    X̄_k (k = 1 … periods, τ_k = 2πk/Ω after the transient) are drawn as dots: one dot for a
    1T-periodic response, n for nT, a vertical smear for quasi-periodic or chaotic motion
    (the seed's Fig. 4 with ``var="delta_sp"``).

    Parameters
    ----------
    ds : xarray.Dataset
        A sweep dataset (:func:`gearchaos.bifurcation`, :func:`gearchaos.sweep.open_sweep`).
    ax
        Axes to draw on (default: a new figure).
    var
        Section variable: ``delta_sp`` (X̄_sp, default), ``delta_sp_dot``, ``delta_rp``,
        ``x_s`` … of the observed ones; for reference systems their state names (``x``).
        ``None`` or a ``delta_sp`` the dataset lacks picks ``delta_sp`` if present, else the
        first observed variable.
    planet
        Planet of per-planet variables (one of the observed planets).
    select
        Values of the other leading dimensions, e.g. ``{"xi": 0.05}`` for one panel of a
        family, ``{"backlash.planet_ring": 3.5}`` for one line of a 2-D sweep, or
        ``{"direction": "up"}``. After selection exactly one swept dimension must remain (it
        becomes the x axis); a remaining ``direction`` dimension is drawn as two overlaid
        branches (up and down) with a legend.
    clearance_lines
        Dashed lines at ±b̄ of the variable's clearance (``gid="clearance"``): b̄ of the swept
        value when the swept parameter is that backlash (a diagonal), else the selected,
        fixed or base gear set's value.
    resonances
        When the x axis is Ω: vertical lines (``gid="resonance"``) at Ω = ω_k/(h ω_n), where
        the h-th mesh harmonic (h = 1 solid, 2 dashed, 3 dotted) meets a natural frequency
        ω_k of the linear model (:func:`gearchaos.analysis.derived.gearset_info`).
    color, s
        Dot colour (default black; up/down branches C0/C3) and size in points².

    Returns
    -------
    matplotlib.axes.Axes
        Points are rasterized, so PDF/SVG stay small. Values that coincide to 10⁻⁴ of the
        y range at one x are drawn once; points with a non-zero ``status`` are skipped and
        counted in a note in the lower right corner.
    """
    if not (isinstance(planet, int | np.integer)):
        raise ParameterError(f"planet must be an integer: got {planet!r}")
    if var == "delta_sp" and "delta_sp" not in ds.data_vars:
        var = None
    var = _resolve_var(ds, var)
    sub = _select(ds, select)
    lay = _layout(sub, var)
    rest = ([lay.family] if lay.family else []) + list(lay.vary)
    if len(rest) != 1:
        if not rest:
            raise ParameterError(
                "nothing left to plot against: select fixed every swept dimension "
                f"({', '.join(map(str, (select or {}).keys()))})"
            )
        raise ParameterError(
            f"a bifurcation diagram needs one swept dimension: the dataset has "
            f"{', '.join(rest)}; fix the others with select, e.g. "
            f"select={{{rest[0]!r}: {_fmt(sub[rest[0]].values[0])}}}"
        )
    x_name = rest[0]
    ax = get_ax(ax)
    x = np.asarray(sub[x_name].values, dtype=np.float64)

    branches: list[tuple[str | None, Any]] = []
    if lay.directions:
        branches = [(d, sub.isel(direction=i)) for i, d in enumerate(lay.directions)]
    else:
        branches = [(None, sub)]

    n_failed = n_missing = n_points = 0
    for direction, part in branches:
        da = _planet_sel(part[var], planet).transpose(x_name, "section")
        y = np.asarray(da.values, dtype=np.float64)
        status = _status(part, (x_name,))
        n_points += y.shape[0]
        if status is not None:
            n_missing += int(np.sum(status == _NOT_RUN))
            n_failed += int(np.sum((status != 0) & (status != _NOT_RUN)))
            y = np.where((status == 0)[:, None], y, np.nan)
        xs, ys = _scatter_points(x, y)
        if direction is None:
            c = "k" if color is None else color
            label = None
        else:
            c = _DIRECTION_COLOURS.get(direction, "C2") if color is None else color
            arrow = "increasing" if direction == "up" else "decreasing"
            label = f"{direction} ({arrow} {axis_symbol(x_name)})"
        ax.scatter(
            xs,
            ys,
            s=s,
            color=c,
            marker="o",
            linewidths=0,
            rasterized=True,
            label=label,
            zorder=2,
        )

    if clearance_lines:
        found = _clearance_of(sub, var, x_name, x)
        if found is not None:
            b, sym = found
            if np.all(b == b[0]):
                lines = [ax.axhline(b[0]), ax.axhline(-b[0])]
            else:
                lines = [*ax.plot(x, b), *ax.plot(x, -b)]
            label = rf"$\pm {sym} = \pm {b[0]:g}$" if np.all(b == b[0]) else rf"$\pm {sym}$"
            for k, line in enumerate(lines):
                line.set(gid=CLEARANCE_GID, zorder=1, label=label if k == 0 else None)
                line.set(**_CLEARANCE_STYLE)

    if resonances and x_name == "omega" and x.size:
        _resonance_lines(ax, sub, float(np.min(x)), float(np.max(x)))

    notes = []
    if n_failed:
        notes.append(f"{n_failed} of {n_points} points failed (not shown)")
    if n_missing:
        notes.append(f"{n_missing} of {n_points} points not run yet (incomplete store)")
    if notes:
        ax.text(
            0.99,
            0.01,
            "\n".join(notes),
            ha="right",
            va="bottom",
            fontsize="x-small",
            color="0.3",
            transform=ax.transAxes,
        )
    if x.size > 1:
        lo, hi = float(np.min(x)), float(np.max(x))
        pad = 0.01 * (hi - lo)
        ax.set_xlim(lo - pad, hi + pad)
    ax.set_xlabel(axis_label(x_name))
    ax.set_ylabel(f"${_var_symbol(var, planet if 'planet' in ds[var].dims else None)}$")
    formatter = ax.yaxis.get_major_formatter()
    if hasattr(formatter, "set_useOffset"):
        formatter.set_useOffset(False)
    if lay.directions or ((clearance_lines or resonances) and ax.get_legend_handles_labels()[0]):
        ax.legend(loc="best", fontsize="small", markerscale=6 / max(math.sqrt(s), 0.1))
    return ax


def _panel_title(k: int, name: str, value: Any, *, letters: bool) -> str:
    prefix = f"({string.ascii_lowercase[k % 26]}) " if letters else ""
    return f"{prefix}{axis_symbol(name)} = {_fmt(value)}"


def _grid(n: int) -> tuple[int, int]:
    ncols = 1 if n == 1 else 2 if n in (2, 4) else 3
    return math.ceil(n / ncols), ncols


def _given(ds: Any) -> list[str]:
    """``symbol = value`` of the seed's figure captions: Ω and the fixed overrides, then b̄_sp,
    b̄_rp, b̄_s and ξ of the (fixed-applied) gear set, leaving out the swept parameters."""
    spec = _spec(ds)
    swept = {a.name for a in spec.axes} if spec is not None else set(ds.dims)
    out: list[str] = []
    shown: set[str] = set()
    if spec is not None:
        for k, v in spec.fixed:
            if _is_number(v) and k not in swept:
                out.append(f"{axis_symbol(k)} = {_fmt(v)}")
                shown.add(k)
    try:
        gs = _gearset(ds)
    except (ParameterError, ValueError):
        gs = None
    if gs is None:
        return out
    bsp, brp = gs.backlash_bar()
    for name, value in (
        ("backlash.sun_planet", bsp),
        ("backlash.planet_ring", brp),
        ("clearance.sun_bearing", gs.sun_bearing_clearance_bar()),
    ):
        if name not in swept and name not in shown:
            out.append(f"{axis_symbol(name)} = {_fmt(value)}")
    d = gs.damping
    damping_swept = swept & {
        "xi",
        "damping.sun_planet",
        "damping.planet_ring",
        "damping.sun_bearing",
    }
    if not damping_swept and "xi" not in shown and d.sun_planet == d.planet_ring == d.sun_bearing:
        out.append(f"{axis_symbol('xi')} = {_fmt(d.sun_planet)}")
    return out


def _suptitle(ds: Any, what: str) -> str:
    name = str(ds.attrs.get("model") or "")
    try:
        gs = _gearset(ds)
    except (ParameterError, ValueError):
        gs = None
    if gs is not None:
        name = gs.name
    lines = [": ".join(p for p in (name, what) if p)]
    given = _given(ds)
    if given:
        lines.append("at " + ", ".join(given))
    t, p = ds.attrs.get("transient_periods"), ds.attrs.get("periods")
    if t is not None and p is not None:
        ic = ds.attrs.get("initial_conditions")
        lines.append(
            f"{_fmt(t)} transient + {_fmt(p)} recorded periods"
            + (f", {ic} initial conditions" if ic else "")
        )
    return "\n".join(lines)


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float | np.integer | np.floating) and not isinstance(v, bool)


def bifurcation_figure(
    ds: Any,
    *,
    var: str | None = "delta_sp",
    planet: int = 1,
    clearance_lines: bool = False,
    resonances: bool = False,
    regimes: bool | None = None,
    figsize: tuple[float, float] | None = None,
) -> Any:
    """Bifurcation diagrams of a 1-D sweep, one panel per family value.

    Panels are titled ``(a) ξ = 0.03``, ``(b) ξ = 0.05`` … like the seed's figures (no letter
    when there is one panel); for ``direction="both"`` each panel overlays the up (C0) and
    down (C3) branches. Options as in :func:`bifurcation`.

    With ``regimes`` (default: when the dataset has ``motion`` labels, as every store written
    by :func:`gearchaos.bifurcation` does) each panel gets a thin band below it coloured by
    the motion label of every swept value (:func:`~gearchaos.plot.regimes.regime_band`), and
    the figure one legend, under all panels, naming exactly the regimes present.

    Returns
    -------
    matplotlib.figure.Figure
        Not registered with pyplot; save it with :func:`gearchaos.plot.savefig`.
    """
    from matplotlib.figure import Figure

    if var == "delta_sp" and "delta_sp" not in ds.data_vars:
        var = None
    var = _resolve_var(ds, var)
    lay = _layout(ds, var)
    if len(lay.vary) != 1:
        raise ParameterError(
            f"bifurcation_figure needs a 1-D sweep: the dataset varies {', '.join(lay.vary)}; "
            "use distinct_map (or sweep_figure) for 2-D sweeps"
        )
    if regimes is None:
        regimes = "motion" in ds.data_vars
    elif regimes and "motion" not in ds.data_vars:
        raise ParameterError(
            "regimes=True needs motion labels (variable 'motion'); label the store with "
            "`gearchaos classify STORE` or pass regimes=False"
        )
    family = lay.family
    values = list(np.asarray(ds[family].values)) if family else [None]
    nrows, ncols = _grid(len(values))
    band = (0.14 if lay.directions else 0.075) if regimes else 0.0
    if figsize is None:
        extra = (0.45 * nrows + 0.5) if regimes else 0.0
        figsize = (
            (7.0, 5.0 + extra) if len(values) == 1 else (5.5 * ncols, 3.6 * nrows + 0.8 + extra)
        )
    fig = Figure(figsize=figsize, layout="constrained")
    if regimes:
        grid = fig.add_gridspec(2 * nrows, ncols, height_ratios=[1.0, band] * nrows)
        axs = np.array(
            [fig.add_subplot(grid[2 * (k // ncols), k % ncols]) for k in range(nrows * ncols)]
        )
        bands = [
            fig.add_subplot(grid[2 * (k // ncols) + 1, k % ncols], sharex=axs[k])
            for k in range(len(values))
        ]
    else:
        axs = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False)).ravel()
        bands = []
    for k, value in enumerate(values):
        ax = axs[k]
        select = {family: value} if family else None
        bifurcation(
            ds,
            ax,
            var=var,
            planet=planet,
            select=select,
            clearance_lines=clearance_lines,
            resonances=resonances,
        )
        if family:
            ax.set_title(_panel_title(k, family, value, letters=len(values) > 1), loc="left")
        if regimes:
            from .regimes import regime_band

            regime_band(ds, bands[k], select=select)
            ax.set_xlabel("")
            ax.tick_params(axis="x", labelbottom=False)
    for ax in axs[len(values) :]:
        ax.set_visible(False)
    if regimes:
        from .regimes import regime_categories, regime_handles

        cats = np.asarray(regime_categories(ds).values, dtype=object).ravel()
        handles = regime_handles(cats)
        fig.legend(
            handles=handles,
            loc="outside lower center",
            ncols=min(len(handles), 8),
            fontsize="small",
            frameon=False,
            title="motion",
            title_fontsize="small",
        )
    fig.suptitle(
        _suptitle(ds, "bifurcation diagram" + ("s" if len(values) > 1 else "")),
        fontsize="medium",
    )
    return fig


# --------------------------------------------------------------------------- distinct maps
def distinct_counts(
    ds: Any,
    *,
    var: str | None = "delta_sp",
    planet: int = 1,
    max_count: int = 16,
    tol: float = 1e-3,
) -> Any:
    """Number of distinct section points of every sweep point (a DataArray over the leading
    dimensions): n for an nT-periodic response, ``max_count + 1`` for "many", 0 for a failed
    point (non-zero status or no finite section value), −1 for a point not run yet (an
    interrupted store).

    Counts the pairs (X̄_k, X̄'_k) when the dataset holds ``<var>_dot`` (else X̄_k alone) with
    :func:`gearchaos.analysis.poincare.count_distinct` and its relative tolerance ``tol``.
    A period is recognised only when the record shows it at least twice: n > 1 distinct points
    among fewer than 2n recorded ones count as "many" (with 10 recorded periods, 10 distinct
    points may be 10T or chaos — record more periods to tell).
    """
    import xarray as xr

    from ..analysis.poincare import count_distinct

    if var == "delta_sp" and "delta_sp" not in ds.data_vars:
        var = None
    var = _resolve_var(ds, var)
    if not (isinstance(max_count, int | np.integer) and max_count >= 1):
        raise ParameterError(f"max_count must be an integer >= 1: got {max_count!r}")
    lead = _leading_dims(ds, var)
    cols = [_planet_sel(ds[var], planet).transpose(*lead, "section")]
    dot = f"{var}_dot"
    if dot in ds.data_vars and "section" in ds[dot].dims:
        cols.append(_planet_sel(ds[dot], planet).transpose(*lead, "section"))
    pts = np.stack([np.asarray(c.values, dtype=np.float64) for c in cols], axis=-1)
    shape = pts.shape[:-2]
    flat = pts.reshape(-1, pts.shape[-2], pts.shape[-1])
    status = _status(ds, lead)
    status = np.zeros(flat.shape[0], dtype=np.int64) if status is None else status.ravel()
    counts = np.where(status == _NOT_RUN, -1, 0).astype(np.int64)
    many = int(max_count) + 1
    for i in np.flatnonzero(status == 0):
        n = count_distinct(flat[i], tol=tol, max_count=int(max_count))
        n_finite = int(np.sum(np.all(np.isfinite(flat[i]), axis=1)))
        # an nT orbit is recognised only when the record shows it at least twice
        counts[i] = many if n > 1 and 2 * n > n_finite else n
    coords = {d: ds[d] for d in lead if d in ds.coords}
    return xr.DataArray(
        counts.reshape(shape),
        dims=lead,
        coords=coords,
        name="distinct_points",
        attrs={"max_count": int(max_count), "tol": float(tol), "var": var},
    )


def _edges(v: np.ndarray) -> np.ndarray:
    """Cell edges around (possibly non-uniform) centres; log-spaced centres get log edges."""
    v = np.asarray(v, dtype=np.float64)
    if v.size == 1:
        d = 0.5 * abs(v[0]) if v[0] != 0 else 0.5
        return np.array([v[0] - d, v[0] + d])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]])


def _category_colours(max_count: int) -> list[Any]:
    from matplotlib import colormaps

    tab = [tuple(c) for c in colormaps["tab20"](np.arange(20))]
    # the tab20 pairs, strong colours first, greys (indices 14, 15) left out
    order = [0, 2, 4, 6, 8, 10, 12, 16, 18, 1, 3, 5, 7, 9, 11, 13, 17, 19]
    palette = [tab[i] for i in order]
    if max_count > len(palette):
        extra = colormaps["viridis"](np.linspace(0, 1, max_count - len(palette)))
        palette += [tuple(c) for c in extra]
    return [_FAILED_COLOUR, *palette[:max_count], _MANY_COLOUR]


def distinct_map(
    ds: Any,
    ax: Any = None,
    *,
    var: str | None = "delta_sp",
    planet: int = 1,
    max_count: int = 16,
    select: Mapping[str, Any] | None = None,
    resonances: bool = False,
    colorbar: bool = True,
) -> Any:
    """Map of a 2-D sweep coloured by the number of distinct section points.

    Every grid point is one cell coloured by the count of :func:`distinct_counts`: the
    categories 1, 2, … , ``max_count`` (1T, 2T, … periodic motion), "many" (quasi-periodic
    or chaotic, more than ``max_count`` points) and "failed" (grey: non-zero status). The
    first varied parameter is on x, the second on y; a family or direction dimension must be
    fixed with ``select``. A labelled colour bar names the categories; with ``resonances``
    and Ω on x, vertical lines mark where a mesh harmonic meets a natural frequency.

    Returns
    -------
    matplotlib.axes.Axes
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap

    if var == "delta_sp" and "delta_sp" not in ds.data_vars:
        var = None
    var = _resolve_var(ds, var)
    sub = _select(ds, select)
    lay = _layout(sub, var)
    left = [*(["direction"] if lay.directions else []), *([lay.family] if lay.family else [])]
    if left:
        raise ParameterError(
            f"distinct_map draws one 2-D grid: fix {', '.join(left)} with select, e.g. "
            f"select={{{left[0]!r}: {_fmt(sub[left[0]].values[0])!r}}}"
        )
    if len(lay.vary) != 2:
        raise ParameterError(
            f"distinct_map needs a 2-D sweep: the dataset varies {', '.join(lay.vary) or 'nothing'}"
            "; use bifurcation for 1-D sweeps"
        )
    xname, yname = lay.vary
    counts = distinct_counts(sub, var=var, planet=planet, max_count=max_count)
    c = np.ma.masked_less(np.asarray(counts.transpose(yname, xname).values), 0)
    x = np.asarray(sub[xname].values, dtype=np.float64)
    y = np.asarray(sub[yname].values, dtype=np.float64)
    colours = _category_colours(int(max_count))
    cmap = ListedColormap(colours)
    norm = BoundaryNorm(np.arange(-0.5, max_count + 2.0, 1.0), cmap.N)
    ax = get_ax(ax)
    mesh = ax.pcolormesh(_edges(x), _edges(y), c, cmap=cmap, norm=norm, rasterized=True)
    ax.set_xlabel(axis_label(xname))
    ax.set_ylabel(axis_label(yname))
    if resonances and xname == "omega" and x.size:
        _resonance_lines(ax, sub, float(np.min(x)), float(np.max(x)))
    n_missing = int(np.ma.count_masked(c))
    if n_missing:
        ax.text(
            0.99,
            0.01,
            f"{n_missing} of {c.size} points not run yet (blank)",
            ha="right",
            va="bottom",
            fontsize="x-small",
            color="0.3",
            transform=ax.transAxes,
        )
    if colorbar:
        fig = ax.figure
        cb = fig.colorbar(mesh, ax=ax, ticks=np.arange(0, max_count + 2))
        labels = ["failed", *(f"{n}T" for n in range(1, max_count + 1)), "many"]
        cb.ax.set_yticklabels(labels, fontsize="x-small")
        sym = _var_symbol(var, planet if "planet" in ds[var].dims else None)
        cb.set_label(f"distinct section points of ${sym}$")
    for axis in (ax.xaxis, ax.yaxis):
        formatter = axis.get_major_formatter()
        if hasattr(formatter, "set_useOffset"):
            formatter.set_useOffset(False)
    return ax


# --------------------------------------------------------------------------- sweep_figure
def sweep_figure(
    ds: Any,
    *,
    var: str | None = "delta_sp",
    planet: int = 1,
    clearance_lines: bool = False,
    resonances: bool = False,
    max_count: int = 16,
    regimes: bool | None = None,
    figsize: tuple[float, float] | None = None,
) -> Any:
    """The figure of a sweep: :func:`bifurcation_figure` for a 1-D sweep, one map per family
    value (and per direction) for a 2-D sweep.

    With ``regimes`` (default: when the dataset has ``motion`` labels) 1-D sweeps get regime
    bands under their panels and 2-D sweeps are drawn as regime maps
    (:func:`~gearchaos.plot.regimes.regime_map`, one categorical legend for the figure);
    without, 2-D sweeps are :func:`distinct_map` s. ``clearance_lines`` applies to bifurcation
    diagrams only; ``max_count`` to distinct-point maps only.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    if var == "delta_sp" and "delta_sp" not in ds.data_vars:
        var = None
    var = _resolve_var(ds, var)
    lay = _layout(ds, var)
    if len(lay.vary) == 1:
        return bifurcation_figure(
            ds,
            var=var,
            planet=planet,
            clearance_lines=clearance_lines,
            resonances=resonances,
            regimes=regimes,
            figsize=figsize,
        )
    if regimes is None:
        regimes = "motion" in ds.data_vars
    selects: list[dict[str, Any]] = [{}]
    if lay.directions:
        selects = [{"direction": d} for d in lay.directions]
    if lay.family:
        selects = [{**s, lay.family: v} for s in selects for v in np.asarray(ds[lay.family].values)]
    nrows, ncols = _grid(len(selects))
    if figsize is None:
        figsize = (6.5 * ncols, 4.5 * nrows + 0.8)
    fig = Figure(figsize=figsize, layout="constrained")
    axs = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False)).ravel()
    for k, sel in enumerate(selects):
        if regimes:
            from .regimes import regime_map

            ax = regime_map(ds, axs[k], select=sel or None, legend=False, resonances=resonances)
        else:
            ax = distinct_map(
                ds,
                axs[k],
                var=var,
                planet=planet,
                max_count=max_count,
                select=sel or None,
                resonances=resonances,
            )
        if sel:
            parts = [
                f"{axis_symbol(d)} = {_fmt(v)}" if d != "direction" else str(v)
                for d, v in sel.items()
            ]
            prefix = f"({string.ascii_lowercase[k % 26]}) " if len(selects) > 1 else ""
            ax.set_title(prefix + ", ".join(parts), loc="left")
    for ax in axs[len(selects) :]:
        ax.set_visible(False)
    if regimes:
        from .regimes import regime_categories, regime_legend

        regime_legend(
            fig,
            np.asarray(regime_categories(ds).values, dtype=object).ravel(),
            loc="outside right upper",
        )
        fig.suptitle(_suptitle(ds, "motion regimes"), fontsize="medium")
    else:
        fig.suptitle(_suptitle(ds, "distinct Poincaré points"), fontsize="medium")
    return fig
