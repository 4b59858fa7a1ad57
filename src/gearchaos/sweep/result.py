"""The read side of a sweep store: :class:`SweepResult`.

A sweep store's attributes say what it holds — the sweep specification (``sweep_toml``), the
model (``model_class``, ``model_fields``: for a gear set, the gear set itself, also in
``gearset_toml``), fixed values, Ω when it is not swept, the clearances, the regime
table. :class:`SweepResult` parses them once and answers the questions every reader asks
(which dimension is the family, what is the forcing period or the clearance of a variable at
each point, how many points failed), so plots, the classifier, the paper's checks and the
command line stop re-parsing attributes.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._files import check_path
from ..errors import ParameterError, Status, StoreError
from ..gearset.schema import CLEARANCES, FIELDS, OMEGA
from ..model.contract import Capabilities
from ..model.system import System
from ..model.target import Target
from .store import open_sweep

__all__ = ["NON_SWEEP_DIMS", "SweepLayout", "SweepResult", "open_result"]


#: Dimensions of a sweep variable that are not swept.
NON_SWEEP_DIMS = ("section", "planet", "planet_all", "state")


@dataclass(frozen=True)
class SweepLayout:
    """Which leading dimensions of a sweep dataset are what: the ``direction`` values (empty
    when there is no direction dimension), the family axis and the varied axes."""

    directions: tuple[str, ...]
    family: str | None
    vary: tuple[str, ...]

    @property
    def swept(self) -> tuple[str, ...]:
        """Family (if any) then varied axes."""
        return ((self.family,) if self.family else ()) + self.vary


class SweepResult:
    """A sweep dataset and what its attributes say, parsed once.

    Wraps the :class:`xarray.Dataset` of a sweep store (:func:`open_sweep`,
    :func:`gearchaos.bifurcation`) or a selection of it. Plots, the classifier, the paper's
    checks and the command line read stores through it instead of re-parsing attributes.

    Attributes
    ----------
    ds
        The dataset (possibly a selection).
    spec
        The :class:`~gearchaos.sweep.spec.SweepSpec` stored in ``sweep_toml`` (``None`` for a
        dataset without one).
    base_gearset
        The gear set the store records (the fields of its planetary model, or
        ``gearset_toml`` in an older store: :func:`~gearchaos.model.record.recorded_gearset`);
        ``None`` for any other model.
    """

    spec: Any
    base_gearset: Any
    _reference: Any
    _target: Any
    _model: Any

    def __init__(self, ds: Any, *, _parsed: SweepResult | None = None):
        import xarray as xr

        if not isinstance(ds, xr.Dataset):
            raise ParameterError(
                "a sweep result must be an xarray.Dataset (gearchaos.open_sweep, "
                f"gearchaos.bifurcation) or a SweepResult: got {type(ds).__name__}"
            )
        self.ds = ds
        if _parsed is not None:
            self.spec = _parsed.spec
            self.base_gearset = _parsed.base_gearset
            self._reference = _parsed._reference
            self._target = _parsed._target
            self._model = _parsed._model
            return
        from .spec import SweepSpec

        attrs = ds.attrs
        text = attrs.get("sweep_toml")
        if text is not None and not isinstance(text, str):
            raise StoreError(f"the store's sweep_toml attribute must be text: got {text!r}")
        self.spec = SweepSpec.from_toml(text) if text else None
        from ..model.record import recorded_gearset

        try:  # the planetary model's reference, or gearset_toml in an older store
            self.base_gearset = recorded_gearset(attrs, where="the sweep store")
        except ParameterError as exc:
            raise StoreError(str(exc)) from None
        self._reference = _UNSET
        self._target = _UNSET
        self._model = _UNSET

    @classmethod
    def of(cls, obj: Any) -> SweepResult:
        """``obj`` itself when it is a :class:`SweepResult`, else the dataset wrapped."""
        return obj if isinstance(obj, SweepResult) else cls(obj)

    @classmethod
    def open(cls, path: str | os.PathLike[str]) -> SweepResult:
        """Open a sweep store (see :func:`open_sweep`)."""
        return cls(open_sweep(path))

    # ------------------------------------------------------------------ parameters
    @property
    def fixed(self) -> dict[str, Any]:
        """Fixed values by dotted name, ``omega`` included when it was not swept."""
        return dict(self.spec.fixed) if self.spec is not None else {}

    def fixed_value(self, name: str) -> float | None:
        """A fixed numeric value, or ``None``."""
        v = self.fixed.get(name)
        if isinstance(v, bool) or not isinstance(v, int | float):
            return None
        return float(v)

    @property
    def preset(self) -> str | None:
        """The built-in preset whose values the stored gear set has (``None`` when none has, or
        for a reference system): a store written with the default before issue 34 records a
        gear set named ``sheng2016`` and says ``"sheng2016-v1"``
        (:func:`~gearchaos.gearset.preset_of`)."""
        from ..gearset import preset_of

        gs = self.base_gearset
        if gs is None:  # gear-set switch: only a gear set can have a preset's values
            return None
        return preset_of(gs)

    @property
    def reference(self) -> System | None:
        """The model the store was swept on with its fixed values applied, as a
        :class:`~gearchaos.model.System` (at the fixed Ω, else Ω = 1): its capabilities
        (contacts, clearances, groups, names, its gear set) say what the store's variables
        are. ``None`` when the store records no model."""
        if self._reference is _UNSET:
            from ..model.target import resolve

            target = self.base_target
            system = None
            if target is not None:
                try:
                    system = resolve(target, self.fixed, default_omega=1.0)
                except ParameterError as exc:
                    raise StoreError(
                        f"the store's fixed values do not apply to {target.name}: {exc}"
                    ) from None
            self._reference = system
        return self._reference

    @property
    def gearset(self) -> Any:
        """The stored gear set with the fixed (non-Ω) values applied (the gear set
        :attr:`reference` is built from), or ``None``: also for a store of a model of the
        user's own that the user has not named (no gear set needs that consent)."""
        from ..model.loading import ModelConsentError

        try:
            reference = self.reference
        except ModelConsentError:
            return None
        return None if reference is None else reference.capabilities.gearset

    @property
    def base_model(self) -> Any:
        """The model the store records how to build again, without its fixed values
        (``model_class``, ``model_fields``; :func:`~gearchaos.model.loading.rebuild_model`):
        the planetary model of its gear set, or another model; ``None`` when it records
        none."""
        if self._model is _UNSET:
            from ..model.loading import rebuild_model

            self._model = rebuild_model(self.ds.attrs, where="the sweep store")
        return self._model

    @property
    def base_target(self) -> Target | None:
        """What the store was swept on, without its fixed values: its gear set, or a
        :class:`~gearchaos.model.System` of its model at Ω = 1; ``None`` when it records
        neither (:func:`~gearchaos.model.record.recorded_target`)."""
        if self._target is _UNSET:
            from ..model.record import recorded_target

            self._target = recorded_target(self.ds.attrs, where="the sweep store")
        return self._target

    @property
    def swept_names(self) -> tuple[str, ...]:
        """The swept parameters (family first), from the spec or the dimensions."""
        if self.spec is not None:
            return tuple(a.name for a in self.spec.axes)
        return tuple(d for d in self.lead_dims if d != "direction")

    # ------------------------------------------------------------------ dimensions
    @property
    def lead_dims(self) -> tuple[str, ...]:
        """The leading (swept) dimensions of this dataset, as ``status`` has them."""
        ds = self.ds
        if "status" in ds.data_vars:
            return tuple(str(d) for d in ds["status"].dims)
        for name in ds.data_vars:
            if "section" in ds[name].dims:
                return tuple(str(d) for d in ds[name].dims if d not in NON_SWEEP_DIMS)
        return ()

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(int(self.ds.sizes[d]) for d in self.lead_dims)

    def layout(self, var: str | None = None) -> SweepLayout:
        """Directions, family and varied dimensions of ``var`` (default: ``status``)."""
        ds = self.ds
        dims = (
            tuple(str(d) for d in ds[var].dims if d not in NON_SWEEP_DIMS)
            if var is not None
            else self.lead_dims
        )
        directions: tuple[str, ...] = ()
        if "direction" in dims:
            directions = tuple(str(v) for v in np.asarray(ds["direction"].values))
            dims = tuple(d for d in dims if d != "direction")
        spec = self.spec
        if spec is not None and spec.family is not None and spec.family.name in dims:
            family: str | None = spec.family.name
            vary = tuple(d for d in dims if d != family)
        else:
            family = None
            vary = tuple(a.name for a in spec.vary if a.name in dims) if spec is not None else ()
            if not vary or len(vary) != len(dims):
                vary = dims  # without a readable spec: every leading dimension is varied
        return SweepLayout(directions, family, vary)

    def line_axis(self, what: str, var: str | None = None) -> str:
        """The one swept dimension left (after a selection) for ``what`` (e.g. "a bifurcation
        diagram") to draw along; a clear error naming what to fix otherwise. A ``direction``
        dimension may remain (drawn as two branches)."""
        rest = list(self.layout(var).swept)
        if len(rest) == 1:
            return rest[0]
        if not rest:
            raise ParameterError(
                f"nothing left for {what} to draw along: select fixed every swept dimension"
            )
        raise ParameterError(
            f"{what} needs one swept dimension: the dataset has {', '.join(rest)}; fix the "
            f"others with select, e.g. select={{{rest[0]!r}: "
            f"{float(self.ds[rest[0]].values[0]):g}}}"
        )

    def grid_axes(self, what: str, var: str | None = None) -> tuple[str, str]:
        """(x, y) of a 2-D sweep for ``what`` (e.g. "regime_map") to draw as one map; a clear
        error when a direction or family dimension is left or the sweep is not 2-D."""
        lay = self.layout(var)
        left = [*(["direction"] if lay.directions else []), *([lay.family] if lay.family else [])]
        if left:
            first = self.ds[left[0]].values[0]
            value = first if isinstance(first, str) else f"{float(first):g}"
            raise ParameterError(
                f"{what} draws one 2-D grid: fix {', '.join(left)} with select, e.g. "
                f"select={{{left[0]!r}: {value!r}}}"
            )
        if len(lay.vary) != 2:
            raise ParameterError(
                f"{what} needs a 2-D sweep: the dataset varies "
                f"{', '.join(lay.vary) or 'nothing'}; draw 1-D sweeps as bifurcation diagrams"
            )
        return lay.vary[0], lay.vary[1]

    def select(self, select: Mapping[str, Any] | None) -> SweepResult:
        """The dataset with the dimensions in ``select`` fixed (numeric axes: one of the swept
        values, matched to 1e-9 relative; ``direction``: ``up`` or ``down``)."""
        if not select:
            return self
        ds = self.ds
        for dim, value in select.items():
            if dim not in ds.dims:
                have = ", ".join(map(str, ds.dims))
                raise ParameterError(
                    f"select names a dimension the dataset does not have ({have}): got {dim!r}"
                )
            coord = np.asarray(ds[dim].values)
            if coord.dtype.kind in "fiu":
                try:
                    v = float(value)
                except (TypeError, ValueError):
                    raise ParameterError(
                        f"select[{dim!r}] must be a number: got {value!r}"
                    ) from None
                i = int(np.argmin(np.abs(coord - v)))
                tol = 1e-9 * max(1.0, float(np.max(np.abs(coord))))
                if abs(float(coord[i]) - v) > tol:
                    raise ParameterError(
                        f"select[{dim!r}] must be one of the swept values "
                        f"({', '.join(f'{float(c):g}' for c in coord)}): got {value!r}"
                    )
                ds = ds.isel({dim: i})
            else:
                values = [str(c) for c in coord]
                if str(value) not in values:
                    raise ParameterError(f"select[{dim!r}] must be one of {values}: got {value!r}")
                ds = ds.isel({dim: values.index(str(value))})
        return SweepResult(ds, _parsed=self)

    def values(self, name: str) -> np.ndarray:
        """A parameter's value at every point of the leading dimensions: the swept axis
        broadcast, or a selected (scalar) coordinate, or ``None`` if neither."""
        dims, shape = self.lead_dims, self.shape
        if name in dims:
            v = np.asarray(self.ds[name].values, dtype=np.float64)
            ax = dims.index(name)
            return np.broadcast_to(
                v.reshape([-1 if i == ax else 1 for i in range(len(dims))]), shape
            )
        if name in self.ds.coords and self.ds[name].ndim == 0:
            return np.full(shape, float(self.ds[name].values))
        raise KeyError(name)

    # ------------------------------------------------------------------ physics
    def forcing_period(self) -> np.ndarray:
        """T = 2π/Ω at every point of the leading dimensions, times the model's
        ``period_factor`` where the store records one."""
        try:
            omega = self.values(OMEGA)
        except KeyError:
            raw = self.ds.attrs.get("omega_fixed")
            if raw is None:
                raw = self.fixed_value(OMEGA)
            if isinstance(raw, bool) or not isinstance(raw, int | float | np.number):
                raise StoreError(
                    f"the store neither sweeps omega nor records a valid omega_fixed: got {raw!r}"
                ) from None
            if not (math.isfinite(float(raw)) and float(raw) > 0):
                raise StoreError(f"the store's omega_fixed must be > 0: got {raw!r}") from None
            omega = np.full(self.shape, float(raw))
        T = 2.0 * math.pi / omega
        factor = float(self.ds.attrs.get("period_factor", 1.0))
        return T if factor == 1.0 else factor * T

    def clearance(self, var: str) -> tuple[np.ndarray, str] | None:
        """(b̄, mathtext symbol) of the clearance acting on ``var`` at every point of the
        leading dimensions — the swept value when the clearance itself is swept, else the
        selected, fixed or stored one; ``None`` for variables without a clearance."""
        if var.endswith("_dot"):
            return None
        shape, attrs = self.shape, self.ds.attrs
        if var in CLEARANCES:
            parameter, _, key = CLEARANCES[var]
            sym = FIELDS[parameter].tex
            try:
                return self._to_bar(parameter, self.values(parameter)), sym
            except KeyError:
                pass
            fixed = self.fixed_value(parameter)
            if fixed is not None:
                return self._to_bar(parameter, np.full(shape, fixed)), sym
            if f"clearance_{key}" in attrs:
                return np.full(shape, float(attrs[f"clearance_{key}"])), sym
            reference = self.reference
            b = None if reference is None else reference.capabilities.clearances.get(key)
            return None if b is None else (np.full(shape, float(b)), sym)
        if f"clearance_{var}" in attrs:  # reference systems: x of the backlash oscillator
            try:
                return np.array(self.values("b")), "b"
            except KeyError:
                return np.full(shape, float(attrs[f"clearance_{var}"])), "b"
        return self._model_clearance(var)

    def _model_clearance(self, var: str) -> tuple[np.ndarray, str] | None:
        """The clearance of a contact judged on ``var`` (a model that records how to build it
        again): the model at every point, with its swept and fixed values, says it (Ω and the
        speeds change no clearance)."""
        from ..gearset.schema import SPEEDS
        from ..model.target import model_for, parameter_names

        try:
            target = self.base_target
        except ParameterError:
            return None
        if target is None:
            return None
        caps = Capabilities.of(model_for(target, {}))
        found = [c for c in caps.contacts if caps.obs_names[c.column] == var]
        if not found:
            return None
        column = found[0].column
        names = set(parameter_names(target)) - {OMEGA, *SPEEDS}
        fixed = {k: v for k, v in self.fixed.items() if k in names}
        swept = {d: self.values(d) for d in self.lead_dims if d in names}
        out = np.empty(self.shape)
        known: dict[tuple[float, ...], float] = {}
        for idx in np.ndindex(*self.shape):
            key = tuple(float(v[idx]) for v in swept.values())
            if key not in known:
                at = Capabilities.of(
                    model_for(target, {**fixed, **dict(zip(swept, key, strict=True))})
                )
                known[key] = next(c.clearance for c in at.contacts if c.column == column)
            out[idx] = known[key]
        return out, rf"b_{{\mathrm{{{found[0].name.replace('_', ' ')}}}}}"

    def _to_bar(self, parameter: str, value: np.ndarray) -> np.ndarray:
        gs = self.base_gearset
        if gs is None:  # gear-set switch: only a gear set gives clearances in metres
            return np.asarray(value, dtype=np.float64)
        units = gs.backlash.units if parameter.startswith("backlash.") else gs.clearance.units
        v = np.asarray(value, dtype=np.float64)
        return v / gs.clearance.characteristic_length if units == "m" else v

    # ------------------------------------------------------------------ outcome
    def status(self) -> np.ndarray:
        """Status codes over the leading dimensions (:class:`~gearchaos.errors.Status`)."""
        if "status" not in self.ds.data_vars:
            raise StoreError("the store has no status variable: not a gearchaos sweep store")
        return np.asarray(self.ds["status"].values)

    def status_counts(self) -> dict[str, int]:
        """How many points ended in each :class:`~gearchaos.errors.Status`, by lower-case
        name (``ok``, ``max_steps``, …, ``not_run``); every name is present."""
        status = self.status()
        return {s.name.lower(): int(np.sum(status == int(s))) for s in Status}

    @property
    def n_failed(self) -> int:
        """Points whose integration failed (not ok, not merely not run)."""
        c = self.status_counts()
        return sum(n for name, n in c.items() if name not in ("ok", "not_run"))

    def regime_table(self) -> dict[str, dict[str, float]]:
        """The stored ``regime_table`` (family value → regime → fraction); empty if none."""
        raw = self.ds.attrs.get("regime_table")
        if not raw:
            return {}
        try:
            table = json.loads(raw) if isinstance(raw, str) else dict(raw)
            return {str(k): {str(r): float(f) for r, f in v.items()} for k, v in table.items()}
        except (TypeError, ValueError, AttributeError):
            raise StoreError("the store's regime_table attribute is not readable") from None


_UNSET: Any = object()


def open_result(path: str | os.PathLike[str]) -> SweepResult:
    """A sweep store opened for reading, as :class:`SweepResult`, or one clear error.

    The check every reader of a user's store shares (``gearchaos plot``, ``classify``,
    ``explore``): a missing path is a :class:`~gearchaos.errors.ParameterError`
    (``store not found: 'RUN.zarr'``), a damaged or foreign store a
    :class:`~gearchaos.errors.StoreError` or a ``ParameterError`` naming the path and why.
    """
    root = check_path(path, f"store must be the path of a sweep store: got {path!r}")
    if not os.path.exists(root):
        raise ParameterError(f"store not found: {root!r}")
    try:
        res = SweepResult.open(root)
    except StoreError:
        raise
    except Exception as exc:  # zarr raises several types for a directory that is no store
        raise ParameterError(f"{root!r} is not a readable sweep store: {exc}") from None
    if "status" not in res.ds.data_vars:
        raise ParameterError(f"{root!r} is not a gearchaos sweep store (no 'status')")
    return res
