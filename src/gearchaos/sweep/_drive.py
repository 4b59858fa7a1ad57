"""How a sweep's tasks are run and written: in this process, on driver threads that overlap one
group's Python work with another's integration (:func:`run_in_process`), or on a pool of
workers or a Dask cluster (:func:`run_pool`); each finished task is written to the store,
which marks it done (:meth:`~gearchaos.sweep.store.SweepStore.write_tasks`)."""

from __future__ import annotations

import contextlib
import itertools
import time
from collections.abc import Iterator
from typing import Any

import numpy as np

from ..integrate._chains import ChainRun
from ..integrate.threads import abandon, resume
from .grid import Grid, Task
from .store import SweepStore

__all__ = ["WRITE_SECONDS", "run_in_process", "run_pool"]


def _groups(todo: list[Task], want: int) -> Iterator[list[Task]]:
    """Consecutive tasks of equal chain length, grouped until a group has ``want`` chains."""
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
        yield group


#: Seconds between the writes of an in-process sweep's finished tasks.
WRITE_SECONDS = 0.5

#: Driver threads of an in-process sweep: each integrates and extracts (verdicts included) one
#: group of tasks, so one group's Python work overlaps another's integration.
_DRIVERS = 3


def run_in_process(
    todo: list[Task], grid: Grid, layout: Any, st: SweepStore, fn: Any, bar: Any
) -> None:
    """Run the groups of tasks here: driver threads each integrate a group (on the kernel's
    threads) and extract it (the verdicts included), while this thread writes the finished
    tasks in order, together every :data:`WRITE_SECONDS` (one assignment per variable: each
    costs about a millisecond, and this thread's writes take the interpreter from the
    drivers) and at the end. An interrupt or a failed group writes the finished tasks first
    and loses at most the groups in flight, a kill also the last :data:`WRITE_SECONDS`'
    tasks; everything written stays."""
    import collections
    import concurrent.futures as cf

    import numba

    def compute(group: list[Task]) -> list[tuple[Task, dict[str, np.ndarray], int]]:
        runs = [grid.task_run(t) for t in group]
        res = fn(ChainRun.concat(runs))
        parts = res.split([len(t.chains) for t in group])
        return [
            (t, layout.extract(t, run, part), int(np.sum(part.status != 0)))
            for t, run, part in zip(group, runs, parts, strict=True)
        ]

    groups = _groups(todo, 2 * numba.get_num_threads())
    width = _DRIVERS
    driver = cf.ThreadPoolExecutor(width, thread_name_prefix="gearchaos-sweep")
    pending: collections.deque[cf.Future[Any]] = collections.deque()
    finished: list[tuple[Task, dict[str, np.ndarray], int]] = []
    written, writing = time.monotonic(), False

    def write() -> None:
        nonlocal written, writing
        writing = True
        st.write_tasks([(t.index, t.block, data) for t, data, _ in finished])
        writing = False
        for t, _, failed in finished:
            bar.advance(t.n_points, failed)
        finished.clear()
        written = time.monotonic()

    resume()
    try:
        for group in itertools.islice(groups, width):
            pending.append(driver.submit(compute, group))
        while pending:
            finished.extend(pending.popleft().result())
            nxt = next(groups, None)
            if nxt is not None:
                pending.append(driver.submit(compute, nxt))
            if not pending or time.monotonic() - written >= WRITE_SECONDS:
                write()
    except BaseException:
        abandon()  # the drivers stop waiting for their blocks: the process can exit at once
        if finished and not writing:  # what was computed is kept (a failed write is not redone)
            with contextlib.suppress(Exception):
                write()
        raise
    finally:
        driver.shutdown(wait=False, cancel_futures=True)


def run_pool(
    todo: list[Task],
    grid: Grid,
    layout: Any,
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
