"""The in-process driver of a sweep (``gearchaos.sweep._drive``): finished tasks are written
together, and an interrupt writes the finished ones before it ends the sweep."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.sweep import _drive
from gearchaos.sweep.run import _Layout
from gearchaos.sweep.store import SweepStore

OSC = gc.backlash_oscillator(1.0, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.6)
ARGS = (OSC, "omega=0.5:2:48")
KW = {"transient_periods": 3, "periods": 4, "progress": False}


def test_an_interrupt_writes_the_finished_tasks_first(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Nothing is written before the end (WRITE_SECONDS is huge), and the last task's
    extraction is interrupted (Ctrl-C): every task finished before it is in the store with its
    marker, the last is not, and resuming gives the uninterrupted sweep."""
    whole = gc.bifurcation(*ARGS, **KW)
    path = tmp_path / "run.zarr"
    monkeypatch.setattr(_drive, "WRITE_SECONDS", 1e9)
    extract = _Layout.extract
    last: list[int] = []

    def interrupted(self, task, run, res):  # type: ignore[no-untyped-def]
        if not last:
            last.append(self.grid.n_tasks - 1)
        if task.index == last[0]:
            raise KeyboardInterrupt
        return extract(self, task, run, res)

    monkeypatch.setattr(_Layout, "extract", interrupted)
    with pytest.raises(KeyboardInterrupt):
        gc.bifurcation(*ARGS, store=path, **KW)
    monkeypatch.undo()
    done = SweepStore(path).done_tasks()
    assert done and last[0] not in done  # the finished tasks were kept, the interrupted not
    with pytest.warns(UserWarning, match="interrupted sweep"):
        part = gc.open_sweep(path)
    ran = part.status.values != int(gc.Status.NOT_RUN)
    np.testing.assert_array_equal(part.x.values[ran], whole.x.values[ran])
    resumed = gc.bifurcation(*ARGS, store=path, **KW)
    np.testing.assert_array_equal(resumed.x.values, whole.x.values)
    assert [str(m) for m in resumed.motion.values] == [str(m) for m in whole.motion.values]
