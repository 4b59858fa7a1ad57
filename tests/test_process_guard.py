"""The session-end process check fails a run that leaves a process behind, and passes one
that does not (run as separate pytest sessions in a scratch directory)."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent

LEAK = """
import subprocess, sys

def test_leaves_a_detached_sleeper():
    # a grandchild re-parented to init, as a killed server leaves its spawned worker
    subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"],
                     start_new_session=True)
"""

CLEAN = """
import subprocess, sys

def test_waits_for_its_child():
    subprocess.run([sys.executable, "-c", "pass"], check=True)
"""


def _run(tmp_path: Path, code: str) -> subprocess.CompletedProcess[str]:
    (tmp_path / "test_case.py").write_text(code, encoding="utf-8")
    (tmp_path / "pytest.ini").write_text("[pytest]\n", encoding="utf-8")
    env = {
        **os.environ,
        "GEARCHAOS_PROCESS_GRACE": "1",
        "PYTHONPATH": f"{HERE}{os.pathsep}{os.environ.get('PYTHONPATH', '')}",
    }
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "process_guard", "-p", "no:cacheprovider",
         "-p", "no:xdist", "test_case.py"],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120,
    )  # fmt: skip


def _sleepers() -> list[int]:
    out = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                cmd = Path(f"/proc/{entry}/cmdline").read_bytes()
            except OSError:
                continue
            if b"time.sleep(120)" in cmd and b"import time" in cmd:
                state = Path(f"/proc/{entry}/stat").read_text().rsplit(")", 1)[1].split()[0]
                if state != "Z":
                    out.append(int(entry))
    return out


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="reads /proc (Linux)")
def test_a_leaked_process_fails_the_run_and_is_ended(tmp_path: Path) -> None:
    before = set(_sleepers())
    proc = _run(tmp_path, LEAK)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "1 passed" in proc.stdout
    assert "left 1 process(es) running" in proc.stdout
    assert "time.sleep(120)" in proc.stdout
    deadline = time.monotonic() + 10
    while set(_sleepers()) - before and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not set(_sleepers()) - before, "the guard did not end the leaked process"


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="reads /proc (Linux)")
def test_a_clean_run_passes(tmp_path: Path) -> None:
    proc = _run(tmp_path, CLEAN)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "left" not in proc.stdout
