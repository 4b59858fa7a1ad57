"""Executors: where tasks run. The parent process is always the only writer of the store.

* in-process (default): tasks run here, the compiled kernel's ``numba.prange`` spreads chains
  over all cores; small tasks are grouped so every call has enough chains;
* ``workers=N``: a pool of N local processes (spawn start method), one numba thread each;
* ``scheduler="tcp://host:port"``: an existing ``dask.distributed`` cluster;
* ``dask_local=N``: a ``dask.distributed.LocalCluster`` with N single-threaded workers.

Every executor runs :func:`run_task_arrays` on the same numbers with the same compiled kernel,
so results are bitwise identical whatever the executor and the number of workers.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import multiprocessing
from collections.abc import Iterator
from typing import Any

import numpy as np

__all__ = ["executor", "run_task_arrays"]


def run_task_arrays(a: dict[str, Any], single_thread: bool = False) -> dict[str, np.ndarray]:
    """Run one task's chains with the compiled chain kernel; returns the raw outputs."""
    from .._numba import call_literal
    from ..integrate.dopri import dopri_chains

    if single_thread:
        import numba

        numba.set_num_threads(1)
    P = a["P"]
    C, L = P.shape[0], P.shape[1]
    ns, no, nt = a["n_samples"], a["n_obs"], a["n_track"]
    n = a["Y0"].shape[1]  # system state, then tangent vectors when Lyapunov exponents are asked
    out_y = np.full((C, L, ns, n), np.nan)
    out_o = np.full((C, L, ns, no), np.nan)
    omin = np.zeros((C, L, nt))
    omax = np.zeros((C, L, nt))
    yf = np.zeros((C, L, n))
    info = np.zeros((C, L, 4))
    status = np.zeros((C, L), dtype=np.int64)
    k = int(a.get("n_tangent", 0))
    lsum = np.zeros((C, L, k))
    call_literal(
        dopri_chains,
        a["kind"],
        a["Y0"],
        P,
        a["SW"],
        a["t_rec"],
        a["dt"],
        ns,
        a["t_end"],
        no,
        nt,
        a["n_state"],
        a["rtol"],
        a["atol"],
        np.inf,
        a["max_steps"],
        a["continuation"],
        out_y,
        out_o,
        omin,
        omax,
        yf,
        info,
        status,
        lsum,
    )
    return {
        "states": out_y,
        "observables": out_o,
        "obs_min": omin,
        "obs_max": omax,
        "final_state": yf,
        "info": info,
        "status": status,
        # exponents: log stretch per unit τ over the samples after the first
        "lyapunov": lsum / ((ns - 1) * a["dt"])[:, :, None] if ns > 1 else lsum * np.nan,
    }


def _single_thread_task(a: dict[str, Any]) -> dict[str, np.ndarray]:
    return run_task_arrays(a, single_thread=True)


def _init_worker() -> None:  # pragma: no cover - runs in worker processes
    import numba

    numba.set_num_threads(1)


class InProcess:
    """Runs tasks here, one after another (each call parallel over its chains)."""

    def submit(self, fn: Any, arg: Any) -> cf.Future[Any]:
        fut: cf.Future[Any] = cf.Future()
        try:
            fut.set_result(fn(arg))
        except BaseException as exc:
            fut.set_exception(exc)
            if isinstance(exc, KeyboardInterrupt):
                raise
        return fut


@contextlib.contextmanager
def executor(
    workers: int | None = None, scheduler: str | None = None, dask_local: int | None = None
) -> Iterator[tuple[Any, Any, str]]:
    """Yield (executor, task function, description) for the chosen execution mode."""
    from ..errors import ParameterError

    chosen = [x is not None for x in (workers, scheduler, dask_local)]
    if sum(chosen) > 1:
        raise ParameterError("choose at most one of workers, scheduler and dask_local")
    if workers is not None:
        if int(workers) < 1:
            raise ParameterError(f"workers must be >= 1: got {workers!r}")
        ctx = multiprocessing.get_context("spawn")
        with cf.ProcessPoolExecutor(
            max_workers=int(workers), mp_context=ctx, initializer=_init_worker
        ) as ex:
            yield ex, run_task_arrays, f"{int(workers)} local processes"
        return
    if scheduler is not None or dask_local is not None:
        try:
            from dask.distributed import Client, LocalCluster
        except ImportError as exc:  # pragma: no cover - dask is in [dev] and [dask]
            raise ParameterError(
                "scheduler/dask_local need dask.distributed: pip install 'gearchaos[dask]'"
            ) from exc
        if scheduler is not None:
            with Client(scheduler) as client:
                yield client.get_executor(), _single_thread_task, f"dask cluster {scheduler}"
            return
        if int(dask_local) < 1:  # type: ignore[arg-type]
            raise ParameterError(f"dask_local must be >= 1: got {dask_local!r}")
        with (
            LocalCluster(
                n_workers=int(dask_local),  # type: ignore[arg-type]
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
            ) as cluster,
            Client(cluster) as client,
        ):
            yield client.get_executor(), _single_thread_task, f"dask LocalCluster ({dask_local})"
        return
    yield InProcess(), run_task_arrays, "in-process (all cores)"
