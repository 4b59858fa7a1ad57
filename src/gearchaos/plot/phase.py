"""Phase portraits, Poincaré maps and the sun-centre orbit."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ParameterError
from ._common import (
    CLEARANCE_GID,
    VarInfo,
    clearance_lines,
    get_ax,
    sample_window,
    variable,
)
from .units import (
    PhysicalScales,
    clearance_notes,
    fit_to_data,
    secondary_axis,
    section_points,
    section_style,
)

__all__ = ["phase_portrait", "poincare_map", "sun_orbit"]


def _with_dot(result: Any, var: str | None, planet: int) -> VarInfo:
    if not (hasattr(result, "section") and hasattr(result, "system")):
        raise ParameterError(
            "result must be a simulation result (gearchaos.simulate(...)): got "
            f"{type(result).__name__}"
        )
    info = variable(result, var, planet)
    if info.dot is None:
        raise ParameterError(
            f"var {info.name!r} has no recorded τ-derivative ({info.name}_dot) for a phase plot"
        )
    return info


#: An orbit within this fraction of the bearing clearance b̄_s is round-off around the centre.
_AT_REST = 1e-9


def phase_portrait(
    result: Any,
    var: str | None = None,
    planet: int = 1,
    ax: Any = None,
    periods: float | None = None,
    *,
    physical: bool = True,
) -> Any:
    """Plot the phase portrait X̄ against X̄' with the Poincaré section points overlaid.

    Parameters
    ----------
    result
        A :class:`~gearchaos.SimulationResult` (``samples_per_period`` ≫ 1 draws the orbit;
        with one sample per period only the section points appear).
    var, planet
        ``delta_sp`` (default, X̄_spi), ``delta_rp``, ``x_s`` or ``y_s`` for planetary
        results; for other systems a state with a ``<var>_dot`` partner (default: the first).
    ax
        Axes to draw on (default: a new figure).
    periods
        Draw only the last ``periods`` recorded periods of the orbit (default: all); the
        section points are always all drawn.

    physical
        Physical axes opposite the dimensionless ones (µm, mm/s), for gear sets.

    Returns
    -------
    matplotlib.axes.Axes
        Limits follow the orbit and the section points; vertical dashed lines mark ±b̄ of
        variables with a clearance where they fall inside, edge notes where they do not.
    """
    info = _with_dot(result, var, planet)
    assert info.dot is not None
    ax = get_ax(ax)
    x = np.asarray(result.series(info.name))
    xd = np.asarray(result.series(info.dot))
    xs, xds = np.asarray(result.section(info.name)), np.asarray(result.section(info.dot))
    data_x, data_y = [xs], [xds]
    if result.samples_per_period > 1:
        sl = sample_window(result, periods)
        ax.plot(x[sl], xd[sl], lw=0.5, color="C0", alpha=0.8, label="orbit")
        data_x.append(x[sl])
        data_y.append(xd[sl])
    section_points(ax, xs, xds)
    _finish(ax, result, info, np.concatenate(data_x), np.concatenate(data_y), physical)
    return ax


def _finish(
    ax: Any, result: Any, info: VarInfo, x: np.ndarray, y: np.ndarray, physical: bool
) -> None:
    """Labels, limits from the data, ±b̄ lines (notes at the edge when outside the data) and
    the physical axes of an x–x' plane."""
    clearance_lines(ax, info, vertical=True)
    ax.set_xlabel(info.label)
    ax.set_ylabel(info.dot_label)
    fit_to_data(ax, x, y, joint=True)
    if info.clearance is not None:
        clearance_notes(ax, "x", (-info.clearance, info.clearance), info.clearance_symbol or "b")
    if physical:
        scales = PhysicalScales.of_result(result)
        secondary_axis(ax, "x", scales.quantity(info.name), scales)
        secondary_axis(ax, "y", scales.quantity(info.dot or ""), scales)


def poincare_map(
    result: Any,
    planet: int = 1,
    ax: Any = None,
    var: str | None = None,
    *,
    physical: bool = True,
) -> Any:
    """Scatter the Poincaré section points (X̄_spi, X̄'_spi) at τ_k = (2πk + φ)/Ω.

    The seed's Poincaré map (MODEL.md §8) with ``var=None`` (X̄_sp of ``planet``); other
    variables as in :func:`phase_portrait`. The axes follow the points (a small margin), the
    dot size and transparency follow their number (:func:`~gearchaos.plot.units.section_style`)
    so the structure of a 10 000-point attractor shows; dashed vertical lines mark ±b̄ where
    they fall inside the points' range, an edge note where they do not. With ``physical`` the
    opposite axes show µm and mm/s (gear sets only). The scatter is rasterized, so vector
    output of many points stays small.
    """
    info = _with_dot(result, var, planet)
    assert info.dot is not None
    ax = get_ax(ax)
    x = np.asarray(result.section(info.name))
    xd = np.asarray(result.section(info.dot))
    n = int(np.sum(np.isfinite(x) & np.isfinite(xd)))
    ax.scatter(x, xd, color="C3", linewidths=0, rasterized=True, zorder=3, **section_style(n))
    _finish(ax, result, info, x, xd, physical)
    return ax


def _equal_spans(ax: Any) -> None:
    """Widen the shorter of the two axis ranges about its centre to the longer one."""
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    half = max(x1 - x0, y1 - y0) / 2
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    ax.set_xlim(cx - half, cx + half)
    ax.set_ylim(cy - half, cy + half)


def sun_orbit(result: Any, ax: Any = None, periods: float | None = None) -> Any:
    """Plot the sun-centre orbit ȳ_s against x̄_s with the bearing clearance square.

    The sun bearing clearance acts along x and y separately (MODEL.md §4), so the bearing is
    out of contact inside the square |x̄_s|, |ȳ_s| ≤ b̄_s, drawn dashed. Equal aspect ratio;
    planetary results only.
    """
    from matplotlib.patches import Rectangle

    if not {"x_s", "y_s"} <= set(result.system.state_names):
        raise ParameterError(
            f"sun_orbit needs a result with sun coordinates x_s, y_s: got a result of "
            f"{result.system.name}"
        )
    ax = get_ax(ax)
    xi = variable(result, "x_s")
    yi = variable(result, "y_s")
    x = np.asarray(result.series("x_s"))
    y = np.asarray(result.series("y_s"))
    if result.samples_per_period > 1:
        sl = sample_window(result, periods)
        ax.plot(x[sl], y[sl], lw=0.5, color="C0", label="orbit")
    xs, ys = np.asarray(result.section("x_s")), np.asarray(result.section("y_s"))
    section_points(ax, xs, ys)
    b = xi.clearance
    if b is not None and b > 0:
        ax.add_patch(
            Rectangle(
                (-b, -b),
                2 * b,
                2 * b,
                fill=False,
                edgecolor="0.35",
                linestyle="--",
                linewidth=0.9,
                gid=CLEARANCE_GID,
                label=rf"$|\bar{{x}}_s|, |\bar{{y}}_s| \leq \bar{{b}}_s = {b:g}$",
            )
        )
    data_x = np.concatenate([xs, x[sample_window(result, periods)]])
    data_y = np.concatenate([ys, y[sample_window(result, periods)]])
    extent = float(np.nanmax(np.abs(np.concatenate([data_x, data_y])), initial=0.0))
    if b is not None and b > 0 and extent < _AT_REST * b:
        # round-off of a sun held at the centre by symmetric meshes: show the clearance, not
        # a magnified cloud of 1e-13 noise that would read as motion
        ax.set_xlim(-1.1 * b, 1.1 * b)
        ax.set_ylim(-1.1 * b, 1.1 * b)
        ax.text(
            0.5,
            0.55,
            f"sun centre at rest\n(|x̄_s|, |ȳ_s| < {max(extent, 1e-300):.0e})",
            transform=ax.transAxes,
            ha="center",
            va="bottom",
            fontsize="small",
            color="0.2",
        )
    else:
        fit_to_data(ax, data_x, data_y, joint=True)
        _equal_spans(ax)
        if b is not None and b > 0:
            clearance_notes(ax, "x", (-b, b), r"\bar{b}_s")
    # square limits in a square box: equal aspect without overruling the fixed limits at
    # every draw ("datalim" did, and matplotlib logged "Ignoring fixed y limits …" each time)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel(xi.label)
    ax.set_ylabel(yi.label)
    return ax
