"""Ctrl-C and SIGTERM stop long computations at once (issue 23, item 13): compiled kernels run
on daemon threads that nobody has to wait for, a sweep's drivers stop waiting when it is
interrupted, and worker processes are ended instead of finishing their blocks.

Each command would compute for minutes; the test only asks that it ends with exit code 130
well before that, and leaves no worker process behind."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

GEARCHAOS = [sys.executable, "-m", "gearchaos"]


def _children(pid: int) -> list[int]:
    out = subprocess.run(["pgrep", "-P", str(pid)], capture_output=True, text=True).stdout
    return [int(x) for x in out.split()]


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split()[2] != "Z"
    except OSError:
        return False


def _interrupt(
    args: list[str], sig: int, ready: Path | None = None
) -> tuple[int, float, list[int]]:
    proc = subprocess.Popen([*GEARCHAOS, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if ready is None or ready.exists():
            break
        time.sleep(0.2)
    time.sleep(3.0)  # into the computation
    workers = _children(proc.pid)
    t0 = time.monotonic()
    proc.send_signal(sig)
    try:
        proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:  # pragma: no cover - the failure case
            proc.kill()
    return proc.returncode, time.monotonic() - t0, workers


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_ctrl_c_stops_a_single_long_simulation() -> None:
    # `simulate --transient 1e9` ignored Ctrl-C for > 30 s (one point: one compiled call)
    rc, took, _ = _interrupt(
        ["simulate", "--set", "omega=1.5", "--transient", "1e6"], signal.SIGINT
    )
    assert rc == 130
    assert took < 15  # the run itself takes minutes


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
@pytest.mark.parametrize("extra", [[], ["--workers", "2"]])
def test_sigterm_stops_a_sweep_of_long_points(tmp_path: Path, extra: list[str]) -> None:
    # a sweep of long points ignored SIGINT and SIGTERM for > 30 s; with --workers, killed
    # sweeps left 3 workers computing for ~15 s
    store = tmp_path / "long.zarr"
    args = ["bifurcation", "-v", "omega=1:2:4", "--transient", "2e5", "--no-verdicts"]
    rc, took, workers = _interrupt([*args, "-o", str(store), *extra], signal.SIGTERM, store)
    assert rc == 130
    assert took < 15
    time.sleep(1.0)
    assert not [w for w in workers if _alive(w)]
    assert store.exists()  # resumable: the next run computes what is left
