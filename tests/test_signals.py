"""Ctrl-C and SIGTERM stop long computations at once (issue 23, item 13): compiled kernels run
on daemon threads that nobody has to wait for, a sweep's drivers stop waiting when it is
interrupted, and worker processes are ended instead of finishing their blocks.

Each command would compute for hours; the test asks that it ends with exit code 130 and one
line of message, and leaves no worker process behind. No test waits for a time (issue 35, item
8: a fresh clone compiled its kernels inside a fixed 3 s wait plus a 60 s timeout on a loaded
machine): the command is signalled once it has written the readiness line that the
environment variable ``GEARCHAOS_READY_LINE`` asks for, after its kernels are compiled. The
bounds below only end a test that hangs; they are minutes, far from any normal pace."""

from __future__ import annotations

import contextlib
import os
import queue
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

import child_processes as child
from gearchaos.integrate.threads import READY_ENV, READY_LINE

GEARCHAOS = [sys.executable, "-m", "gearchaos"]
#: Upper bounds (seconds) that only end a hung test: compiling on a loaded machine, stopping.
COMPILE_BOUND = 900.0
STOP_BOUND = 120.0


def _children(pid: int) -> list[int]:
    out = subprocess.run(["pgrep", "-P", str(pid)], capture_output=True, text=True).stdout
    return [int(x) for x in out.split()]


class Command:
    """A gearchaos command in a subprocess, its stderr read line by line as it comes; a
    ``prelude`` (Python source) runs in that process before the command."""

    def __init__(self, args: list[str], prelude: str | None = None):
        env = {**os.environ, READY_ENV: "1"}
        run = GEARCHAOS
        if prelude is not None:
            main = "import runpy; runpy.run_module('gearchaos', run_name='__main__')"
            run = [sys.executable, "-c", f"{prelude}\n{main}"]
        self.proc = subprocess.Popen(
            [*run, *args],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
            start_new_session=True,  # a Ctrl-C of the test run reaches only the test
            # the command starts with Ctrl-C's default action whatever an earlier test left in
            # this worker (an ignored SIGINT is inherited, and Python then never raises
            # KeyboardInterrupt)
            preexec_fn=child.default_sigint,
        )
        self.lines: queue.Queue[str | None] = queue.Queue()
        self.seen: list[str] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.proc.stderr is not None
        for line in self.proc.stderr:
            self.lines.put(line.rstrip("\n"))
        self.lines.put(None)

    def wait_for(self, text: str, bound: float = COMPILE_BOUND) -> None:
        """Block until a line ``text`` arrives; fail if the command ends or hangs first."""
        deadline = time.monotonic() + bound
        while True:
            try:
                line = self.lines.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                self.kill()
                pytest.fail(f"no {text!r} line within {bound:.0f} s: {self.seen}")
            if line is None:
                pytest.fail(f"ended ({self.proc.wait()}) before {text!r}: {self.seen}")
            self.seen.append(line)
            if line == text:
                return

    def finish(self, bound: float = STOP_BOUND) -> tuple[int, list[str]]:
        """(exit code, every stderr line) once the command ends."""
        try:
            self.proc.wait(timeout=bound)
        except subprocess.TimeoutExpired:
            self.kill()
            pytest.fail(f"still running {bound:.0f} s after the signal: {self.seen}")
        self._reader.join()
        while (line := self.lines.get()) is not None:
            self.seen.append(line)
        return self.proc.returncode, self.seen

    def kill(self) -> None:
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()


def _interrupt(
    args: list[str], sig: int, prelude: str | None = None
) -> tuple[int, list[str], list[int]]:
    cmd = Command(args, prelude)
    try:
        cmd.wait_for(READY_LINE)
        workers = _children(cmd.proc.pid)
        cmd.proc.send_signal(sig)
        rc, lines = cmd.finish()
    finally:
        cmd.kill()
    return rc, lines, workers


def _quiet(lines: list[str]) -> list[str]:
    """The lines besides the readiness lines and the first-compile notice: what a user sees
    of the stop."""
    notice = ("compiling numerical kernels", "analysis:", "load them from the cache")
    return [ln for ln in lines if ln.strip() and ln != READY_LINE and not ln.startswith(notice)]


def _all_gone(pids: list[int], bound: float = STOP_BOUND) -> list[int]:
    deadline = time.monotonic() + bound
    while (left := [p for p in pids if child.running(p)]) and time.monotonic() < deadline:
        time.sleep(0.05)
    return left


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_ctrl_c_stops_a_single_long_simulation() -> None:
    # `simulate --transient 1e9` ignored Ctrl-C for > 30 s (one point: one compiled call); the
    # run takes many minutes, so exit 130 within the bound is the signal's doing
    rc, lines, _ = _interrupt(
        ["simulate", "--set", "omega=1.5", "--transient", "2e6", "--no-plot"], signal.SIGINT
    )
    assert rc == 130, lines
    said = _quiet(lines)  # nothing, or one line of message: no traceback, no asyncio dump
    assert len(said) <= 1 and all(ln.startswith("error: interrupted") for ln in said), lines


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
@pytest.mark.parametrize(
    ("extra", "sig"),
    [
        ([], signal.SIGINT),
        (["--workers", "2"], signal.SIGINT),
        ([], signal.SIGTERM),
        (["--dask-local", "2"], signal.SIGINT),
    ],
    ids=["in-process-SIGINT", "workers-SIGINT", "in-process-SIGTERM", "dask-local-SIGINT"],
)
def test_a_signal_stops_a_sweep_of_long_points_quietly(
    tmp_path: Path, extra: list[str], sig: int
) -> None:
    # a sweep of long points ignored SIGINT and SIGTERM for > 30 s; with --workers, killed
    # sweeps left 3 workers computing for ~15 s; issue 35: the message and exit 130 were
    # followed by "Task was destroyed but it is pending!" dumps, and with --dask-local by
    # Dask's "Worker process still alive after 4.0 seconds, killing", cancelled tasks and
    # tracebacks of closed connections
    store = tmp_path / "long.zarr"
    args = ["bifurcation", "-v", "omega=1:2:4", "--transient", "2e6", "--no-verdicts", "-q"]
    rc, lines, workers = _interrupt([*args, "-o", str(store), *extra], sig)
    assert rc == 130, lines
    said = _quiet(lines)
    assert len(said) == 1 and said[0].startswith("error: interrupted"), lines
    assert not _all_gone(workers)
    assert store.exists()  # resumable: the next run computes what is left


#: Makes the wakeup of ``concurrent.futures``' exit hook (``_python_exit``) lose its race with
#: a pool's management thread that still runs at exit: the hook finds the thread's pipe open,
#: the thread closes it, then the hook writes (CPython takes no lock there). Only a pool whose
#: management thread was not joined before the exit hooks can lose.
EXIT_RACE_LOST = """
from concurrent.futures import process

def wakeup(self, real=process._ThreadWakeup.wakeup):
    if process._global_shutdown and not self._closed:
        for thread, other in list(process._threads_wakeups.items()):
            if other is self:
                thread.join()
        self._writer.send_bytes(b"")
    else:
        real(self)

process._ThreadWakeup.wakeup = wakeup
"""
#: Ctrl-C again at the moment an interrupted pool of workers is shut down.
SECOND_SIGNAL = """
import os, signal
from concurrent.futures import ProcessPoolExecutor

def shutdown(self, wait=True, *, cancel_futures=False, real=ProcessPoolExecutor.shutdown):
    if cancel_futures:
        os.kill(os.getpid(), signal.SIGINT)
    real(self, wait, cancel_futures=cancel_futures)

ProcessPoolExecutor.shutdown = shutdown
"""


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
@pytest.mark.parametrize(
    "prelude", [EXIT_RACE_LOST, EXIT_RACE_LOST + SECOND_SIGNAL], ids=["once", "twice"]
)
def test_interrupted_workers_leave_nothing_to_the_exit_hooks(tmp_path: Path, prelude: str) -> None:
    # under load an interrupted `bifurcation --workers 2` printed its one line, then "Exception
    # ignored in atexit callback" and a traceback through concurrent/futures/process.py
    # _python_exit: the pool was shut down without waiting, its management thread left running
    # to the exit hooks, whose wakeup raced the thread closing its pipe. Here the hook loses
    # that race whenever it can, and (twice) Ctrl-C comes again while the pool is ended
    store = tmp_path / "long.zarr"
    args = ["bifurcation", "-v", "omega=1:2:4", "--transient", "2e6", "--no-verdicts", "-q"]
    rc, lines, workers = _interrupt(
        [*args, "-o", str(store), "--workers", "2"], signal.SIGINT, prelude
    )
    assert rc == 130, lines
    said = _quiet(lines)
    assert len(said) == 1 and said[0].startswith("error: interrupted"), lines
    assert not _all_gone(workers)
    assert store.exists()


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_an_interrupted_pool_is_ended_before_the_interrupt_goes_on() -> None:
    # a pool left to the exit hooks fails there (the test above) or, with a worker that
    # SIGTERM does not end, hangs the exit joining it; ended by executor(), nothing is left:
    # no worker, no management thread, its wakeup pipe closed (the exit hook skips it)
    from concurrent.futures import process

    from gearchaos.sweep.execute import Execution, executor

    pids: list[int] = []
    try:
        with pytest.raises(KeyboardInterrupt), executor(Execution(workers=1)) as (ex, _, _):
            # this worker outlives SIGTERM: one that has not ended when the exit hooks run
            ignored = ex.submit(signal.signal, signal.SIGTERM, signal.SIG_IGN)
            assert ignored.result(timeout=COMPILE_BOUND) == signal.SIG_DFL
            ex.submit(time.sleep, 3600.0)
            pids = list(ex._processes)
            manager = ex._executor_manager_thread
            wakeup = process._threads_wakeups[manager]
            raise KeyboardInterrupt
        assert not manager.is_alive()
        assert wakeup._closed
        assert pids and not [p for p in pids if child.running(p)]
    finally:  # the old way left the worker running
        for p in pids:
            with contextlib.suppress(OSError):
                os.kill(p, signal.SIGKILL)
