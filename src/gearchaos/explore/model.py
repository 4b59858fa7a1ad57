"""The explorer's model: what a sweep store shows and what a click selects, without a browser.

:class:`ExploreModel` reads a store through :class:`~gearchaos.sweep.SweepResult` and answers
the questions the web page asks: the points of the bifurcation diagram (every stored section
value X̄_k against its swept value) or the cells of a 2-D regime map, the colour band of motion
labels, which swept point lies nearest a click, and that point's stored Poincaré section,
label and λ₁. It never simulates; :mod:`gearchaos.explore.compute` does, off the server.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._checks import check_int
from ..errors import ParameterError, Status
from ..gearset.schema import describe
from ..plot._common import clearances_in_metres, edges
from ..plot.regimes import REGIME_COLOURS, regime_category
from ..plot.units import PhysicalScales
from ..sweep.result import SweepResult

__all__ = [
    "ExploreModel",
    "Point",
    "parameter_axis_label",
    "parameter_label",
    "variable_label",
]

#: Symbols of the section variables as the seed writes them, in Unicode (``%s``: the
#: planet's subscript): X̄_sp1 = δ_sp1/b_c.
_VAR_SYMBOLS = {
    "delta_sp": ("X̄ₛₚ%s", "δₛₚ%s/b_c"),
    "delta_rp": ("X̄ᵣₚ%s", "δᵣₚ%s/b_c"),
    "force_sp": ("F̄ₛₚ%s", None),
    "force_rp": ("F̄ᵣₚ%s", None),
    "x_s": ("x̄ₛ", "xₛ/b_c"),
    "y_s": ("ȳₛ", "yₛ/b_c"),
    "sigma": ("σ̄", None),
}
_SUBSCRIPT_DIGITS = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")


def variable_label(var: str, planet: int | None = None) -> str:
    """Axis label of a section variable: ``delta_sp`` → ``X̄ₛₚ₁ = δₛₚ₁/b_c``,
    ``delta_sp_dot`` → ``X̄′ₛₚ₁ = dX̄ₛₚ₁/dτ``; other names label themselves."""
    base, dot = (var[:-4], True) if var.endswith("_dot") else (var, False)
    if base not in _VAR_SYMBOLS:
        return var
    sym, definition = _VAR_SYMBOLS[base]
    n = str(planet or 1).translate(_SUBSCRIPT_DIGITS)
    sym = sym % n if "%s" in sym else sym
    if dot:
        return f"{sym[:2]}′{sym[2:]} = d{sym}/dτ"
    if definition is None:
        return sym
    return f"{sym} = {definition % n if '%s' in definition else definition}"


def parameter_label(name: str) -> str:
    """Axis label of a swept parameter from the registry: ``omega`` → ``Ω = ω/ω_n``,
    ``backlash.sun_planet`` → ``b_sp [m]`` style; an unknown name labels itself."""
    if name == "omega":
        return "Ω = ω/ω_n (dimensionless mesh frequency)"
    field = describe(name)
    if field is None:
        return name
    unit = "" if field.unit in ("", "1") else f" [{field.unit}]"
    return f"{field.symbol}{unit} ({name})"


def parameter_axis_label(name: str) -> str:
    """Axis label of a swept parameter for a plot axis: ``Ω = ω/ωₙ`` for Ω, else
    :func:`parameter_label`."""
    if name == "omega":
        return "Ω = ω/ωₙ (dimensionless mesh frequency)"
    return parameter_label(name)


@dataclass(frozen=True)
class Point:
    """One swept point of a store.

    Attributes
    ----------
    index
        Its indices along the store's leading dimensions (``status``'s dimensions).
    values
        Its swept values by dotted name (family value included; no ``direction``).
    direction
        ``up`` or ``down`` for a store with both continuation branches, else ``None``.
    sun_rpm
        The sun speed n_s [rpm] at the point's Ω where the gear set defines it (swept or
        fixed Ω), else ``None``.
    metres
        The names among ``values`` of clearances the gear set gives in metres (shown in µm).
    """

    index: tuple[int, ...]
    values: Mapping[str, float]
    direction: str | None = None
    sun_rpm: float | None = None
    metres: frozenset[str] = frozenset()

    def title(self) -> str:
        """``Ω = 1.43, n_s = 7234 rpm`` style text naming the point (a clearance in metres
        in µm: ``b_sp = 100 µm``)."""
        parts = [
            f"{_symbol(k)} = {v * 1e6:.4g} µm" if k in self.metres else f"{_symbol(k)} = {v:.6g}"
            for k, v in self.values.items()
        ]
        if self.sun_rpm is not None:
            parts.append(f"n_s = {self.sun_rpm:.5g} rpm")
        if self.direction:
            parts.append(f"{self.direction} branch")
        return ", ".join(parts)


def _symbol(name: str) -> str:
    field = describe(name)
    return field.symbol if field is not None else name


class ExploreModel:
    """A sweep store as the explorer shows it.

    Parameters
    ----------
    res
        The store (:class:`~gearchaos.sweep.SweepResult` or a dataset).
    var, planet
        The section variable drawn (default: the store's first observed one, ``delta_sp`` of
        planet 1 — X̄_sp1 = δ_sp1/b_c — for gear sets).
    select
        Values of the dimensions not drawn: the family value and the ``direction`` of a
        store with both branches (default: the first of each).
    store
        The store's path (for the computations, which reopen it in a worker process).
    """

    def __init__(
        self,
        res: Any,
        *,
        var: str | None = None,
        planet: int = 1,
        select: Mapping[str, Any] | None = None,
        store: str | None = None,
    ):
        self.full = SweepResult.of(res)
        self.store = store
        ds = self.full.ds
        have = [str(n) for n in ds.data_vars if "section" in ds[n].dims]
        if var is None:
            spec = self.full.spec
            first = [n for n in (spec.observe if spec is not None else ()) if n in have]
            var = (first or have or ["delta_sp"])[0]
        if var not in ds.data_vars or "section" not in ds[var].dims:
            raise ParameterError(
                f"var must be a section variable of the store ({', '.join(have)}): got {var!r}"
            )
        self.var = var
        self.planet = check_int("planet", planet, lo=1)
        if "planet" in ds[var].dims:
            planets = [int(p) for p in np.asarray(ds["planet"].values)]
            if self.planet not in planets:
                raise ParameterError(
                    f"planet must be one of the store's observed planets {planets}: got {planet!r}"
                )
        lay = self.full.layout()
        self.directions = lay.directions
        self.family = lay.family
        self.vary = lay.vary
        if len(self.vary) not in (1, 2):
            raise ParameterError(
                f"the explorer draws 1-D and 2-D sweeps: this one varies {', '.join(self.vary)}"
            )
        chosen = dict(select or {})
        for key in chosen:
            if key not in ("direction", self.family):
                raise ParameterError(
                    f"select may fix the family ({self.family}) and the direction: got {key!r}"
                )
        if self.directions and "direction" not in chosen:
            chosen["direction"] = self.directions[0]
        if self.family and self.family not in chosen:
            chosen[self.family] = float(ds[self.family].values[0])
        self.selection = chosen
        self.res = self.full.select(chosen)
        self._lead = self.full.lead_dims
        self._fixed_index = {d: self._index_of(d, v) for d, v in chosen.items() if d in self._lead}
        # the sun speed per unit Ω, where the gear set defines one over the whole sweep
        self._rpm_per_omega = PhysicalScales.of_sweep(self.full).rpm_per_omega
        self._metres = frozenset(clearances_in_metres(self.full.gearset))

    # ------------------------------------------------------------------ axes
    @property
    def is_map(self) -> bool:
        """A 2-D sweep (drawn as a regime map), not a bifurcation diagram."""
        return len(self.vary) == 2

    def axis(self, name: str) -> np.ndarray:
        """The swept values of an axis."""
        return np.asarray(self.full.ds[name].values, dtype=np.float64)

    def family_values(self) -> list[float]:
        return [float(v) for v in self.axis(self.family)] if self.family else []

    def _index_of(self, dim: str, value: Any) -> int:
        coord = np.asarray(self.full.ds[dim].values)
        if coord.dtype.kind in "fiu":
            return int(np.argmin(np.abs(coord.astype(np.float64) - float(value))))
        return [str(c) for c in coord].index(str(value))

    # ------------------------------------------------------------------ points
    def nearest(self, x: float, y: float | None = None) -> Point:
        """The swept point nearest a click at (``x``, ``y``) in data coordinates: the nearest
        swept value of the first varied parameter (and of the second, for a map).

        Raises :class:`~gearchaos.errors.ParameterError` for a non-finite coordinate.
        """
        coords: list[float | None] = [x] if not self.is_map else [x, y]
        index = []
        for name, c in zip(self.vary, coords, strict=True):
            if c is None or not math.isfinite(float(c)):
                raise ParameterError(f"a click on {name} must be a finite number: got {c!r}")
            index.append(int(np.argmin(np.abs(self.axis(name) - float(c)))))
        return self.point(*index)

    def point(self, *index: int) -> Point:
        """The point at ``index`` along the varied axes (the family and direction are the
        model's selection)."""
        if len(index) != len(self.vary):
            raise ParameterError(
                f"a point needs one index per varied axis ({', '.join(self.vary)}): got {index}"
            )
        full: dict[str, int] = dict(self._fixed_index)
        for name, i in zip(self.vary, index, strict=True):
            n = self.axis(name).size
            full[name] = check_int(f"index of {name}", int(i), lo=0, hi=n - 1)
        values = {}
        if self.family:
            values[self.family] = float(self.axis(self.family)[full[self.family]])
        for name in self.vary:
            values[name] = float(self.axis(name)[full[name]])
        direction = str(self.selection["direction"]) if self.directions else None
        omega = values.get("omega", self.full.fixed_value("omega"))
        rpm = None if omega is None or self._rpm_per_omega is None else omega * self._rpm_per_omega
        return Point(tuple(full[d] for d in self._lead), values, direction, rpm, self._metres)

    def _at(self, name: str, point: Point) -> np.ndarray:
        da = self.full.ds[name].isel(dict(zip(self._lead, point.index, strict=True)))
        if "planet" in da.dims:
            da = da.sel(planet=self.planet)
        return np.asarray(da.values)

    def section(self, point: Point) -> tuple[np.ndarray, np.ndarray, str, str]:
        """The stored Poincaré section of ``point``: (X̄_k, X̄′_k, x label, y label) with the
        derivative when the store holds it, else the return map (X̄_k, X̄_k+1). Points the
        integration did not reach (NaN) are left out."""
        x = self._at(self.var, point).astype(np.float64)
        dot = f"{self.var}_dot"
        if dot in self.full.ds.data_vars:
            y = self._at(dot, point).astype(np.float64)
            ok = np.isfinite(x) & np.isfinite(y)
            return x[ok], y[ok], self.var_label(), variable_label(dot, self.planet)
        x = x[np.isfinite(x)]
        sym = self.var_label().split(" = ")[0]
        return x[:-1], x[1:], f"{sym}(k)", f"{sym}(k+1)"

    def var_label(self) -> str:
        return variable_label(self.var, self.planet)

    def label(self, point: Point) -> str:
        """The stored motion label of ``point`` (``1T`` … ``nT``, ``QP``, ``chaos``,
        ``unresolved``, ``failed``; ``not run`` for a point of an unfinished store)."""
        if int(self._at("status", point)) == int(Status.NOT_RUN):
            return "not run"
        if "motion" not in self.full.ds.data_vars:
            return "unlabelled"
        return str(self._at("motion", point)).strip() or "not run"

    def lle(self, point: Point) -> float | None:
        """The stored largest Lyapunov exponent λ₁ (per unit τ), or ``None``."""
        if "lle" not in self.full.ds.data_vars:
            return None
        v = float(self._at("lle", point))
        return v if math.isfinite(v) else None

    def lle_error(self, point: Point) -> float | None:
        """The stored standard error of λ₁ (0: exact, from the multipliers), or ``None``."""
        if "lle_error" not in self.full.ds.data_vars:
            return None
        v = float(self._at("lle_error", point))
        return v if math.isfinite(v) else None

    def evidence(self, point: Point) -> str:
        """What decided the stored label (the verdict's flag and max |μ|; a label from the
        record alone says it is not confirmed), or ``""`` for a store of an earlier version
        labelled from its records alone without verdict columns."""
        from ..dynamics.verdict.evidence import EVIDENCE, evidence_words

        if "verdict" not in self.full.ds.data_vars:
            return ""
        names = {v: k for k, v in EVIDENCE.items()}
        key = names.get(int(self._at("verdict", point)), "unknown")
        text = f"decided by {evidence_words(key)}"
        mu = float(self._at("max_multiplier", point))
        if math.isfinite(mu):
            text += f", max |μ| = {mu:.6g}"
        return text

    def status(self, point: Point) -> str:
        return Status(int(self._at("status", point))).name.lower()

    # ------------------------------------------------------------------ whole diagram
    def labels(self) -> np.ndarray:
        """Display category of every drawn point (:func:`~gearchaos.plot.regimes.regime_category`)
        over the varied axes."""
        ds = self.res.ds
        status = np.asarray(ds["status"].values)
        if "motion" in ds.data_vars:
            raw = np.asarray(ds["motion"].values).astype(str)
        else:
            raw = np.full(status.shape, "unresolved")
        raw = np.where(status == int(Status.NOT_RUN), "", raw)
        return np.vectorize(regime_category, otypes=[object])(raw)

    def diagram(self) -> dict[str, np.ndarray]:
        """The bifurcation diagram's scatter: ``x`` (swept value), ``y`` (stored section
        value X̄_k) and ``i`` (the point's index) of every finite stored section value."""
        if self.is_map:
            raise ParameterError("a 2-D sweep is drawn as a regime map, not a diagram")
        name = self.vary[0]
        da = self.res.ds[self.var]
        if "planet" in da.dims:
            da = da.sel(planet=self.planet)
        v = np.asarray(da.transpose(name, "section").values, dtype=np.float64)
        xs = np.broadcast_to(self.axis(name)[:, None], v.shape)
        ii = np.broadcast_to(np.arange(v.shape[0])[:, None], v.shape)
        ok = np.isfinite(v)
        return {"x": xs[ok], "y": v[ok], "i": ii[ok]}

    def band(self) -> dict[str, list[Any]]:
        """One cell per swept value (1-D) or grid point (2-D), coloured by motion: ``x``,
        ``width`` (and ``y``, ``height`` for a map), ``colour``, ``label``."""
        cats = self.labels()
        xe = edges(self.axis(self.vary[0]))
        if not self.is_map:
            return {
                "x": list(0.5 * (xe[1:] + xe[:-1])),
                "width": list(np.diff(xe)),
                "colour": [REGIME_COLOURS[str(c)] for c in cats],
                "label": [str(c) for c in cats],
            }
        ye = edges(self.axis(self.vary[1]))
        dims = tuple(str(d) for d in self.res.ds["status"].dims)
        if dims != self.vary:
            cats = cats.T
        gx, gy = np.meshgrid(np.arange(xe.size - 1), np.arange(ye.size - 1), indexing="ij")
        return {
            "x": list(0.5 * (xe[gx] + xe[gx + 1]).ravel()),
            "y": list(0.5 * (ye[gy] + ye[gy + 1]).ravel()),
            "width": list((xe[gx + 1] - xe[gx]).ravel()),
            "height": list((ye[gy + 1] - ye[gy]).ravel()),
            "colour": [REGIME_COLOURS[str(c)] for c in cats.ravel()],
            "label": [str(c) for c in cats.ravel()],
        }

    def regime_fractions(self) -> dict[str, float]:
        """Fraction of the drawn points in each display category, in legend order."""
        cats = [str(c) for c in self.labels().ravel()]
        out = {c: cats.count(c) / len(cats) for c in REGIME_COLOURS if c in cats}
        return out
