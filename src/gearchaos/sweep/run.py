"""Front door for sweeps: :func:`bifurcation`.

``bifurcation(gearset, "omega=0.01:4:800", family={"xi": [0.03, 0.05, 0.07, 0.09]})`` runs one
simulation per grid point with the seed's protocol (zero start, transient discarded, one
Poincaré point per mesh period), in parallel, into a resumable Zarr store, and returns the
result as an :class:`xarray.Dataset`.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
import time
from collections.abc import Iterator
from typing import Any

import numpy as np

from .._version import provenance
from ..errors import ParameterError, Status
from ..integrate._chains import ChainOutput, ChainRun
from .execute import InProcess, executor
from .grid import Grid, Task
from .spec import DEFAULT_OBSERVE, SweepSpec
from .store import SweepStore

__all__ = ["bifurcation", "run_sweep"]


def _tracked_groups(system: Any) -> list[tuple[str, np.ndarray, bool]]:
    """Tracked observables grouped: per-planet groups (delta_sp …) and scalars (x_s …)."""
    names = system.obs_names[: system.n_track]
    out: list[tuple[str, np.ndarray, bool]] = []
    seen: set[str] = set()
    for k, nm in enumerate(names):
        head, _, tail = nm.rpartition("_")
        if tail.isdigit():
            if head not in seen:
                seen.add(head)
                idx = [j for j, m in enumerate(names) if m.rpartition("_")[0] == head]
                out.append((head, np.array(idx), True))
        else:
            out.append((nm, np.array([k]), False))
    return out


class _Layout:
    """Store variables of a sweep and how to fill them from kernel outputs."""

    def __init__(self, grid: Grid):
        spec, ref = grid.spec, grid.reference
        self.grid = grid
        self.lead_dims = grid.dims
        self.lead_shape = grid.shape
        self.observed = [ref.observable(nm, spec.planets) for nm in spec.observe]
        self.tracked = _tracked_groups(ref)
        self.n_planets = int(getattr(ref.model, "n_planets", 0))
        self.state_names = ref.state_names

    def variables(self) -> tuple[dict[str, Any], dict[str, tuple[int, ...]]]:
        spec = self.grid.spec
        lead, shp, ch = self.lead_dims, self.lead_shape, self.grid.chunks
        ns, npl = int(spec.periods), len(spec.planets)
        var: dict[str, Any] = {}
        chunks: dict[str, tuple[int, ...]] = {}
        for ob in self.observed:
            nm, per_planet = ob.name, ob.per_planet
            dims = (*lead, "section", *(("planet",) if per_planet else ()))
            shape = (*shp, ns, *((npl,) if per_planet else ()))
            var[nm] = (dims, (shape, "float64"), np.nan, {"long_name": f"{nm} at the section"})
            chunks[nm] = (*ch, ns, *((npl,) if per_planet else ()))
        for nm, cols, per_planet in self.tracked:
            for which in ("min", "max"):
                dims = (*lead, *(("planet_all",) if per_planet else ()))
                shape = (*shp, *((cols.size,) if per_planet else ()))
                var[f"{nm}_{which}"] = (
                    dims,
                    (shape, "float64"),
                    np.nan,
                    {"long_name": f"{which} of {nm} over the recorded window"},
                )
                chunks[f"{nm}_{which}"] = (*ch, *((cols.size,) if per_planet else ()))
        var["status"] = (
            lead,
            (shp, "int8"),
            int(Status.NOT_RUN),
            {"flag_values": [int(s) for s in Status], "flag_meanings": Status.meanings()},
        )
        chunks["status"] = ch
        for nm in ("steps_accepted", "steps_rejected"):
            var[nm] = (lead, (shp, "int64"), -1, {"long_name": nm.replace("_", " ")})
            chunks[nm] = ch
        if spec.lyapunov:
            var["lle"] = (
                lead,
                (shp, "float64"),
                np.nan,
                {
                    "long_name": "largest Lyapunov exponent λ_1 per unit τ = ω_n t",
                    "method": "variational equations, Gram–Schmidt every forcing period",
                },
            )
            chunks["lle"] = ch
        n = len(self.state_names)
        var["final_state"] = (
            (*lead, "state"),
            ((*shp, n), "float64"),
            np.nan,
            {"long_name": "state at the end of the recorded window"},
        )
        chunks["final_state"] = (*ch, n)
        return var, chunks

    def extract(self, task: Task, run: ChainRun, out: ChainOutput) -> dict[str, np.ndarray]:
        """Block arrays of every variable for one finished task."""
        spec = self.grid.spec
        bshape = tuple(b.stop - b.start for b in task.block)
        starts = tuple(b.start for b in task.block)
        ns, npl = int(spec.periods), len(spec.planets)
        data: dict[str, np.ndarray] = {}
        for ob in self.observed:
            data[ob.name] = np.full((*bshape, ns, *((npl,) if ob.per_planet else ())), np.nan)
        for nm, cols, per_planet in self.tracked:
            for which in ("min", "max"):
                data[f"{nm}_{which}"] = np.full(
                    (*bshape, *((cols.size,) if per_planet else ())), np.nan
                )
        data["status"] = np.full(bshape, int(Status.NOT_RUN), dtype=np.int8)
        data["steps_accepted"] = np.full(bshape, -1, dtype=np.int64)
        data["steps_rejected"] = np.full(bshape, -1, dtype=np.int64)
        n_st = len(self.state_names)
        data["final_state"] = np.full((*bshape, n_st), np.nan)
        if spec.lyapunov:
            data["lle"] = np.full(bshape, np.nan)
            lle = out.lyapunov(run.dt)
        for c, chain in enumerate(task.chains):
            for j, idx in enumerate(chain):
                pos = tuple(i - s for i, s in zip(idx, starts, strict=True))
                for ob in self.observed:
                    data[ob.name][pos] = ob.take(out.states[c, j], out.observables[c, j])
                for nm, cols, per_planet in self.tracked:
                    lo, hi = out.obs_min[c, j][cols], out.obs_max[c, j][cols]
                    data[f"{nm}_min"][pos] = lo if per_planet else lo[0]
                    data[f"{nm}_max"][pos] = hi if per_planet else hi[0]
                data["status"][pos] = out.status[c, j]
                data["steps_accepted"][pos] = int(out.info[c, j, 0])
                data["steps_rejected"][pos] = int(out.info[c, j, 1])
                data["final_state"][pos] = out.final_state[c, j, :n_st]
                if spec.lyapunov:
                    data["lle"][pos] = lle[c, j, 0]
        return data


def _coords(grid: Grid, layout: _Layout) -> dict[str, tuple[tuple[str, ...], np.ndarray]]:
    spec = grid.spec
    c: dict[str, tuple[tuple[str, ...], np.ndarray]] = {}
    if len(spec.directions) > 1:
        c["direction"] = (("direction",), np.array(spec.directions, dtype="U4"))
    for a in spec.axes:
        c[a.name] = ((a.name,), np.array(a.values, dtype=float))
    c["section"] = (("section",), np.arange(int(spec.periods)))
    if any(ob.per_planet for ob in layout.observed):
        c["planet"] = (("planet",), np.array(spec.planets, dtype=np.int64))
    if any(per for *_, per in layout.tracked):
        c["planet_all"] = (("planet_all",), np.arange(1, layout.n_planets + 1))
    c["state"] = (("state",), np.array(layout.state_names, dtype="U16"))
    return c


def _attrs(target: Any, grid: Grid) -> dict[str, Any]:
    from ..gearset import GearSet

    spec, ref = grid.spec, grid.reference
    a: dict[str, Any] = {
        "title": f"gearchaos sweep of {ref.name}",
        "model": ref.model.name if not isinstance(target, GearSet) else "planetary",
        "gearset_toml": target.to_toml() if isinstance(target, GearSet) else "",
        "model_parameters": "" if isinstance(target, GearSet) else repr(target.model),
        "sweep_toml": spec.to_toml(),
        "rtol": float(spec.rtol),
        "atol": float(spec.atol),
        "transient_periods": float(spec.transient_periods),
        "periods": int(spec.periods),
        "initial_conditions": spec.initial_conditions,
        "direction": spec.direction,
        "dims": list(grid.dims),
        **provenance(),
    }
    if "omega" not in [ax.name for ax in spec.axes]:
        a["omega_fixed"] = float(ref.omega)
    # clearances and scales of the base gear set with the fixed overrides (not of a grid point)
    model = grid.base_model()
    if hasattr(model, "scales"):
        a["omega_n_rad_s"] = float(model.scales.omega_n)
        a["characteristic_length_m"] = float(model.scales.length)
    for k, v in getattr(model, "clearances", {}).items():
        a[f"clearance_{k}"] = float(v)
    return a


@contextlib.contextmanager
def _sigterm_as_interrupt() -> Iterator[None]:
    """SIGTERM behaves like Ctrl-C during a sweep, so finished chunks stay in the store."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum: int, frame: Any) -> None:
        raise KeyboardInterrupt(f"signal {signum}")

    old = signal.signal(signal.SIGTERM, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, old)


def run_sweep(
    target: Any,
    spec: SweepSpec,
    *,
    store: str | os.PathLike[str] | None = None,
    overwrite: bool = False,
    workers: int | None = None,
    scheduler: str | None = None,
    dask_local: int | None = None,
    progress: bool = True,
    chunk_points: int | None = None,
    classify: bool = True,
) -> Any:
    """Run (or resume) a sweep described by ``spec``; return its :class:`xarray.Dataset`."""
    grid = Grid(target, spec, chunk_points=chunk_points)
    layout = _Layout(grid)
    st = SweepStore(store)
    attrs = _attrs(target, grid)
    identity = {k: attrs[k] for k in ("model", "gearset_toml", "model_parameters", "sweep_toml")}
    if st.exists() and overwrite:
        st.remove()
    if st.exists():
        st.check_same(identity)
        if st.attrs().get("complete"):
            return st.open()
    elif store is not None and os.path.exists(os.fspath(store)):
        if overwrite:
            st.remove()
        else:
            raise ParameterError(
                f"{os.fspath(store)} exists and is not a gearchaos sweep store; "
                "choose another path or pass overwrite=True (--overwrite)"
            )
    if not st.exists():
        variables, chunks = layout.variables()
        st.create(_coords(grid, layout), variables, chunks, attrs)

    done = st.done_tasks()
    todo = [t for t in grid.tasks() if t.index not in done]
    n_total = int(np.prod(grid.shape))
    n_done = n_total - sum(t.n_points for t in todo)
    bar = _Bar(progress, n_total, n_done)
    with (
        _sigterm_as_interrupt(),
        bar,
        executor(workers, scheduler, dask_local) as (ex, fn, desc),
    ):
        bar.describe(desc)
        if isinstance(ex, InProcess):
            _run_in_process(todo, grid, layout, st, fn, bar)
        else:
            _run_pool(todo, grid, layout, st, ex, fn, bar, workers or dask_local or 8)
    # every task is written: drop the markers before classification consolidates the metadata
    st.clear_progress()
    if classify:
        from .classify import classify_store

        classify_store(st.zarr_store)
    st.finish()
    return st.open()


def _run_in_process(
    todo: list[Task], grid: Grid, layout: _Layout, st: SweepStore, fn: Any, bar: Any
) -> None:
    import numba

    want = 2 * numba.get_num_threads()
    i = 0
    while i < len(todo):
        group = [todo[i]]
        chains = len(todo[i].chains)
        L = max(len(c) for c in todo[i].chains)
        i += 1
        while i < len(todo) and chains < want and max(len(c) for c in todo[i].chains) == L:
            group.append(todo[i])
            chains += len(todo[i].chains)
            i += 1
        runs = [grid.task_run(t) for t in group]
        res = fn(ChainRun.concat(runs))
        parts = res.split([len(t.chains) for t in group])
        for t, run, part in zip(group, runs, parts, strict=True):
            st.write(t.index, t.block, layout.extract(t, run, part))
            bar.advance(t.n_points, int(np.sum(part.status != 0)))


def _run_pool(
    todo: list[Task],
    grid: Grid,
    layout: _Layout,
    st: SweepStore,
    ex: Any,
    fn: Any,
    bar: Any,
    width: int,
) -> None:
    import concurrent.futures as cf

    it = iter(todo)
    inflight: dict[Any, tuple[Task, ChainRun]] = {}

    def submit_next() -> bool:
        t = next(it, None)
        if t is None:
            return False
        run = grid.task_run(t)
        inflight[ex.submit(fn, run)] = (t, run)
        return True

    for _ in range(2 * int(width)):
        if not submit_next():
            break
    try:
        while inflight:
            finished, _ = cf.wait(list(inflight), return_when=cf.FIRST_COMPLETED)
            for fut in finished:
                t, run = inflight.pop(fut)
                res = fut.result()
                st.write(t.index, t.block, layout.extract(t, run, res))
                bar.advance(t.n_points, int(np.sum(res.status != 0)))
                submit_next()
    finally:
        for fut in inflight:
            fut.cancel()


class _Bar:
    """Rich progress bar (points done, points/s, ETA) on stderr; silent when disabled."""

    def __init__(self, enabled: bool, total: int, done: int):
        self.enabled = enabled
        self.total, self.done, self.failed = total, done, 0
        self.t0 = time.perf_counter()
        self.started_at = done
        self._p: Any = None

    def __enter__(self) -> _Bar:
        if self.enabled:
            from rich.console import Console
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeElapsedColumn,
                TimeRemainingColumn,
            )

            self._p = Progress(
                TextColumn("[bold]sweep[/] {task.description}"),
                BarColumn(),
                MofNCompleteColumn(),
                TextColumn("points · {task.fields[rate]} points/s · failed {task.fields[failed]}"),
                TimeElapsedColumn(),
                TextColumn("ETA"),
                TimeRemainingColumn(),
                console=Console(stderr=True),
            )
            self._p.__enter__()
            self._id = self._p.add_task(
                "", total=self.total, completed=self.done, rate="–", failed=0
            )
        return self

    def __exit__(self, *exc: Any) -> None:
        if self._p is not None:
            self._p.__exit__(*exc)

    def describe(self, text: str) -> None:
        if self._p is not None:
            self._p.update(self._id, description=f"({text})")

    def advance(self, n: int, failed: int) -> None:
        self.done += n
        self.failed += failed
        if self._p is not None:
            dt = time.perf_counter() - self.t0
            rate = (self.done - self.started_at) / dt if dt > 0 else 0.0
            self._p.update(self._id, advance=n, rate=f"{rate:.1f}", failed=self.failed)


def _default_observe(target: Any) -> tuple[str, ...]:
    """X̄_sp and X̄'_sp for gear sets; a reference system's first tracked observable and its
    derivative."""
    from ..model.system import System

    if not isinstance(target, System) or hasattr(target.model, "n_planets"):
        return DEFAULT_OBSERVE
    names, nt = target.obs_names, target.n_track
    return (names[0], names[nt]) if len(names) > nt else (names[0],)


def bifurcation(
    target: Any,
    vary: Any,
    *,
    family: Any = None,
    fixed: dict[str, Any] | None = None,
    store: str | os.PathLike[str] | None = None,
    overwrite: bool = False,
    workers: int | None = None,
    scheduler: str | None = None,
    dask_local: int | None = None,
    progress: bool = True,
    **options: Any,
) -> Any:
    """Bifurcation diagram (or 2-D map) data: Poincaré sections over a parameter grid.

    Parameters
    ----------
    target
        A :class:`~gearchaos.gearset.GearSet` or a :class:`~gearchaos.model.System`.
    vary
        One or two axes: ``"omega=0.01:4:800"``, a list of such strings, or a mapping
        ``{"backlash.planet_ring": numpy_array}``. Syntax: ``start:stop:count``,
        ``log:start:stop:count`` or ``a,b,c``.
    family
        One more axis drawn as separate panels (e.g. ``{"xi": [0.03, 0.05, 0.07, 0.09]}``).
    fixed
        Fixed overrides by dotted name, ``omega`` included when it is not swept.
    store
        Path of a Zarr store. Written chunk by chunk; an interrupted sweep (Ctrl-C, SIGTERM,
        SIGKILL) resumes when called again with the same arguments; other settings are refused
        unless ``overwrite``. ``None`` keeps the result in memory.
    workers, scheduler, dask_local
        Executor: N local processes, a ``dask.distributed`` scheduler address, or a local Dask
        cluster of N workers. Default: in-process on all cores. Results are bitwise identical
        whatever the executor.
    progress
        Show a progress bar (points, points/s, ETA) on stderr.
    **options
        The sweep's options (:class:`~gearchaos.sweep.spec.SweepSpec`):

        ``observe``, ``planets``
            Variables of :func:`gearchaos.simulate`'s dataset stored at every section point,
            and the planets of the per-planet ones. Default: X̄_sp1 and X̄'_sp1 (``delta_sp``,
            ``delta_sp_dot``) for gear sets; the first tracked observable and its derivative
            (e.g. ``x``, ``x_dot``) for reference systems.
        ``initial_conditions``, ``direction``
            ``fresh`` (zero state everywhere, the seed's protocol) or ``continuation`` along
            the first varied axis, ``up``, ``down`` or ``both`` (shows hysteresis).
        ``lyapunov``
            Also store the largest Lyapunov exponent ``lle`` of every point (variational
            equations integrated with the trajectory, under the same error control, so section
            values agree with a sweep without it to the tolerance, not bitwise).
        ``transient_periods`` (100), ``periods`` (100), ``rtol``, ``atol``, ``max_steps``
            Protocol and tolerances (:class:`~gearchaos.integrate.settings.SolverSettings`),
            or ``solver=SolverSettings(...)``.

    Returns
    -------
    xarray.Dataset
        Dimensions: (``direction``,) family axis, varied axes, ``section``, ``planet``; per
        point ``status``, step counts, extrema of every mesh deflection and the final state.
        Attributes carry the gear set, the sweep specification, the solver settings and versions.
    """
    if options.get("observe") is None:
        options["observe"] = _default_observe(target)
    spec = SweepSpec.build(vary, family=family, fixed=fixed, **options)
    return run_sweep(
        target,
        spec,
        store=store,
        overwrite=overwrite,
        workers=workers,
        scheduler=scheduler,
        dask_local=dask_local,
        progress=progress,
    )
