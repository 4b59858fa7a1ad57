"""A test run ends every process it starts: a session-end check that fails the run otherwise.

The controlling pytest process marks the environment with a fresh token; every process the
tests start inherits it (subprocesses, spawned multiprocessing and Dask workers, the explorer's
server), also when it outlives its parent and is re-parented to init. When the session ends
(after pytest-xdist has stopped its workers), any process still carrying the token, or still a
descendant of this one, is listed, terminated, and the run fails. Loaded by ``conftest.py``;
``-p process_guard`` loads it into any pytest run (its own test does that).
"""

from __future__ import annotations

import os
import signal
import time
import uuid
from collections.abc import Iterator

import pytest

#: The environment variable that carries the session's token.
TOKEN = "GEARCHAOS_TEST_SESSION"
#: Seconds a process may take to end after the session (xdist workers closing, a server
#: answering SIGTERM) before it counts as left running.
GRACE = float(os.environ.get("GEARCHAOS_PROCESS_GRACE", "15"))


def pytest_configure(config: pytest.Config) -> None:
    if hasattr(config, "workerinput"):  # an xdist worker: it inherited the controller's token
        return
    os.environ[TOKEN] = f"{os.getpid()}-{uuid.uuid4().hex}"
    config.stash[_OWNER] = os.environ[TOKEN]


_OWNER = pytest.StashKey[str]()


def _proc(pid: int, name: str) -> bytes:
    with open(f"/proc/{pid}/{name}", "rb") as f:
        return f.read()


def _pids() -> Iterator[int]:
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            yield int(entry)


def _parent_and_state(pid: int) -> tuple[int, str]:
    stat = _proc(pid, "stat").decode(errors="replace")
    fields = stat[stat.rindex(")") + 2 :].split()
    return int(fields[1]), fields[0]


def survivors(token: str, root: int) -> dict[int, str]:
    """Live processes (not zombies) other than ``root`` that carry ``token`` in their
    environment or descend from ``root``: {pid: command line}."""
    marker = f"{TOKEN}={token}".encode()
    parents: dict[int, int] = {}
    found: dict[int, str] = {}
    for pid in _pids():
        if pid == root:
            continue
        try:
            parent, state = _parent_and_state(pid)
            if state == "Z":
                continue
            parents[pid] = parent
            if marker in _proc(pid, "environ").split(b"\0"):
                found[pid] = ""
        except (OSError, ValueError, IndexError):
            continue  # ended meanwhile, or not ours to read
    for pid in parents:
        seen, p = set(), pid
        while p in parents and p not in seen:
            seen.add(p)
            p = parents[p]
            if p == root:
                found[pid] = ""
                break
    for pid in list(found):
        try:
            found[pid] = _proc(pid, "cmdline").replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            del found[pid]
            continue
        if parents.get(pid) == root and "multiprocessing.resource_tracker" in found[pid]:
            # the resource tracker of this very process: it ends when this process does
            # (its pipe closes), after the check; one whose parent is gone is a leak
            del found[pid]
    return found


@pytest.hookimpl(trylast=True)
def pytest_sessionfinish(session: pytest.Session) -> None:
    token = session.config.stash.get(_OWNER, None)
    if token is None or not os.path.isdir("/proc/self"):
        return
    deadline = time.monotonic() + GRACE
    left = survivors(token, os.getpid())
    while left and time.monotonic() < deadline:
        time.sleep(0.2)
        left = survivors(token, os.getpid())
    if not left:
        return
    lines = [f"  pid {pid}: {cmd.strip()[:200]}" for pid, cmd in sorted(left.items())]
    for sig in (signal.SIGTERM, signal.SIGKILL):
        for pid in left:
            try:
                os.kill(pid, sig)
            except OSError:
                pass
        time.sleep(1.0)
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    text = f"the tests left {len(left)} process(es) running (now terminated):\n" + "\n".join(lines)
    if reporter is not None:
        reporter.write_sep("=", "processes left running", red=True)
        reporter.write_line(text)
    else:
        print(text)
    session.exitstatus = pytest.ExitCode.TESTS_FAILED
