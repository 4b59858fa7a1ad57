"""The threads that run compiled kernels, and how an interrupt stops waiting for them.

Compiled code cannot be stopped once it runs. So that Ctrl-C or SIGTERM still ends a command
within a second — a single point of ``simulate --transient 1e9``, a sweep of long points —
kernels run on **daemon** worker threads (:class:`DaemonPool`), and whoever waits for them waits
in short slices:

* the main thread waits interruptibly, so a signal raises ``KeyboardInterrupt`` there at once;
* any other thread (a sweep's driver) stops waiting as soon as :func:`abandon` was called
  (the sweep calls it when interrupted), with ``KeyboardInterrupt`` too.

The block that is running goes on in its daemon thread until the process exits, which then
does not wait for it. Results are never affected: a block's numbers are the same whichever
thread runs it.

**Readiness.** With the environment variable :data:`READY_ENV` (``GEARCHAOS_READY_LINE``) set
to anything but ``""`` or ``0``, a process writes :data:`READY_LINE` to stderr once, when it
first waits for compiled blocks or runs one on its own thread (:func:`announce_ready`): its
kernels are compiled (or loaded from the cache) and the computation runs, so a signal is
handled at once from there on. A script or a test that must interrupt a computation rather
than its start-up waits for this line, not for a time (a fresh clone compiles for a minute or
more on a loaded machine). Worker processes (local or Dask) inherit the variable and write the
line too.
"""

from __future__ import annotations

import concurrent.futures as cf
import os
import queue
import threading
from typing import Any

__all__ = [
    "READY_ENV",
    "READY_LINE",
    "DaemonPool",
    "abandon",
    "abandoned",
    "announce_ready",
    "pool",
    "resume",
    "wait_all",
]

#: Set when the waits of other threads must end (an interrupted sweep).
_ABANDON = threading.Event()
#: The slice, in seconds, in which a waiting thread looks at :func:`abandoned`.
WAIT_SLICE = 0.1

#: The environment variable that asks for :data:`READY_LINE` (see the module docstring).
READY_ENV = "GEARCHAOS_READY_LINE"
#: The line written to stderr when a process first waits for compiled blocks.
READY_LINE = "gearchaos: kernels ready, computing"
#: The process that wrote the line (a forked child writes its own).
_READY_PID: list[int] = []
_READY_LOCK = threading.Lock()


def announce_ready() -> None:
    """Write :data:`READY_LINE` once per process when :data:`READY_ENV` asks for it; called
    where compiled blocks start (:func:`wait_all`, a driver's or Dask worker's own block)."""
    if os.environ.get(READY_ENV, "") in ("", "0"):
        return
    pid = os.getpid()
    with _READY_LOCK:
        if _READY_PID == [pid]:
            return
        _READY_PID[:] = [pid]
    try:
        os.write(2, f"{READY_LINE}\n".encode())  # unbuffered: seen before the wait begins
    except OSError:
        pass


def abandon() -> None:
    """Make every thread that waits for kernel blocks stop waiting (``KeyboardInterrupt``)."""
    _ABANDON.set()


def resume() -> None:
    """Let threads wait again (a new command or sweep in the same process)."""
    _ABANDON.clear()


def abandoned() -> bool:
    return _ABANDON.is_set()


class DaemonPool:
    """``threads`` daemon worker threads taking calls from one queue (the interface of
    :meth:`concurrent.futures.Executor.submit`): a process that exits never waits for them."""

    def __init__(self, threads: int, name: str = "gearchaos") -> None:
        self._jobs: queue.SimpleQueue[Any] = queue.SimpleQueue()
        for k in range(threads):
            threading.Thread(target=self._work, name=f"{name}-{k}", daemon=True).start()

    def _work(self) -> None:
        while True:
            fn, args, fut = self._jobs.get()
            if not fut.set_running_or_notify_cancel():
                continue
            try:
                fut.set_result(fn(*args))
            except BaseException as exc:  # handed to the waiting thread
                fut.set_exception(exc)

    def submit(self, fn: Any, *args: Any) -> cf.Future[Any]:
        fut: cf.Future[Any] = cf.Future()
        self._jobs.put((fn, args, fut))
        return fut


_POOLS: dict[tuple[int, int], DaemonPool] = {}
_LOCK = threading.Lock()


def pool(threads: int) -> DaemonPool:
    """The process's pool of ``threads`` daemon threads (a pool does not survive a fork)."""
    key = (os.getpid(), int(threads))
    with _LOCK:
        found = _POOLS.get(key)
        if found is None:
            found = _POOLS[key] = DaemonPool(int(threads))
    return found


def wait_all(futures: list[cf.Future[Any]]) -> None:
    """Wait for every future (their exceptions are raised) in slices: a signal interrupts the
    main thread's wait at once, :func:`abandon` any other thread's within a slice; then the
    blocks not yet started are cancelled and ``KeyboardInterrupt`` is raised."""
    main = threading.current_thread() is threading.main_thread()
    announce_ready()
    try:
        pending = set(futures)
        while pending:
            if not main and _ABANDON.is_set():
                raise KeyboardInterrupt
            done, pending = cf.wait(
                pending, timeout=None if main else WAIT_SLICE, return_when=cf.FIRST_EXCEPTION
            )
            for f in done:
                f.result()
    except BaseException:
        for f in futures:
            f.cancel()
        raise
