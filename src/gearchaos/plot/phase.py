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
    is_planetary,
    readable_limits,
    sample_window,
    variable,
)

__all__ = ["phase_portrait", "poincare_map", "sun_orbit"]


def _with_dot(result: Any, var: str | None, planet: int) -> VarInfo:
    info = variable(result, var, planet)
    if info.dot is None:
        raise ParameterError(
            f"var {info.name!r} has no recorded τ-derivative ({info.name}_dot) for a phase plot"
        )
    return info


def phase_portrait(
    result: Any,
    var: str | None = None,
    planet: int = 1,
    ax: Any = None,
    periods: float | None = None,
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

    Returns
    -------
    matplotlib.axes.Axes
        Vertical dashed lines mark ±b̄ of variables with a clearance.
    """
    info = _with_dot(result, var, planet)
    assert info.dot is not None
    ax = get_ax(ax)
    x = np.asarray(result.series(info.name))
    xd = np.asarray(result.series(info.dot))
    if result.samples_per_period > 1:
        sl = sample_window(result, periods)
        ax.plot(x[sl], xd[sl], lw=0.5, color="C0", alpha=0.8, label="orbit")
    ax.plot(
        result.section(info.name),
        result.section(info.dot),
        ".",
        ms=4,
        color="C3",
        label="section points",
        zorder=3,
        rasterized=True,
    )
    clearance_lines(ax, info, vertical=True)
    ax.set_xlabel(info.label)
    ax.set_ylabel(info.dot_label)
    readable_limits(ax, joint=True)
    return ax


def poincare_map(
    result: Any,
    planet: int = 1,
    ax: Any = None,
    var: str | None = None,
) -> Any:
    """Scatter the Poincaré section points (X̄_spi, X̄'_spi) at τ_k = (2πk + φ)/Ω.

    The seed's Poincaré map (MODEL.md §8) with ``var=None`` (X̄_sp of ``planet``); other
    variables as in :func:`phase_portrait`. The scatter is rasterized, so vector output of
    many points stays small. Dashed vertical lines mark ±b̄.
    """
    info = _with_dot(result, var, planet)
    assert info.dot is not None
    ax = get_ax(ax)
    x = np.asarray(result.section(info.name))
    xd = np.asarray(result.section(info.dot))
    ax.scatter(x, xd, s=6, color="C3", linewidths=0, rasterized=True, zorder=3)
    clearance_lines(ax, info, vertical=True)
    ax.set_xlabel(info.label)
    ax.set_ylabel(info.dot_label)
    readable_limits(ax, joint=True)
    return ax


def sun_orbit(result: Any, ax: Any = None, periods: float | None = None) -> Any:
    """Plot the sun-centre orbit ȳ_s against x̄_s with the bearing clearance square.

    The sun bearing clearance acts along x and y separately (MODEL.md §4), so the bearing is
    out of contact inside the square |x̄_s|, |ȳ_s| ≤ b̄_s, drawn dashed. Equal aspect ratio;
    planetary results only.
    """
    from matplotlib.patches import Rectangle

    if not is_planetary(result):
        raise ParameterError(
            f"sun_orbit needs a planetary result: got a result of {result.system.name}"
        )
    ax = get_ax(ax)
    xi = variable(result, "x_s")
    yi = variable(result, "y_s")
    x = np.asarray(result.series("x_s"))
    y = np.asarray(result.series("y_s"))
    if result.samples_per_period > 1:
        sl = sample_window(result, periods)
        ax.plot(x[sl], y[sl], lw=0.5, color="C0", label="orbit")
    ax.plot(
        result.section("x_s"),
        result.section("y_s"),
        ".",
        ms=4,
        color="C3",
        label="section points",
        zorder=3,
        rasterized=True,
    )
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
    readable_limits(ax, joint=True)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(xi.label)
    ax.set_ylabel(yi.label)
    return ax
