"""Amplitude–frequency curves: continued branches beside the brute-force up/down sweeps.

The response amplitude of a periodic orbit is the peak-to-peak deflection over the orbit,
A = max δ̄ − min δ̄ (of a mesh, one planet), read from the extrema every branch point
(:func:`gearchaos.continuation`) and every sweep point (:func:`gearchaos.response`,
:func:`gearchaos.bifurcation`) stores. :func:`amplitude_figure` draws, over the swept
parameter (usually Ω), A of every continued branch — stable stretches solid, unstable ones
dashed, its folds, period doublings, Neimark–Sacker and grazing events marked — and beside it
the brute-force points of the up and down sweeps of a response store (up ▲, down ▼), their
jumps between periodic neighbours as arrows (:func:`~gearchaos.sweep.frequency.find_jumps`),
and the motion band under it. Where the sweeps settle on a stable periodic orbit the points
lie on a stable branch; a jump leaves a branch at a fold.

With ``quantity="force_peak"`` the same figure draws the peak contact force max |F̄ᶜ| of one
mesh instead (the mesh whose deflection is ``var``): ``force_peak_<mesh>`` of every branch
point (over its orbit) beside the sweeps' ``force_peak_<mesh>`` (over their recorded windows)
— one definition, :func:`gearchaos.model.response.peak_contact_forces`, for both.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..sweep import SweepResult
from ..sweep.frequency import find_jumps
from ._common import axis_label, fmt, model_symbols, parameter_symbols, var_symbol
from .bifurcation import suptitle
from .branch import BRANCH_COLOURS, branch_labels, mark_event
from .placement import place_event_labels
from .regimes import regime_band, regime_categories, regime_legend_below
from .response import MESH_LABEL, periodic_mask
from .units import PhysicalScales, fit_to_data, linear_axis

__all__ = [
    "AMPLITUDE_GID",
    "QUANTITIES",
    "amplitude_figure",
    "amplitude_of",
    "amplitude_var",
    "force_mesh",
    "peak_force_of",
]

#: ``gid`` prefix of the artists of :func:`amplitude_figure`.
AMPLITUDE_GID = "amplitude"
#: Marker and colour of the sweep directions.
SWEEP_STYLE = {"up": ("^", "0.25"), "down": ("v", "0.6"), None: ("o", "0.4")}
#: What the figure draws over the swept parameter: the deflection's peak-to-peak amplitude,
#: or the peak contact force of its mesh (the response sweep's name).
QUANTITIES = ("amplitude", "force_peak")


def amplitude_var(ds: Any, var: str | None = None) -> str:
    """The deflection whose amplitude is drawn: ``var`` or, by default, ``delta_sp`` (else the
    first tracked variable with stored extrema that is not a contact force)."""
    have = [
        str(v)[:-4]
        for v in ds.data_vars
        if str(v).endswith("_max") and f"{str(v)[:-4]}_min" in ds.data_vars
    ]
    if var is None:
        plain = [v for v in have if not v.startswith("contact_force")]
        if not plain:
            raise ParameterError("the dataset stores no extrema (no VAR_min and VAR_max)")
        return "delta_sp" if "delta_sp" in plain else plain[0]
    if var not in have:
        raise ParameterError(
            f"var must be a variable with stored extrema ({', '.join(have)}): got {var!r}"
        )
    return var


def amplitude_of(ds: Any, var: str, planet: int = 1) -> Any:
    """max − min of ``var`` over the orbit (branch) or recorded window (sweep), of
    ``planet`` for per-planet variables (a DataArray over the other dimensions)."""
    return _planet_of(ds[f"{var}_max"] - ds[f"{var}_min"], planet)


def _planet_of(v: Any, planet: int) -> Any:
    if "planet_all" in v.dims:
        planets = [int(p) for p in np.asarray(v["planet_all"].values)]
        if planet not in planets:
            raise ParameterError(f"planet must be one of {planets}: got {planet!r}")
        v = v.sel(planet_all=planet)
    return v


def force_mesh(ds: Any, branches: Sequence[Any], var: str | None = None) -> str:
    """The mesh whose peak contact force is drawn: by default the first of the sweep's
    (``sp``, ``rp``, ``mesh``), else the mesh whose deflection is ``var`` (as the branches'
    ``force_peak_<mesh>`` record it)."""
    meshes = [m for m in MESH_LABEL if f"force_peak_{m}" in ds.data_vars]
    if not meshes:
        raise ParameterError(
            "quantity='force_peak' needs a store of gearchaos response (gc.response): this "
            "store has no force_peak_* variables"
        )
    if var is None:
        return meshes[0]
    found = {
        str(br[f"force_peak_{m}"].attrs.get("deflection")): m
        for br in branches
        for m in meshes
        if f"force_peak_{m}" in br.data_vars
    }
    if var not in found:
        have = ", ".join(sorted(found)) or "none: no branch stores peak contact forces"
        raise ParameterError(
            f"var must be the deflection of a mesh with peak contact forces ({have}): got {var!r}"
        )
    return found[var]


def peak_force_of(ds: Any, mesh: str, planet: int = 1) -> Any:
    """``force_peak_<mesh>`` of ``ds`` (a branch or a response sweep) of ``planet`` for
    per-planet meshes; a branch file written before branches stored it is refused by name."""
    key = f"force_peak_{mesh}"
    if key not in ds.data_vars:
        src = ds.encoding.get("source")
        raise ParameterError(
            f"{'branch ' + str(src) if src else 'the branch'} has no variable {key} (the peak "
            "contact force over the orbit; branch files written before gearchaos stored it "
            "lack it): continue the branch again to draw its peak contact force"
        )
    return _planet_of(ds[key], planet)


def _draw_branch(ax: Any, br: Any, amp: np.ndarray, colour: str, label: str,
                 named: set[str]) -> np.ndarray:  # fmt: skip
    name = str(br.attrs["parameter"])
    lam = np.asarray(br[name].values, dtype=float)
    stable = np.asarray(br["stable"].values, dtype=bool)
    for which, style in ((True, "-"), (False, "--")):
        shown = stable == which
        shown[1:] |= (stable == which)[:-1]  # keep the joins between stretches
        if not shown.any():
            continue
        ax.plot(
            lam, np.where(shown, amp, np.nan), style, color=colour, lw=1.4 if which else 1.0,
            zorder=3, gid=f"{AMPLITUDE_GID}:branch:{'stable' if which else 'unstable'}",
            label=f"{label} ({'stable' if which else 'unstable'})",
        )  # fmt: skip
    s = np.asarray(br["arclength"].values, dtype=float)
    for k in range(br.sizes.get("event", 0)):
        i = min(max(int(br.event_point.values[k]), 0), lam.size - 1)
        a = amp[i]
        if i + 1 < lam.size and s[i + 1] > s[i]:
            f = (float(br.event_arclength.values[k]) - s[i]) / (s[i + 1] - s[i])
            a = amp[i] + min(max(f, 0.0), 1.0) * (amp[i + 1] - amp[i])
        mark_event(ax, str(br.event_kind.values[k]), float(br.event_value.values[k]), a, named,
                   AMPLITUDE_GID)  # fmt: skip
    return amp


def amplitude_figure(
    ds: Any,
    branches: Sequence[Any],
    *,
    var: str | None = None,
    planet: int = 1,
    quantity: str = "amplitude",
    rel_jump: float = 0.25,
    figsize: tuple[float, float] | None = None,
) -> Any:
    """The amplitude–frequency figure of a 1-D (response) sweep and continued branches, or
    (``quantity="force_peak"``) their peak contact force over the swept parameter.

    Parameters
    ----------
    ds
        A 1-D sweep store or dataset (a response store's up and down sweeps, or any 1-D
        bifurcation sweep) with the extrema of ``var``.
    branches
        Continued branches of the swept parameter (:func:`gearchaos.continuation`,
        :func:`gearchaos.dynamics.continuation.cascade.open_cascade`).
    var, planet
        The deflection (default ``delta_sp``; ``x`` for the backlash oscillator) and planet;
        with ``quantity="force_peak"``, the deflection of the mesh whose force is drawn
        (default the sweep's first mesh, :func:`force_mesh`).
    quantity
        ``"amplitude"`` (max − min of ``var``) or ``"force_peak"`` (the peak contact force
        max |F̄ᶜ| of its mesh: ``force_peak_<mesh>`` of the branches and of the response sweep;
        both store it, branches since they record it — an older branch file is refused by
        the variable's name).
    rel_jump
        Jump threshold as a fraction of a sweep curve's range (:func:`find_jumps`); only
        jumps between two periodic points are drawn.

    Returns
    -------
    matplotlib.figure.Figure
        The first axes holds the branches (``gid`` ``amplitude:branch:stable`` /
        ``…:unstable``, events ``amplitude:event:<kind>``), the sweep points
        (``amplitude:sweep:up`` / ``…:down``) and jumps (``amplitude:jump``); the second, when
        the store has motion labels, the motion band.
    """
    from matplotlib.figure import Figure

    if quantity not in QUANTITIES:
        raise ParameterError(f"quantity must be one of {', '.join(QUANTITIES)}: got {quantity!r}")
    res = SweepResult.of(ds)
    sd = res.ds
    branches = list(branches)
    force = quantity == "force_peak"
    if force:
        mesh = force_mesh(sd, branches, var)
        amp = peak_force_of(sd, mesh, planet)
    else:
        var = amplitude_var(sd, var)
        amp = amplitude_of(sd, var, planet)
    lead = [d for d in amp.dims if d != "direction"]
    if len(lead) != 1:
        raise ParameterError(f"amplitude_figure draws 1-D sweeps: got dimensions {lead}")
    xname = lead[0]
    values = []
    for br in branches:
        if str(br.attrs.get("parameter")) != xname:
            raise ParameterError(
                f"branches must continue the swept parameter {xname}: got "
                f"{br.attrs.get('parameter')!r}"
            )
        # the branch stores the extrema of var, or the peak force of the mesh
        of = (
            peak_force_of(br, mesh, planet)
            if force
            else amplitude_of(br, amplitude_var(br, var), planet)
        )
        values.append(np.asarray(of.values, dtype=float))
    x = np.asarray(sd[xname].values, dtype=float)
    directions = list(sd["direction"].values) if "direction" in sd.dims else [None]
    labelled = "motion" in sd.data_vars
    fig = Figure(figsize=figsize or (10.0, 5.6 if labelled else 5.0), layout="constrained")
    if labelled:
        grid = fig.add_gridspec(2, 1, height_ratios=[1.0, 0.1 * len(directions) + 0.02])
        ax = fig.add_subplot(grid[0, 0])
        band = fig.add_subplot(grid[1, 0], sharex=ax)
    else:
        ax, band = fig.add_subplot(), None
    ys: list[np.ndarray] = []
    for d in directions:
        y = np.asarray((amp.sel(direction=d) if d is not None else amp).values, dtype=float)
        ys.append(y)
        marker, colour = SWEEP_STYLE.get(d, SWEEP_STYLE[None])
        ax.plot(
            x, y, ls="none", marker=marker, ms=4, mfc="none", mec=colour, zorder=4,
            gid=f"{AMPLITUDE_GID}:sweep:{d or 'points'}",
            label=f"brute-force sweep{', ' + d if d else ''}",
        )  # fmt: skip
        periodic = periodic_mask(sd, d)
        if periodic is None:
            continue
        for xj in find_jumps(x, y, rel=rel_jump, where=periodic):
            k = int(np.searchsorted(x, xj))
            y0, y1 = (y[k], y[k - 1]) if d == "down" else (y[k - 1], y[k])
            ax.annotate(
                "", xy=(xj, y1), xytext=(xj, y0), gid=f"{AMPLITUDE_GID}:jump",
                arrowprops={"arrowstyle": "->", "color": colour, "lw": 1.2},
            )  # fmt: skip
    labels = branch_labels(branches) if len(branches) > 1 else [
        f"period-{int(br.attrs.get('period', 1))} branch" for br in branches
    ]  # fmt: skip
    named: set[str] = set()
    lo, hi = float(np.min(x)), float(np.max(x))
    for k, br in enumerate(branches):
        colour = BRANCH_COLOURS[k % len(BRANCH_COLOURS)]
        a = _draw_branch(ax, br, values[k], colour, labels[k], named)
        lam = np.asarray(br[str(br.attrs["parameter"])].values, dtype=float)
        ys.append(a[(lam >= lo) & (lam <= hi)])
    pad = 0.02 * (hi - lo)
    ax.set_xlim(lo - pad, hi + pad)
    fit_to_data(ax, None, np.concatenate([np.ravel(y) for y in ys]))
    scales = PhysicalScales.of_sweep(res)
    if force:
        per = "planet_all" in sd[f"force_peak_{mesh}"].dims
        sub = f"_{{{mesh}{planet}}}" if per else ("" if mesh == "mesh" else f"_{{{mesh}}}")
        ax.set_ylabel(f"peak contact force $\\max|\\bar F^c{sub}|$")
        found = scales.factor("force")
        right = f"peak contact force {found[1]}" if found else ""
    else:
        assert var is not None  # amplitude_var chose it
        per = "planet" in sd[f"{var}_max"].dims or "planet_all" in sd[f"{var}_max"].dims
        sym = var_symbol(var, planet if per else None, model_symbols(sd.attrs))
        ax.set_ylabel(f"amplitude $\\max {sym} - \\min {sym}$")
        kind = scales.quantity(var)
        found = scales.factor(kind) if kind is not None else None
        right = f"amplitude {found[1]}" if found else ""
    ax.grid(alpha=0.3, lw=0.5)
    if found is not None:
        linear_axis(ax, "y", found[0], right)
    if xname == "omega":
        rpm = scales.factor("omega")
        if rpm is not None:
            linear_axis(ax, "x", rpm[0], rpm[1])
    # beside the axes: folds, jumps and resonance peaks fill every corner of the curves
    ax.legend(
        fontsize="x-small",
        loc="upper left",
        bbox_to_anchor=(1.12 if found else 1.02, 1.0),
        borderaxespad=0.0,
    )
    bottom = ax
    if band is not None:
        limits = ax.get_xlim()
        regime_band(res, band)
        band.set_xlim(*limits)
        ax.tick_params(axis="x", labelbottom=False)
        regime_legend_below(fig, np.asarray(regime_categories(res).values, dtype=object).ravel())
        bottom = band
    bottom.set_xlabel(axis_label(xname, parameter_symbols(sd.attrs)))
    what = "amplitude–frequency curves"
    if force:
        who = f"{MESH_LABEL[mesh]} mesh" + (f", planet {planet}" if per else "")
        what = "peak contact force curves" + (f" ({who})" if mesh != "mesh" else "")
    rtols = sorted({fmt(br.attrs.get("rtol")) for br in branches if br.attrs.get("rtol")})
    extra = f"continued branches (rtol {', '.join(rtols)}) beside the brute-force sweeps"
    fig.suptitle(f"{suptitle(res, what)}\n{extra}", fontsize="medium")
    place_event_labels(fig)
    return fig
