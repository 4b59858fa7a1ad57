"""Motion regimes in colour: one fixed categorical palette, regime bands and regime maps.

Every sweep store carries a motion label per point (``motion``: ``1T`` … ``nT``, ``QP``,
``chaos``, ``unresolved``, ``failed``; :func:`gearchaos.sweep.classify_store`). This module
draws them with one palette used by every figure of the package (bands, maps, Poincaré
galleries, the CLI's regime tables), so a colour means the same regime everywhere:

* :data:`REGIME_COLOURS` — the palette, by display category (:data:`REGIME_ORDER`); periods
  beyond 8T are grouped as ``≥ 9T``; a point of an interrupted store that was never run is
  ``not run``;
* :func:`regime_band` — a thin coloured strip under a 1-D bifurcation panel with the label of
  every swept value (two rows for up/down continuation branches);
* :func:`regime_map` — a 2-D sweep (Ω × ξ, Ω × b̄_rp, …) as a categorical map;
* :func:`regime_legend` / :func:`regime_handles` — a legend that names exactly the regimes
  present.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from types import MappingProxyType
from typing import Any

import numpy as np

from ..analysis.motion import Motion
from ..errors import ParameterError, Status
from ..sweep.result import SweepResult
from ._common import axis_label, edges, get_ax, no_offset, parameter_symbols, resonance_lines

__all__ = [
    "NOT_RUN",
    "PERIODIC_CATEGORIES",
    "REGIME_COLOURS",
    "REGIME_GID",
    "REGIME_ORDER",
    "regime_band",
    "regime_categories",
    "regime_category",
    "regime_colour",
    "regime_handles",
    "regime_legend",
    "regime_legend_below",
    "regime_map",
]

#: Largest period shown in a colour of its own; longer ones are grouped as ``≥ 9T``.
MAX_OWN_PERIOD = 8
#: Display category of a point of an interrupted store that was never computed (status 4).
NOT_RUN = Motion.not_run().format()
#: ``gid`` prefix of the artists drawn by :func:`regime_band` and :func:`regime_map`.
REGIME_GID = "regime"

_LONG_PERIODS = f"≥ {Motion.periodic(MAX_OWN_PERIOD + 1)}"

#: Display categories of periodic motion: 1T … 8T and ``≥ 9T``.
PERIODIC_CATEGORIES: tuple[str, ...] = (
    *(Motion.periodic(n).format() for n in range(1, MAX_OWN_PERIOD + 1)),
    _LONG_PERIODS,
)
#: Display categories in legend order.
REGIME_ORDER: tuple[str, ...] = (
    *PERIODIC_CATEGORIES,
    *(
        m.format()
        for m in (
            Motion.quasi_periodic(),
            Motion.chaos(),
            Motion.unresolved(),
            Motion.failed(),
            Motion.not_run(),
        )
    ),
)

#: The palette: display category → colour (hex). Periodic orbits in blues, greens, olive,
#: indigo and pink, quasi-periodic orange, chaos red, unresolved grey, failed black, not run
#: white. 5T is Tol's indigo, not the brown it was: brown sat as close to the unresolved grey
#: and to chaos red as CIEDE2000 ΔE 16 and 10 under simulated deutan- and protanopia, indigo
#: stands ≥ 19 from every other colour of the palette under every colour vision.
REGIME_COLOURS: Mapping[str, str] = MappingProxyType(
    {
        "1T": "#1f77b4",
        "2T": "#17becf",
        "3T": "#2ca02c",
        "4T": "#bcbd22",
        "5T": "#332288",
        "6T": "#e377c2",
        "7T": "#9edae5",
        "8T": "#98df8a",
        _LONG_PERIODS: "#c5b0d5",
        "QP": "#ff7f0e",
        "chaos": "#d62728",
        "unresolved": "#7f7f7f",
        "failed": "#000000",
        NOT_RUN: "#ffffff",
    }
)

_NOT_RUN_STATUS = int(Status.NOT_RUN)


# --------------------------------------------------------------------------- categories
def regime_category(label: Any) -> str:
    """Display category of a motion label: ``1T`` … ``8T`` as they are, ``9T`` and longer as
    ``≥ 9T``, ``QP``, ``chaos``, ``unresolved``, ``failed``; an empty label is ``not run``,
    anything else (e.g. the old ``many``) ``unresolved``."""
    s = str(label).strip()
    if s in REGIME_COLOURS:  # a category already (``≥ 9T`` is one, not a label)
        return s
    try:
        motion = Motion.parse(s)  # the empty text of a store's unset point: not run
    except ParameterError:
        return Motion.unresolved().format()
    if motion.is_periodic and motion.period > MAX_OWN_PERIOD:
        return _LONG_PERIODS
    return motion.format()


def regime_colour(label: Any) -> str:
    """The palette colour of a motion label (see :func:`regime_category`)."""
    return REGIME_COLOURS[regime_category(label)]


def _ordered(categories: Iterable[str]) -> list[str]:
    present = set(categories)
    return [c for c in REGIME_ORDER if c in present]


def regime_handles(labels: Iterable[Any]) -> list[Any]:
    """Legend patches for the display categories of ``labels``, in :data:`REGIME_ORDER`
    (each category once, only those present)."""
    from matplotlib.patches import Patch

    return [
        Patch(facecolor=REGIME_COLOURS[c], edgecolor="0.3", linewidth=0.5, label=c)
        for c in _ordered(regime_category(x) for x in labels)
    ]


def regime_legend(target: Any, labels: Iterable[Any], **kwargs: Any) -> Any:
    """A legend on ``target`` (an Axes or a Figure) naming exactly the regimes of ``labels``.

    Keyword arguments go to ``target.legend``; the defaults are a ``motion`` title and a small
    font. Returns the legend (None when ``labels`` is empty).
    """
    handles = regime_handles(labels)
    if not handles:
        return None
    opts: dict[str, Any] = {"title": "motion", "fontsize": "small", "title_fontsize": "small"}
    opts.update(kwargs)
    return target.legend(handles=handles, **opts)


def regime_legend_below(fig: Any, labels: Iterable[Any], *, title: str = "motion") -> Any:
    """One legend under all panels of ``fig`` naming exactly the regimes of ``labels``: in
    one row where the figure is wide enough (0.85 inch a regime, 8 at most), else in rows of
    equal length."""
    handles = regime_handles(labels)
    widest = max(1, min(8, int(fig.get_figwidth() / 0.85)))
    rows = math.ceil(len(handles) / widest) if handles else 1
    return fig.legend(
        handles=handles,
        loc="outside lower center",
        ncols=max(1, math.ceil(len(handles) / rows)),
        fontsize="small",
        frameon=False,
        title=title,
        title_fontsize="small",
    )


def regime_categories(ds: Any, *, select: Mapping[str, Any] | None = None) -> Any:
    """Display categories of every point of a sweep dataset (a DataArray of ``motion``'s
    dimensions), after fixing the dimensions in ``select``; points with status 4 (never run,
    an interrupted store) are ``not run``.

    Raises
    ------
    ParameterError
        The dataset has no ``motion`` labels (label a store with ``gearchaos classify STORE``
        or :func:`gearchaos.sweep.classify_store`).
    """
    res = SweepResult.of(ds)
    if "motion" not in res.ds.data_vars:
        raise ParameterError(
            "the dataset has no motion labels (variable 'motion'); label a store with "
            "`gearchaos classify STORE` or gearchaos.sweep.classify_store(STORE)"
        )
    sub = res.select(select).ds
    motion = sub["motion"]
    cats = np.vectorize(regime_category, otypes=[object])(np.asarray(motion.values, dtype=str))
    cats = np.asarray(cats, dtype=object).reshape(motion.shape)
    if "status" in sub.data_vars and sub["status"].dims == motion.dims:
        cats = np.where(np.asarray(sub["status"].values) == _NOT_RUN_STATUS, NOT_RUN, cats)
    return motion.copy(data=cats)


def _runs(cats: list[str]) -> list[tuple[int, int, str]]:
    """Maximal runs (start, stop, category) of equal neighbours."""
    out: list[tuple[int, int, str]] = []
    start = 0
    for i in range(1, len(cats) + 1):
        if i == len(cats) or cats[i] != cats[start]:
            out.append((start, i, cats[start]))
            start = i
    return out


# --------------------------------------------------------------------------- band
def regime_band(
    ds: Any,
    ax: Any = None,
    *,
    select: Mapping[str, Any] | None = None,
    legend: bool = False,
) -> Any:
    """A thin strip coloured by the motion label of every value of the swept parameter.

    Meant to sit under a :func:`~gearchaos.plot.bifurcation` panel with a shared x axis
    (:func:`~gearchaos.plot.bifurcation_figure` does that): each swept value owns the cell from
    the midpoint to its left neighbour to the midpoint to its right one, so the colours line up
    with the dots above; runs of one label are drawn as one bar (``gid="regime:<category>"``).

    Parameters
    ----------
    ds : xarray.Dataset
        A sweep dataset with ``motion`` labels (every store written by
        :func:`gearchaos.bifurcation`; older ones after ``gearchaos classify STORE``).
    ax
        Axes to draw on (default: a new figure).
    select
        Values of the other leading dimensions, as for :func:`~gearchaos.plot.bifurcation`
        (e.g. ``{"xi": 0.05}``); exactly one swept dimension must remain. A remaining
        ``direction`` dimension is drawn as two rows, up above down.
    legend
        Add a legend naming the regimes present (figures put one legend under all panels
        instead).

    Returns
    -------
    matplotlib.axes.Axes
        y ticks hidden (or naming the branches), x label the swept parameter, x limits the
        outer cell edges.
    """
    res = SweepResult.of(ds).select(select)
    sub = res.ds
    cats_da = regime_categories(res)
    directions = res.layout("motion").directions
    x_name = res.line_axis("a regime band", "motion")
    x = np.asarray(sub[x_name].values, dtype=np.float64)
    order = np.argsort(x, kind="stable")
    cell = edges(x[order])
    rows: list[tuple[str | None, Any]]
    if directions:
        rows = [(d, cats_da.isel(direction=i)) for i, d in enumerate(directions)]
    else:
        rows = [(None, cats_da)]
    ax = get_ax(ax)
    n_rows = len(rows)
    seen: list[str] = []
    for r, (_, da) in enumerate(rows):
        cats = [str(c) for c in np.asarray(da.transpose(x_name).values)[order]]
        y0 = n_rows - 1 - r  # first row on top
        spans: dict[str, list[tuple[float, float]]] = {}
        for i, j, cat in _runs(cats):
            spans.setdefault(cat, []).append((float(cell[i]), float(cell[j] - cell[i])))
        for cat in _ordered(spans):
            ax.broken_barh(
                spans[cat],
                (y0, 1.0),
                facecolors=REGIME_COLOURS[cat],
                edgecolors="none",
                gid=f"{REGIME_GID}:{cat}",
                label=cat if cat not in seen else None,
                rasterized=len(x) > 200,
            )
            seen.append(cat)
    ax.set_ylim(0.0, float(n_rows))
    ax.set_xlim(float(cell[0]), float(cell[-1]))
    if directions:
        ax.set_yticks([n_rows - 0.5 - r for r in range(n_rows)], [d for d, _ in rows])
        ax.tick_params(axis="y", labelsize="x-small", length=0)
    else:
        ax.set_yticks([])
    ax.set_xlabel(axis_label(x_name, parameter_symbols(sub.attrs)))
    no_offset(ax.xaxis)
    if legend:
        regime_legend(ax, seen, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    return ax


# --------------------------------------------------------------------------- map
def regime_map(
    ds: Any,
    ax: Any = None,
    *,
    select: Mapping[str, Any] | None = None,
    legend: bool = True,
    resonances: bool = False,
) -> Any:
    """A 2-D sweep (Ω × ξ, Ω × b̄_rp, …) as a map coloured by the motion label of every point.

    The first varied parameter is on x, the second on y; every grid point is one cell
    (``pcolormesh``, ``gid="regime"``) coloured from :data:`REGIME_COLOURS`. A family or
    direction dimension must be fixed with ``select``. With ``legend`` a categorical legend
    right of the map names exactly the regimes present; with ``resonances`` and Ω on x,
    vertical lines mark where a mesh harmonic meets a natural frequency (as in
    :func:`~gearchaos.plot.bifurcation`).

    Returns
    -------
    matplotlib.axes.Axes
        The mesh's data are indices into the categories present (in :data:`REGIME_ORDER`), so
        ``mesh.to_rgba(mesh.get_array())`` gives each cell's colour.
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap

    res = SweepResult.of(ds).select(select)
    sub = res.ds
    cats_da = regime_categories(res)
    xname, yname = res.grid_axes("regime_map", "motion")
    cats = np.asarray(cats_da.transpose(yname, xname).values, dtype=object)
    present = _ordered(str(c) for c in cats.ravel())
    index = {c: k for k, c in enumerate(present)}
    codes = np.vectorize(index.__getitem__, otypes=[np.int64])(cats) if cats.size else cats
    x = np.asarray(sub[xname].values, dtype=np.float64)
    y = np.asarray(sub[yname].values, dtype=np.float64)
    ox, oy = np.argsort(x, kind="stable"), np.argsort(y, kind="stable")
    codes = np.asarray(codes)[np.ix_(oy, ox)]
    cmap = ListedColormap([REGIME_COLOURS[c] for c in present])
    norm = BoundaryNorm(np.arange(-0.5, len(present) + 0.5, 1.0), cmap.N)
    ax = get_ax(ax)
    ax.pcolormesh(
        edges(x[ox]),
        edges(y[oy]),
        codes,
        cmap=cmap,
        norm=norm,
        rasterized=True,
        gid=REGIME_GID,
    )
    psym = parameter_symbols(sub.attrs)
    ax.set_xlabel(axis_label(xname, psym))
    ax.set_ylabel(axis_label(yname, psym))
    if resonances and xname == "omega" and x.size:
        resonance_lines(ax, res.gearset, float(np.min(x)), float(np.max(x)))
    no_offset(ax.xaxis, ax.yaxis)
    if legend:
        regime_legend(ax, present, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    return ax
