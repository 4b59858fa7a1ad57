"""Impact maps: the contact regime of a mesh over two swept parameters.

A classified sweep store of a gear set carries, per point and planet, the contact regime of
each mesh over the recorded window (``contact_sp``, ``contact_rp``; MODEL.md §8, written by
:func:`gearchaos.sweep.classify_store` from the stored minimum deflections): 0 no impact (the
teeth never separate), 1 single-sided impact (they separate and meet again on the drive
flank), 2 double-sided impact (they hit the back flank too), −1 unknown (a failed point).
:func:`impact_map` draws one mesh of one planet as a categorical map over a 2-D sweep (the
codes themselves are the image's data), :func:`impact_figure` one map per family value and
direction with physical axes (sun speed in rpm, clearances in µm) opposite the dimensionless
ones — where a gear train rattles (single-sided) or hits both flanks (double-sided), next to
the motion-regime map of the same store.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..sweep.result import SweepResult
from ._common import axis_label, edges, get_ax, no_offset, parameter_symbols

__all__ = ["IMPACT_COLOURS", "IMPACT_GID", "IMPACT_NAMES", "impact_figure", "impact_map"]

#: ``gid`` of the mesh drawn by :func:`impact_map`.
IMPACT_GID = "impact"
#: Colour of each contact code (its data value in the map).
IMPACT_COLOURS: dict[int, str] = {-1: "#ffffff", 0: "#cfe0ef", 1: "#f2a541", 2: "#a4161a"}
#: Legend name of each contact code (the store's ``flag_meanings``, in words).
IMPACT_NAMES: dict[int, str] = {
    -1: "unknown (failed point)",
    0: "no impact",
    1: "single-sided impact",
    2: "double-sided impact",
}
#: Mesh names accepted, and the store's key of each.
MESHES = {"sp": "sp", "sun_planet": "sp", "rp": "rp", "planet_ring": "rp"}
MESH_WORDS = {"sp": "sun–planet", "rp": "planet–ring"}


def _mesh_key(mesh: str) -> str:
    key = MESHES.get(str(mesh))
    if key is None:
        raise ParameterError(f"mesh must be one of {', '.join(MESHES)}: got {mesh!r}")
    return key


def contact_codes(res: SweepResult, mesh: str, planet: int | None) -> tuple[Any, str]:
    """The contact codes of ``mesh`` (DataArray over the swept dimensions) of ``planet``
    (``None``: the most severe over the planets), and the variable's name."""
    key = _mesh_key(mesh)
    name = f"contact_{key}"
    ds = res.ds
    if name not in ds.data_vars:
        raise ParameterError(
            f"the store has no contact regimes ({name}): an impact map needs a classified "
            "sweep of a gear set (gearchaos classify STORE)"
        )
    meanings = str(ds[name].attrs.get("flag_meanings", "")).split()
    values = [int(v) for v in np.ravel(ds[name].attrs.get("flag_values", []))]
    expected = ["unknown", "none", "single_sided", "double_sided"]
    if meanings and (meanings != expected or values != [-1, 0, 1, 2]):
        raise ParameterError(
            f"{name} must have flag_values [-1, 0, 1, 2] meaning {' '.join(expected)}: got "
            f"{values} meaning {' '.join(meanings)}"
        )
    da = ds[name]
    if planet is None:
        return da.max("planet_all"), name
    planets = [int(p) for p in np.asarray(ds["planet_all"].values)]
    if planet not in planets:
        raise ParameterError(f"planet must be one of the store's {planets}: got {planet!r}")
    return da.sel(planet_all=planet), name


def impact_map(
    ds: Any,
    ax: Any = None,
    *,
    mesh: str = "sp",
    planet: int | None = 1,
    select: Mapping[str, Any] | None = None,
    legend: bool = True,
) -> Any:
    """The contact regime of one mesh over a 2-D sweep, one cell per grid point.

    Parameters
    ----------
    ds
        A classified sweep store or dataset of a gear set (two swept parameters).
    ax
        Axes to draw on (default: a new figure).
    mesh
        ``sp`` / ``sun_planet`` or ``rp`` / ``planet_ring``.
    planet
        The planet, or ``None`` for the most severe regime over the planets.
    select
        Fixes a family or direction dimension (as :func:`~gearchaos.plot.regime_map`).
    legend
        A legend right of the map naming the regimes present.

    Returns
    -------
    matplotlib.axes.Axes
        The map (``gid="impact"``) holds the stored codes (−1, 0, 1, 2) as its data, rows
        along the second swept parameter, both axes in increasing order; its colours are
        :data:`IMPACT_COLOURS`.
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap

    res = SweepResult.of(ds).select(select)
    codes_da, _ = contact_codes(res, mesh, planet)
    xname, yname = res.grid_axes("impact_map")
    codes = np.asarray(codes_da.transpose(yname, xname).values, dtype=np.int64)
    x = np.asarray(res.ds[xname].values, dtype=np.float64)
    y = np.asarray(res.ds[yname].values, dtype=np.float64)
    ox, oy = np.argsort(x, kind="stable"), np.argsort(y, kind="stable")
    codes = codes[np.ix_(oy, ox)]
    order = sorted(IMPACT_COLOURS)
    cmap = ListedColormap([IMPACT_COLOURS[k] for k in order])
    norm = BoundaryNorm(np.arange(order[0] - 0.5, order[-1] + 1.0, 1.0), cmap.N)
    ax = get_ax(ax)
    ax.pcolormesh(
        edges(x[ox]), edges(y[oy]), codes, cmap=cmap, norm=norm, rasterized=True,
        edgecolors="none", gid=IMPACT_GID,
    )  # fmt: skip
    psym = parameter_symbols(res.ds.attrs)
    ax.set_xlabel(axis_label(xname, psym))
    ax.set_ylabel(axis_label(yname, psym))
    no_offset(ax.xaxis, ax.yaxis)
    if legend:
        _legend(ax, codes, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    return ax


def _handles(codes: Any) -> list[Any]:
    from matplotlib.patches import Patch

    present = sorted({int(c) for c in np.ravel(codes)})
    return [
        Patch(facecolor=IMPACT_COLOURS[c], edgecolor="0.4", lw=0.5, label=IMPACT_NAMES[c])
        for c in present
    ]


def _legend(target: Any, codes: Any, **kwargs: Any) -> Any:
    return target.legend(handles=_handles(codes), title="contact regime", fontsize="small",
                         title_fontsize="small", **kwargs)  # fmt: skip


def impact_figure(
    ds: Any,
    *,
    mesh: str = "sp",
    planet: int | None = 1,
    physical: bool = True,
    figsize: tuple[float, float] | None = None,
) -> Any:
    """The impact map of one mesh of a 2-D sweep, one panel per family value (and per
    direction), with one legend naming the regimes present and physical axes (sun speed in
    rpm, clearances in µm) opposite the dimensionless ones.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from .bifurcation import suptitle
    from .maps import map_panels

    res = SweepResult.of(ds)
    key = _mesh_key(mesh)
    codes_all, _ = contact_codes(res, key, planet)  # refused before anything is drawn
    lay = res.layout()
    if len(lay.vary) != 2:
        raise ParameterError(
            f"an impact map needs a 2-D sweep: the store varies {', '.join(lay.vary) or 'nothing'}"
        )

    def draw(ax: Any, sel: dict[str, Any] | None) -> Any:
        return impact_map(res, ax, mesh=key, planet=planet, select=sel, legend=False)

    fig = map_panels(res, lay, draw, figsize, height=4.6, physical=physical)
    _legend(fig, codes_all.values, loc="outside lower center", ncol=4)
    who = "the most severe planet" if planet is None else f"planet {planet}"
    fig.suptitle(
        suptitle(res, f"contact regime of the {MESH_WORDS[key]} mesh ({who})"),
        fontsize="medium",
    )
    return fig
