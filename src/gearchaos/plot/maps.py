"""Maps of 2-D sweeps and the figure of any sweep.

* :func:`distinct_counts` / :func:`distinct_map` — a 2-D sweep coloured by the number of
  distinct section points of every grid point (1T, 2T, …, many);
* :func:`sweep_figure` — whichever figure fits the dataset: bifurcation diagrams for a 1-D
  sweep (:func:`~gearchaos.plot.bifurcation.bifurcation_figure`), one regime map
  (:func:`~gearchaos.plot.regimes.regime_map`) or distinct-point map per family value and
  direction for a 2-D sweep.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from .._checks import check_bool, check_int, check_real
from ..analysis.motion import Motion
from ..errors import ParameterError, Status
from ..sweep.result import SweepResult
from ._common import (
    axis_label,
    corner_note,
    edges,
    get_ax,
    model_symbols,
    no_offset,
    parameter_symbols,
    resonance_lines,
    var_symbol,
)
from .bifurcation import (
    _planet_sel,
    bifurcation_figure,
    panel_grid,
    resolve_var,
    selection_title,
    suptitle,
)
from .regimes import regime_categories, regime_legend_below, regime_map
from .units import PhysicalScales, physical_axis

__all__ = ["distinct_counts", "distinct_map", "sweep_figure"]

_FAILED_COLOUR = "0.7"
_MANY_COLOUR = "0.1"
_NOT_RUN = int(Status.NOT_RUN)


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

    res = SweepResult.of(ds)
    ds = res.ds
    var = resolve_var(ds, var)
    if not (isinstance(max_count, int | np.integer) and max_count >= 1):
        raise ParameterError(f"max_count must be an integer >= 1: got {max_count!r}")
    lead = tuple(d for d in res.lead_dims if d in ds[var].dims)
    cols = [_planet_sel(ds[var], planet).transpose(*lead, "section")]
    dot = f"{var}_dot"
    if dot in ds.data_vars and "section" in ds[dot].dims:
        cols.append(_planet_sel(ds[dot], planet).transpose(*lead, "section"))
    pts = np.stack([np.asarray(c.values, dtype=np.float64) for c in cols], axis=-1)
    shape = pts.shape[:-2]
    flat = pts.reshape(-1, pts.shape[-2], pts.shape[-1])
    status = (
        np.asarray(ds["status"].transpose(*lead).values).ravel()
        if "status" in ds.data_vars
        else np.zeros(flat.shape[0], dtype=np.int64)
    )
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

    res = SweepResult.of(ds).select(select)
    sub = res.ds
    var = resolve_var(sub, var)
    xname, yname = res.grid_axes("distinct_map", var)
    counts = distinct_counts(res, var=var, planet=planet, max_count=max_count)
    c = np.ma.masked_less(np.asarray(counts.transpose(yname, xname).values), 0)
    x = np.asarray(sub[xname].values, dtype=np.float64)
    y = np.asarray(sub[yname].values, dtype=np.float64)
    colours = _category_colours(int(max_count))
    cmap = ListedColormap(colours)
    norm = BoundaryNorm(np.arange(-0.5, max_count + 2.0, 1.0), cmap.N)
    ax = get_ax(ax)
    mesh = ax.pcolormesh(edges(x), edges(y), c, cmap=cmap, norm=norm, rasterized=True)
    psym = parameter_symbols(sub.attrs)
    ax.set_xlabel(axis_label(xname, psym))
    ax.set_ylabel(axis_label(yname, psym))
    if resonances and xname == "omega" and x.size:
        resonance_lines(ax, res.gearset, float(np.min(x)), float(np.max(x)))
    n_missing = int(np.ma.count_masked(c))
    if n_missing:
        corner_note(ax, f"{n_missing} of {c.size} points not run yet (blank)")
    if colorbar:
        fig = ax.figure
        cb = fig.colorbar(mesh, ax=ax, ticks=np.arange(0, max_count + 2))
        periodic = (Motion.periodic(n).format() for n in range(1, max_count + 1))
        labels = [Motion.failed().format(), *periodic, "many"]
        cb.ax.set_yticklabels(labels, fontsize="x-small")
        sym = var_symbol(
            var, planet if "planet" in sub[var].dims else None, model_symbols(sub.attrs)
        )
        cb.set_label(f"distinct section points of ${sym}$")
    no_offset(ax.xaxis, ax.yaxis)
    return ax


# --------------------------------------------------------------------------- sweep_figure
#: Largest figure side in inches (a 200-inch side at 100 dpi is 20 000 pixels).
MAX_FIGURE_INCHES = 200.0


def _check_options(
    planet: Any, clearance_lines: Any, resonances: Any, max_count: Any, regimes: Any, figsize: Any
) -> None:
    """The options of :func:`sweep_figure`, checked before anything is read or drawn."""
    check_int("planet", planet, lo=1)
    check_bool("clearance_lines", clearance_lines)
    check_bool("resonances", resonances)
    check_int("max_count", max_count, lo=1, hi=10_000)
    if regimes is not None:
        check_bool("regimes", regimes)
    if figsize is not None:
        if not isinstance(figsize, tuple | list) or len(figsize) != 2:
            raise ParameterError(f"figsize must be (width, height) in inches: got {figsize!r}")
        for side in figsize:
            check_real("figsize", side, lo=0.0, hi=MAX_FIGURE_INCHES, lo_open=True)


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
    branches: Sequence[Any] = (),
) -> Any:
    """The figure of a sweep: :func:`bifurcation_figure` for a 1-D sweep, one map per family
    value (and per direction) for a 2-D sweep.

    With ``regimes`` (default: when the dataset has ``motion`` labels) 1-D sweeps get regime
    bands under their panels and 2-D sweeps are drawn as regime maps
    (:func:`~gearchaos.plot.regimes.regime_map`, one categorical legend under the panels);
    without, 2-D sweeps are :func:`distinct_map` s. Maps of a gear set get the physical axes
    opposite the dimensionless ones (:func:`~gearchaos.plot.units.physical_axis`: sun speed
    in rpm opposite Ω, µm opposite a clearance in units of b_c). ``clearance_lines`` applies
    to bifurcation diagrams only; ``max_count`` to distinct-point maps only; ``branches``
    (continued branches of periodic orbits, drawn over the diagrams of their parameter) to 1-D
    sweeps only.

    Returns
    -------
    matplotlib.figure.Figure
    """
    res = SweepResult.of(ds)
    _check_options(planet, clearance_lines, resonances, max_count, regimes, figsize)
    ds = res.ds
    var = resolve_var(ds, var)
    lay = res.layout(var)
    if var is not None and "planet" in ds[var].dims:
        _planet_sel(ds[var], planet)  # an unobserved planet is refused, whatever the figure
    if len(lay.vary) == 1:
        return bifurcation_figure(
            res,
            var=var,
            planet=planet,
            clearance_lines=clearance_lines,
            resonances=resonances,
            regimes=regimes,
            figsize=figsize,
            branches=branches,
        )
    if regimes is None:
        regimes = "motion" in ds.data_vars

    def draw(ax: Any, sel: dict[str, Any] | None) -> Any:
        if regimes:
            return regime_map(res, ax, select=sel, legend=False, resonances=resonances)
        return distinct_map(
            res, ax, var=var, planet=planet, max_count=max_count, select=sel,
            resonances=resonances,
        )  # fmt: skip

    fig = map_panels(res, lay, draw, figsize, height=4.5)
    if regimes:
        # under the panels, as the other figures' regime legends: beside them at the top it
        # covered the end of a long title
        regime_legend_below(fig, np.asarray(regime_categories(res).values, dtype=object).ravel())
        fig.suptitle(suptitle(res, "motion regimes"), fontsize="medium")
    else:
        fig.suptitle(suptitle(res, "distinct Poincaré points"), fontsize="medium")
    return fig


def map_panels(
    res: SweepResult,
    lay: Any,
    draw: Callable[[Any, dict[str, Any] | None], Any],
    figsize: tuple[float, float] | None,
    *,
    height: float,
    physical: bool = True,
) -> Any:
    """The figure of a 2-D map over ``lay.vary`` (regimes, distinct points, impact): one panel
    per direction and family value, each drawn by ``draw(ax, selection or None)``, with the
    physical axes opposite the dimensionless ones (rpm opposite Ω, µm opposite a clearance …:
    :func:`~gearchaos.plot.units.physical_axis`, as the stability chart) and its selection as
    its title; spare panels hidden. ``height``: inches a row of panels."""
    from matplotlib.figure import Figure

    selects: list[dict[str, Any]] = [{}]
    if lay.directions:
        selects = [{"direction": d} for d in lay.directions]
    if lay.family:
        values = np.asarray(res.ds[lay.family].values)
        selects = [{**s, lay.family: v} for s in selects for v in values]
    nrows, ncols = panel_grid(len(selects))
    fig = Figure(figsize=figsize or (6.5 * ncols, height * nrows + 0.8), layout="constrained")
    axs = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False)).ravel()
    scales = PhysicalScales.of_sweep(res) if physical else PhysicalScales()
    symbols = parameter_symbols(res.ds.attrs)
    for k, sel in enumerate(selects):
        ax = draw(axs[k], sel or None)
        physical_axis(ax, "x", lay.vary[0], scales, res.gearset)
        physical_axis(ax, "y", lay.vary[1], scales, res.gearset)
        if sel:
            ax.set_title(selection_title(sel, k, len(selects), symbols), loc="left")
    for ax in axs[len(selects) :]:
        ax.set_visible(False)
    return fig
