"""Continued branches of periodic orbits drawn over bifurcation diagrams.

A branch (:func:`gearchaos.continuation`) holds, per point, the parameter value, the orbit's n
section values and its stability. :func:`branch_overlay` draws the section values of one
variable against the parameter — stable stretches solid, unstable ones dashed — and marks each
event (fold, period doubling, Neimark–Sacker, grazing) with a symbol and its name, so a reader
sees *why* the brute-force diagram underneath changes where it does.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import ParameterError
from ._common import get_ax

__all__ = ["BRANCH_GID", "EVENT_STYLE", "branch_matches", "branch_overlay"]

#: ``gid`` prefix of the artists drawn by :func:`branch_overlay`.
BRANCH_GID = "branch"

#: Marker and colour of each event kind, and the name written beside it.
EVENT_STYLE: dict[str, tuple[str, str, str]] = {
    "fold": ("s", "tab:purple", "fold"),
    "period_doubling": ("v", "tab:orange", "PD"),
    "neimark_sacker": ("D", "tab:green", "NS"),
    "branch_point": ("P", "tab:brown", "BP"),
    "grazing": ("x", "0.35", "graze"),
}


def _fixed(branch: Any) -> dict[str, Any]:
    raw = branch.attrs.get("fixed", "{}")
    try:
        data = json.loads(raw) if isinstance(raw, str) else dict(raw)
    except (TypeError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def branch_matches(branch: Any, x_name: str, select: Mapping[str, Any] | None) -> bool:
    """Whether ``branch`` belongs on a panel whose x axis is ``x_name`` and whose other
    dimensions are fixed at ``select``: same parameter, and every selected value that the
    branch fixes agrees (to 1e-9 relative)."""
    if str(branch.attrs.get("parameter")) != x_name:
        return False
    fixed = _fixed(branch)
    for name, value in (select or {}).items():
        if name in fixed and isinstance(value, int | float | np.number):
            if not np.isclose(float(fixed[name]), float(value), rtol=1e-9, atol=0.0):
                return False
    return True


def branch_overlay(
    branch: Any,
    ax: Any = None,
    *,
    var: str = "delta_sp",
    planet: int = 1,
    color: str = "tab:blue",
    events: bool = True,
    label: str | None = None,
) -> Any:
    """Draw a continued branch over a bifurcation diagram of the same parameter.

    Parameters
    ----------
    branch
        A branch dataset (:func:`gearchaos.continuation`, :func:`gearchaos.analysis.open_branch`).
    ax
        Axes to draw on (default: a new figure).
    var, planet
        The section variable (one of the branch's observed ones) and the planet.
    color
        Colour of the branch; stable stretches are solid, unstable ones dashed.
    events
        Mark the events with a symbol each and name them (``PD``, ``NS``, ``fold``, ``graze``).
    label
        Legend label (default: ``period-n branch``).

    Returns
    -------
    matplotlib.axes.Axes
        The artists carry ``gid`` ``branch:stable``, ``branch:unstable`` and
        ``branch:event:<kind>``.
    """
    name = str(branch.attrs.get("parameter", ""))
    if name not in branch.coords or var not in branch.data_vars:
        have = ", ".join(str(v) for v in branch.data_vars if "section" in branch[v].dims)
        raise ParameterError(f"var must be a section variable of the branch ({have}): got {var!r}")
    ax = get_ax(ax)
    lam = np.asarray(branch[name].values, dtype=np.float64)
    da = branch[var]
    if "planet" in da.dims:
        planets = [int(p) for p in np.asarray(branch["planet"].values)]
        if planet not in planets:
            raise ParameterError(f"planet must be one of the branch's {planets}: got {planet!r}")
        da = da.sel(planet=planet)
    y = np.asarray(da.transpose("point", "section").values, dtype=np.float64)
    stable = np.asarray(branch["stable"].values, dtype=bool)
    n = int(branch.attrs.get("period", 1))
    text = label or f"period-{n} branch"
    for which, style in ((True, "-"), (False, "--")):
        # NaN where the other stability holds, keeping the joins between stretches
        mask = stable == which
        shown = mask.copy()
        shown[1:] |= mask[:-1]
        for j in range(y.shape[1]):
            yy = np.where(shown, y[:, j], np.nan)
            if np.all(np.isnan(yy)):
                continue
            ax.plot(
                lam,
                yy,
                style,
                color=color,
                lw=1.1 if which else 0.9,
                zorder=3,
                gid=f"{BRANCH_GID}:{'stable' if which else 'unstable'}",
                label=(f"{text} ({'stable' if which else 'unstable'})" if j == 0 else None),
            )
    if events and branch.sizes.get("event", 0):
        seen: set[str] = set()
        for k in range(branch.sizes["event"]):
            kind = str(branch.event_kind.values[k])
            marker, colour, short = EVENT_STYLE.get(kind, ("o", "k", kind))
            value = float(branch.event_value.values[k])
            i = int(branch.event_point.values[k])
            i = min(max(i, 0), y.shape[0] - 1)
            ys = y[i]
            ax.scatter(
                np.full(ys.size, value),
                ys,
                marker=marker,
                s=36,
                facecolors="none" if marker not in ("x", "P") else colour,
                edgecolors=colour,
                linewidths=1.2,
                zorder=4,
                gid=f"{BRANCH_GID}:event:{kind}",
                label=short if short not in seen else None,
            )
            seen.add(short)
            ax.annotate(
                short,
                (value, float(np.nanmax(ys))),
                xytext=(0, 6),
                textcoords="offset points",
                ha="center",
                fontsize="x-small",
                color=colour,
                gid=f"{BRANCH_GID}:event-label",
            )
    return ax
