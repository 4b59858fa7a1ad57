"""Basin images and basin fractions (stores of :mod:`gearchaos.sweep.basins`).

* :func:`basin_image` — the 2-D slice of initial states, each cell coloured by the attractor
  its start reaches, with every attractor's section points overlaid (its projection on the
  slice's two coordinates) and a legend naming each attractor with its evidence
  (``1T (x ≈ 1.13, |μ| 0.52)``, ``chaos (λ₁ 0.071)``);
* :func:`fraction_curves` — across the parameter, the fraction of starts ending on each
  attractor (followed as a track), with its confidence band;
* :func:`basins_figure` — either as a figure, for ``gearchaos plot``.

An attractor's colour is the regime palette's colour of its label
(:data:`~gearchaos.plot.regimes.REGIME_COLOURS`), so a 1T basin is the blue of a 1T region
of a regime map; a second (third …) attractor of the same label gets a darker (lighter)
shade of it. Failed starts are black, starts not computed white.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..model.record import recorded_parameters
from ._common import (
    axis_label,
    edges,
    fmt,
    get_ax,
    given,
    model_symbols,
    parameter_symbols,
    speed_text,
    stored_model,
    stored_target,
    subject,
    var_symbol,
)
from .regimes import regime_colour
from .units import PhysicalScales, physical_axis

__all__ = ["attractor_colours", "basin_image", "basins_figure", "fraction_curves"]

#: gid of the overlaid section points.
SECTION_GID = "basin-attractor"
_SHADES = (0.0, -0.35, 0.45, -0.6, 0.7)


def _shade(colour: Any, amount: float) -> tuple[float, float, float]:
    """``colour`` mixed with black (amount < 0) or white (amount > 0)."""
    from matplotlib.colors import to_rgb

    rgb = np.array(to_rgb(colour))
    mixed = rgb * (1 + amount) if amount < 0 else rgb + (1 - rgb) * amount
    r, g, b = (float(v) for v in np.clip(mixed, 0.0, 1.0))
    return r, g, b


def attractor_colours(labels: list[str]) -> list[tuple[float, float, float]]:
    """One colour per attractor: its label's palette colour, shaded for repeats."""
    seen: dict[str, int] = {}
    out = []
    for lab in labels:
        k = seen.get(lab, 0)
        seen[lab] = k + 1
        out.append(_shade(regime_colour(lab), _SHADES[k % len(_SHADES)]))
    return out


def _symbol(name: str, attrs: Any) -> str:
    """Mathtext label of a state: the model's symbol (:func:`model_symbols`), else the
    generic form."""
    return f"${var_symbol(name, None, model_symbols(attrs))}$"


def _scales(attrs: Any) -> PhysicalScales:
    """The store's scales (``characteristic_length_m``, ``omega_n_rad_s``) with the sun speed
    per unit Ω and the quantities of its model (:func:`stored_model`), where it has them."""
    from ..model.contract import Capabilities
    from ..model.target import speeds_at

    length, omega_n = attrs.get("characteristic_length_m"), attrs.get("omega_n_rad_s")
    model = stored_model(attrs)
    rpm = None if model is None else speeds_at(model, 1.0).get("sun_rpm")
    quantities = None if model is None else Capabilities.of(model).quantities
    return PhysicalScales(
        length_m=length, omega_n=omega_n, rpm_per_omega=rpm, quantities=quantities
    )


def _point_model(attrs: Any, values: Mapping[str, Any]) -> Any:
    """The stored model with the basin point's other values applied (the stored model when
    they are none of its parameters; ``None`` when it cannot be built): it turns Ω into the
    sun speed where it has speeds."""
    from ..model.target import model_for

    target = stored_target(attrs)
    if target is None:
        return None
    try:
        return model_for(target, {k: v for k, v in values.items() if k != "omega"})
    except (ParameterError, TypeError):
        return model_for(target, {})


def _physical(ax: Any, axis: str, name: str, attrs: Any) -> None:
    physical_axis(ax, axis, name, _scales(attrs), symbol=_symbol(name, attrs))


def _catalogue(ds: Any, group: int = 0) -> list[dict[str, Any]]:
    text = ds.attrs.get("attractors")
    if not isinstance(text, str):
        raise ParameterError(
            "the basin store has no attractor legend yet (an interrupted computation): run it "
            "again to finish it"
        )
    entries: list[dict[str, Any]] = json.loads(text)[str(group)]["entries"]
    return entries


def _legend_text(e: dict[str, Any], name: str, column: int) -> str:
    from ..dynamics.attractors.basins import BasinAttractor

    return BasinAttractor.from_record(e).legend(name, column, fmt)


def basin_image(ds: Any, ax: Any = None, *, points: bool = True) -> Any:
    """Draw a ``basins`` store on ``ax`` (see the module docstring); return the Axes."""
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    if ds.attrs.get("kind") != "basins":
        raise ParameterError(f"basin_image needs a basins store: got kind {ds.attrs.get('kind')!r}")
    ax = get_ax(ax)
    yname, xname = ds.attrs["dims"]
    entries = _catalogue(ds)
    codes = np.asarray(ds["attractor"].values)
    labels = [str(e["label"]) for e in entries]
    colours = [
        (0.0, 0.0, 0.0),
        (1.0, 1.0, 1.0),
        *attractor_colours(labels),
    ]  # -2 failed, -1 not run, 0 …
    cmap = ListedColormap(colours)
    x, y = np.asarray(ds[xname].values), np.asarray(ds[yname].values)
    ax.pcolormesh(
        edges(x),
        edges(y),
        codes + 2,
        cmap=cmap,
        vmin=-0.5,
        vmax=len(colours) - 0.5,
        shading="flat",
        rasterized=True,
    )
    names = list(np.asarray(ds["state"].values).astype(str))
    ix, iy = names.index(xname), names.index(yname)
    handles = []
    present = set(np.unique(codes).tolist())
    for k, e in enumerate(entries):
        if k not in present:
            continue
        col = colours[k + 2]
        frac = float(np.mean(codes == k))
        handles.append(
            Patch(
                facecolor=col,
                edgecolor="0.3",
                linewidth=0.5,
                label=f"{_legend_text(e, _symbol(xname, ds.attrs), ix)}: {100 * frac:.3g} %",
            )
        )
        if points:
            pts = np.asarray(e["section_states"], dtype=float)
            ax.plot(
                pts[:, ix],
                pts[:, iy],
                ls="none",
                marker="o" if e["period"] else ".",
                ms=6 if e["period"] else 2,
                mfc=_shade(col, -0.5) if e["period"] else "k",
                mec="white",
                mew=1.0 if e["period"] else 0.0,
                gid=SECTION_GID,
                zorder=3,
            )
    for code, name, col in ((-2, "failed", (0, 0, 0)), (-1, "not run", (1, 1, 1))):
        if code in present:
            frac = float(np.mean(codes == code))
            handles.append(
                Patch(facecolor=col, edgecolor="0.3", label=f"{name}: {100 * frac:.3g} %")
            )
    ax.set_xlim(edges(x)[[0, -1]])
    ax.set_ylim(edges(y)[[0, -1]])
    ax.set_xlabel(_symbol(xname, ds.attrs))
    ax.set_ylabel(_symbol(yname, ds.attrs))
    _physical(ax, "x", xname, ds.attrs)
    _physical(ax, "y", yname, ds.attrs)
    ax.legend(
        handles=handles,
        title="attractor (basin share)",
        fontsize="small",
        title_fontsize="small",
        loc="upper left",
        bbox_to_anchor=(1.02 if not _has_right_axis(ds, yname) else 1.18, 1.0),
        borderaxespad=0.0,
    )
    return ax


def _has_right_axis(ds: Any, yname: str) -> bool:
    scales = _scales(ds.attrs)
    q = scales.quantity(yname)
    return q is not None and scales.factor(q) is not None


def fraction_curves(ds: Any, ax: Any = None, *, confidence: float = 0.95) -> Any:
    """Draw the basin fractions of a ``basin_fractions`` store (one line per attractor
    track, its Wilson band at ``confidence``); return the Axes."""
    from ..sweep.basin_fractions import fractions

    ax = get_ax(ax)
    fr = fractions(ds, confidence=confidence)
    param = ds.attrs["dims"][0]
    p = np.asarray(fr[param].values, dtype=float)
    labels = [str(v) for v in fr["track_label"].values]
    state = _symbol(str(ds["state"].values[0]), ds.attrs)
    psym = parameter_symbols(ds.attrs)
    colours = attractor_colours(labels)
    for j, t in enumerate(np.asarray(fr["track"].values)):
        col = (0.0, 0.0, 0.0) if t == -2 else colours[j]
        there = np.asarray(fr["present"].values[:, j])  # drawn where the attractor exists
        f = np.where(there, fr["fraction"].values[:, j], np.nan)
        lo = np.where(there, fr["fraction_low"].values[:, j], np.nan)
        hi = np.where(there, fr["fraction_high"].values[:, j], np.nan)
        name = "failed" if t == -2 else _track_legend(fr, j, state, param, psym)
        ax.fill_between(p, lo, hi, color=col, alpha=0.2, lw=0)
        ax.errorbar(
            p, f, yerr=[f - lo, hi - f], color=col, marker="o", ms=3, capsize=2, lw=1.2,
            elinewidth=0.8, label=name,
        )  # fmt: skip
    ax.set_ylim(-0.02, 1.02)
    if p.size > 1:  # a margin: the end points and their intervals stay visible
        pad = 0.03 * (p.max() - p.min())
        ax.set_xlim(p.min() - pad, p.max() + pad)
    ax.set_xlabel(axis_label(param, psym))
    n = int(ds.sizes["start"])
    ax.set_ylabel(f"fraction of {n} starts")
    _physical(ax, "x", param, ds.attrs)
    ax.legend(
        title=f"attractor ({100 * confidence:g} % Wilson band)",
        fontsize="small",
        title_fontsize="small",
        loc="upper left",
        bbox_to_anchor=(1.02, 1.0),
        borderaxespad=0.0,
    )
    return ax


def _track_legend(
    fr: Any, j: int, state: str, param: str, symbols: Mapping[str, str] | None = None
) -> str:
    """``1T ($x$ ≈ 1.08 at $\\Omega$ = 0.8)``: the label of track j of :func:`fractions`
    and where its attractor lies (``state``, a symbol) at the parameter value where it is
    first found."""
    where = float(fr["track_position"].values[j])
    at = given(param, float(fr["track_found_at"].values[j]), symbols)
    return f"{fr['track_label'].values[j]} ({state} ≈ {fmt(where, '.3g')} at {at})"


def basins_figure(ds: Any) -> Any:
    """A figure of a basin store: the image of a ``basins`` store, the fraction curves of a
    ``basin_fractions`` store; the title says the model and the operating point."""
    import matplotlib.pyplot as plt

    kind = ds.attrs.get("kind")
    fig, ax = plt.subplots(figsize=(8.4, 5.2), layout="constrained")
    spec = json.loads(ds.attrs["basin_spec"])
    if "omega" not in spec["values"] and "omega" in ds.attrs and ds.attrs["dims"][0] != "omega":
        spec["values"] = {"omega": float(ds.attrs["omega"]), **spec["values"]}
    psym = parameter_symbols(ds.attrs)
    model = _point_model(ds.attrs, spec["values"])
    point = ", ".join(
        given(k, v, psym) + (speed_text(v, model) if k == "omega" else "")
        for k, v in spec["values"].items()
    )
    if kind == "basins":
        basin_image(ds, ax)
        title = f"{subject(ds.attrs)}: basins of attraction" + (f" at {point}" if point else "")
        n = ds["attractor"].size
        title += f" ({n} starts, {ds.attrs['transient_periods']:g} + {ds.attrs['periods']} periods)"
    elif kind == "basin_fractions":
        fraction_curves(ds, ax)
        title = f"{subject(ds.attrs)}: basin fractions" + (f" at {point}" if point else "")
    else:
        plt.close(fig)
        raise ParameterError(f"not a basin store: kind {kind!r}")
    shown = recorded_parameters(ds.attrs)  # a model that is not a gear set: its parameters
    if shown:
        title += "\n" + ", ".join(given(k, v, psym) for k, v in shown.items())
    ax.set_title(title, fontsize="medium")
    return fig
