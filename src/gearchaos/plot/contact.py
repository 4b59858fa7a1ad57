"""Contact regime against speed: does a gearbox rattle, and from which speed?

:func:`contact_figure` draws a 1-D sweep or response store of a gear set (usually over Ω) as
one band per mesh — no separation, single-sided impact (the teeth part and meet again on the
drive flank: rattle), double-sided impact (they hit the back flank too) — one row per sweep
direction of a continuation in both directions, and one row per planet where the planets'
regimes differ (:func:`gearchaos.sweep.contact.contact_ranges`). A response store
(:func:`gearchaos.response`) adds a panel above with the peak contact force of each mesh (the
most loaded planet) in k_m,sp b_c and, on its right axis, in newtons, with the static mesh force
dotted. Over Ω the top axis shows the sun speed in rpm.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..sweep.contact import CONTACT_MESHES, ContactRange, contact_ranges
from ..sweep.result import SweepResult
from ._common import axis_label, edges, no_offset, parameter_symbols
from .impact import IMPACT_COLOURS
from .units import PhysicalScales, fit_to_data, linear_axis

__all__ = ["CONTACT_BAND_GID", "REGIME_CODES", "contact_figure"]

#: ``gid`` prefix of the bars of the contact bands (``contact:<regime>``).
CONTACT_BAND_GID = "contact"
#: Code of each regime in :data:`~gearchaos.plot.impact.IMPACT_COLOURS` (the impact map's).
REGIME_CODES = {"unknown": -1, "none": 0, "single_sided": 1, "double_sided": 2}
#: Legend names of the regimes.
REGIME_NAMES = {
    "none": "no separation",
    "single_sided": "single-sided impact (rattle)",
    "double_sided": "double-sided impact",
    "unknown": "unknown (failed point)",
}
MESH_WORDS = {"sun_planet": "sun–planet", "planet_ring": "planet–ring"}
#: Colours of the meshes' force curves (outside the regime and contact palettes).
MESH_COLOURS = {"sun_planet": "0.1", "planet_ring": "#9467bd"}
ARROWS = {"up": "↑", "down": "↓", None: ""}


def _rows(ranges: list[ContactRange]) -> list[tuple[str, str | None, int | None]]:
    """The bands, top to bottom: (mesh, direction, planet index or None for all planets)."""
    rows: list[tuple[str, str | None, int | None]] = []
    keys: list[tuple[str, str | None]] = []
    for r in ranges:
        if (r.mesh, r.direction) not in keys:
            keys.append((r.mesh, r.direction))
    for mesh, direction in keys:
        mine = [r for r in ranges if (r.mesh, r.direction) == (mesh, direction)]
        if all(r.uniform for r in mine):
            rows.append((mesh, direction, None))
        else:
            rows += [(mesh, direction, k) for k in range(len(mine[0].planets))]
    return rows


def _row_label(mesh: str, direction: str | None, planet: int | None) -> str:
    text = MESH_WORDS[mesh] + ("" if planet is None else f" {planet}")
    return f"{text} {ARROWS[direction]}".strip()


def _force_curves(ax: Any, res: SweepResult, x_name: str, directions: tuple[str, ...]) -> None:
    ds = res.ds
    x = np.asarray(ds[x_name].values, dtype=np.float64)
    order = np.argsort(x, kind="stable")
    values: list[np.ndarray] = []
    static: np.ndarray | None = None
    for key, mesh in CONTACT_MESHES.items():
        name = f"force_peak_{key}"
        for direction in directions or (None,):
            da = ds[name] if direction is None else ds[name].sel(direction=direction)
            if "planet_all" in da.dims:
                da = da.max("planet_all")  # the most loaded planet
            y = np.asarray(da.transpose(x_name).values, dtype=np.float64)[order]
            values.append(y)
            ax.plot(
                x[order],
                y,
                "--" if direction == "down" else "-",
                color=MESH_COLOURS[mesh],
                lw=1.0,
                marker="v" if direction == "down" else ("^" if direction == "up" else "o"),
                ms=2.5,
                label=f"{MESH_WORDS[mesh]}" + (f", {direction}" if direction else ""),
                gid=f"force:{mesh}:{direction or 'all'}",
            )
            lf = ds.get(f"load_factor_{key}")
            if key == "sp" and lf is not None and static is None:
                lf = lf if direction is None else lf.sel(direction=direction)
                ratio = y / np.asarray(lf.transpose(x_name).values, dtype=np.float64)[order]
                static = np.where(np.isfinite(ratio), ratio, np.nan)
    if static is not None and np.isfinite(static).any():
        ax.plot(x[order], static, ":", color="0.3", lw=0.9, label="static mesh force")
        values.append(static)
    ax.set_ylabel(r"peak contact force $\max|\bar F^c|$", fontsize="small")
    fit_to_data(ax, x, np.concatenate(values))
    ax.grid(alpha=0.3, lw=0.5)
    ax.legend(fontsize="x-small", ncol=2, loc="best")


def contact_figure(
    ds: Any, *, select: dict[str, Any] | None = None, figsize: tuple[float, float] | None = None
) -> Any:
    """The contact regime of every mesh against the swept parameter of a 1-D sweep.

    Parameters
    ----------
    ds
        A sweep or response store (or dataset, or :class:`~gearchaos.sweep.SweepResult`) of a
        gear set with one swept parameter left after ``select``, with contact regimes
        (``contact_sp``, ``contact_rp``: every store of ``gearchaos bifurcation`` and
        ``gearchaos response``).
    select
        Values of other swept dimensions (a family value).
    figsize
        Figure size in inches (default 7 wide; 1.7 inch of bands plus 3 of forces).

    Returns
    -------
    matplotlib.figure.Figure
        The last axes holds the bands: each regime's bars are drawn with
        ``gid="contact:<regime>"`` in the impact map's colours
        (:data:`~gearchaos.plot.impact.IMPACT_COLOURS`), one row per mesh (and direction;
        per planet where they differ), each swept value owning the cell between the
        midpoints to its neighbours. With forces stored, the first axes draws the peak contact
        force of each mesh (``gid="force:<mesh>:<direction>"``) with a newton axis opposite.
    """
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    from .bifurcation import suptitle

    res = SweepResult.of(ds).select(select)
    ranges = contact_ranges(res)
    sub = res.ds
    x_name = res.line_axis("a contact figure", "contact_sp")
    directions = res.layout().directions
    rows = _rows(ranges)
    forces = all(f"force_peak_{k}" in sub.data_vars for k in CONTACT_MESHES)
    band_h = 0.3 + 0.22 * len(rows)
    fig = Figure(figsize=figsize or (7.0, band_h + (3.2 if forces else 1.6)), layout="constrained")
    if forces:
        grid = fig.add_gridspec(2, 1, height_ratios=[3.0, band_h])
        top = fig.add_subplot(grid[0, 0])
        band = fig.add_subplot(grid[1, 0], sharex=top)
        _force_curves(top, res, x_name, directions)
        top.tick_params(axis="x", labelbottom=False)
    else:
        top = band = fig.add_subplot(1, 1, 1)
    x = np.asarray(sub[x_name].values, dtype=np.float64)
    cells = edges(np.sort(x))
    xs = np.sort(x)
    present: list[str] = []
    n = len(rows)
    for k, (mesh, direction, planet) in enumerate(rows):
        y0 = n - 1 - k
        spans: dict[str, list[tuple[float, float]]] = {}
        for r in ranges:
            if (r.mesh, r.direction) != (mesh, direction):
                continue
            regime = r.regime if planet is None else r.regimes[planet]
            i = int(np.searchsorted(xs, r.start))
            j = int(np.searchsorted(xs, r.stop)) + 1
            spans.setdefault(regime, []).append((float(cells[i]), float(cells[j] - cells[i])))
        for regime, bars in spans.items():
            band.broken_barh(
                bars,
                (y0 + 0.08, 0.84),
                facecolors=IMPACT_COLOURS[REGIME_CODES[regime]],
                edgecolors="none",
                gid=f"{CONTACT_BAND_GID}:{regime}",
            )
            if regime not in present:
                present.append(regime)
    band.set_ylim(0.0, float(n))
    band.set_yticks(
        [n - 0.5 - k for k in range(n)],
        [_row_label(m, d, None if p is None else ranges[0].planets[p]) for m, d, p in rows],
    )
    band.tick_params(axis="y", labelsize="x-small", length=0)
    band.set_xlim(float(cells[0]), float(cells[-1]))
    if forces:
        scales = PhysicalScales.of_sweep(res)
        found = scales.factor("force")
        if found is not None:
            linear_axis(top, "y", found[0], f"$F^c$ {found[1]}")
    band.set_xlabel(axis_label(x_name, parameter_symbols(sub.attrs)))
    no_offset(band.xaxis)
    if x_name == "omega":
        rpm = PhysicalScales.of_sweep(res).factor("omega")
        if rpm is not None:
            linear_axis(top, "x", rpm[0], rpm[1])
    order = [r for r in REGIME_CODES if r in present]
    handles = [
        Patch(
            facecolor=IMPACT_COLOURS[REGIME_CODES[r]],
            edgecolor="0.4",
            lw=0.5,
            label=REGIME_NAMES[r],
        )
        for r in sorted(order, key=lambda r: REGIME_CODES[r])
    ]
    fig.legend(
        handles=handles,
        loc="outside lower center",
        ncols=len(handles),
        fontsize="small",
        frameon=False,
        title="contact regime over the recorded window",
        title_fontsize="small",
    )
    fig.suptitle(suptitle(res, "contact regime of each mesh"), fontsize="medium")
    return fig
