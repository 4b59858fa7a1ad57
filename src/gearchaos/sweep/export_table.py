"""The tables of an export: one row per point, and one row per section sample.

:func:`export_tables` turns a result dataset (a sweep or response store, a basin or
basin-fraction store, a simulation file) into two lists of :class:`Column` s:

* **points** — one row per point of the result (a swept value, a start of a basin image, the
  one operating point of a simulation): the swept parameters, Ω and, where the result is of a
  gear set, the sun speed ``sun_rpm`` and the mesh frequency ``mesh_hz`` at that point (through
  the gear set's ω_n and tooth numbers: :meth:`~gearchaos.gearset.GearSet.sun_speed_rpm`), then
  every per-point variable (``status``, ``motion``, ``lle``, ``max_multiplier``, load factors,
  contact regimes …). A variable over planets or state components gets one column per value
  (``contact_sp_p3``, ``final_state_x_s``); coded variables (``status``, ``verdict``,
  ``contact_sp`` …) are written as their meanings (``ok``, ``floquet``, ``single_sided``).
* **sections** — one row per point and section sample: the point's lead columns (the same
  names, so both tables join on them), ``section`` (and ``tau`` for a simulation), then the
  section values, one column per observed planet (``delta_sp_p1``; a user model's members by
  its ``member_name``, ``x_stage1``).

A column name carries its unit when the unit is physical: ``sun_rpm``, ``mesh_hz``,
``torque.input_Nm``, ``force_peak_sp_p1_N``; a swept clearance gets both its value in units of
b_c (``backlash.sun_planet_bar``) and in micrometres (``backlash.sun_planet_um``), whichever
units its gear-set file uses. Peak and RMS contact forces of a response store get a twin in
newtons, its RMS transmission errors one in µm. Dimensionless names stay as they are
(``omega``, ``xi``, ``lle``). Physical columns need the gear set (its scales change with a
swept stiffness or mass, so they are computed point by point); a user model's result has
none, and no code is ever imported to get them.

Every text value from the result (labels, coordinate values, names) goes through
:func:`~gearchaos._text.escape_text`, so a control character is written as a visible escape.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._text import escape_text
from ..errors import StoreError
from ..gearset.schema import FIELDS, MODULE_BOUNDED, OMEGA, UNITS, XI, describe
from ..model.target import MEMBER_WORD

__all__ = ["Column", "ExportTables", "export_tables", "lead_dims"]

#: Dimensions spread over one column per value (planets, state components).
WIDE_DIMS = ("planet_all", "planet", "state")

#: Per-point variables written first, in this order (the verdict and its evidence).
_FIRST = (
    "status",
    "motion",
    "label",
    "attractor",
    "period",
    "lle",
    "lle_error",
    "max_multiplier",
    "k01",
    "verdict",
    "indicators_agree",
    "record",
)

#: Unit slugs of the gear-set schema's units in column names.
_UNIT_SLUG = {
    "m": "m",
    "deg": "deg",
    "kg": "kg",
    "kg m^2": "kg_m2",
    "N/m": "N_per_m",
    "N m": "Nm",
    "mesh cycles": "cycles",
}

#: Physical twins of response quantities (prefix of the variable → quantity).
_PHYSICAL_PREFIX = (
    ("force_peak_", "force"),
    ("force_rms_", "force"),
    ("contact_force_", "force"),
    ("dte_rms_", "length"),
)

#: Simulation attributes that are per-point values of its one point.
_SIMULATION_POINT_ATTRS = ("status", "steps_accepted", "steps_rejected", "steps_switch")


@dataclass(frozen=True)
class Column:
    """One column of an export table: its name, one value per row, its unit (``1``:
    dimensionless, ``""``: text), what it is, and for a coded variable the meanings its values
    take."""

    name: str
    values: np.ndarray
    unit: str = "1"
    description: str = ""
    meanings: tuple[str, ...] = ()

    def record(self) -> dict[str, Any]:
        """The column's entry in the export's sidecar."""
        out: dict[str, Any] = {"unit": self.unit, "description": self.description}
        if self.meanings:
            out["values"] = list(self.meanings)
        return out


@dataclass(frozen=True)
class ExportTables:
    """The point table and the section table of a result (``sections`` empty when the result
    records no sections)."""

    kind: str
    points: tuple[Column, ...]
    sections: tuple[Column, ...] = ()


def lead_dims(ds: Any, kind: str) -> tuple[str, ...]:
    """The dimensions over which a result of ``kind`` has one point each."""
    if kind == "simulation":
        return ()
    var = "attractor" if kind in ("basins", "basin_fractions") else "status"
    if var not in ds.data_vars:
        raise StoreError(f"the {kind} result has no {var!r} variable: nothing to tabulate")
    return tuple(str(d) for d in ds[var].dims)


def _coord(ds: Any, dim: str) -> np.ndarray:
    if dim in ds.coords:
        return np.asarray(ds[dim].values)
    return np.arange(int(ds.sizes[dim]))


def _text(values: np.ndarray) -> np.ndarray:
    return np.array([escape_text(v) for v in values.ravel()], dtype=object)


def _flat(values: Any) -> np.ndarray:
    arr = np.asarray(values)
    return _text(arr) if arr.dtype.kind in "OUS" else arr.ravel()


def _decoded(values: np.ndarray, attrs: Any) -> tuple[np.ndarray, tuple[str, ...]]:
    """A coded variable's values as its meanings (an unknown code stays a number)."""
    codes, meanings = attrs.get("flag_values"), attrs.get("flag_meanings")
    if codes is None or not isinstance(meanings, str):
        return values, ()
    if isinstance(codes, str):  # written as text by some Zarr versions
        codes = [c for c in codes.strip("[]").replace(",", " ").split() if c]
    try:
        table = {
            int(c): escape_text(m) for c, m in zip(np.ravel(codes), meanings.split(), strict=False)
        }
    except (TypeError, ValueError):
        return values, ()
    out = np.array(
        [table.get(int(v), str(int(v))) if np.isfinite(v) else "" for v in values.ravel()],
        dtype=object,
    )
    return out, tuple(table.values())


def _description(var: Any) -> str:
    return escape_text(var.attrs.get("long_name", ""))


class _Physics:
    """The gear set at every point of a result, and the scales it gives (``None`` without a
    gear set): ω_n, sun rpm per unit Ω, b_c and k_m,sp b_c, one value per row."""

    def __init__(self, gs: Any, grids: dict[str, np.ndarray], n: int):
        self.gearset = gs
        self.n = n
        self.rows: list[Any] = []
        if gs is None:  # gear-set switch: an export never imports a model's code for scales
            return
        from ..model.planetary import nondimensionalise

        names = [d for d in grids if d in FIELDS or d == XI]
        cache: dict[tuple[Any, ...], tuple[Any, Any]] = {}
        for i in range(n):
            key = tuple(_scalar(grids[d][i]) for d in names)
            if key not in cache:
                point = gs.evolve(dict(zip(names, key, strict=True))) if names else gs
                cache[key] = (point, nondimensionalise(point)[1])
            self.rows.append(cache[key])

    def __bool__(self) -> bool:
        return self.gearset is not None  # gear-set switch: as above, physics of gear sets

    def each(self, fn: Any) -> np.ndarray:
        return np.array([fn(gs, sc) for gs, sc in self.rows], dtype=np.float64)


def _scalar(v: Any) -> Any:
    if isinstance(v, np.generic):
        return v.item()
    return v


def _clearance_bar(gs: Any, name: str, value: float) -> float:
    units = gs[MODULE_BOUNDED[name]]
    return value / gs.clearance.characteristic_length if units == "m" else value


def _parameter_columns(name: str, values: np.ndarray, phys: _Physics) -> list[Column]:
    """The columns of a swept (lead) coordinate: its name with the unit of a physical
    parameter; a clearance in units of b_c and in µm."""
    values = _flat(values)
    if values.dtype == object:  # text: a direction, a label
        return [Column(escape_text(name), values, "", "")]
    found = describe(name)
    desc = escape_text(found.meaning) if found is not None else ""
    if name not in FIELDS:  # omega, xi, a model's own parameter, a state of a basin image
        return [Column(escape_text(name), values, "1", desc)]
    if MODULE_BOUNDED.get(name) and phys:
        v = values.astype(np.float64)
        bar = np.array(
            [_clearance_bar(gs, name, float(x)) for x, (gs, _) in zip(v, phys.rows, strict=True)]
        )
        um = bar * phys.each(lambda gs, sc: sc.length) * 1e6
        return [
            Column(f"{name}_bar", bar, "b_c", f"{desc} (in units of b_c)"),
            Column(f"{name}_um", um, "µm", f"{desc} (micrometres)"),
        ]
    unit = UNITS.get(name, "1")
    slug = _UNIT_SLUG.get(unit)
    return [Column(f"{name}_{slug}" if slug else name, values, unit if slug else "1", desc)]


def _speed_columns(omega: np.ndarray | None, phys: _Physics) -> list[Column]:
    """Sun speed and mesh frequency at every point (a gear set's result only)."""
    if omega is None or not phys:
        return []
    om = np.asarray(omega, dtype=np.float64)
    rpm = np.array([gs.sun_speed_rpm(float(w)) for w, (gs, _) in zip(om, phys.rows, strict=True)])
    hz = om * phys.each(lambda gs, sc: sc.omega_n) / (2.0 * math.pi)
    return [
        Column("sun_rpm", rpm, "rpm", "sun (input) speed n_s = 60 Ω ω_n (z_s + z_r)/(2π z_s z_r)"),
        Column("mesh_hz", hz, "Hz", "mesh frequency f_m = Ω ω_n/2π"),
    ]


def _physical_twin(name: str, col: Column, phys: _Physics) -> Column | None:
    """The value of a response quantity in newtons or micrometres."""
    if not phys:
        return None
    for prefix, quantity in _PHYSICAL_PREFIX:
        if name.startswith(prefix):
            v = np.asarray(col.values, dtype=np.float64)
            if quantity == "force":
                return Column(
                    f"{col.name}_N",
                    v * phys.each(lambda gs, sc: sc.force),
                    "N",
                    f"{col.description} (newtons)",
                )
            um = v * phys.each(lambda gs, sc: sc.length) * 1e6
            return Column(f"{col.name}_um", um, "µm", f"{col.description} (micrometres)")
    return None


#: Response quantities, written after the verdict and the contact regimes.
_RESPONSE_PREFIXES = ("load_factor_", "force_peak_", "force_rms_", "dte_rms_")


def _ordered(ds: Any) -> list[str]:
    """Per-point variables in the order a reader looks for them: the verdict and its evidence,
    the contact regimes (coded variables), the response quantities, then the rest."""
    names = [str(n) for n in ds.data_vars]
    first = [n for n in _FIRST if n in names]
    coded = [n for n in names if n not in first and "flag_meanings" in ds[n].attrs]
    response = [n for p in _RESPONSE_PREFIXES for n in names if n.startswith(p) and n not in coded]
    done = {*first, *coded, *response}
    return [*first, *coded, *response, *(n for n in names if n not in done)]


def _wide_label(ds: Any, dim: str, label: Any) -> str:
    """A member column's suffix: the store's ``member_name`` and the member's number
    (``stage1``; ``p1`` for planets and stores without one), a state component by its name."""
    if dim not in ("planet_all", "planet"):
        return escape_text(label)
    raw = ds.attrs.get("member_name", "p")
    if not isinstance(raw, str) or not MEMBER_WORD.fullmatch(raw):
        raise StoreError(
            "the store's member_name must be a word of at most 32 letters and digits, starting "
            f"with a letter: got {escape_text(repr(raw))}"
        )
    return f"{raw}{label}"


def _point_columns(ds: Any, lead: tuple[str, ...], phys: _Physics) -> list[Column]:
    cols: list[Column] = []
    for name in _ordered(ds):
        var = ds[name]
        dims = tuple(str(d) for d in var.dims)
        if "section" in dims or not set(lead) <= set(dims):
            continue
        extra = [d for d in dims if d not in lead]
        if len(extra) > 1 or (extra and extra[0] not in WIDE_DIMS):
            continue  # e.g. the time samples of a simulation: not one column each
        desc = _description(var)
        if not extra:
            values, meanings = _decoded(_flat(var.transpose(*lead).values), var.attrs)
            unit = "" if values.dtype == object else "1"
            col = Column(escape_text(name), values, unit, desc, meanings)
            cols.append(col)
            twin = _physical_twin(name, col, phys)
            if twin is not None:
                cols.append(twin)
            continue
        (dim,) = extra
        block = np.asarray(var.transpose(*lead, dim).values).reshape(-1, var.sizes[dim])
        group: list[Column] = []
        for k, label in enumerate(_coord(ds, dim)):
            values, meanings = _decoded(_flat(block[:, k]), var.attrs)
            unit = "" if values.dtype == object else "1"
            name_k = f"{escape_text(name)}_{_wide_label(ds, dim, label)}"
            group.append(Column(name_k, values, unit, desc, meanings))
        twins = [_physical_twin(name, col, phys) for col in group]
        cols += group + [t for t in twins if t is not None]
    return cols


def _section_columns(
    ds: Any, lead: tuple[str, ...], lead_cols: list[Column], n: int
) -> list[Column]:
    """The section table: lead columns repeated per sample, the sample index, then the
    section variables (one column per observed planet)."""
    if "section" not in ds.dims:
        return []
    ns = int(ds.sizes["section"])
    cols = [Column(c.name, np.repeat(c.values, ns), c.unit, c.description) for c in lead_cols]
    cols.append(Column("section", np.tile(np.arange(ns), n), "1", "index k of the section sample"))
    if "tau" in ds.coords and ds["tau"].dims == ("section",):
        tau = np.asarray(ds["tau"].values, dtype=np.float64)
        cols.append(Column("tau", np.tile(tau, n), "1", "τ = ω_n t at the section"))
    for name in (str(v) for v in ds.data_vars):
        var = ds[name]
        dims = tuple(str(d) for d in var.dims)
        if "section" not in dims or not set(lead) <= set(dims):
            continue
        extra = [d for d in dims if d not in (*lead, "section")]
        if len(extra) > 1 or (extra and extra[0] not in WIDE_DIMS):
            continue
        desc = _description(var)
        if not extra:
            values = _flat(var.transpose(*lead, "section").values)
            cols.append(Column(escape_text(name), values, "1", desc))
            continue
        (dim,) = extra
        block = np.asarray(var.transpose(*lead, "section", dim).values)
        block = block.reshape(-1, var.sizes[dim])
        for k, label in enumerate(_coord(ds, dim)):
            name_k = f"{escape_text(name)}_{_wide_label(ds, dim, label)}"
            cols.append(Column(name_k, _flat(block[:, k]), "1", desc))
    return cols


def _fixed_omega(ds: Any, kind: str, spec_fixed: dict[str, Any]) -> float | None:
    if kind in ("sweep", "response"):
        v = spec_fixed.get(OMEGA)
    else:
        v = ds.attrs.get(OMEGA)
    if isinstance(v, bool) or not isinstance(v, int | float | np.number):
        return None
    return float(v)


def export_tables(ds: Any, kind: str, *, gearset: Any = None, fixed: Any = None) -> ExportTables:
    """The point and section tables of a result ``ds`` of ``kind`` (see the module docstring).

    Parameters
    ----------
    ds
        The result dataset, loaded.
    kind
        ``sweep``, ``response``, ``basins``, ``basin_fractions`` or ``simulation``.
    gearset
        The gear set of the result with its fixed values applied (``None``: a model's result;
        no physical columns).
    fixed
        The fixed values of a sweep (Ω among them when it was not swept).
    """
    lead = lead_dims(ds, kind)
    shape = tuple(int(ds.sizes[d]) for d in lead)
    n = int(np.prod(shape)) if lead else 1
    axes = [_coord(ds, d) for d in lead]
    mesh = np.meshgrid(*axes, indexing="ij") if lead else []
    grids = {d: g.reshape(-1) for d, g in zip(lead, mesh, strict=True)}
    phys = _Physics(gearset, grids, n)
    lead_cols: list[Column] = []
    for d in lead:
        lead_cols += _parameter_columns(d, grids[d], phys)
    points = list(lead_cols)
    omega = grids.get(OMEGA)
    if omega is None:
        value = _fixed_omega(ds, kind, dict(fixed or {}))
        if value is not None:
            omega = np.full(n, value)
            points += _parameter_columns(OMEGA, omega, phys)
    points += _speed_columns(omega, phys)
    if kind == "simulation":
        for key in _SIMULATION_POINT_ATTRS:
            if key in ds.attrs:
                v = ds.attrs[key]
                arr = (
                    np.array([escape_text(v)], dtype=object)
                    if isinstance(v, str)
                    else np.array([v])
                )
                points.append(Column(key, arr, "" if isinstance(v, str) else "1", key))
    points += _point_columns(ds, lead, phys)
    sections = _section_columns(ds, lead, lead_cols, n)
    return ExportTables(kind, tuple(points), tuple(sections))
