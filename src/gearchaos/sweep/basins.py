"""Basins of attraction and basin fractions: :func:`basins` and :func:`basin_fractions`.

``basins(target, "x=-2:2:200", "x_dot=-2:2:200", omega=1.2)`` integrates one start per point
of a 2-D slice of initial states (two named state coordinates; the others at ``base_state``)
at one operating point and labels each start by the attractor it reaches;
``basin_fractions(target, "omega=1:2:40", starts=200)`` draws ``starts`` uniform random
starts in a box of initial states at every value of a parameter and estimates the fraction
ending on each attractor with its Wilson confidence interval
(:mod:`gearchaos.sweep.basin_fractions`).

How a start is labelled (:mod:`gearchaos.dynamics.attractors.basins`): an attractor catalogue is
built
from a seeded sample of ``sample`` starts of the operating point by
:func:`~gearchaos.dynamics.attractors.coexistence.attractors` (each attractor decided by the motion
verdict: orbits confirmed by shooting with their multipliers, chaos by λ₁ ± its error); every
start's record is matched against it, and only the starts that match nothing get the verdict
(the catalogue grows by the attractors they find).

Like a sweep, the integrations run as tasks of ``chunk_points`` starts in one compiled call
each (threads in-process, ``workers`` local processes, a Dask cluster at ``scheduler`` or a
local one of ``dask_local`` workers); this process matches them in task order and is the only
writer of the resumable Zarr store (:mod:`gearchaos.sweep._basin_store`). Results do not
depend on the executor.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import json
import os
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, TypedDict

import numpy as np

from .._checks import check_bool, check_int, check_memory, check_real
from .._version import provenance
from ..dynamics.attractors.basins import (
    FAILED,
    Catalogue,
    catalogue_from_sample,
    identify,
    link_tracks,
)
from ..dynamics.verdict.decide import CONFIRM_PERIODS, confirmed_settings
from ..errors import ParameterError, Status, StoreError
from ..integrate._chains import ChainRun
from ..integrate.interface import Info
from ..integrate.settings import SolverSettings, split_keywords
from ..model.record import target_record
from ..model.system import System
from ..model.target import Target, resolve, scale_attrs
from ._basin_store import BasinStore, open_basins
from .execute import EXECUTION_OPTIONS, Execution, InProcess, executor
from .integrity import StoreLock
from .progress import _Bar
from .run import _sigterm_as_interrupt, _store_path
from .spec import Axis, parse_axis

__all__ = ["BASIN_SETTINGS", "basins", "open_basins"]

#: Default protocol of a start: 200 transient periods, 32 recorded section points.
BASIN_SETTINGS = SolverSettings(transient_periods=200, periods=32)
#: Names a basin store uses itself (not available as slice coordinates).
_RESERVED = frozenset({"attractor", "label", "status", "state", "start", "final_state"})


@dataclass(frozen=True)
class _Task:
    index: int
    rows: slice


class _Job:
    """The starts of a basin computation: ``R`` rows of ``S`` starts (an image row, or the
    starts at one parameter value), the operating point of each row, and the store layout."""

    def __init__(
        self,
        target: Target,
        kind: str,
        dims: tuple[str, str],
        coords: dict[str, Any],
        row_values: list[dict[str, Any]],
        starts: np.ndarray,
        cfg: SolverSettings,
        spec: dict[str, Any],
        chunk_points: int,
    ):
        self.target, self.kind, self.dims, self.coords = target, kind, dims, coords
        self.starts = starts  # (R, S, n)
        self.cfg, self.spec = cfg, spec
        self.R, self.S, self.n = starts.shape
        # one operating point for an image (group 0), one per row for fractions
        self.group_values = row_values
        self.systems = [resolve(target, v) for v in row_values]
        self.ref = self.systems[0]
        self.rows_per_task = max(1, int(chunk_points) // self.S)

    def group(self, row: int) -> int:
        return 0 if len(self.group_values) == 1 else row

    def tasks(self) -> list[_Task]:
        step = self.rows_per_task
        return [
            _Task(i, slice(r, min(r + step, self.R))) for i, r in enumerate(range(0, self.R, step))
        ]

    def run(self, task: _Task) -> ChainRun:
        rows = range(task.rows.start, task.rows.stop)
        chains = [[self.systems[self.group(r)]] for r in rows for _ in range(self.S)]
        y0 = self.starts[task.rows].reshape(-1, self.n)
        return ChainRun.from_systems(chains, self.cfg, y0=y0)

    def variables(self) -> tuple[dict[str, Any], dict[str, tuple[int, ...]]]:
        shape, rows, n = (self.R, self.S), self.rows_per_task, self.n
        d = self.dims
        var: dict[str, Any] = {
            "attractor": (
                d,
                (shape, "int32"),
                -1,
                {"long_name": "attractor reached (index into the legend; -1 not run, -2 failed)"},
            ),
            "label": (d, (shape, "<U10"), "", {"long_name": "motion label of that attractor"}),
            "status": (
                d,
                (shape, "int8"),
                int(Status.NOT_RUN),
                {"flag_values": [int(s) for s in Status], "flag_meanings": Status.meanings()},
            ),
            "steps_accepted": (d, (shape, "int64"), -1, {"long_name": "steps accepted"}),
            "final_state": (
                (*d, "state"),
                ((*shape, n), "float64"),
                np.nan,
                {"long_name": "state at the end of the record (on the section)"},
            ),
        }
        if self.kind == "basin_fractions":
            var["initial_state"] = (
                (*d, "state"),
                ((*shape, n), "float64"),
                np.nan,
                {"long_name": "the random initial state"},
            )
        chunks = {k: (rows, self.S, *((n,) if len(v[0]) == 3 else ())) for k, v in var.items()}
        return var, chunks

    def attrs(self) -> dict[str, Any]:
        ref = self.ref
        return {
            "title": f"gearchaos {self.kind.replace('_', ' ')} of {ref.name}",
            "kind": self.kind,
            **target_record(self.target),
            "basin_spec": json.dumps(self.spec, sort_keys=True),
            "confirm_periods": int(self.spec["confirm_periods"]),
            **self.cfg.to_record(),
            "dims": list(self.dims),
            "omega": float(ref.omega),
            **scale_attrs(ref.model),
            **provenance(),
        }


def _run(
    job: _Job,
    store: Any,
    overwrite: bool,
    execution: Execution,
    progress: bool,
    sample: int,
    seed: int,
    match: _Rules,
) -> Any:
    path = _store_path(store)
    st = BasinStore(path)
    attrs = job.attrs()
    lock = StoreLock(path) if path is not None else contextlib.nullcontext()
    with lock:
        identity = {k: attrs[k] for k in ("kind", "model", "gearset_toml", "basin_spec")}
        identity.update(job.cfg.to_record())
        if st.exists() and overwrite:
            st.remove()
        if st.exists():
            st.verify()
            old = st.attrs()
            diffs = [k for k, v in identity.items() if old.get(k) != v]
            if diffs:
                raise StoreError(
                    f"{path} holds a basin computation with other settings (differs in "
                    f"{', '.join(diffs)}); use another output path, or overwrite=True "
                    "(--overwrite) to replace it"
                )
            if old.get("complete"):
                st.clear_stale_progress()
                return st.open()
        elif path is not None and os.path.lexists(path):
            raise StoreError(
                f"{path!r} exists and is not a gearchaos basin store: it is never replaced, "
                "not even with overwrite=True (--overwrite); move it away or choose another path"
            )
        if not st.exists():
            var, chunks = job.variables()
            coords: dict[str, tuple[tuple[str, ...], np.ndarray]] = {
                k: ((k,), np.asarray(v)) for k, v in job.coords.items()
            }
            coords["state"] = (("state",), np.array(job.ref.state_names, dtype="U16"))
            st.create(coords, var, chunks, attrs)
            if job.kind == "basin_fractions":
                _write_initial_states(st, job)
        cats = {k: Catalogue.from_record(v) for k, v in st.read_catalogues().items()}
        done = st.done_tasks()
        todo = [t for t in job.tasks() if t.index not in done]
        total = job.R * job.S
        bar = _Bar(progress, total, total - sum((t.rows.stop - t.rows.start) * job.S for t in todo))
        with _sigterm_as_interrupt(), bar, executor(execution) as (ex, fn, desc):
            bar.describe(f"of starts, {desc}")
            width = (
                1
                if isinstance(ex, InProcess)
                else 2 * (execution.workers or execution.dask_local or 4)
            )
            _drive(job, st, todo, ex, fn, width, bar, cats, sample, seed, match)
        final = {
            "attractors": json.dumps(
                {k: c.to_record() for k, c in sorted(cats.items(), key=lambda kv: int(kv[0]))}
            )
        }
        if job.kind == "basin_fractions":
            ordered = [cats.get(str(r)) for r in range(job.R)]
            final["tracks"] = json.dumps(link_tracks(ordered))
        st.finish_with(final)
        return st.open()


def _write_initial_states(st: BasinStore, job: _Job) -> None:
    import zarr

    g = zarr.open_group(st.zarr_store, mode="a", use_consolidated=False)
    arr = g["initial_state"]
    assert isinstance(arr, zarr.Array)
    arr[...] = job.starts


def _drive(
    job: _Job,
    st: BasinStore,
    todo: list[_Task],
    ex: Any,
    fn: Any,
    width: int,
    bar: Any,
    cats: dict[str, Catalogue],
    sample: int,
    seed: int,
    match: _Rules,
) -> None:
    """Integrate the tasks on ``ex`` (``width`` in flight), identify and write them here in
    task order, so the catalogue grows the same way whatever the executor."""
    it = iter(todo)
    inflight: dict[Any, _Task] = {}
    finished: dict[int, Any] = {}
    order = [t.index for t in todo]
    pos = 0

    def submit_next() -> None:
        t = next(it, None)
        if t is not None:
            inflight[ex.submit(fn, job.run(t))] = t

    for _ in range(width):
        submit_next()
    try:
        while inflight:
            ready, _ = cf.wait(list(inflight), return_when=cf.FIRST_COMPLETED)
            for fut in ready:
                t = inflight.pop(fut)
                finished[t.index] = (t, fut.result())
                submit_next()
            while pos < len(order) and order[pos] in finished:
                t, out = finished.pop(order[pos])
                data = _identify_task(job, t, out, cats, sample, seed, match)
                st.write_catalogues({k: c.to_record() for k, c in cats.items()})
                st.write(t.index, (t.rows,), data)
                bar.advance(data["status"].size, int(np.sum(data["attractor"] == FAILED)))
                pos += 1
    finally:
        for fut in inflight:
            fut.cancel()


def _identify_task(
    job: _Job,
    task: _Task,
    out: Any,
    cats: dict[str, Catalogue],
    sample: int,
    seed: int,
    match: _Rules,
) -> dict[str, np.ndarray]:
    rows = range(task.rows.start, task.rows.stop)
    nr, S, n = len(rows), job.S, job.n
    sec = out.states[:, 0, :, :n].reshape(nr, S, -1, n)
    fin = out.final_state[:, 0, :n].reshape(nr, S, n)
    status = out.status[:, 0].reshape(nr, S)
    codes = np.full((nr, S), FAILED, dtype=np.int32)
    for i, r in enumerate(rows):
        g = job.group(r)
        key = str(g)
        values = job.group_values[g]
        if key not in cats:  # the catalogue of this operating point, from a sample of its starts
            everything = job.starts if len(job.group_values) == 1 else job.starts[r : r + 1]
            flat = everything.reshape(-1, n)
            rng = np.random.default_rng([seed, g])
            pick = rng.choice(flat.shape[0], size=min(sample, flat.shape[0]), replace=False)
            cats[key] = catalogue_from_sample(
                job.target, values, flat[np.sort(pick)], job.cfg, **match
            )
        codes[i] = identify(
            cats[key],
            job.target,
            values,
            job.systems[g],
            job.cfg,
            sec[i],
            fin[i],
            status[i] == 0,
            verdict=confirmed_settings(match["confirm_periods"]),
        )
    labels = np.full((nr, S), "", dtype="<U10")
    for i, r in enumerate(rows):
        cat = cats[str(job.group(r))]
        for c in np.unique(codes[i]):
            labels[i][codes[i] == c] = "failed" if c == FAILED else cat.entries[int(c)].label
    return {
        "attractor": codes,
        "label": labels,
        "status": status.astype(np.int8),
        "steps_accepted": out.info[:, 0, Info.ACCEPTED].astype(np.int64).reshape(nr, S),
        "final_state": fin.copy(),
    }


def _base_state(system: System, base_state: Any) -> np.ndarray:
    """The state of the coordinates not varied: zeros, a mapping by state name or an array."""
    names, n = list(system.state_names), system.n_state
    y = np.zeros(n)
    if base_state is None:
        return y
    if isinstance(base_state, Mapping):
        for k, v in base_state.items():
            if k not in names:
                raise ParameterError(
                    f"base_state names an unknown state {k!r}: the states are {', '.join(names)}"
                )
            y[names.index(k)] = check_real(f"base_state[{k!r}]", v)
        return y
    try:
        arr = np.array(base_state, dtype=np.float64)
    except (TypeError, ValueError):
        raise ParameterError(
            f"base_state must be a mapping of state names to values or an array of {n} "
            f"values: got {type(base_state).__name__}"
        ) from None
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise ParameterError(f"base_state must be {n} finite values: got shape {arr.shape}")
    return arr


def _state_axis(system: System, item: Any, which: str) -> Axis:
    try:
        ax = parse_axis(item)
    except ParameterError as exc:
        raise ParameterError(str(exc), name=which) from None
    names = list(system.state_names)
    if ax.name not in names:
        raise ParameterError(
            f"{which} must name a state of the model ({', '.join(names)}): got {ax.name!r}",
            name=which,
        )
    if ax.name in _RESERVED:
        raise ParameterError(
            f"{which}: the state name {ax.name!r} is reserved in basin stores", name=which
        )
    if len(ax.values) < 2:
        raise ParameterError(f"{which} needs at least 2 values: got {len(ax.values)}", name=which)
    steps = np.diff(np.asarray(ax.values))
    if not np.all(steps > 0):  # an image's axis: equal or falling values make no image
        lo, hi, n = min(ax.values), max(ax.values), len(ax.values)
        way = (
            f"give {ax.name}={lo:g}:{hi:g}:{n}"
            if lo < hi and np.all(steps < 0)
            else f"give distinct values, e.g. {ax.name}={lo - 1:g}:{hi + 1:g}:{n}"
            if lo == hi
            else "give them in increasing order"
        )
        raise ParameterError(
            f"{which} must give increasing values of {ax.name} (the axis of an image): got "
            f"{_shown_values(ax.values)}; {way}",
            name=which,
        )
    return ax


def _shown_values(values: tuple[float, ...]) -> str:
    shown = ", ".join(f"{v:g}" for v in values[:4])
    return shown + (f", … ({len(values)} values)" if len(values) > 4 else "")


def check_starts_memory(what: str, rows: int, columns: int, n: int, name: str) -> None:
    """Refuse, before the starts are made, ``rows`` × ``columns`` starts of ``n`` states that
    would not fit in memory: the starts themselves (n float64), the image's coordinates of each
    (2 float64) and the attractor code the result is read back as (int32), per start. The
    refusal's name is ``name``, the keyword to change."""
    try:
        check_memory(
            f"{what} ({rows} × {columns} starts of {n} states)",
            float(rows) * float(columns) * (8.0 * (n + 2) + 4.0),
        )
    except ParameterError as exc:
        raise ParameterError(str(exc), name=name) from None


def _varied_base(base_state: Any, axes: tuple[Axis, Axis]) -> None:
    """Refuse a ``base_state`` mapping that sets a coordinate the image varies: its value
    would be replaced at every start (the mapping's point is the coordinates not varied)."""
    if not isinstance(base_state, Mapping):
        return
    for ax, which in zip(axes, ("x", "y"), strict=True):
        if ax.name in base_state:
            raise ParameterError(
                f"base_state sets {ax.name}, which the image varies along {which}; leave "
                f"{ax.name} out of base_state",
                name="base_state",
            )


def _split(
    kwargs: dict[str, Any], settings: Any, params: Any, door: Any, target: Target
) -> tuple[dict[str, Any], SolverSettings, Execution]:
    where = Execution(**{k: kwargs.pop(k) for k in EXECUTION_OPTIONS if k in kwargs})
    values, cfg = split_keywords(
        kwargs,
        settings,
        params,
        BASIN_SETTINGS,
        door=door,
        target=target,
        options=EXECUTION_OPTIONS,
    )
    return values, cfg.replace(samples_per_period=1), where


class _Rules(TypedDict):
    """The rules that make a start's attractor (:func:`catalogue_from_sample`'s keywords):
    the matching tolerances and the last window that confirms chaos and QP."""

    tol: float
    spread_fraction: float
    confirm_periods: int


def _match_options(tol: float, spread_fraction: float, confirm_periods: int) -> _Rules:
    return {
        "tol": check_real("tol", tol, lo=0.0, lo_open=True),
        "spread_fraction": check_real(
            "spread_fraction", spread_fraction, lo=0.0, hi=1.0, lo_open=True
        ),
        "confirm_periods": check_int("confirm_periods", confirm_periods, lo=0, hi=10**6),
    }


def basins(
    target: Target,
    x: Any,
    y: Any,
    *,
    base_state: Any = None,
    params: Mapping[str, Any] | None = None,
    settings: SolverSettings | None = None,
    store: str | os.PathLike[str] | None = None,
    overwrite: bool = False,
    progress: bool = True,
    sample: int = 32,
    seed: int = 0,
    tol: float = 1e-4,
    spread_fraction: float = 0.25,
    confirm_periods: int = CONFIRM_PERIODS,
    chunk_points: int = 1000,
    **values_and_settings: Any,
) -> Any:
    """The basin image of one operating point over a 2-D slice of initial states.

    Parameters
    ----------
    target
        A :class:`~gearchaos.gearset.GearSet` or a :class:`~gearchaos.model.System`.
    x, y
        The two state coordinates of the slice and their values, ``"x=-2:2:200"`` (the
        syntax of sweep axes; names from the model's ``state_names``).
    base_state
        The other coordinates: a mapping by state name, an array of every state, or None
        (zero).
    params, **values_and_settings
        The executor (``workers``, ``scheduler``, ``dask_local``: where the integrations
        run, :class:`~gearchaos.sweep.execute.Execution`), parameter values (``omega=1.2``;
        dotted names in ``params``) and solver settings (``transient_periods`` 200,
        ``periods`` 32 recorded section points, ``rtol`` …).
    store, overwrite, progress
        As for :func:`~gearchaos.sweep.bifurcation`: a resumable Zarr store (None: memory).
    sample, seed
        Starts (drawn with ``seed`` from the image) from which the attractor catalogue is
        built before the image is matched against it.
    tol, spread_fraction
        The matching rules (:mod:`gearchaos.dynamics.attractors.basins`).
    confirm_periods
        A chaotic or quasi-periodic attractor is catalogued only after a last window of at
        least this many periods confirms it (default 2000, as for
        :func:`~gearchaos.dynamics.attractors.coexistence.attractors`): a chaotic transient that
        ends on
        an orbit within it is that orbit's start. Stored in the ``confirm_periods`` attribute
        (and ``basin_spec``).
    chunk_points
        Starts per task (one compiled call each).

    Returns
    -------
    xarray.Dataset
        Dims (y, x); ``attractor`` codes (index into ``attrs["attractors"]["0"]["entries"]``,
        −2 failed), ``label``, ``status``, ``steps_accepted``, ``final_state``; attributes with
        the model or gear set, ``basin_spec``, ``confirm_periods``, the settings and versions.
    """
    kw = dict(values_and_settings)
    values, cfg, where = _split(kw, settings, params, basins, target)
    system = resolve(target, values)
    ax, ay = _state_axis(system, x, "x"), _state_axis(system, y, "y")
    if ax.name == ay.name:
        raise ParameterError(
            f"x and y must be two different states: got {ax.name!r} twice", name="y"
        )
    _varied_base(base_state, (ax, ay))
    base = _base_state(system, base_state)
    check_starts_memory("the basin image y × x", len(ay.values), len(ax.values), base.size, "x")
    names = list(system.state_names)
    X, Y = np.meshgrid(np.array(ax.values), np.array(ay.values))
    starts = np.broadcast_to(base, (*X.shape, base.size)).copy()
    starts[..., names.index(ax.name)] = X
    starts[..., names.index(ay.name)] = Y
    sample = check_int("sample", sample, lo=1, hi=10_000)
    seed = check_int("seed", seed, lo=0)
    match = _match_options(tol, spread_fraction, confirm_periods)
    spec = {
        "x": [ax.name, list(ax.values)],
        "y": [ay.name, list(ay.values)],
        "base_state": [float(v) for v in base],
        "values": {k: _jsonable(v) for k, v in sorted(values.items())},
        "sample": sample,
        "seed": seed,
        **match,
    }
    job = _Job(
        target,
        "basins",
        (ay.name, ax.name),
        {ay.name: np.array(ay.values), ax.name: np.array(ax.values)},
        [values],
        starts,
        cfg,
        spec,
        check_int("chunk_points", chunk_points, lo=1),
    )
    return _run(
        job,
        store,
        check_bool("overwrite", overwrite),
        where,
        check_bool("progress", progress),
        sample,
        seed,
        match,
    )


def _jsonable(v: Any) -> Any:
    return float(v) if isinstance(v, int | float | np.floating) else str(v)
