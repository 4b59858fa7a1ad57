"""Frequency-response curves of a response sweep (:func:`gearchaos.response`).

Four panels over the swept parameter (usually Ω): peak and RMS contact force of each mesh type,
dynamic load factor and RMS dynamic transmission error, and under them the motion band of the
bifurcation diagram (:func:`~gearchaos.plot.regimes.regime_band`: the verdict of every point,
one row per sweep direction) with a legend of the labels. The up branch is drawn solid, the
down branch dashed. The curves' own marks follow the verdicts, so that none contradicts them:

* a **jump** (an arrow in the direction of the sweep,
  :func:`~gearchaos.sweep.frequency.find_jumps`) joins two neighbouring points of one branch
  that are both periodic (nT) — a chaotic curve scatters from point to point without jumping;
* **hysteresis** is shaded between the branches only where both directions are periodic at
  the same value and their responses differ, at two neighbouring values at least: two
  coexisting periodic motions. Where either
  branch is QP, chaotic, unresolved or failed, nothing is shaded. The legend names the
  shading (:data:`HYSTERESIS_LABEL`) when there is one.

A store without motion labels gets neither marks nor band. Over Ω the top axis shows the sun
speed in rpm and the mesh frequency in Hz, and the force and DTE panels a physical axis (N,
µm) on the right, where the gear set defines them.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..sweep import SweepResult
from ..sweep.frequency import find_jumps
from .bifurcation import suptitle
from .regimes import (
    PERIODIC_CATEGORIES,
    regime_band,
    regime_categories,
    regime_legend_below,
)
from .units import PhysicalScales, fit_to_data, linear_axis

__all__ = ["response_figure"]

#: Panels: (quantity, y label, physical quantity of the right axis).
PANELS = (
    ("force_peak", r"peak contact force $\max|\bar F^c|$", "force"),
    ("force_rms", r"RMS contact force $\sqrt{\langle \bar F^{c\,2}\rangle}$", "force"),
    ("load_factor", r"load factor $\max|F^c|/F_{static}$", None),
    (
        "dte_rms",
        r"RMS DTE $\sqrt{\langle(\bar\delta-\langle\bar\delta\rangle)^2\rangle}$",
        "length",
    ),
)
MESH_LABEL = {"sp": "sun–planet", "rp": "planet–ring", "mesh": "mesh"}
#: Mesh colours outside the regime palette (whose blue is 1T and red chaos).
MESH_COLOR = {"sp": "0.1", "rp": "#9467bd", "mesh": "0.1"}
#: Relative difference of the branches (to the panel's range) shaded as hysteresis.
HYSTERESIS_REL = 0.02
#: The legend entry of the shading between the branches.
HYSTERESIS_LABEL = "hysteresis (two periodic branches)"


def _meshes(ds: Any) -> list[str]:
    return [m for m in ("sp", "rp", "mesh") if f"force_peak_{m}" in ds]


def periodic_mask(ds: Any, direction: str | None) -> np.ndarray | None:
    """Per swept value, whether the verdict of ``direction`` is periodic (nT); None without
    motion labels."""
    if "motion" not in ds.data_vars:
        return None
    cats = regime_categories(ds)
    if direction is not None:
        cats = cats.sel(direction=direction)
    return np.array([c in PERIODIC_CATEGORIES for c in np.ravel(cats.values)])


def _branch(ds: Any, name: str, direction: str | None) -> np.ndarray:
    v = ds[name]
    if direction is not None:
        v = v.sel(direction=direction)
    if "planet_all" in v.dims:
        v = v.max("planet_all")  # the most loaded planet
    return np.asarray(v.values, dtype=float)


def response_figure(
    ds: Any, *, rel_jump: float = 0.25, figsize: tuple[float, float] | None = None
) -> Any:
    """The frequency-response figure of a response sweep store or dataset.

    Parameters
    ----------
    ds
        A dataset of :func:`gearchaos.response` (or its :class:`~gearchaos.sweep.SweepResult`).
    rel_jump
        Jump threshold as a fraction of a curve's range (:func:`find_jumps`).
    figsize
        Figure size in inches (default 7 × 10 with the motion band, 7 × 9 without).

    Returns
    -------
    matplotlib.figure.Figure
        Per-planet quantities are drawn for the most loaded planet (max over the planets).
        Jumps (``gid="jump"``) join periodic neighbours only, hysteresis (``gid="hysteresis"``)
        is shaded only where both branches are periodic and differ by more than
        :data:`HYSTERESIS_REL` of the panel's range (module docstring); the last axes is the
        motion band when the store has motion labels.
    """
    from matplotlib.figure import Figure

    res = SweepResult.of(ds)
    ds = res.ds
    meshes = _meshes(ds)
    if not meshes:
        from ..errors import ParameterError

        raise ParameterError(
            "response_figure needs a response sweep (gearchaos response / gc.response): "
            "the store has no force_peak_* variables"
        )
    lead = [d for d in ds["force_peak_" + meshes[0]].dims if d not in ("direction", "planet_all")]
    if len(lead) != 1:
        raise ValueError(f"response_figure draws 1-D sweeps: got dimensions {lead}")
    xname = lead[0]
    x = np.asarray(ds[xname].values, dtype=float)
    directions = list(ds["direction"].values) if "direction" in ds.dims else [None]
    periodic = {d: periodic_mask(ds, d) for d in directions}
    labelled = all(p is not None for p in periodic.values())
    scales = PhysicalScales.of_sweep(res)
    fig = Figure(figsize=figsize or (7.0, 10.0 if labelled else 9.0), layout="constrained")
    if labelled:
        band_h = 0.12 * len(directions)
        grid = fig.add_gridspec(len(PANELS) + 1, 1, height_ratios=[1.0] * len(PANELS) + [band_h])
        axes = [fig.add_subplot(grid[0, 0])]
        axes += [fig.add_subplot(grid[k, 0], sharex=axes[0]) for k in range(1, len(PANELS))]
        band = fig.add_subplot(grid[len(PANELS), 0], sharex=axes[0])
    else:
        axes = list(fig.subplots(len(PANELS), 1, sharex=True))
        band = None
    shaded = False
    for ax, (q, ylabel, phys) in zip(axes, PANELS, strict=True):
        ys: list[np.ndarray] = []
        for m in meshes:
            branches = {d: _branch(ds, f"{q}_{m}", d) for d in directions}
            for d, y in branches.items():
                ys.append(y)
                style = "--" if d == "down" else "-"
                marker = "v" if d == "down" else ("^" if d == "up" else "o")
                label = MESH_LABEL[m] + (f", {d}" if d else "")
                ax.plot(
                    x, y, style, color=MESH_COLOR[m], marker=marker, ms=2.5, lw=1.0, label=label
                )
                if periodic[d] is None:
                    continue
                for xj in find_jumps(x, y, rel=rel_jump, where=periodic[d]):
                    k = int(np.searchsorted(x, xj))
                    y0, y1 = y[k - 1], y[k]
                    if d == "down":
                        y0, y1 = y1, y0
                    ax.annotate(
                        "",
                        xy=(xj, y1),
                        xytext=(xj, y0),
                        arrowprops={"arrowstyle": "->", "color": MESH_COLOR[m], "lw": 1.2},
                        gid="jump",
                    )
            if len(branches) == 2 and labelled:
                up, down = branches["up"], branches["down"]
                both = np.asarray(periodic["up"]) & np.asarray(periodic["down"])
                span = np.nanmax([np.nanmax(up), np.nanmax(down)]) - np.nanmin(
                    [np.nanmin(up), np.nanmin(down)]
                )
                differ = np.abs(up - down) > HYSTERESIS_REL * span if span > 0 else both & False
                shade = both & differ
                # a band needs two neighbours: a lone value would be a shading of zero width
                shade &= np.r_[False, shade[:-1]] | np.r_[shade[1:], False]
                if shade.any():
                    shaded = True
                    ax.fill_between(
                        x,
                        np.fmin(up, down),
                        np.fmax(up, down),
                        where=shade,
                        color=MESH_COLOR[m],
                        alpha=0.15,
                        lw=0,
                        gid="hysteresis",
                    )
        ax.set_ylabel(ylabel, fontsize="small")
        fit_to_data(ax, x, np.concatenate(ys))
        if phys is not None:
            found = scales.factor(phys)
            if found is not None:
                unit = "F" if phys == "force" else "δ"
                linear_axis(ax, "y", found[0], f"{unit} {found[1]}")
        ax.grid(alpha=0.3, lw=0.5)
    handles, names = axes[0].get_legend_handles_labels()
    if shaded:  # the shading's colour is each mesh's, faint: one entry says what it means
        from matplotlib.patches import Patch

        handles.append(Patch(facecolor="0.1", alpha=0.15, lw=0, label=HYSTERESIS_LABEL))
        names.append(HYSTERESIS_LABEL)
    axes[0].legend(handles, names, fontsize="x-small", ncol=2, loc="best")
    xlabel = r"$\Omega = \omega/\omega_n$" if xname == "omega" else xname
    bottom = axes[-1]
    if band is not None:
        limits = axes[0].get_xlim()
        regime_band(res, band)
        band.set_xlim(*limits)  # the panels' limits, not the band's outer cells
        for ax in axes:
            ax.tick_params(axis="x", labelbottom=False)
        cats = np.asarray(regime_categories(res).values, dtype=object).ravel()
        regime_legend_below(fig, cats)
        bottom = band
    bottom.set_xlabel(xlabel)
    if xname == "omega":
        rpm = scales.factor("omega")
        if rpm is not None:
            linear_axis(axes[0], "x", rpm[0], rpm[1])
        hz = scales.factor("mesh_hz")
        if hz is not None:
            sec = bottom.secondary_xaxis(
                "bottom",
                functions=(lambda v: np.asarray(v) * hz[0], lambda v: np.asarray(v) / hz[0]),
            )
            sec.spines["bottom"].set_position(("outward", 34))
            sec.set_xlabel(f"mesh frequency $f_m$ {hz[1]}", fontsize="small")
            sec.tick_params(labelsize="small")
    fig.suptitle(suptitle(res, "frequency response"), fontsize="medium")
    return fig
