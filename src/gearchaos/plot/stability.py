"""Stability charts: boundary curves of :func:`gearchaos.boundary_curve` over a 2-D regime map.

Each curve is drawn in the plane of its two parameters (swapped when the map has them the
other way round), styled by its kind and named in one legend: ``fold (jump)``, ``period
doubling``, ``Neimark–Sacker``, ``grazing: <mesh> contact loss`` (the contact of the curve);
its codimension-2 points (cusp, fold–flip, resonances …) are marked and named. Under the curves
the regime map of a classified 2-D sweep of the same two parameters
(:func:`~gearchaos.plot.regime_map`), and opposite the dimensionless axes the physical ones
(sun speed in rpm opposite Ω, µm opposite clearances in units of b_c) when the gear set defines
them. Lines carry ``gid="boundary:<kind>"``, codimension-2 markers ``gid="codim2:<kind>"``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ParameterError
from ._common import (
    at_line,
    axis_label,
    get_ax,
    given_values,
    no_offset,
    parameter_symbols,
    stored_fixed,
    stored_gearset,
    stored_target,
    subject,
)
from .units import PhysicalScales, physical_axis

__all__ = ["BOUNDARY_STYLES", "boundary_label", "stability_chart", "stability_figure"]

#: Line style of each boundary kind (drawn with a white halo, visible on every regime colour).
BOUNDARY_STYLES: dict[str, dict[str, Any]] = {
    "fold": {"color": "black", "linestyle": "-", "linewidth": 2.0},
    "period_doubling": {"color": "#c51b7d", "linestyle": "--", "linewidth": 2.2},
    "neimark_sacker": {"color": "#6a3d9a", "linestyle": "-.", "linewidth": 2.2},
    "grazing": {"color": "#4d4d4d", "linestyle": ":", "linewidth": 2.4},
}
_NAMES = {
    "fold": "fold (jump)",
    "period_doubling": "period doubling",
    "neimark_sacker": "Neimark–Sacker",
}
_CODIM2 = {
    "cusp": ("cusp", "^"),
    "fold_flip": ("fold–flip", "D"),
    "resonance_1_1": ("1:1 resonance", "s"),
    "resonance_1_2": ("1:2 resonance", "s"),
    "resonance_1_3": ("1:3 resonance", "p"),
    "resonance_1_4": ("1:4 resonance", "h"),
    "fold_neimark_sacker": ("fold–Neimark–Sacker", "D"),
    "flip_neimark_sacker": ("flip–Neimark–Sacker", "D"),
    "grazing_fold": ("grazing meets fold", "o"),
    "grazing_period_doubling": ("grazing meets period doubling", "o"),
    "grazing_neimark_sacker": ("grazing meets Neimark–Sacker", "o"),
}
_MESH_WORDS = {"sun_planet": "sun–planet", "planet_ring": "planet–ring", "sun_bearing": "bearing"}


def boundary_label(curve: Any) -> str:
    """The legend name of a curve's kind: ``fold (jump)``, ``period doubling``,
    ``Neimark–Sacker`` or ``grazing: sun–planet contact loss`` (its contact, flank)."""
    kind = str(curve.attrs.get("curve_kind", ""))
    if kind != "grazing":
        return _NAMES.get(kind, kind)
    contact, _, side = str(curve.attrs.get("contact", "")).partition(":")
    base = contact.rstrip("_0123456789xy") if contact[-1:].isdigit() else contact
    words = _MESH_WORDS.get(base.rstrip("_"), base.replace("_", " "))
    flank = {"back": " (back flank)", "negative": " (negative side)"}.get(side, "")
    return f"grazing: {words} contact loss{flank}"


def _check_curve(curve: Any) -> None:
    if curve.attrs.get("kind") != "boundary_curve":
        raise ParameterError(
            "curves must be boundary curves (gearchaos.boundary_curve, gearchaos boundary): "
            f"got a dataset titled {curve.attrs.get('title', '?')!r}"
        )


def stability_chart(
    curves: Any,
    regimes: Any = None,
    ax: Any = None,
    *,
    select: Any = None,
    codim2: bool = True,
    legend: bool = True,
) -> Any:
    """Boundary curves in their parameter plane, over the regime map of ``regimes``.

    Parameters
    ----------
    curves
        One curve dataset or a list (:func:`gearchaos.boundary_curve`,
        :func:`gearchaos.open_curve`), all in the same two parameters.
    regimes
        A classified 2-D sweep of the same two parameters (a store path, dataset or
        :class:`~gearchaos.sweep.SweepResult`), drawn under the curves; None: curves alone.
    ax
        Axes to draw on (default: a new figure).
    select
        Family or direction values of the sweep to fix, as for
        :func:`~gearchaos.plot.regime_map`.
    codim2
        Mark and name the codimension-2 points of the curves.
    legend
        One legend right of the axes: the regimes present, then each boundary kind and
        codimension-2 point.

    Returns
    -------
    matplotlib.axes.Axes
    """
    import matplotlib.patheffects as pe

    curves = list(curves) if isinstance(curves, list | tuple) else [curves]
    if not curves:
        raise ParameterError("curves must hold at least one boundary curve: got none")
    for cv in curves:
        _check_curve(cv)
    names = (str(curves[0].attrs["parameter"]), str(curves[0].attrs["parameter2"]))
    ax = get_ax(ax)
    handles: list[Any] = []
    if regimes is not None:
        from ..sweep.result import SweepResult
        from .regimes import regime_categories, regime_handles, regime_map

        res = SweepResult.of(regimes).select(select)
        xname, yname = res.grid_axes("a stability chart", "motion")
        if {xname, yname} != set(names):
            raise ParameterError(
                f"the regime map varies {xname} and {yname}, the curves {names[0]} and "
                f"{names[1]}: draw curves over a map of the same two parameters"
            )
        names = (xname, yname)
        regime_map(res, ax, legend=False)
        cats = np.asarray(regime_categories(res).values, dtype=object).ravel()
        handles += regime_handles(str(c) for c in cats)
    halo = [pe.Stroke(linewidth=4.0, foreground="white", alpha=0.8), pe.Normal()]
    seen: set[str] = set()
    for cv in curves:
        if {str(cv.attrs["parameter"]), str(cv.attrs["parameter2"])} != set(names):
            raise ParameterError(
                f"every curve must vary {names[0]} and {names[1]}: {cv.attrs['parameter']} and "
                f"{cv.attrs['parameter2']} given"
            )
        kind = str(cv.attrs["curve_kind"])
        label = boundary_label(cv)
        (line,) = ax.plot(
            cv[names[0]].values,
            cv[names[1]].values,
            label=None if label in seen else label,
            gid=f"boundary:{kind}",
            path_effects=halo,
            zorder=3,
            **BOUNDARY_STYLES[kind],
        )
        if label not in seen:
            handles.append(line)
            seen.add(label)
        if not codim2:
            continue
        for k in range(cv.sizes.get("event", 0)):
            ekind = str(cv.event_kind.values[k])
            name, marker = _CODIM2.get(ekind, (ekind, "o"))
            v1, v2 = float(cv.event_value.values[k]), float(cv.event_value2.values[k])
            xy = (v1, v2) if names[0] == cv.attrs["parameter"] else (v2, v1)
            mark = ax.scatter(
                [xy[0]], [xy[1]], marker=marker, s=70, facecolor="white", edgecolor="black",
                linewidth=1.3, zorder=4, gid=f"codim2:{ekind}",
                label=None if name in seen else name,
            )  # fmt: skip
            if name not in seen:
                handles.append(mark)
                seen.add(name)
    if regimes is None:
        psym = parameter_symbols(curves[0].attrs)
        ax.set_xlabel(axis_label(names[0], psym))
        ax.set_ylabel(axis_label(names[1], psym))
        no_offset(ax.xaxis, ax.yaxis)
    if legend:
        ax.legend(
            handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0,
            fontsize="small", title="motion and boundaries" if regimes is not None else None,
        )  # fmt: skip
    return ax


def _scales(curve: Any, regimes: Any) -> tuple[PhysicalScales, Any]:
    """Physical scales and gear set from the sweep, else from what the curve file records
    (its target over the two parameters' ranges; none when it records no model that can be
    built again)."""
    if regimes is not None:
        from ..sweep.result import SweepResult

        res = SweepResult.of(regimes)
        return PhysicalScales.of_sweep(res), res.gearset
    target = stored_target(curve.attrs)
    if target is None:
        return PhysicalScales(), None
    names = (str(curve.attrs["parameter"]), str(curve.attrs["parameter2"]))
    return PhysicalScales.over(target, {n: curve[n].values for n in names}), stored_gearset(
        curve.attrs
    )


def stability_figure(
    curves: Any, regimes: Any = None, *, physical: bool = True, select: Any = None
) -> Any:
    """A figure of :func:`stability_chart` with physical axes opposite the dimensionless ones
    and a title naming the model and the fixed values."""
    from matplotlib.figure import Figure

    curves = list(curves) if isinstance(curves, list | tuple) else [curves]
    fig = Figure(figsize=(8.6, 5.2), layout="constrained")
    ax = fig.add_subplot()
    stability_chart(curves, regimes, ax, select=select)
    if physical and curves:
        scales, gs = _scales(curves[0], regimes)
        physical_axis(ax, "x", _label_name(ax.get_xlabel(), curves[0], regimes, 0), scales, gs)
        physical_axis(ax, "y", _label_name(ax.get_ylabel(), curves[0], regimes, 1), scales, gs)
    fig.suptitle(_title(curves[0].attrs), fontsize="medium")
    return fig


def _title(attrs: Any) -> str:
    """``sheng2016: stability chart`` and, below, the values the curves hold fixed as symbols
    (``at b̄_sp = 3, …``, :func:`given_values`), not the file's JSON."""
    gearset = stored_gearset(attrs)
    values = given_values(
        attrs,
        fixed=stored_fixed(attrs),
        gearset=gearset,
        leave_out=(str(attrs.get("parameter", "")), str(attrs.get("parameter2", ""))),
    )
    head = ": ".join(p for p in (subject(attrs, gearset), "stability chart") if p)
    return head + ("\n" + at_line(values) if values else "")


def _label_name(label: str, curve: Any, regimes: Any, k: int) -> str:
    """The parameter on axis k (0: x) of the chart."""
    if regimes is not None:
        from ..sweep.result import SweepResult

        return SweepResult.of(regimes).layout("motion").vary[k]
    return str(curve.attrs["parameter" if k == 0 else "parameter2"])
