"""Frequency-response curves of a response sweep (:func:`gearchaos.response`).

Four panels over the swept parameter (usually Ω): peak and RMS contact force of each mesh type,
dynamic load factor and RMS dynamic transmission error. The up branch is drawn solid, the down
branch dashed; jumps (:func:`~gearchaos.sweep.frequency.find_jumps`) are marked with arrows in the
direction of the sweep, and where the branches differ the band between them is shaded. Over Ω
the top axis shows the sun speed in rpm and the mesh frequency in Hz, and the force and DTE
panels a physical axis (N, µm) on the right, where the gear set defines them.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..sweep import SweepResult
from ..sweep.frequency import find_jumps
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
MESH_COLOR = {"sp": "C0", "rp": "C3", "mesh": "C0"}


def _meshes(ds: Any) -> list[str]:
    return [m for m in ("sp", "rp", "mesh") if f"force_peak_{m}" in ds]


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
        Figure size in inches (default 7 × 9).

    Returns
    -------
    matplotlib.figure.Figure
        Per-planet quantities are drawn for the most loaded planet (max over the planets).
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
    scales = PhysicalScales.of_sweep(res)
    fig = Figure(figsize=figsize or (7.0, 9.0), layout="constrained")
    axes = fig.subplots(len(PANELS), 1, sharex=True)
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
                for xj in find_jumps(x, y, rel=rel_jump):
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
            if len(branches) == 2:
                up, down = branches["up"], branches["down"]
                span = np.nanmax([np.nanmax(up), np.nanmax(down)]) - np.nanmin(
                    [np.nanmin(up), np.nanmin(down)]
                )
                differ = np.abs(up - down) > 0.02 * span if span > 0 else np.zeros_like(up, bool)
                ax.fill_between(
                    x,
                    np.fmin(up, down),
                    np.fmax(up, down),
                    where=differ,
                    color=MESH_COLOR[m],
                    alpha=0.12,
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
    axes[0].legend(fontsize="x-small", ncol=2, loc="best")
    xlabel = r"$\Omega = \omega/\omega_n$" if xname == "omega" else xname
    axes[-1].set_xlabel(xlabel)
    if xname == "omega":
        rpm = scales.factor("omega")
        if rpm is not None:
            linear_axis(axes[0], "x", rpm[0], rpm[1])
        hz = scales.factor("mesh_hz")
        if hz is not None:
            sec = axes[-1].secondary_xaxis(
                -0.32, functions=(lambda v: np.asarray(v) * hz[0], lambda v: np.asarray(v) / hz[0])
            )
            sec.set_xlabel(f"mesh frequency $f_m$ {hz[1]}", fontsize="small")
            sec.tick_params(labelsize="small")
    title = ds.attrs.get("title", "").replace("sweep", "frequency response")
    fig.suptitle(title, fontsize="medium")
    return fig
