"""Physical units beside the dimensionless ones, and axes that follow the data.

Every dimensionless quantity of the model has a physical counterpart fixed by the gear set
(MODEL.md §7): lengths x = b_c x̄, velocities ẋ = b_c ω_n x̄', forces F = k_m,sp b_c F̄, time
t = τ/ω_n, the mesh frequency f_m = Ω ω_n/2π and the sun speed n_s = 60 f_m (z_s + z_r)/(z_s z_r).
:class:`PhysicalScales` holds these factors (from a simulation or a sweep store),
:func:`secondary_axis` adds the physical axis opposite the dimensionless one and
:func:`physical_axis` that of a swept parameter or state (rpm opposite Ω, µm opposite b̄ …).
:func:`fit_to_data` sets limits from the data alone (clearance lines never widen them),
:func:`clearance_notes` marks the clearances that fall outside, and :func:`section_style`
sizes Poincaré points so that structure shows for a hundred and for ten thousand points.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..gearset.schema import MODULE_BOUNDED, OMEGA
from ..model.target import Target
from ._common import axis_symbol, fmt

__all__ = [
    "CLEARANCE_NOTE_GID",
    "PhysicalScales",
    "clearance_notes",
    "fit_to_data",
    "linear_axis",
    "notes_clear_of",
    "physical_axis",
    "secondary_axis",
    "section_points",
    "section_style",
    "var_quantity",
]

#: ``gid`` of the edge notes of clearances outside the data range.
CLEARANCE_NOTE_GID = "clearance-note"
#: Margin around the data range, as a fraction of it.
MARGIN = 0.05
#: Margin of data with at most SPARSE distinct values (the points of a short periodic orbit).
SPARSE = 8
SPARSE_MARGIN = 0.25


@dataclass(frozen=True)
class PhysicalScales:
    """Factors from dimensionless to physical values (``None`` where not defined)."""

    length_m: float | None = None  # b_c
    omega_n: float | None = None  # rad/s
    force_n: float | None = None  # k_m,sp b_c
    rpm_per_omega: float | None = None  # sun speed [rpm] per unit Ω
    #: The model's forcing period T in units of 2π/Ω (its ``period_factor``): one period
    #: lasts T/ω_n = period_factor·2π/(Ω ω_n) (:meth:`period_ms`).
    period_factor: float = dataclasses.field(default=1.0, compare=False)
    #: The model's ``quantities`` (variable or group → ``length``, ``velocity``, ``force``),
    #: which :meth:`quantity` reads; ``None``: the planetary model's.
    quantities: Mapping[str, str] | None = dataclasses.field(
        default=None, compare=False, hash=False, repr=False
    )

    @classmethod
    def of_model(cls, model: Any) -> PhysicalScales:
        """The scales of a model that gives them (its ``scales``: ω_n, the length and the
        scale of each quantity it uses), with the sun speed per unit Ω where it has speeds
        (:func:`~gearchaos.model.target.speeds_at`); none for a model without scales."""
        from ..model.contract import Capabilities
        from ..model.target import speeds_at

        caps = Capabilities.of(model)
        sc = caps.scales
        if sc is None:
            return cls()
        used = set(caps.quantities.values())
        force = float(sc.force) if "force" in used else None
        rpm = speeds_at(model, 1.0).get("sun_rpm")
        return cls(
            float(sc.length), float(sc.omega_n), force, rpm, caps.period_factor, caps.quantities
        )

    @classmethod
    def of_result(cls, result: Any) -> PhysicalScales:
        return cls.of_model(result.system.model)

    @classmethod
    def of_sweep(cls, res: Any) -> PhysicalScales:
        """From a :class:`~gearchaos.sweep.SweepResult`: its target (gear set or model) with
        the fixed values, over the ranges of its swept parameters (:meth:`over`); none when
        the store's model cannot be built again."""
        from ..errors import ParameterError

        try:
            target = res.base_target
        except ParameterError:  # a model the user has not named: no scales to read
            return cls()
        if target is None:
            return cls()
        fixed = {k: v for k, v in res.fixed.items() if k != OMEGA}
        ranges = {
            name: np.asarray(res.ds[name].values, dtype=np.float64)
            for name in res.swept_names
            if name in res.ds.coords
        }
        return cls.over(target, ranges, fixed)

    @classmethod
    def over(
        cls, target: Target, ranges: Mapping[str, Any], fixed: Mapping[str, Any] | None = None
    ) -> PhysicalScales:
        """The scales of ``target`` (a gear set or a :class:`~gearchaos.model.System`) with
        the ``fixed`` values, where parameters take the values ``ranges`` (name → values): a
        scale that one of them changes (ω_n along a stiffness or a mass, b_c along the
        characteristic length …) is left undefined, since a physical axis linear in the
        dimensionless one would be wrong along it (checked at both ends of each range)."""
        from ..model.target import model_for

        fixed = dict(fixed or {})
        base = cls.of_model(model_for(target, fixed))
        varying: set[str] = set()
        for name, values in ranges.items():
            if name == OMEGA:
                continue
            values = np.asarray(values, dtype=np.float64)
            for v in (float(np.nanmin(values)), float(np.nanmax(values))):
                end = cls.of_model(model_for(target, {**fixed, name: v}))
                varying |= {f for f in SCALE_FIELDS if not _same(getattr(base, f), getattr(end, f))}
        cleared: dict[str, Any] = dict.fromkeys(varying)
        return dataclasses.replace(base, **cleared)

    def quantity(self, var: str) -> str | None:
        """The physical quantity of the variable ``var`` in the model these scales are of
        (:func:`var_quantity` of its ``quantities``)."""
        return var_quantity(var, self.quantities)

    def factor(self, quantity: str) -> tuple[float, str] | None:
        """(factor, axis label) of a quantity: ``length`` (µm), ``velocity`` (mm/s),
        ``force`` (N), ``omega`` (sun speed, rpm), ``mesh_hz`` (Hz per Ω); the time of one
        forcing period at a given Ω is :meth:`period_ms`."""
        if quantity == "length" and self.length_m:
            return self.length_m * 1e6, "[µm]"
        if quantity == "velocity" and self.length_m and self.omega_n:
            return self.length_m * self.omega_n * 1e3, "[mm/s]"
        if quantity == "force" and self.force_n:
            return self.force_n, "[N]"
        if quantity == "omega" and self.rpm_per_omega:
            return self.rpm_per_omega, "sun speed [rpm]"
        if quantity == "mesh_hz" and self.omega_n:
            return self.omega_n / (2.0 * math.pi), "[Hz]"
        return None

    def period_ms(self, omega: float) -> float | None:
        """One forcing period T of the model at Ω in milliseconds: T/ω_n with
        T = ``period_factor``·2π/Ω (:attr:`~gearchaos.model.System.period`: 2π/Ω unless the
        model declares a forcing of several frequencies)."""
        if not self.omega_n:
            return None
        return 2e3 * math.pi * self.period_factor / (omega * self.omega_n)


#: The scale fields of :class:`PhysicalScales` (not the quantities table).
SCALE_FIELDS = tuple(f.name for f in dataclasses.fields(PhysicalScales) if f.compare)


def _same(a: float | None, b: float | None) -> bool:
    return (a is None and b is None) or (
        a is not None and b is not None and math.isclose(a, b, rel_tol=1e-9)
    )


def var_quantity(var: str, quantities: Mapping[str, str] | None = None) -> str | None:
    """The physical quantity of a section variable, from a model's ``quantities`` (the model
    contract's; default: the planetary model's): ``delta_sp`` → ``length``, ``delta_sp_dot``
    → ``velocity``, ``force_rp`` and ``contact_force_rp`` → ``force``; a group's member as
    its group (``delta_sp_1``, ``p_1_dot``); ``None`` otherwise."""
    import re

    from ..model.planetary import PlanetaryModel

    table = PlanetaryModel.quantities if quantities is None else quantities
    var = re.sub(r"_\d+(_dot)?$", lambda m: m.group(1) or "", var)  # delta_sp_1_dot → …_dot
    var = re.sub(r"_\d+$", "", var)
    return table.get(var)


def secondary_axis(
    ax: Any, axis: str, quantity: str | None, scales: PhysicalScales, *, symbol: str = ""
) -> Any:
    """The physical axis opposite a dimensionless one (top for x, right for y), linear in
    it; nothing when the scales do not define the quantity. Returns the secondary axis."""
    if quantity is None:
        return None
    found = scales.factor(quantity)
    if found is None:
        return None
    return linear_axis(ax, axis, found[0], f"{symbol} {found[1]}".strip())


def physical_axis(
    ax: Any,
    axis: str,
    name: str,
    scales: PhysicalScales,
    gearset: Any = None,
    *,
    symbol: str | None = None,
) -> Any:
    """The physical axis opposite the dimensionless axis of ``name`` (top for x, right for
    y), for every map, diagram and chart over parameters or states: the sun speed in rpm
    opposite Ω, µm opposite a clearance that ``gearset`` gives in units of b_c (``backlash.*``,
    ``clearance.sun_bearing``), µm, mm/s or N opposite a state (:func:`var_quantity`, labelled
    ``symbol``); nothing where the scales do not define it (a reference system) or the axis
    is physical already (a torque in N m). A clearance that ``gearset`` gives in metres
    (``backlash.units = "m"``) is read in µm (the axis relabelled ``b_sp [µm]``, its ticks
    in µm: :func:`metres_axis`) with b̄ = b/b_c opposite. Returns the axis or None."""
    if name == OMEGA:
        found = scales.factor("omega")
        return None if found is None else linear_axis(ax, axis, found[0], found[1])
    if MODULE_BOUNDED.get(name):
        units = _units(gearset, name)
        if units == "m":
            return metres_axis(ax, axis, name, scales)
        if units != "dimensionless":
            return None
        sym = symbol or _unbarred(name)
        return secondary_axis(ax, axis, "length", scales, symbol=sym)
    return secondary_axis(ax, axis, scales.quantity(name), scales, symbol=symbol or "")


def _unbarred(name: str) -> str:
    """The symbol of a clearance in metres: ``$b_{sp}$`` (its b̄ without the bar)."""
    return axis_symbol(name).replace("\\bar ", "")


def _units(gearset: Any, name: str) -> str | None:
    """The units (``dimensionless`` or ``m``) in which ``gearset`` gives the clearance
    ``name``; None without a gear set."""
    # gear-set switch: clearances in metres are a gear set's input setting (backlash.units)
    if gearset is None:
        return None
    from ..gearset.mapping import get_value

    return str(get_value(gearset, str(MODULE_BOUNDED[name])))


def metres_axis(ax: Any, axis: str, name: str, scales: PhysicalScales) -> Any:
    """The axis of a clearance ``name`` whose values are in metres, read in µm: labelled
    ``$b_{sp}$ [µm]`` with ticks 10⁶ times the values, and b̄ = b/b_c (the model's
    dimensionless clearance) opposite where b_c is defined. Returns the opposite axis or
    None."""
    from matplotlib.ticker import FuncFormatter

    label = f"{_unbarred(name)} [µm]"
    shared = ax.get_shared_x_axes() if axis == "x" else ax.get_shared_y_axes()
    for other in shared.get_siblings(ax):  # a regime band below shares the axis and its label
        target = other.xaxis if axis == "x" else other.yaxis
        if other is ax or target.get_label_text():
            target.set_major_formatter(FuncFormatter(lambda v, _: fmt(v * 1e6, ".4g")))
            target.set_label_text(label)
    if not scales.length_m:
        return None
    return linear_axis(ax, axis, 1.0 / scales.length_m, axis_symbol(name))


def linear_axis(ax: Any, axis: str, k: float, label: str) -> Any:
    """A secondary axis (top for x, right for y) showing ``k`` times the primary values."""

    def forward(v: Any) -> Any:
        return np.asarray(v) * k

    def inverse(v: Any) -> Any:
        return np.asarray(v) / k

    if axis == "x":
        sec = ax.secondary_xaxis("top", functions=(forward, inverse))
        sec.set_xlabel(label, fontsize="small")
    else:
        sec = ax.secondary_yaxis("right", functions=(forward, inverse))
        sec.set_ylabel(label, fontsize="small")
    sec.tick_params(labelsize="small")
    return sec


def data_range(
    values: Any, *, margin: float = MARGIN, mag: float | None = None, sparse: bool = False
) -> tuple[float, float] | None:
    """[lo, hi] of the finite values widened by ``margin`` of their span. A span below 10⁻⁶ of
    the largest magnitude (``mag``, default the values') shows ±5 % of that magnitude around
    the centre (±1 around zero): a periodic point spread by integration noise (≈ rtol ≤ 10⁻⁸
    of it) stays a point, while two section values 10⁻⁴ apart (a narrow 2T) stay two. With
    ``sparse`` (section points), values that take at most ``SPARSE`` distinct levels (to 10⁻³
    of their span: the points of an nT orbit) get ``SPARSE_MARGIN`` of their span, so that no
    point sits on the frame."""
    v = np.asarray(values, dtype=np.float64).ravel()
    v = v[np.isfinite(v)]
    if v.size == 0:
        return None
    lo, hi = float(v.min()), float(v.max())
    m = float(np.max(np.abs(v))) if mag is None else mag
    if hi - lo <= 1e-6 * m or m == 0.0:
        centre = 0.5 * (lo + hi)
        half = 0.05 * m if m > 0 else 1.0
        return centre - half, centre + half
    few = sparse and np.unique(np.round((v - lo) / (hi - lo), 3)).size <= SPARSE
    pad = (SPARSE_MARGIN if few else margin) * (hi - lo)
    return lo - pad, hi + pad


def fit_to_data(
    ax: Any, x: Any = None, y: Any = None, *, joint: bool = False, mag: float | None = None
) -> None:
    """Set the limits of ``ax`` from the data (``x``, ``y``; either may be ``None`` to keep an
    axis as it is), ignoring clearance and reference lines; turn axis offsets off. With
    ``joint`` (x–x' planes) the degenerate-span test uses the larger magnitude of both and the
    points of a short periodic orbit get a wider margin (:func:`data_range`);
    ``mag`` sets that magnitude (for values drawn relative to an offset)."""
    if joint and x is not None and y is not None:
        both = np.concatenate([np.ravel(np.asarray(x, float)), np.ravel(np.asarray(y, float))])
        both = both[np.isfinite(both)]
        mag = float(np.max(np.abs(both))) if both.size else None
    for data, setter, axis in ((x, ax.set_xlim, ax.xaxis), (y, ax.set_ylim, ax.yaxis)):
        if data is not None and axis.get_scale() == "linear":
            found = data_range(data, mag=mag, sparse=joint)
            if found is not None:
                setter(*found)
        formatter = axis.get_major_formatter()
        if hasattr(formatter, "set_useOffset"):
            formatter.set_useOffset(False)


def clearance_notes(
    ax: Any, axis: str, values: Any, symbol: str, text: str | None = None
) -> list[Any]:
    """Mark the clearance levels of ``values`` (scalars) that lie outside the limits of
    ``axis`` with a small note at that edge (``−b̄_sp = −3 ↓``, or ``text`` for every level;
    levels beyond the same edge share one note); returns the notes."""
    lo, hi = ax.get_ylim() if axis == "y" else ax.get_xlim()
    edges: dict[bool, list[str]] = {True: [], False: []}  # below/left → texts
    for v in sorted({float(v) for v in np.ravel(values) if np.isfinite(v)}):
        if lo <= v <= hi:
            continue
        sign = "−" if v < 0 else "+"
        edges[v < lo].append(text or f"{sign}${symbol}$ = {fmt(v)}")
    notes = []
    for below, texts in edges.items():
        if not texts:
            continue
        text = ", ".join(texts)
        if axis == "y":
            xy, ha, va = (
                ((0.99, 0.01), "right", "bottom") if below else ((0.99, 0.99), "right", "top")
            )
            text += " ↓" if below else " ↑"
        else:
            xy, ha, va = (
                ((0.01, 0.5), "left", "center") if below else ((0.99, 0.5), "right", "center")
            )
            text = ("← " + text) if below else (text + " →")
        notes.append(
            ax.text(
                *xy,
                text,
                transform=ax.transAxes,
                ha=ha,
                va=va,
                fontsize="small",
                color="0.2",
                gid=CLEARANCE_NOTE_GID,
                bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.8},
                rotation=90 if axis == "x" else 0,
            )
        )
    return notes


def notes_clear_of(ax: Any, legend: Any) -> None:
    """Move the clearance notes of ``ax`` that the legend covers to the opposite side."""
    if legend is None:
        return
    box = legend.get_window_extent()
    for note in ax.texts:
        if note.get_gid() != CLEARANCE_NOTE_GID or not note.get_window_extent().overlaps(box):
            continue
        x, y = note.get_position()
        if note.get_rotation() == 0:  # a note at the top or bottom edge: to the other corner
            note.set_position((1.0 - x, y))
            note.set_horizontalalignment("left" if x > 0.5 else "right")
        else:  # a note at a side edge: up or down
            note.set_position((x, 0.05 if y >= 0.5 else 0.95))
            note.set_verticalalignment("bottom" if y >= 0.5 else "top")


def section_style(n: int) -> dict[str, float]:
    """Marker area (points²) and alpha of n Poincaré points: bold dots for a few, fine
    translucent ones for many, so that a 10 000-point chaotic attractor shows its folds."""
    n = max(int(n), 1)
    s = float(np.clip(60.0 / math.sqrt(n), 0.25, 16.0))
    alpha = float(np.clip((300.0 / n) ** 0.35, 0.3, 1.0))
    return {"s": s, "alpha": alpha}


def section_points(ax: Any, xs: np.ndarray, ys: np.ndarray) -> None:
    """Overlay Poincaré section points, sized and faded by their number (:func:`section_style`;
    Poincaré maps, phase portraits and time histories alike)."""
    style = section_style(xs.size)
    ax.plot(
        xs,
        ys,
        ".",
        ms=max(1.0, float(np.sqrt(style["s"]))),
        alpha=style["alpha"],
        color="C3",
        label="section points",
        zorder=3,
        rasterized=True,
    )
