"""Motion labels for every point of a sweep store, and the regime table.

:func:`classify_store` reads the stored Poincaré sections (the first two observed variables,
first observed planet — X̄_sp1 and X̄'_sp1 by default) and, when present, the largest Lyapunov
exponents, labels every point with :func:`gearchaos.analysis.classify.classify_sections`
(1T … nT, QP, chaos, unresolved; ``failed`` where the integration failed) and writes the
variables ``motion``, ``period`` (0: none found), ``k01`` (0–1 test), ``indicators_agree``,
``contact_KEY`` for each kind of mesh among the model's contacts (``contact_sp`` and
``contact_rp`` of a planetary train; contact regime of every mesh, MODEL.md §8: 0 none, 1
single-sided, 2 double-sided impact) and the attribute ``regime_table`` (JSON: fraction of
the swept points in each regime, per family value when there is a family). It needs no
re-simulation, so ``gearchaos classify run.zarr`` can re-label a stored sweep with other
tolerances.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._checks import check_int, check_real
from .._output import remove_stale_staging, replace_dir, staging_prefix, write_error
from ..analysis.motion import LABEL_DTYPE, Motion
from ..errors import ParameterError, Status, StoreError
from .result import SweepResult
from .store import SweepStore, consolidate, foreign_files_ignored, open_sweep, set_attributes
from .verdicts import RECORD_VARIABLES, VERDICT_COLUMNS

__all__ = ["classify_dataset", "classify_store"]

#: Default tolerance of period detection, relative to the attractor's size, and the longest
#: period recognised as nT (of :func:`classify_store` and of the labels ``--orbits`` confirms).
PERIOD_RTOL = 1e-3
MAX_PERIOD = 64


def _section_pair(res: SweepResult) -> np.ndarray:
    """(X_k, X'_k) of the first two observed section variables, first observed planet."""
    ds = res.ds
    observed = res.spec.observe if res.spec is not None else tuple(ds.data_vars)
    names = [n for n in observed if n in ds.data_vars and "section" in ds[n].dims]
    if not names:
        raise StoreError("the store holds no section variables to classify")
    cols = []
    for n in names[:2]:
        v = ds[n]
        if "planet" in v.dims:
            v = v.isel(planet=0)
        cols.append(np.asarray(v.transpose(..., "section").values, dtype=float))
    return np.stack(cols, axis=-1)


def classify_dataset(
    ds: Any,
    *,
    period_rtol: float = PERIOD_RTOL,
    max_period: int = MAX_PERIOD,
    decide: bool = True,
) -> dict[str, Any]:
    """Labels and indicators for every point of a sweep dataset (nothing written).

    Every store written since sweeps store their verdicts holds the verdict columns
    (:mod:`gearchaos.sweep.verdicts`): a store decided by the confirming verdict has its labels
    read as stored (never re-decided); a store labelled from the record alone (evidence
    ``record``, ``verdicts=False``) is decided again by the same record mode with these
    tolerances (``record_verdicts`` holds the new verdicts) unless ``decide`` is False: a
    sweep's own classification at its end, whose tasks labelled every point by the same record
    mode with the same tolerances, reads their labels as stored. A store of an earlier version
    without verdict columns is labelled by :func:`_old_layout_labels`.
    """
    res = SweepResult.of(ds)
    if "verdict" not in res.ds.data_vars:
        return _old_layout_labels(res, period_rtol=period_rtol, max_period=max_period)
    if _record_mode(res):
        if not decide:
            return _record_as_stored(res)
        return _from_record(res, period_rtol=period_rtol, max_period=max_period)
    return _from_verdicts(res)


def _lle_inputs(res: SweepResult) -> dict[str, Any]:
    """The λ₁ a sweep recorded (``lyapunov`` without verdicts), with the record's length in
    periods and the forcing period of every point (its bound), or nothing."""
    ds = res.ds
    if "lle" not in ds.data_vars:
        return {}
    spec = res.spec
    return {
        "lle": np.asarray(ds["lle"].transpose(*res.lead_dims).values, dtype=float),
        "run_periods": int(spec.solver.periods if spec is not None else ds.attrs["periods"]),
        "forcing_period": res.forcing_period(),
    }


def _old_layout_labels(res: SweepResult, *, period_rtol: float, max_period: int) -> dict[str, Any]:
    """The labels of a store written before every sweep stored its verdicts (no verdict
    columns: a sweep without verdicts, labelled after it ran): from its section values with
    :func:`~gearchaos.analysis.classify.classify_sections`, exactly as those versions did."""
    from ..analysis.classify import classify_sections

    pts = _section_pair(res)
    kw: dict[str, Any] = {"details": True, "rtol": period_rtol, "max_period": max_period}
    lle = _lle_inputs(res)
    if lle:
        kw["lle"] = np.asarray(res.ds["lle"].values, dtype=float)
        kw.update(run_periods=lle["run_periods"], forcing_period=lle["forcing_period"])
    details = classify_sections(pts, **kw)
    return _tabulate(res, [details[idx] for idx in np.ndindex(*res.shape)])


def _record_mode(res: SweepResult) -> bool:
    """Whether a store's verdicts are all from the record alone (a sweep without verdicts):
    every point's evidence ``record``, ``failed`` or not computed yet. A store of the
    confirming verdict never is, so its Floquet and Lyapunov verdicts are never re-decided."""
    from ..dynamics.verdict.evidence import EVIDENCE

    spec = res.spec
    if spec is not None and spec.verdicts:
        return False
    codes = {int(c) for c in np.unique(np.asarray(res.ds["verdict"].values))}
    return codes <= {EVIDENCE["record"], EVIDENCE["failed"], EVIDENCE["not_computed"]}


def _from_record(res: SweepResult, *, period_rtol: float, max_period: int) -> dict[str, Any]:
    """A record-mode store decided again, by the record mode of the verdict
    (:func:`~gearchaos.dynamics.verdict.record.decide_from_record`) with these tolerances:
    the labels the sweep stored at the default ones, or new ones with others."""
    from ..dynamics.verdict.record import decide_from_record

    status = res.status()
    pairs = _section_pair(res)
    pts = pairs.reshape(-1, *pairs.shape[-2:])
    lle = _lle_inputs(res)
    verdicts = decide_from_record(
        pts,
        (status == 0).reshape(-1),
        lle=lle["lle"].reshape(-1) if lle else None,
        run_periods=lle.get("run_periods"),
        forcing_period=np.asarray(lle["forcing_period"]).reshape(-1) if lle else None,
        period_rtol=period_rtol,
        longest_period=max_period,
    )
    return {**_tabulate(res, verdicts), "record_verdicts": verdicts}


def _record_as_stored(res: SweepResult) -> dict[str, Any]:
    """A record-mode store's labels, periods, K and indicator agreement as its tasks stored
    them (a failed or not-run point labelled by its status), with its contact regimes and
    regime table."""
    ds, lead = res.ds, res.lead_dims
    if not all(name in ds.data_vars for name in RECORD_VARIABLES):  # earlier record stores
        return _from_record(res, period_rtol=PERIOD_RTOL, max_period=MAX_PERIOD)
    labels = _stored_labels(res)
    return {
        "dims": lead,
        **_contact(res),
        "motion": labels,
        "period": np.asarray(ds["period"].transpose(*lead).values, dtype=np.int16),
        "k01": np.asarray(ds["k01"].transpose(*lead).values, dtype=float),
        "indicators_agree": np.asarray(ds["indicators_agree"].transpose(*lead).values, dtype=bool),
        "regime_table": _regime_table(res, labels),
    }


def _stored_labels(res: SweepResult) -> np.ndarray:
    """The labels a store's tasks wrote, a failed or not-run point labelled by its status."""
    labels = np.asarray(res.ds["motion"].transpose(*res.lead_dims).values).astype(LABEL_DTYPE)
    status = res.status()
    for idx in np.ndindex(*labels.shape):
        labels[idx] = _status_label(int(status[idx])) or labels[idx]
    return labels


def _tabulate(res: SweepResult, decided: list[Any]) -> dict[str, Any]:
    """The label arrays of a store from one decision per point (in ``np.ndindex`` order of
    its grid: the record classification's details or the record-mode verdicts, which have
    ``label``, ``period``, ``k01`` and ``agree``); a failed integration labels its point."""
    shape, status = res.shape, res.status()
    labels = np.empty(shape, dtype=LABEL_DTYPE)
    period = np.zeros(shape, dtype=np.int16)
    k01 = np.full(shape, np.nan)
    agree = np.ones(shape, dtype=bool)
    for d, idx in zip(decided, np.ndindex(*shape), strict=True):
        labels[idx] = _status_label(int(status[idx])) or d.label
        period[idx] = d.period or 0
        k01[idx] = np.nan if d.k01 is None else d.k01
        agree[idx] = bool(d.agree)
    return {
        "dims": res.lead_dims,
        **_contact(res),
        "motion": labels,
        "period": period,
        "k01": k01,
        "indicators_agree": agree,
        "regime_table": _regime_table(res, labels),
    }


def _status_label(status: int) -> str | None:
    """The label a point's integration status imposes: ``failed`` for a failed integration,
    ``not run`` for a point an interrupted sweep has not computed (never "failed": nothing
    failed), None for a point that ran."""
    if status == int(Status.NOT_RUN):
        return Motion.not_run().format()
    return Motion.failed().format() if status != 0 else None


def _from_verdicts(res: SweepResult) -> dict[str, Any]:
    """The stored verdicts' labels (:mod:`gearchaos.sweep.verdicts`): nothing is re-decided;
    the period follows from the label, and the contact regimes and regime table are added."""
    ds = res.ds
    labels = _stored_labels(res)
    period = np.zeros(labels.shape, dtype=np.int16)
    for idx in np.ndindex(*labels.shape):
        period[idx] = Motion.parse(str(labels[idx])).period
    return {
        "dims": res.lead_dims,
        **_contact(res),
        "motion": labels,
        "period": period,
        "k01": np.asarray(ds["k01"].transpose(*res.lead_dims).values, dtype=float),
        "indicators_agree": np.ones(labels.shape, dtype=bool),
        "regime_table": _regime_table(res, labels),
    }


def _regime_table(res: SweepResult, labels: np.ndarray) -> dict[str, Any]:
    """Fraction of the points in each regime, per family value when there is a family (of the
    points computed: an interrupted sweep's points not run yet are left out)."""
    from ..analysis.classify import regime_table

    ds, lead_dims = res.ds, res.lead_dims
    fam = res.layout().family
    table: dict[str, Any]
    if fam is not None and fam in lead_dims:
        ax = lead_dims.index(fam)
        table = {
            f"{fam}={float(v):g}": regime_table(_ran(np.take(labels, i, axis=ax).ravel()))
            for i, v in enumerate(ds[fam].values)
        }
    else:
        table = {"all": regime_table(_ran(labels.ravel()))}
    return table


def _ran(labels: np.ndarray) -> np.ndarray:
    return labels[labels != Motion.not_run().format()]


def label_periods(
    pts: np.ndarray,
    status: np.ndarray,
    *,
    lle: np.ndarray | None = None,
    run_periods: int | None = None,
    forcing_period: np.ndarray | None = None,
) -> np.ndarray:
    """Period n of the label nT that :func:`classify_store` gives each point (0 where the label
    is QP, chaos, unresolved or failed), from its section pairs ``pts`` (..., section, 2), its
    integration ``status`` and, when the sweep has them, the Lyapunov exponents."""
    from ..analysis.classify import classify_sections

    kw: dict[str, Any] = {"rtol": PERIOD_RTOL, "max_period": MAX_PERIOD}
    if lle is not None:
        kw.update(lle=lle, run_periods=run_periods, forcing_period=forcing_period)
    labels = classify_sections(pts, **kw)
    out = np.zeros(labels.shape, dtype=int)
    for idx in np.ndindex(*labels.shape):
        if status[idx] == 0:
            out[idx] = Motion.parse(str(labels[idx])).period
    return out


@dataclass(frozen=True)
class _Mesh:
    """A kind of mesh of the store's model whose regime a sweep stores as ``contact_KEY``: the
    tracked ``group`` of its deflections (per member: one column each), the ``key`` (the
    label of its force group, else the name of its contact, without the member's number) and
    the ``words`` naming it in a long name (``each sun–planet mesh``, ``the mesh 'mesh'``)."""

    key: str
    group: str
    per_member: bool
    words: str


def _meshes(res: SweepResult) -> list[_Mesh]:
    """The kinds of mesh of the store's model (its capabilities): each tracked group whose
    observables are all mesh contacts (bearings are judged on both extrema, which a sweep does
    not turn into regimes), and whose minimum the store holds. None for a model the store
    records but that cannot be built here (a model's file the user has not named): its
    labels need no model."""
    try:
        reference = res.reference
    except ParameterError:
        return []
    if reference is None:
        return []
    caps = reference.capabilities
    meshes = {c.column: c for c in caps.contacts if c.kind == "mesh"}
    labels = {deflection: label for label, _, deflection in caps.force_groups}
    out = []
    for group, cols, per in reference.tracked_groups():
        if f"{group}_min" not in res.ds.data_vars or not all(int(j) in meshes for j in cols):
            continue
        name = meshes[int(cols[0])].name
        if per:  # sun_planet_1 … → each sun–planet mesh
            stem = name.rpartition("_")[0]
            words = f"each {stem.replace('_', '–')} mesh"
        else:
            stem, words = name, f"the mesh {name!r}"
        out.append(_Mesh(labels.get(group, stem), group, bool(per), words))
    return out


def _contact(res: SweepResult) -> dict[str, Any]:
    """Contact regime codes of each kind of mesh (MODEL.md §8) from the stored minimum
    deflections against the clearance at every point: 0 where the drive flanks never part
    (min δ̄ > b̄), 1 single-sided (min δ̄ ≥ −b̄), 2 double-sided, −1 unknown (no value)."""
    out: dict[str, Any] = {}
    ds = res.ds
    for mesh in _meshes(res):
        found = res.clearance(mesh.group)
        if found is None:
            continue
        tail = ("planet_all",) if mesh.per_member else ()
        dmin = np.asarray(ds[f"{mesh.group}_min"].transpose(*res.lead_dims, *tail).values)
        b = found[0][..., None] if mesh.per_member else found[0]
        code = np.where(dmin > b, 0, np.where(dmin >= -b, 1, 2)).astype(np.int8)
        code[np.isnan(dmin)] = -1
        out[f"contact_{mesh.key}"] = code
    return out


def _staging(zstore: Any) -> str | None:
    """A temporary Zarr group beside an on-disk store (same file system), or None."""
    if not isinstance(zstore, str):
        return None
    parent = os.path.dirname(os.path.abspath(zstore))
    remove_stale_staging(zstore)  # what a killed classification left beside the store
    return tempfile.mkdtemp(prefix=staging_prefix(zstore), suffix=".partial", dir=parent)


def _swap_in(staging: str, zstore: str, attrs: dict[str, Any]) -> None:
    """Put the arrays written under ``staging`` in place of the store's (renames, which need
    no space; the old arrays go into ``staging``, removed by the caller; a concurrent
    classification of the store never makes it fail: :func:`replace_dir`), then its attributes
    (one atomic write)."""
    trash = tempfile.mkdtemp(prefix=".old-", dir=staging)
    for name in sorted(os.listdir(staging)):
        new = os.path.join(staging, name)
        if name.startswith(".") or not os.path.isdir(new):
            continue
        replace_dir(new, os.path.join(zstore, name), trash)
    set_attributes(zstore, attrs)


def classify_store(
    store: str | os.PathLike[str] | Any,
    *,
    period_rtol: float = PERIOD_RTOL,
    max_period: int = MAX_PERIOD,
    decide: bool = True,
) -> dict[str, Any]:
    """Label every point of a sweep store in place; returns the regime table.

    ``period_rtol`` is the tolerance of period detection relative to the attractor's size
    (:func:`~gearchaos.analysis.periodicity.detect_period`), ``max_period`` the longest period
    recognised as nT; ``decide`` False reads a record-mode store's labels as its tasks stored
    them (:func:`classify_dataset`).
    """
    import xarray as xr
    import zarr

    check_real("period_rtol", period_rtol, lo=0.0, hi=1.0, lo_open=True, hi_open=True)
    check_int("max_period", max_period, lo=1, hi=10_000)
    from zarr.abc.store import Store

    if not isinstance(store, str | os.PathLike | Store):
        raise ParameterError(
            "store must be the path of a sweep store such as 'run.zarr': "
            f"got {type(store).__name__}"
        )
    zstore = os.fspath(store) if isinstance(store, str | os.PathLike) else store
    if isinstance(zstore, str):
        open_sweep(zstore)  # a damaged or foreign store is reported, never relabelled
    try:
        with foreign_files_ignored():
            ds = xr.open_zarr(zstore, chunks=None, consolidated=False)
    except Exception as exc:  # zarr and xarray raise many types for damaged metadata
        raise StoreError(
            f"{zstore!r} is not a readable sweep store ({type(exc).__name__}: {exc})"
        ) from None
    res = classify_dataset(ds, period_rtol=period_rtol, max_period=max_period, decide=decide)
    # on disk the new arrays are written beside the store first and swapped in by renames,
    # so a full disk or a kill leaves the store as it was, never half rewritten
    try:
        staging = _staging(zstore)
    except OSError as exc:
        raise write_error(exc, "sweep store", str(zstore)) from None
    try:
        g = (
            zarr.open_group(staging, mode="w", zarr_format=2)
            if staging
            else zarr.open_group(zstore, mode="a", use_consolidated=False)
        )
        dims = list(res["dims"])
        for mesh in _meshes(SweepResult(ds)):
            name = f"contact_{mesh.key}"
            if name not in res:
                continue
            arr = g.create_array(
                name,
                shape=res[name].shape,
                chunks=res[name].shape,
                dtype="int8",
                fill_value=None,
                attributes={
                    "long_name": f"contact regime of {mesh.words} over the recorded window",
                    "flag_values": [-1, 0, 1, 2],
                    "flag_meanings": "unknown none single_sided double_sided",
                    "_ARRAY_DIMENSIONS": [*dims, *(["planet_all"] if mesh.per_member else [])],
                },
                overwrite=True,
            )
            arr[...] = res[name]
        docs = {
            "motion": ("1T…nT, QP, chaos, unresolved or failed", ""),
            "period": (RECORD_VARIABLES["period"][0], 0),
            "k01": ("0–1 test for chaos K (Gottwald & Melbourne)", np.nan),
            "indicators_agree": (RECORD_VARIABLES["indicators_agree"][0], False),
        }
        if "verdict" in ds.data_vars:  # the verdict columns' own descriptions
            docs["motion"] = (VERDICT_COLUMNS["motion"].long_name, "")
            docs["k01"] = (VERDICT_COLUMNS["k01"].long_name, np.nan)
        # a confirming verdict's labels are never rewritten here; a record-mode store's are
        # the record mode's again, with these tolerances (verdict, lle and the rest unchanged:
        # they do not depend on them)
        protected = "verdict" in ds.data_vars and "record_verdicts" not in res
        for name, (doc, fill) in docs.items():
            if protected and name in ("motion", "k01"):
                continue  # written by every task with its verdict: never rewritten in place
            values = res[name]
            arr = g.create_array(
                name,
                shape=values.shape,
                chunks=values.shape if values.size else "auto",
                dtype=values.dtype,
                # only floats carry a fill value (NaN): xarray would mask a bool False or a
                # period 0 equal to the fill value as missing (the array is written whole)
                fill_value=fill if values.dtype.kind == "f" else None,
                attributes={"long_name": doc, "_ARRAY_DIMENSIONS": dims},
                overwrite=True,
            )
            arr[...] = values
        attrs: dict[str, Any] = {
            "regime_table": json.dumps(res["regime_table"]),
            "classification_rtol": float(period_rtol),
        }
        if staging is None:
            g.attrs.update(attrs)
        else:
            _swap_in(staging, str(zstore), attrs)
    except OSError as exc:
        raise write_error(exc, "sweep store", str(zstore)) from None
    finally:
        if staging is not None:
            shutil.rmtree(staging, ignore_errors=True)
    consolidate(zstore)
    if isinstance(zstore, str):
        SweepStore(zstore).refresh_manifest()
    return dict(res["regime_table"])
