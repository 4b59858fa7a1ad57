"""Executors: where tasks run. The parent process is always the only writer of the store.

* in-process (default): tasks run here, :func:`~gearchaos.integrate.run_chains` spreads
  chains over all cores on its threads; small tasks are grouped so every call has enough chains;
* ``workers=N``: a pool of N local processes (spawn start method), one numba thread each,
  each ending as soon as its parent is gone, even killed with SIGKILL (:func:`watch_parent`);
* ``scheduler="tcp://host:port"``: an existing ``dask.distributed`` cluster;
* ``dask_local=N``: a ``dask.distributed.LocalCluster`` with N single-threaded workers.

Every executor runs :func:`~gearchaos.integrate.run_chains` on the same numbers with the same
compiled kernel, so results are bitwise identical whatever the executor and the number of
workers.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import functools
import logging
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from .._checks import check_int
from ..errors import ParameterError
from ..integrate._chains import run_chains

__all__ = [
    "EXECUTION_OPTIONS",
    "Execution",
    "InProcess",
    "end_pool",
    "executor",
    "watch_parent",
]


#: Seconds between two looks of a worker at its parent (the portable fallback of the death
#: signal).
PARENT_POLL_SECONDS = 0.5


def watch_parent(parent: int, death_signal: bool = True) -> None:  # pragma: no cover - workers
    """End this worker process as soon as its parent ``parent`` (a pid) is gone, also when
    the parent was killed with SIGKILL and could not end it: no worker outlives its command.

    On Linux the kernel kills it (``prctl(PR_SET_PDEATHSIG, SIGKILL)``, set through ctypes)
    when ``death_signal``: the signal follows the *thread* that started the worker, so it is
    asked for only where that thread lives as long as the pool. Everywhere, a daemon thread
    looks at ``os.getppid()`` every :data:`PARENT_POLL_SECONDS` and ends the process when it
    changed (the orphan was adopted by init or a subreaper); it also covers a parent that died
    before the signal was set. Called first by the initializer of every worker pool."""
    if death_signal and sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)  # 1 = PR_SET_PDEATHSIG
    if os.getppid() != parent:
        os._exit(1)

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(PARENT_POLL_SECONDS)
        os._exit(1)

    threading.Thread(target=watch, name="gearchaos-parent-watch", daemon=True).start()


def _init_worker(parent: int) -> None:  # pragma: no cover - runs in worker processes
    import numba

    watch_parent(parent)
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
def _signals_deferred(insist: bool = True) -> Iterator[None]:
    """Hold Ctrl-C and SIGTERM until the block ends, then raise ``KeyboardInterrupt`` if one
    came: a Dask cluster interrupted while it starts can be neither used nor closed (Dask
    tries again at exit and fails with a traceback). With ``insist`` a second signal is not
    held: whoever insists is not kept waiting by a start that hangs; without, every signal is
    held (a block that ends within a bound, such as :func:`end_pool`)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    came: list[int] = []

    def hold(signum: int, frame: Any) -> None:
        came.append(signum)
        if insist and len(came) > 1:
            raise KeyboardInterrupt(f"signal {signum}")

    old = {s: signal.signal(s, hold) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for s, handler in old.items():
            signal.signal(s, handler)
    if came:
        raise KeyboardInterrupt(f"signal {came[0]}")


@contextlib.contextmanager
def _local_cluster(n: int) -> Iterator[Any]:
    """A client of a local Dask cluster of ``n`` single-threaded worker processes.

    Ctrl-C or SIGTERM while the cluster starts takes effect once it has started (interrupted
    there, Dask can neither use nor close it, and fails again at exit with a traceback). At
    the end, interrupted or not, the workers are ended at once (:func:`_end_cluster`): their
    results are read already, or nobody will read them."""
    from dask.distributed import Client, LocalCluster

    with _signals_deferred():
        cluster = LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            # no dashboard; the scheduler's own HTTP server on a free loopback port (by
            # default it takes :8787 on every interface, and warns when that is taken)
            scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"},
        )
        try:
            client = Client(cluster)
        except BaseException:
            _end_cluster(None, cluster)
            raise
    try:
        yield client
    finally:
        with _signals_deferred():
            _end_cluster(client, cluster)


def _end_cluster(client: Any, cluster: Any) -> None:
    """End a local Dask cluster without waiting for its workers: each nanny is told not to
    restart its worker, the worker process is killed, then the client and the cluster close.
    A graceful close would wait for a worker still in a compiled block (Dask then logs
    "Worker process still alive after 4.0 seconds, killing", the cancelled tasks, and — cut
    short by a second signal — pending asyncio tasks at exit). The scheduler's notice that a
    killed worker's connection closed ("Batched Comm Closed", an INFO record with a traceback,
    logged when the kill lands while the scheduler is sending) is expected here and not
    shown while the cluster ends."""
    batched = logging.getLogger("distributed.batched")
    level = batched.level
    batched.setLevel(logging.WARNING)
    try:
        for nanny in list(cluster.workers.values()):
            nanny.close_gracefully(reason="gearchaos sweep ended")
            pid = nanny.pid
            if pid:
                with contextlib.suppress(OSError):
                    os.kill(pid, signal.SIGKILL)
        if client is not None:
            client.close()
        cluster.close()
    finally:
        batched.setLevel(level)


#: Seconds :func:`end_pool` waits for the killed workers and for the pool's management
#: thread: a bound against a hang only (a killed process is gone at once).
END_BOUND = 60.0


def end_pool(ex: cf.ProcessPoolExecutor) -> None:
    """End a local process pool at once and completely (an interrupted or failed sweep or
    calibration reads none of its results): the calls not started are cancelled, the workers
    are killed (SIGKILL: SIGTERM leaves a worker that handles or ignores it running, and a
    compiled block would only finish for nobody) and reaped, and the pool's management thread
    is joined once it has seen them end, each within :data:`END_BOUND` seconds. Ctrl-C and
    SIGTERM are held meanwhile (:func:`_signals_deferred`; one that came is raised after).

    So nothing is left to Python's exit hooks. A pool only shut down without waiting
    (``shutdown(wait=False)``) leaves its management thread running, and at exit
    ``concurrent.futures``' hook (``_python_exit``) wakes it through a pipe that the thread
    may close at the same moment — that wakeup takes no lock (CPython issues 84176, 125451;
    Python 3.11 has it): "Exception ignored … OSError: handle is closed" after the message —
    then joins it (a worker SIGTERM did not end keeps the exit waiting)."""
    with _signals_deferred(insist=False):
        processes = list((getattr(ex, "_processes", None) or {}).values())
        manager = getattr(ex, "_executor_manager_thread", None)
        ex.shutdown(wait=False, cancel_futures=True)
        for proc in processes:
            with contextlib.suppress(OSError, ValueError):  # gone already, or closed
                proc.kill()
        for proc in processes:
            with contextlib.suppress(OSError, ValueError, AssertionError):
                proc.join(END_BOUND)
        if manager is not None and manager is not threading.current_thread():
            manager.join(END_BOUND)


#: The keyword names of :class:`Execution`.
EXECUTION_OPTIONS = ("workers", "scheduler", "dask_local")


@dataclass(frozen=True)
class Execution:
    """Where the tasks of a sweep run: in-process on all cores (the default), ``workers`` local
    processes, an existing ``dask.distributed`` cluster at ``scheduler``, or a local Dask
    cluster of ``dask_local`` workers — at most one of the three."""

    workers: int | None = None
    scheduler: str | None = None
    dask_local: int | None = None

    def __post_init__(self) -> None:
        chosen = [x is not None for x in (self.workers, self.scheduler, self.dask_local)]
        if sum(chosen) > 1:
            raise ParameterError("choose at most one of workers, scheduler and dask_local")
        if self.workers is not None:
            check_int("workers", self.workers, lo=1, hi=4096)
        if self.dask_local is not None:
            check_int("dask_local", self.dask_local, lo=1, hi=4096)
        if self.scheduler is not None and (
            not isinstance(self.scheduler, str) or "://" not in self.scheduler
        ):
            raise ParameterError(
                f"scheduler must be an address such as tcp://HOST:8786: got {self.scheduler!r}"
            )


@contextlib.contextmanager
def executor(execution: Execution | None = None) -> Iterator[tuple[Any, Any, str]]:
    """Yield (executor, task function, description) for the chosen execution mode."""
    ex_ = execution or Execution()
    single = functools.partial(run_chains, single_thread=True)
    if ex_.workers is not None:
        n = int(ex_.workers)
        ctx = multiprocessing.get_context("spawn")
        # started by this thread's submits, which last as long as the pool: the death signal
        # of watch_parent may follow this thread
        ex = cf.ProcessPoolExecutor(
            max_workers=n, mp_context=ctx, initializer=_init_worker, initargs=(os.getpid(),)
        )
        try:
            yield ex, run_chains, f"{n} local processes"
        except BaseException:
            # interrupted or failed: end the workers now (a clean shutdown would wait for the
            # blocks they compute, seconds of compiled code whose result nobody reads)
            end_pool(ex)
            raise
        ex.shutdown(wait=True)
        return
    if ex_.scheduler is not None or ex_.dask_local is not None:
        try:
            from dask.distributed import Client
        except ImportError as exc:  # pragma: no cover - dask is in [dev] and [dask]
            raise ParameterError(
                "scheduler/dask_local need dask.distributed: pip install 'gearchaos[dask]'"
            ) from exc
        if ex_.scheduler is not None:
            try:
                client = Client(ex_.scheduler, timeout=30)
            except (OSError, TimeoutError, ValueError) as exc:
                raise ParameterError(
                    f"scheduler {ex_.scheduler!r} cannot be reached: {exc}"
                ) from None
            with client:
                yield client.get_executor(), single, f"dask cluster {ex_.scheduler}"
            return
        n = int(ex_.dask_local)  # type: ignore[arg-type]
        with _local_cluster(n) as client:
            yield client.get_executor(), single, f"dask LocalCluster ({n})"
        return
    yield InProcess(), run_chains, "in-process (all cores)"
