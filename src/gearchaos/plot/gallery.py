"""Poincaré galleries: one Poincaré map per parameter value, titled with value, motion and LLE.

The seed shows the evolution of the motion along a parameter path as grids of Poincaré maps
(its Figs. 5, 7 and 10: X̄_sp1 against X̄'_sp1 at τ_k = 2πk/Ω). :func:`poincare_gallery` draws
such a grid from finished simulations and their summaries — it never simulates; the runner
:func:`gearchaos.paper.galleries.run_gallery` and ``gearchaos poincare --vary ...`` do that.
Every panel is titled like ``(o) Ω = 1.875 · 2T · λ₁ = −0.012`` and framed in the colour of
its motion regime (the palette of :mod:`gearchaos.plot.regimes`); optional rows of phase
portraits and amplitude spectra go under each map.
"""

from __future__ import annotations

import math
import string
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from ..errors import ParameterError
from ._common import axis_symbol, fmt, frequency_axis, message, variable
from .phase import phase_portrait, poincare_map
from .regimes import regime_colour, regime_legend_below
from .timeseries import spectrum

__all__ = ["GALLERY_EXTRAS", "gallery_title", "parse_extras", "poincare_gallery"]

#: Extra rows a gallery can add under each Poincaré map, in drawing order.
GALLERY_EXTRAS = ("phase", "spectrum")


def gallery_title(param: str, value: float, summary: dict[str, Any] | None) -> str:
    """Panel title ``Ω = 1.875 (9485 rpm) · 2T · λ₁ = −0.012`` (mathtext symbols; the sun
    speed of a gear set's summary; the LLE only when
    the summary has one, with its standard error when the verdict estimated it —
    ``λ₁ = 0.065 ± 0.005`` —, ``failed`` for a failed integration)."""
    parts = [f"{axis_symbol(param)} = {fmt(value)}"]
    rpm = (summary or {}).get("sun_speed_rpm") if param == "omega" else None
    if rpm is not None:  # a gear set's: the sun speed beside Ω
        parts[0] += f" ({fmt(rpm, '.5g')} rpm)"
    if summary is not None:
        parts.append(str(summary.get("motion", "?")))
        lle = summary.get("lle")
        if lle is not None and math.isfinite(float(lle)):
            text = rf"$\lambda_1$ = {fmt(lle, '.2g')}"
            err = summary.get("lle_error")
            if err is not None and math.isfinite(float(err)) and err > 0:
                text += f" ± {fmt(err, '.1g')}"
            parts.append(text)
    return " · ".join(parts)


def parse_extras(with_: Iterable[str] | str | None) -> tuple[str, ...]:
    """``("phase", "spectrum")`` from ``"phase,spectrum"`` or an iterable, in drawing order;
    unknown names raise :class:`~gearchaos.errors.ParameterError`."""
    if with_ is None:
        return ()
    items = with_.split(",") if isinstance(with_, str) else list(with_)
    names = {str(i).strip().lower() for i in items if str(i).strip()}
    bad = sorted(names - set(GALLERY_EXTRAS))
    if bad:
        raise ParameterError(
            f"with_ must name some of {', '.join(GALLERY_EXTRAS)}: got {', '.join(map(repr, bad))}"
        )
    return tuple(n for n in GALLERY_EXTRAS if n in names)


#: From this many panels per row on, a panel's title takes two lines (value; label and λ₁):
#: on one line ``(a) Ω = 0.81 (4637.7 rpm) · QP · λ₁ = −0.00018 ± 0.0007`` runs into the next
#: panel's title.
WRAP_COLUMNS = 4


def _ncols(n: int) -> int:
    if n <= 4:
        return max(n, 1)
    return min(n, math.ceil(math.sqrt(4.0 * n / 3.0)))


def _small(ax: Any) -> None:
    ax.tick_params(labelsize="x-small")
    ax.xaxis.label.set_size("small")
    ax.yaxis.label.set_size("small")


def poincare_gallery(
    results: Sequence[Any],
    summaries: Sequence[dict[str, Any] | None] | None,
    *,
    param: str,
    values: Sequence[float],
    with_: Iterable[str] | str | None = (),
    planet: int = 1,
    ncols: int | None = None,
    title: str | None = None,
    figsize: tuple[float, float] | None = None,
) -> Any:
    """A grid of Poincaré maps (X̄_spi against X̄'_spi), one per parameter value.

    Parameters
    ----------
    results
        One :class:`~gearchaos.SimulationResult` per value (for reference systems their first
        state and its derivative are drawn).
    summaries
        The :func:`~gearchaos.analysis.summarize` dictionary of each result (``motion``,
        ``lle`` …; computed without an LLE where an entry, or the whole argument, is None).
        A summary whose ``status`` is not ``ok`` (or whose ``motion`` is ``failed``) draws a
        message instead of a map.
    param, values
        The varied parameter's dotted name (``omega``, ``backlash.sun_planet`` …) and the value
        of each result, for the titles ``(a) Ω = 1.2 · 1T · λ₁ = −0.013``.
    with_
        Extra rows under every map: ``"phase"`` (phase portrait, needs
        ``samples_per_period > 1`` for the orbit) and/or ``"spectrum"`` (amplitude spectrum,
        needs ``samples_per_period >= 4``), as names or ``"phase,spectrum"``.
    planet
        The planet of X̄_sp (planetary results).
    ncols
        Panels per row (default: about 4:3 for the whole grid).
    title
        Figure title (default: ``Poincaré maps of X̄_sp1 versus X̄'_sp1 at different Ω``).

    Returns
    -------
    matplotlib.figure.Figure
        Panel frames in the colour of the motion regime; one legend under all panels names
        exactly the regimes present. Not registered with pyplot; save with
        :func:`gearchaos.plot.savefig`.
    """
    from matplotlib.figure import Figure

    from ..analysis.summary import summarize

    results = list(results)
    values = [float(v) for v in values]
    n = len(results)
    if n == 0:
        raise ParameterError("results must hold at least one simulation result: got none")
    if len(values) != n:
        raise ParameterError(f"values must have one value per result ({n}): got {len(values)}")
    sums: list[dict[str, Any] | None] = [None] * n if summaries is None else list(summaries)
    if len(sums) != n:
        raise ParameterError(f"summaries must have one entry per result ({n}): got {len(sums)}")
    extras = parse_extras(with_)
    cols = _ncols(n) if ncols is None else int(ncols)
    if cols < 1:
        raise ParameterError(f"ncols must be an integer >= 1: got {ncols!r}")
    block = 1 + len(extras)
    rows = math.ceil(n / cols)
    if figsize is None:
        figsize = (3.3 * cols, 2.9 * rows * block + 1.2)
    fig = Figure(figsize=figsize, layout="constrained")
    axs = np.atleast_2d(fig.subplots(rows * block, cols, squeeze=False))
    labels: list[str] = []
    var0 = None
    for k, (result, value) in enumerate(zip(results, values, strict=True)):
        summary = sums[k]
        if summary is None:
            summary = summarize(result)
        failed = summary.get("status", "ok") != "ok" or summary.get("motion") == "failed"
        # a record-only summary has no motion: the panel is unresolved, never its record label
        label = "failed" if failed else str(summary.get("motion") or "unresolved")
        labels.append(label)
        shown = {**summary, "motion": label}
        r0, c = (k // cols) * block, k % cols
        var = None  # the model's default observable
        info = variable(result, var, planet)
        if var0 is None:
            var0 = info
        ax = axs[r0, c]
        if failed:
            message(ax, f"integration {summary.get('status', 'failed')}")
        else:
            poincare_map(result, planet, ax=ax, var=var)
            ax.set_xlabel(f"${info.symbol}$")
            ax.set_ylabel(f"${info.dot_symbol}$")
        letter = f"({string.ascii_lowercase[k % 26]}) " if n > 1 else ""
        text = letter + gallery_title(param, value, shown)
        if cols >= WRAP_COLUMNS:  # narrow panels: the label and λ₁ under the value
            text = text.replace(" · ", "\n", 1)
        ax.set_title(text, fontsize="small", loc="left")
        colour = regime_colour(label)
        for spine in ax.spines.values():
            spine.set_edgecolor(colour)
            spine.set_linewidth(2.0)
        _small(ax)
        for j, extra in enumerate(extras, start=1):
            ex = axs[r0 + j, c]
            if failed:
                message(ex, "—")
            elif extra == "phase":
                try:
                    p = float(result.solver.periods)
                    phase_portrait(result, var, planet, ax=ex, periods=min(20.0, p))
                    ex.set_xlabel(f"${info.symbol}$")
                    ex.set_ylabel(f"${info.dot_symbol}$")
                    ex.set_title("phase portrait", fontsize="x-small", loc="left")
                except ParameterError as e:
                    message(ex, str(e))
            elif result.samples_per_period >= 4:
                spectrum(result, var, planet, ax=ex)
                ex.set_xlabel(f"${frequency_axis(result)[0]}$")
                ex.set_ylabel("amplitude")
                ex.set_title("amplitude spectrum", fontsize="x-small", loc="left")
            else:
                message(ex, "no spectrum: samples_per_period < 4")
            _small(ex)
    for k in range(n, rows * cols):
        r0, c = (k // cols) * block, k % cols
        for j in range(block):
            axs[r0 + j, c].set_visible(False)
    if title is None:
        assert var0 is not None
        title = (
            f"Poincaré maps of ${var0.symbol}$ versus ${var0.dot_symbol}$ "
            f"at different {axis_symbol(param)}"
        )
    fig.suptitle(title, fontsize="medium")
    regime_legend_below(fig, labels, title="motion (panel frame colour)")
    return fig
