"""Compiling a kernel in another thread leaves the process's warning state alone.

``tests/sweep/test_keyword_vocabulary.py::…old_spellings_warn[bifurcation]`` failed now and
then under ``pytest -n 2`` ("DID NOT WARN") and passed alone: ``_numba.entry_point`` wrapped
the compile in ``warnings.catch_warnings()``, which puts back on exit the process-wide state
it saved on entry. A sweep interrupted by an earlier test in the same worker
(``test_sweep_orbits``, ``test_sweep_validation_23``, ``test_basins_store`` stop one with
KeyboardInterrupt) leaves its driver threads running; one that was compiling put back that
earlier test's state in the middle of the later test's ``pytest.warns``, and the warning went
to the stale recorder.
"""

from __future__ import annotations

import threading
import warnings
from typing import Any

import numpy as np
import pytest

from gearchaos import _numba


class _SlowDispatcher:
    """A dispatcher whose compile waits to be released, as a long compile in a driver thread."""

    def __init__(self) -> None:
        self.entered = threading.Event()
        self.release = threading.Event()

    def compile(self, sig: Any) -> object:
        self.entered.set()
        assert self.release.wait(30)
        return object()


def test_a_compile_ending_in_another_thread_keeps_the_warnings_recorded_meanwhile(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(_numba, "_ENTRIES", {})
    slow = _SlowDispatcher()
    with warnings.catch_warnings():  # the state of an earlier test, when the compile began
        thread = threading.Thread(
            target=_numba.entry_point, args=(slow, 0, np.zeros(1)), daemon=True
        )
        thread.start()
        assert slow.entered.wait(30)
    with pytest.warns(DeprecationWarning, match="the later test's warning"):
        slow.release.set()  # the compile ends inside the later block
        thread.join(30)
        warnings.warn("the later test's warning", DeprecationWarning, stacklevel=1)
    assert not thread.is_alive()
