"""Bifurcation diagrams of sweep stores (:func:`gearchaos.bifurcation`).

A sweep dataset has leading dimensions (``direction`` when both directions were run, the
family axis, the varied axes — named by their dotted parameter names), then ``section`` (one
Poincaré point per recorded mesh period) and ``planet`` (the observed planets). These plots
read such a dataset (an open Zarr store, the return value of :func:`gearchaos.bifurcation`, or
a :class:`~gearchaos.sweep.SweepResult`) and never simulate:

* :func:`bifurcation` — section values of one variable against one swept parameter, the seed's
  bifurcation diagram (Fig. 4: X̄_sp1 against Ω);
* :func:`bifurcation_figure` — one panel per family value, titled ``(a) ξ = 0.03`` … like the
  seed's figures; up and down continuation branches overlaid in two colours outside the regime
  palette, with a regime band under every panel when the store has motion labels.

Maps of 2-D sweeps are in :mod:`gearchaos.plot.maps`.
"""

from __future__ import annotations

import math
import string
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..errors import ParameterError, Status
from ..sweep.result import SweepResult
from ._common import (
    _CLEARANCE_STYLE,
    CLEARANCE_GID,
    at_line,
    axis_label,
    axis_symbol,
    corner_note,
    fmt,
    get_ax,
    given,
    given_values,
    model_symbols,
    no_offset,
    parameter_symbols,
    resonance_lines,
    subject,
    var_symbol,
)
from .branch import BRANCH_COLOURS, branch_labels, branch_matches, branch_overlay
from .placement import place_event_labels
from .regimes import regime_band, regime_categories, regime_legend_below
from .units import (
    PhysicalScales,
    clearance_notes,
    fit_to_data,
    notes_clear_of,
    physical_axis,
    secondary_axis,
)

__all__ = ["bifurcation", "bifurcation_figure", "resolve_var", "suptitle"]

#: Colours of the up and down branches of a continuation sweep: dark teal and dark brown, none
#: of them a regime colour (:data:`~gearchaos.plot.regimes.REGIME_COLOURS`: the dots of a
#: branch say where it went, not what motion it is) and told apart with every common colour
#: vision (CIEDE2000 ΔE ≥ 10 from every regime colour and ≥ 15 from each other under
#: simulated protan-, deutan- and tritanopia; tests/plot/test_palette_contrast.py).
DIRECTION_COLOURS = {"up": "#01665e", "down": "#543005"}
_NOT_RUN = int(Status.NOT_RUN)


def resolve_var(ds: Any, var: str | None) -> str:
    """The section variable to draw: ``var`` if the dataset has it; ``None`` or a missing
    ``delta_sp`` picks ``delta_sp`` if present, else the first section variable."""
    names = [str(n) for n in ds.data_vars if "section" in ds[n].dims]
    if var == "delta_sp" and "delta_sp" not in names:
        var = None
    if var is None:
        if "delta_sp" in names:
            return "delta_sp"
        if not names:
            raise ParameterError("ds holds no section variable (dimension 'section')")
        return names[0]
    if var not in names:
        raise ParameterError(
            f"var must name a section variable of the dataset ({', '.join(names)}): got {var!r}"
        )
    return var


def _planet_sel(da: Any, planet: int) -> Any:
    if "planet" not in da.dims:
        return da
    planets = [int(p) for p in np.asarray(da["planet"].values)]
    if planet not in planets:
        raise ParameterError(
            f"planet must be one of the observed planets {planets}: got {planet!r}"
        )
    return da.sel(planet=planet)


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
    s: float | None = None,
    branches: Sequence[Any] = (),
    physical: bool = True,
    relative: bool | None = None,
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
        ω_k of the linear model (:func:`gearchaos.model.derived.gearset_info`).
    color, s
        Dot colour (default black; up/down branches :data:`DIRECTION_COLOURS`) and size in
        points² (default: from 0.3 for 10⁴ or more drawn values up to 6 for a few hundred, so
        that a coarse sweep stays visible and a fine one keeps its structure).
    branches
        Continued branches of periodic orbits (:func:`gearchaos.continuation`) to overlay:
        those of the x-axis parameter whose fixed values agree with ``select`` are drawn,
        stable solid, unstable dashed, with their events marked and named
        (:func:`~gearchaos.plot.branch.branch_overlay`), in the quantity the diagram shows
        (X̄ − b̄ when ``relative``); each named in the legend by its file (or its start).
    physical
        Physical axes opposite the dimensionless ones: the variable in µm (mm/s, N) on the
        right, and when the x axis is Ω the sun speed in rpm on top (gear sets only).
    relative
        Draw X̄ − b̄ (the deflection beyond the drive-flank edge of the clearance) instead of
        X̄. ``None`` (default) does so exactly when the swept parameter is the clearance of
        ``var`` itself (b̄_sp for X̄_sp …): X̄ then grows with b̄
        and the attractor would be a thin band along the diagonal X̄ = b̄; the clearance edges
        become X̄ − b̄ = 0 (drive flank) and −2b̄ (back flank).

    Returns
    -------
    matplotlib.axes.Axes
        Points are rasterized, so PDF/SVG stay small. Values that coincide to 10⁻⁴ of the
        y range at one x are drawn once; points with a non-zero ``status`` are skipped and
        counted in a note in the lower right corner.
    """
    if not (isinstance(planet, int | np.integer)):
        raise ParameterError(f"planet must be an integer: got {planet!r}")
    res = SweepResult.of(ds).select(select)
    sub = res.ds
    var = resolve_var(sub, var)
    lay = res.layout(var)
    x_name = res.line_axis("a bifurcation diagram", var)
    psym = parameter_symbols(sub.attrs)
    ax = get_ax(ax)
    x = np.asarray(sub[x_name].values, dtype=np.float64)
    found = res.clearance(var)
    b_line: np.ndarray = np.full(x.shape, np.nan)  # the clearance along the x axis
    clear_sym = ""
    if found is not None:
        b_line = np.asarray(found[0], dtype=np.float64)
        if b_line.ndim > 1:  # a direction dimension: the clearance does not depend on it
            b_line = b_line.reshape(-1, b_line.shape[-1])[0]
        clear_sym = found[1]
    if relative is None:
        relative = bool(
            found is not None and b_line.size == x.size > 1 and not np.all(b_line == b_line[0])
        )
    if relative and (found is None or b_line.size != x.size):
        raise ParameterError(
            f"relative=True needs a clearance of {var!r} along the swept axis {x_name!r}"
        )

    parts: list[tuple[str | None, Any]] = []
    if lay.directions:
        parts = [(d, sub.isel(direction=i)) for i, d in enumerate(lay.directions)]
    else:
        parts = [(None, sub)]

    n_failed = n_missing = n_points = 0
    all_y: list[np.ndarray] = []
    for direction, part in parts:
        da = _planet_sel(part[var], planet).transpose(x_name, "section")
        y = np.asarray(da.values, dtype=np.float64)
        status = np.asarray(part["status"].transpose(x_name).values) if "status" in part else None
        n_points += y.shape[0]
        if status is not None:
            n_missing += int(np.sum(status == _NOT_RUN))
            n_failed += int(np.sum((status != 0) & (status != _NOT_RUN)))
            y = np.where((status == 0)[:, None], y, np.nan)
        if relative:
            y = y - b_line[:, None]
        xs, ys = _scatter_points(x, y)
        all_y.append(ys)
        if direction is None:
            c = "k" if color is None else color
            label = None
        else:
            c = DIRECTION_COLOURS.get(direction, "0.4") if color is None else color
            arrow = "increasing" if direction == "up" else "decreasing"
            label = f"{direction} ({arrow} {axis_symbol(x_name, psym)})"
        ax.scatter(
            xs,
            ys,
            s=float(np.clip(3000.0 / max(xs.size, 1), 0.3, 6.0)) if s is None else s,
            color=c,
            marker="o",
            linewidths=0,
            rasterized=True,
            label=label,
            zorder=2,
        )

    if not clearance_lines:
        found = None
    if found is not None and relative:
        b, sym = b_line, found[1]
        lines = [ax.axhline(0.0), *ax.plot(x, -2.0 * b)]
        label = rf"flank edges $\bar X = \pm {sym}$"
        for k, line in enumerate(lines):
            line.set(gid=CLEARANCE_GID, zorder=1, label=label if k == 0 else None)
            line.set(**_CLEARANCE_STYLE)
    elif found is not None:
        b = b_line
        sym = found[1]
        if np.all(b == b[0]):
            lines = [ax.axhline(b[0]), ax.axhline(-b[0])]
        else:
            lines = [*ax.plot(x, b), *ax.plot(x, -b)]
        label = rf"$\pm {sym} = \pm {b[0]:g}$" if np.all(b == b[0]) else rf"$\pm {sym}$"
        for k, line in enumerate(lines):
            line.set(gid=CLEARANCE_GID, zorder=1, label=label if k == 0 else None)
            line.set(**_CLEARANCE_STYLE)

    if resonances and x_name == "omega" and x.size:
        resonance_lines(ax, res.gearset, float(np.min(x)), float(np.max(x)))
    shown = [b for b in branches if branch_matches(b, x_name, select)]
    named: set[str] = set()
    for k, (branch, text) in enumerate(zip(shown, branch_labels(shown), strict=True)):
        colour = BRANCH_COLOURS[(k + 2) % len(BRANCH_COLOURS)]
        branch_overlay(
            branch, ax, var=var, planet=planet, color=colour, label=text, relative=relative,
            named=named,
        )  # fmt: skip

    notes = []
    if n_failed:
        notes.append(f"{n_failed} of {n_points} points failed (not shown)")
    if n_missing:
        notes.append(f"{n_missing} of {n_points} points not run yet (incomplete store)")
    if notes:
        corner_note(ax, "\n".join(notes))
    if x.size > 1:
        lo, hi = float(np.min(x)), float(np.max(x))
        pad = 0.01 * (hi - lo)
        ax.set_xlim(lo - pad, hi + pad)
    # the y axis follows the section values (the clearance lines and branches never widen it)
    # drawn relative to b̄, the degenerate-span test still uses |X̄| (integration noise scales
    # with it), so a settled point does not become a magnified cloud of round-off
    mag = (
        float(np.nanmax(np.abs(np.concatenate(all_y)) + np.nanmax(b_line)))
        if (relative and all_y and np.concatenate(all_y).size)
        else None
    )
    fit_to_data(ax, None, np.concatenate(all_y) if all_y else None, mag=mag)
    levels = np.asarray(found[0], dtype=np.float64).ravel() if found is not None else None
    if found is not None and relative:
        edge = rf"drive-flank edge $\bar X = {found[1]}$"
        if clearance_notes(ax, "y", (0.0,), found[1], text=edge) and np.all(
            -2.0 * b_line < ax.get_ylim()[0]
        ):
            for line in ax.get_lines():  # the edges are off the axes: the note replaces them
                if line.get_gid() == CLEARANCE_GID:
                    line.set_label("_nolegend_")
    elif found is not None and levels is not None and np.all(levels == levels[0]):
        if clearance_notes(ax, "y", (-levels[0], levels[0]), found[1]) and not (
            ax.get_ylim()[0] <= levels[0] <= ax.get_ylim()[1]
            or ax.get_ylim()[0] <= -levels[0] <= ax.get_ylim()[1]
        ):
            for line in ax.get_lines():  # both lines off the axes: the notes replace them
                if line.get_gid() == CLEARANCE_GID:
                    line.set_label("_nolegend_")
    ax.set_xlabel(axis_label(x_name, psym))
    symbol = var_symbol(
        var, planet if "planet" in sub[var].dims else None, model_symbols(sub.attrs)
    )
    if relative:
        symbol += f" - {clear_sym}"
    ax.set_ylabel(f"${symbol}$")
    no_offset(ax.yaxis)
    if physical:
        scales = PhysicalScales.of_sweep(res)
        secondary_axis(ax, "y", scales.quantity(var), scales)
        # rpm opposite Ω, µm opposite a clearance in b_c (a clearance in metres read in µm)
        physical_axis(ax, "x", x_name, scales, res.gearset)
    if lay.directions or (
        (clearance_lines or resonances or branches) and ax.get_legend_handles_labels()[0]
    ):
        legend = ax.legend(loc="best", fontsize="small")
        for handle in legend.legend_handles:  # the diagram's dots are too small for a legend
            if handle is not None and hasattr(handle, "set_sizes") and len(handle.get_sizes()):
                handle.set_sizes([max(float(handle.get_sizes()[0]), 16.0)])
        notes_clear_of(ax, legend)
    return ax


def _panel_title(
    k: int, name: str, value: Any, *, letters: bool, symbols: Mapping[str, str] | None = None
) -> str:
    prefix = f"({string.ascii_lowercase[k % 26]}) " if letters else ""
    return f"{prefix}{given(name, value, symbols)}"


def selection_title(
    sel: Mapping[str, Any], k: int, n: int, symbols: Mapping[str, str] | None = None
) -> str:
    """The title of panel k of n that shows the selection ``sel`` (family or direction
    values): ``(b) ξ = 0.05, up``, the letter only when there are several panels;
    ``symbols``: the model's parameter symbols
    (:func:`~gearchaos.plot._common.parameter_symbols`)."""
    parts = [given(d, v, symbols) if d != "direction" else str(v) for d, v in sel.items()]
    prefix = f"({string.ascii_lowercase[k % 26]}) " if n > 1 else ""
    return prefix + ", ".join(parts)


def panel_grid(n: int) -> tuple[int, int]:
    """(rows, columns) of a figure with n panels."""
    ncols = 1 if n == 1 else 2 if n in (2, 4) else 3
    return math.ceil(n / ncols), ncols


def _given(res: SweepResult) -> list[str]:
    """``symbol = value`` of the seed's figure captions (:func:`given_values`): Ω and the
    fixed overrides, then b̄_sp, b̄_rp, b̄_s and ξ of the (fixed-applied) gear set or a reference
    system's parameters, leaving out the swept parameters."""
    return given_values(
        res.ds.attrs, fixed=res.fixed, gearset=res.gearset, leave_out=res.swept_names
    )


def suptitle(ds: Any, what: str) -> str:
    """The figure title of a sweep: the gear set (or model) and ``what``, the given values,
    the protocol."""
    res = SweepResult.of(ds)
    attrs = res.ds.attrs
    lines = [": ".join(p for p in (subject(attrs, res.gearset), what) if p)]
    values = _given(res)
    if values:
        lines.append(at_line(values))
    t, p = attrs.get("transient_periods"), attrs.get("periods")
    if t is not None and p is not None:
        ic = attrs.get("initial_conditions")
        lines.append(
            f"{fmt(t)} transient + {fmt(p)} recorded periods"
            + (f", {ic} initial conditions" if ic else "")
        )
    return "\n".join(lines)


def bifurcation_figure(
    ds: Any,
    *,
    var: str | None = "delta_sp",
    planet: int = 1,
    clearance_lines: bool = False,
    resonances: bool = False,
    regimes: bool | None = None,
    figsize: tuple[float, float] | None = None,
    branches: Sequence[Any] = (),
) -> Any:
    """Bifurcation diagrams of a 1-D sweep, one panel per family value.

    Panels are titled ``(a) ξ = 0.03``, ``(b) ξ = 0.05`` … like the seed's figures (no letter
    when there is one panel); for ``direction="both"`` each panel overlays the up (dark teal)
    and down (dark brown) branches. Options as in :func:`bifurcation`.

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

    res = SweepResult.of(ds)
    ds = res.ds
    var = resolve_var(ds, var)
    lay = res.layout(var)
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
    nrows, ncols = panel_grid(len(values))
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
            res,
            ax,
            var=var,
            planet=planet,
            select=select,
            clearance_lines=clearance_lines,
            resonances=resonances,
            branches=branches,
        )
        if family:
            ax.set_title(
                _panel_title(
                    k,
                    family,
                    value,
                    letters=len(values) > 1,
                    symbols=parameter_symbols(res.ds.attrs),
                ),
                loc="left",
            )
        if regimes:
            regime_band(res, bands[k], select=select)
            bands[k].set_xlabel(ax.get_xlabel())  # the diagram's: µm for a clearance in metres
            ax.set_xlabel("")
            ax.tick_params(axis="x", labelbottom=False)
    for ax in axs[len(values) :]:
        ax.set_visible(False)
    if regimes:
        cats = np.asarray(regime_categories(res).values, dtype=object).ravel()
        regime_legend_below(fig, cats)
    fig.suptitle(
        suptitle(res, "bifurcation diagram" + ("s" if len(values) > 1 else "")),
        fontsize="medium",
    )
    place_event_labels(fig)  # last: the layout is final
    return fig
