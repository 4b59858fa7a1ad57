"""Issue 23, items 10, 11 and 15: values that were accepted silently, the labels and notices of
an interrupted store, and errors that named nothing."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import gearchaos as gc
from gearchaos.analysis.classify import classify_motion
from gearchaos.dynamics import save_branch
from gearchaos.errors import ParameterError
from gearchaos.model.modal import natural_frequencies
from gearchaos.sweep.store import SweepStore

OSC = gc.backlash_oscillator(1.0, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.2)


def _interrupted(path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A sweep killed after its first task was written (Ctrl-C)."""
    original = SweepStore.write_tasks
    calls = []

    def write_tasks(self, tasks):  # type: ignore[no-untyped-def]
        # the first task of the first write, then Ctrl-C (writes are batched since issue 36)
        if calls:
            raise KeyboardInterrupt
        calls.append(tasks[0][0])
        original(self, tasks[:1])
        if len(tasks) > 1:
            raise KeyboardInterrupt

    monkeypatch.setattr(SweepStore, "write_tasks", write_tasks)
    with pytest.raises(KeyboardInterrupt):
        gc.bifurcation(
            OSC, "omega=0.5:2:120", store=path, transient_periods=3, periods=4, progress=False
        )
    monkeypatch.undo()


def test_an_interrupted_store_says_so_and_its_points_are_not_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # classify labelled the not-run points of an interrupted store "failed" (16 of 24 →
    # 66.7 % failed), and plot/export read it without a word
    store = tmp_path / "run.zarr"
    _interrupted(store, monkeypatch)
    with pytest.warns(UserWarning, match=r"interrupted sweep: \d+ of 120 points are not"):
        ds = gc.open_sweep(store)
    not_run = int(np.sum(ds.status.values == int(gc.Status.NOT_RUN)))
    assert 0 < not_run < 120
    with pytest.warns(UserWarning, match="interrupted sweep"):
        table = gc.sweep.classify_store(store)
    with pytest.warns(UserWarning, match="interrupted sweep"):
        labels = [str(x) for x in gc.open_sweep(store).motion.values]
    # a verdict store keeps its stored labels: a point not run has the empty label, which
    # every reader shows as "not run"; the regime table says "not run", never "failed"
    assert sum(lab in ("", "not run") for lab in labels) == not_run
    assert "failed" not in labels
    # the regime table is over the points computed
    assert sum(table["all"].values()) == pytest.approx(1.0)
    assert "not run" not in table["all"]


def test_values_that_were_accepted_silently_are_refused(tmp_path: Path) -> None:
    with pytest.raises(ParameterError, match=r"rtol must lie in \[1e-14, 0.1\]|rtol"):
        gc.simulate(OSC, omega=1.0, rtol=0.5)
    with pytest.raises(ParameterError, match="rtol must be a finite number in"):
        natural_frequencies(gc.preset("sheng2016-v1"), rtol=float("nan"))
    with pytest.raises(ParameterError, match="min_step <= step <= max_step"):
        gc.continuation(OSC, ("omega", 1.5, 1.6), min_step=0.1, max_step=0.001)
    with pytest.raises(ParameterError, match="save_branch needs a branch dataset"):
        save_branch(xr.Dataset(), tmp_path / "b.nc")
    with pytest.raises(ParameterError, match="save_branch needs a branch dataset"):
        save_branch(None, tmp_path / "b.nc")
    assert not list(tmp_path.iterdir())


def test_errors_name_what_was_wrong() -> None:
    from gearchaos.plot.phase import poincare_map

    with pytest.raises(ParameterError, match="points must be section points"):
        classify_motion("abc")
    with pytest.raises(ParameterError, match="result must be a simulation result"):
        poincare_map(None)


def test_a_status_reads_as_its_name() -> None:
    # issue 24: `res.status` formatted as `0`
    res = gc.simulate(OSC, omega=1.0, transient_periods=2, periods=2)
    assert f"{res.status}" == str(res.status) == "ok"
    assert f"{res.status:d}" == "0" and int(res.status) == 0  # the code where asked for
    assert str(gc.Status.NOT_RUN) == "not_run"
