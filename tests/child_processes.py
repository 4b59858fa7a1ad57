"""Helpers for tests that start a command and signal or watch it (no fixtures: plain functions).

``tests/`` is on ``sys.path`` (its ``conftest.py``), so any test module imports them by name.
"""

from __future__ import annotations

import signal


def default_sigint() -> None:
    """``preexec_fn`` of a child: SIGINT's default action, as a shell gives a command. A SIGINT
    left ignored in a pytest worker by an earlier test would be inherited, and the child's
    Python then never raises KeyboardInterrupt."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def running(pid: int) -> bool:
    """Whether process ``pid`` exists and is not a zombie (Linux ``/proc``)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split()[2] != "Z"
    except OSError:
        return False
