"""No process outlives its command, and no killed writer's temporaries outlive a rerun
(issue 33).

``kill -9`` of ``gearchaos bifurcation --workers 2`` left its worker processes (and the
resource tracker they keep alive) running in 8 of 10 trials, still alive a minute later: a
worker blocked on its task queue, or computing, never learnt that its parent was gone. Each
worker now has the kernel kill it when its parent dies (Linux: ``PR_SET_PDEATHSIG``) and
watches its parent's pid as a portable fallback.

A killed ``continue -o b.zarr`` left its hidden staging directory ``.b.zarr.*.partial``
beside the output, which the successful rerun kept. Temporaries now carry their writer's
host and pid, and a rerun removes those whose writer no longer runs — never one a running
writer still fills.

Each case waits for a readiness signal (the workers visible and a task written; a writer's
temporary on disk), never for a fixed time, and bounds every wait generously for a loaded
CI machine. Whatever happens, the test ends every process it started.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest
from fuzz_helpers import COUNTS

pytestmark = pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="reads /proc (Linux)")

#: Seconds any wait may take (a loaded CI machine); the conditions come in seconds.
BOUND = 120.0

#: A sweep far longer than the wait for its first task: 4 points a task, 200 points.
SWEEP = ["bifurcation", "--workers", "2", "--vary", "omega=0.5:3.5:200", "--transient", "300",
         "--periods", "50", "-o", "run.zarr"]  # fmt: skip

#: A short continuation of the default gear set, written as a Zarr branch.
CONTINUE = ["continue", "--vary", "omega=3.3:3.45", "-o", "b.zarr"]


def _stat(pid: int) -> tuple[int, str] | None:
    """(parent pid, state) of a process, or None when it is gone."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    fields = text[text.rindex(")") + 2 :].split()
    return int(fields[1]), fields[0]


def _alive(pid: int) -> bool:
    st = _stat(pid)
    return st is not None and st[1] != "Z"


def _children(pid: int) -> set[int]:
    out = set()
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            st = _stat(int(entry))
            if st is not None and st[0] == pid and st[1] != "Z":
                out.add(int(entry))
    return out


def _cmdline(pid: int) -> bytes:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return b""


def _wait(ready: Callable[[], bool], what: str, proc: subprocess.Popen[str], log: Path) -> None:
    deadline = time.monotonic() + BOUND
    while not ready():
        if proc.poll() is not None:
            raise AssertionError(f"the command ended before {what}: {log.read_text()}")
        if time.monotonic() > deadline:
            raise AssertionError(f"no {what} after {BOUND} s")
        time.sleep(0.05)


def _end(pids: set[int]) -> None:
    for pid in pids:
        if _alive(pid):
            os.kill(pid, signal.SIGKILL)


def _gearchaos(args: list[str], cwd: Path, **kw: object) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [sys.executable, "-m", "gearchaos", *args], cwd=cwd, text=True,
        env={**os.environ, "COLUMNS": "1000"}, **kw,  # type: ignore[call-overload]
    )  # fmt: skip


def test_kill_9_of_a_sweep_with_workers_leaves_no_process(tmp_path: Path) -> None:
    log = tmp_path / "stderr.txt"
    with log.open("w") as err:
        proc = _gearchaos(SWEEP, tmp_path, stdout=subprocess.DEVNULL, stderr=err)
    tree: set[int] = set()
    try:
        # ready: both workers started, and a task they computed is written
        workers = lambda: {p for p in _children(proc.pid) if b"spawn_main" in _cmdline(p)}  # noqa: E731
        markers = tmp_path / "run.zarr" / "_progress"
        _wait(
            lambda: len(workers()) >= 2 and markers.is_dir() and any(markers.iterdir()),
            "two workers with a task written",
            proc,
            log,
        )
        tree = _children(proc.pid)  # the workers and the resource tracker they keep alive
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=BOUND)
        deadline = time.monotonic() + BOUND
        while {p for p in tree if _alive(p)} and time.monotonic() < deadline:
            time.sleep(0.1)
        left = {p: _cmdline(p)[:120] for p in tree if _alive(p)}
        if left:
            COUNTS["bifurcation --workers 2 kill -9 [orphans]"] += 1
        assert not left, f"processes outlived their killed parent by {BOUND} s: {left}"
    finally:
        if proc.poll() is None:
            tree |= _children(proc.pid)
            proc.kill()
            proc.wait(timeout=BOUND)
        _end(tree)


#: A writer of the branch store b.zarr, killed inside its staged write (what a kill -9 of
#: `continue -o b.zarr` while it writes leaves), or, with "wait", kept running in it.
WRITER = """
import os, signal, sys
from gearchaos._output import staged_dir
with staged_dir("b.zarr", what="branch store") as tmp:
    with open(os.path.join(tmp, ".zgroup"), "w") as f:
        f.write("{}")
    print(tmp, flush=True)
    if sys.argv[1] == "kill":
        os.kill(os.getpid(), signal.SIGKILL)
    sys.stdin.read()  # until the test closes it
    raise SystemExit("not finished: the staged write is removed")
"""


def _writer(cwd: Path, how: str) -> tuple[subprocess.Popen[str], Path]:
    proc = subprocess.Popen(
        [sys.executable, "-c", WRITER, how], cwd=cwd, text=True,
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
    )  # fmt: skip
    assert proc.stdout is not None
    line = proc.stdout.readline().strip()  # the readiness signal: the temporary exists
    assert line, proc.stderr.read() if proc.stderr else ""
    return proc, Path(line)


def test_a_rerun_removes_what_a_killed_writer_left_and_keeps_a_live_ones(tmp_path: Path) -> None:
    killed, stale = _writer(tmp_path, "kill")
    killed.wait(timeout=BOUND)
    assert killed.returncode == -signal.SIGKILL
    for stream in (killed.stdin, killed.stdout, killed.stderr):
        if stream is not None:
            stream.close()
    assert stale.is_dir() and stale.name.startswith(".b.zarr.")
    older = tmp_path / ".b.zarr.abcd1234.partial"  # an older version's name: no pid in it
    older.mkdir()
    live, running = _writer(tmp_path, "wait")
    try:
        rerun = _gearchaos(CONTINUE, tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        _, err = rerun.communicate(timeout=BOUND)
        assert rerun.returncode == 0, err
        assert (tmp_path / "b.zarr").is_dir()
        assert not stale.exists(), "the killed writer's staging directory outlived the rerun"
        assert running.is_dir(), "a running writer's staging directory was removed"
        assert older.is_dir(), "a temporary whose writer is unknown was removed"
    finally:
        live.communicate(timeout=BOUND)  # closes stdin: the writer ends, removing its own
    assert not running.exists()
