"""Continued branches of periodic orbits drawn over bifurcation diagrams.

A branch (:func:`gearchaos.continuation`) holds, per point, the parameter value, the orbit's n
section values and its stability. :func:`branch_overlay` draws the section values of one
variable against the parameter — stable stretches solid, unstable ones dashed — and marks each
event (fold, period doubling, Neimark–Sacker, grazing) with a symbol and its name, so a reader
sees *why* the brute-force diagram underneath changes where it does. :func:`branch_figure`
draws one or several branch files on their own (``gearchaos plot BRANCH.nc``).

When the continued parameter is the clearance of the drawn variable (b̄_sp for X̄_sp …), the
branch is drawn as X̄ − b̄ (``relative``), as the bifurcation diagrams of such sweeps are: X̄
grows with b̄ and the branch would otherwise be a line along the diagonal.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..gearset.schema import CLEARANCES, FIELDS
from ._common import (
    at_line,
    axis_label,
    axis_symbol,
    fmt,
    get_ax,
    given_values,
    model_symbols,
    parameter_symbols,
    resonance_lines,
    stored_fixed,
    stored_gearset,
    stored_model,
    subject,
    var_symbol,
)
from .placement import EVENT_LABEL_GID, LABEL_PLACES, place_event_labels
from .units import (
    PhysicalScales,
    clearance_notes,
    fit_to_data,
    physical_axis,
    secondary_axis,
)

__all__ = [
    "BRANCH_COLOURS",
    "BRANCH_GID",
    "EVENT_LABEL_GID",
    "EVENT_NAMES",
    "EVENT_STYLE",
    "branch_clearance",
    "branch_figure",
    "branch_labels",
    "branch_matches",
    "branch_overlay",
    "mark_event",
]

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

#: Colours of the branches of :func:`branch_figure`, none an event's (over a sweep's diagram
#: from the third on: the first two are the up and down sweeps' colours).
BRANCH_COLOURS = ("tab:blue", "tab:red", "tab:cyan", "tab:pink", "tab:olive", "navy", "darkred")

#: The legend entry of each event kind.
EVENT_NAMES: dict[str, str] = {
    "fold": "fold (μ = +1)",
    "period_doubling": "period doubling PD (μ = −1)",
    "neimark_sacker": "Neimark–Sacker NS (|μ| = 1)",
    "branch_point": "branch point BP (μ = +1)",
    "grazing": "grazing (contact starts/ends)",
}


def branch_clearance(branch: Any, var: str) -> np.ndarray | None:
    """b̄ of the clearance acting on ``var`` at every point of ``branch`` — the continued
    value when the clearance itself is continued, else the gear set's (or the reference
    system's) — or ``None`` for variables without a clearance."""
    if var.endswith("_dot"):
        return None
    name = str(branch.attrs.get("parameter", ""))
    lam = np.asarray(branch[name].values, dtype=np.float64)
    if var in CLEARANCES:
        parameter, _, key = CLEARANCES[var]
        gs = stored_gearset(branch.attrs)
        # gear-set switch: this variable's clearance is a gear-set parameter (b̄ or metres)
        if gs is None:
            return None
        if name == parameter:
            units = gs.backlash.units if parameter.startswith("backlash.") else gs.clearance.units
            return lam / gs.clearance.characteristic_length if units == "m" else lam.copy()
        bsp, brp = gs.backlash_bar()
        b = {"sun_planet": bsp, "planet_ring": brp}.get(key, gs.sun_bearing_clearance_bar())
        return np.full(lam.shape, float(b))
    if f"clearance_{var}" in branch.attrs:  # reference systems: x of the backlash oscillator
        if name == "b":
            return lam.copy()
        return np.full(lam.shape, float(branch.attrs[f"clearance_{var}"]))
    return None


def _clearance_symbol(var: str) -> str:
    if var in CLEARANCES:
        return FIELDS[CLEARANCES[var][0]].tex
    return "b"


def branch_labels(branches: Sequence[Any]) -> list[str]:
    """Legend labels that tell the branches apart: the file name (when the branch was opened
    from one; once per file for the branches of a cascade), the period and the start
    (``from PD at Ω = 1.95``), numbered where two would still read the same."""
    labels = []
    seen: set[str] = set()
    for br in branches:
        n = int(br.attrs.get("period", 1))
        source = str(getattr(br, "encoding", {}).get("source", "") or "")
        start = str(br.attrs.get("start", ""))
        text = f"period-{n} branch"
        if " at " in start:  # switched at an event: say where
            kind, _, where = start.partition(" at ")
            pname, _, value = where.split(" (")[0].partition("=")
            short = EVENT_STYLE[kind][2] if kind in EVENT_STYLE else kind.replace("_", " ")
            try:
                sym = axis_symbol(pname, parameter_symbols(br.attrs))
                text += f" from {short} at {sym} = {fmt(float(value))}"
            except ValueError:
                text += f" from {short} at {where.split(' (')[0]}"
        if source and source not in seen:
            text = f"{Path(source).name}: {text}"
        seen.add(source)
        labels.append(text)
    for text in set(labels):
        same = [k for k, t in enumerate(labels) if t == text]
        if len(same) > 1:
            for j, k in enumerate(same):
                lo, hi = (br := branches[k]).attrs.get("range_start"), br.attrs.get("range_stop")
                extra = f" ({fmt(lo)} → {fmt(hi)})" if lo is not None and hi is not None else ""
                labels[k] = f"{text}{extra} #{j + 1}"
    return labels


def branch_matches(branch: Any, x_name: str, select: Mapping[str, Any] | None) -> bool:
    """Whether ``branch`` belongs on a panel whose x axis is ``x_name`` and whose other
    dimensions are fixed at ``select``: same parameter, and every selected value that the
    branch fixes agrees (to 1e-9 relative)."""
    if str(branch.attrs.get("parameter")) != x_name:
        return False
    fixed = stored_fixed(branch.attrs)
    for name, value in (select or {}).items():
        if name in fixed and isinstance(value, int | float | np.number):
            if not np.isclose(float(fixed[name]), float(value), rtol=1e-9, atol=0.0):
                return False
    return True


def _section_values(branch: Any, var: str, planet: int) -> np.ndarray:
    name = str(branch.attrs.get("parameter", ""))
    if name not in branch.coords or var not in branch.data_vars:
        have = ", ".join(str(v) for v in branch.data_vars if "section" in branch[v].dims)
        raise ParameterError(f"var must be a section variable of the branch ({have}): got {var!r}")
    da = branch[var]
    if "planet" in da.dims:
        planets = [int(p) for p in np.asarray(branch["planet"].values)]
        if planet not in planets:
            raise ParameterError(f"planet must be one of the branch's {planets}: got {planet!r}")
        da = da.sel(planet=planet)
    return np.asarray(da.transpose("point", "section").values, dtype=np.float64)


def branch_overlay(
    branch: Any,
    ax: Any = None,
    *,
    var: str = "delta_sp",
    planet: int = 1,
    color: str = "tab:blue",
    events: bool = True,
    label: str | None = None,
    relative: bool = False,
    named: set[str] | None = None,
) -> Any:
    """Draw a continued branch over a bifurcation diagram of the same parameter.

    Parameters
    ----------
    branch
        A branch dataset (:func:`gearchaos.continuation`, :func:`gearchaos.dynamics.open_branch`).
    ax
        Axes to draw on (default: a new figure).
    var, planet
        The section variable (one of the branch's observed ones) and the planet.
    color
        Colour of the branch; stable stretches are solid, unstable ones dashed.
    events
        Mark the events with a symbol each at the branch's section values there (interpolated
        in arclength between the two branch points around it), write its short name (``PD``,
        ``NS``, ``fold``, ``graze``) beside it and its full name in the legend.
    label
        Legend label (default: ``period-n branch``).
    relative
        Draw X̄ − b̄ (:func:`branch_clearance`), as the diagram underneath does when its swept
        parameter is the clearance of ``var``.
    named
        Event kinds already in the legend (updated): each kind is named once per axes.

    Returns
    -------
    matplotlib.axes.Axes
        The artists carry ``gid`` ``branch:stable``, ``branch:unstable`` and
        ``branch:event:<kind>``.
    """
    y = _section_values(branch, var, planet)
    name = str(branch.attrs.get("parameter", ""))
    ax = get_ax(ax)
    lam = np.asarray(branch[name].values, dtype=np.float64)
    if relative:
        b = branch_clearance(branch, var)
        if b is None:
            raise ParameterError(f"relative=True needs a clearance of {var!r}: it has none")
        y = y - b[:, None]
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
                lw=1.3 if which else 1.0,
                zorder=3,
                gid=f"{BRANCH_GID}:{'stable' if which else 'unstable'}",
                label=(f"{text} ({'stable' if which else 'unstable'})" if j == 0 else None),
            )
    if events and branch.sizes.get("event", 0):
        _draw_events(ax, branch, y, set() if named is None else named)
    return ax


def _draw_events(ax: Any, branch: Any, y: np.ndarray, named: set[str]) -> None:
    s = np.asarray(branch["arclength"].values, dtype=np.float64)
    for k in range(branch.sizes["event"]):
        i = min(max(int(branch.event_point.values[k]), 0), y.shape[0] - 1)
        ys = y[i]
        if i + 1 < y.shape[0] and s[i + 1] > s[i]:  # between the two points, in arclength
            f = (float(branch.event_arclength.values[k]) - s[i]) / (s[i + 1] - s[i])
            ys = y[i] + min(max(f, 0.0), 1.0) * (y[i + 1] - y[i])
        mark_event(
            ax, str(branch.event_kind.values[k]), float(branch.event_value.values[k]), ys,
            named, BRANCH_GID,
        )  # fmt: skip


def mark_event(ax: Any, kind: str, x: float, ys: Any, named: set[str], gid: str) -> None:
    """Mark an event of ``kind`` at the parameter value ``x`` and the values ``ys`` (one per
    section point): its marker (``gid`` ``<gid>:event:<kind>``), its full name in the legend
    once per kind (``named``, updated) and its short name (``PD``, ``fold`` …) beside the
    highest marker — above it until
    :func:`~gearchaos.plot.placement.place_event_labels` moves it clear of the curves."""
    marker, colour, short = EVENT_STYLE.get(kind, ("o", "k", kind))
    ys = np.atleast_1d(np.asarray(ys, dtype=np.float64))
    filled = marker in ("x", "P")  # line markers take one colour, the others a rim
    ax.scatter(
        np.full(ys.size, x),
        ys,
        marker=marker,
        s=40,
        **({"c": colour} if filled else {"facecolors": "none", "edgecolors": colour}),
        linewidths=1.3,
        zorder=5,
        gid=f"{gid}:event:{kind}",
        label=EVENT_NAMES.get(kind, kind) if kind not in named else None,
    )
    named.add(kind)
    ax.annotate(
        short,
        (x, float(np.nanmax(ys))),
        xytext=LABEL_PLACES[0][:2],
        textcoords="offset points",
        ha=LABEL_PLACES[0][2],
        va=LABEL_PLACES[0][3],
        fontsize="x-small",
        color=colour,
        zorder=6,
        gid=EVENT_LABEL_GID,
    )


def _given(branch: Any) -> list[str]:
    """``symbol = value`` of the values the branch holds fixed (:func:`given_values`), leaving
    out the continued parameter."""
    return given_values(
        branch.attrs,
        fixed=stored_fixed(branch.attrs),
        gearset=stored_gearset(branch.attrs),
        leave_out=(str(branch.attrs.get("parameter", "")),),
    )


def branch_figure(
    branches: Sequence[Any],
    *,
    var: str | None = None,
    planet: int = 1,
    relative: bool | None = None,
    clearance_lines: bool = False,
    resonances: bool = False,
    physical: bool = True,
    figsize: tuple[float, float] | None = None,
) -> Any:
    """One or several continued branches on their own: the section values of ``var`` of each
    periodic orbit against the continued parameter, stable stretches solid, unstable ones
    dashed, the events marked and named in the legend; the gear set and the values it holds
    fixed in the title.

    Parameters
    ----------
    branches
        Branch datasets of one parameter (:func:`gearchaos.dynamics.open_branch`).
    var, planet
        Section variable (default ``delta_sp``, else the first one the branches observed) and
        planet.
    relative
        Draw X̄ − b̄ (default: when the continued parameter is the clearance of ``var``).
    clearance_lines
        Dashed lines at ±b̄ of the variable's clearance (0 and −2b̄, the flank edges, when
        ``relative``).
    resonances
        When the parameter is Ω: the mesh-harmonic resonances of the gear set, as in
        :func:`~gearchaos.plot.bifurcation.bifurcation`.
    physical
        Physical axes opposite the dimensionless ones (µm, mm/s; sun speed in rpm).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    branches = list(branches)
    if not branches:
        raise ParameterError("branches must hold at least one branch: got none")
    names = [str(br.attrs.get("parameter", "")) for br in branches]
    if len(set(names)) > 1:
        raise ParameterError(
            f"branches must continue one parameter to share an axis: got {', '.join(names)}"
        )
    name = names[0]
    if var is None:
        have = [str(v) for v in branches[0].data_vars if "section" in branches[0][v].dims]
        if not have:
            raise ParameterError("the branch holds no section variable (dimension 'section')")
        var = "delta_sp" if "delta_sp" in have else have[0]
    clearances = [branch_clearance(br, var) for br in branches]
    if relative is None:
        relative = all(b is not None and np.ptp(b) > 0 for b in clearances)
    fig = Figure(figsize=figsize or (7.0, 4.8), layout="constrained")
    ax = fig.add_subplot()
    labels = branch_labels(branches) if len(branches) > 1 else [None]
    named: set[str] = set()
    ys = []
    for k, br in enumerate(branches):
        colour = BRANCH_COLOURS[k % len(BRANCH_COLOURS)]
        branch_overlay(
            br, ax, var=var, planet=planet, color=colour, label=labels[k], relative=relative,
            named=named,
        )  # fmt: skip
        y = _section_values(br, var, planet)
        b = clearances[k]
        ys.append(y - b[:, None] if relative and b is not None else y)
    lam = np.concatenate([np.asarray(br[name].values, dtype=float) for br in branches])
    ax.set_xlim(*_padded(lam))
    fit_to_data(ax, None, np.concatenate([y.ravel() for y in ys]))
    sym = _clearance_symbol(var)
    b0 = clearances[0]
    if clearance_lines and b0 is not None:
        levels = [0.0] if relative else [float(b0[0]), -float(b0[0])]
        for level in levels:
            ax.axhline(level, color="0.35", ls=":", lw=0.9, zorder=1, gid="clearance")
        clearance_notes(ax, "y", levels, sym)
        if relative:
            for br, b in zip(branches, clearances, strict=True):
                if b is not None:
                    x = np.asarray(br[name].values, dtype=float)
                    ax.plot(x, -2.0 * b, color="0.35", ls=":", lw=0.9, zorder=1, gid="clearance")
    gs = stored_gearset(branches[0].attrs)
    if resonances and name == "omega":
        resonance_lines(ax, gs, *ax.get_xlim())
    ax.set_xlabel(axis_label(name, parameter_symbols(branches[0].attrs)))
    per = "planet" in branches[0][var].dims
    ylabel = var_symbol(var, planet if per else None, model_symbols(branches[0].attrs))
    ax.set_ylabel(f"${ylabel} - {sym}$" if relative else f"${ylabel}$")
    model = stored_model(branches[0].attrs) if physical else None
    if model is not None:  # the model's scales and quantities: none without scales
        scales = PhysicalScales.of_model(model)
        secondary_axis(ax, "y", scales.quantity(var), scales)
        # rpm opposite Ω, µm opposite a clearance in b_c (a clearance in metres read in µm)
        physical_axis(ax, "x", name, scales, gs)
    ax.legend(loc="best", fontsize="small")
    fig.suptitle(_title(branches, var, planet), fontsize="medium")
    place_event_labels(fig)  # last: the layout is final
    return fig


def _padded(v: np.ndarray) -> tuple[float, float]:
    lo, hi = float(np.nanmin(v)), float(np.nanmax(v))
    pad = 0.02 * (hi - lo) if hi > lo else 0.05 * max(abs(lo), 1.0)
    return lo - pad, hi + pad


def _title(branches: list[Any], var: str, planet: int) -> str:
    first = branches[0]
    model = subject(first.attrs, stored_gearset(first.attrs))
    periods = sorted({int(br.attrs.get("period", 1)) for br in branches})
    what = (
        f"continued period-{periods[0]} orbit"
        if len(branches) == 1
        else "continued branches of period " + ", ".join(str(n) for n in periods)
    )
    lines = [
        f"{model}: {what}, section values against "
        f"{axis_symbol(first.attrs['parameter'], parameter_symbols(first.attrs))}"
    ]
    values = _given(first)
    if values:
        lines.append(at_line(values))
    rtol = first.attrs.get("rtol")
    u = [
        float(x)
        for br in branches
        if "event_uncertainty" in br
        for x in np.asarray(br["event_uncertainty"].values)
        if np.isfinite(x)
    ]
    solver = f"shooting + pseudo-arclength continuation, rtol {fmt(rtol)}" if rtol else ""
    if u:
        solver += f"; events located to ±{fmt(max(u), '.0e')} or better"
    if solver:
        lines.append(solver)
    return "\n".join(lines)
