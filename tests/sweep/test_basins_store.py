"""The basin store: resumable like a sweep store, equal on every executor, with provenance."""

from __future__ import annotations

import json

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.errors import StoreError
from gearchaos.sweep.store import SweepStore

#: a small twin-well image in several tasks (chunk_points: 3 rows of 8 starts per task)
ARGS = ("x=-1.8:1.8:8", "x_dot=-1.8:1.8:8")
KW = {"transient_periods": 40, "periods": 8, "progress": False, "chunk_points": 24}
VARIABLES = ("attractor", "label", "status", "steps_accepted", "final_state")


def twin_well():
    return gc.duffing(1.2, delta=0.25, alpha=-1.0, beta=1.0, gamma=0.1)


@pytest.fixture(scope="module")
def whole():
    return gc.basins(twin_well(), *ARGS, **KW).load()


def assert_same(a, b):
    for name in VARIABLES:
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
    assert json.loads(a.attrs["attractors"]) == json.loads(b.attrs["attractors"])


def test_store_records_every_parameter_and_the_version(whole, tmp_path):
    ds = gc.basins(twin_well(), *ARGS, **KW, store=tmp_path / "b.zarr")
    assert_same(ds, whole)
    a = ds.attrs
    assert a["complete"] is True and a["kind"] == "basins"
    assert a["version"] == gc.__version__ and "numba_version" in a
    assert a["transient_periods"] == 40 and a["periods"] == 8 and "rtol" in a
    assert "Duffing(delta=0.25" in a["model_parameters"] and a["omega"] == 1.2
    spec = json.loads(a["basin_spec"])
    assert spec["x"][0] == "x" and len(spec["x"][1]) == 8 and spec["sample"] == 32
    assert ds["attractor"].dims == ("x_dot", "x")
    assert not (tmp_path / "b.zarr" / "_attractors.json").exists()  # moved into the attributes


def test_interrupted_then_resumed_equals_uninterrupted(whole, tmp_path, monkeypatch):
    path = tmp_path / "run.zarr"
    original, calls = SweepStore.write, []

    def write_then_stop(self, task_index, block, data):
        original(self, task_index, block, data)
        calls.append(task_index)
        if len(calls) == 2:
            raise KeyboardInterrupt

    monkeypatch.setattr(SweepStore, "write", write_then_stop)
    with pytest.raises(KeyboardInterrupt):
        gc.basins(twin_well(), *ARGS, **KW, store=path)
    monkeypatch.undo()
    assert (path / "_attractors.json").exists()  # the catalogue so far, for the resume
    with pytest.warns(UserWarning, match="interrupted basin computation"):
        part = gc.sweep.basins.open_basins(path)
    assert np.sum(part["attractor"].values == -1) == 64 - 2 * 24
    resumed = gc.basins(twin_well(), *ARGS, **KW, store=path)
    assert_same(resumed, whole)


def test_other_settings_are_refused_and_overwrite_replaces(tmp_path):
    path = tmp_path / "b.zarr"
    gc.basins(twin_well(), *ARGS, **KW, store=path)
    with pytest.raises(StoreError, match=r"other settings.*transient_periods"):
        gc.basins(twin_well(), *ARGS, **{**KW, "transient_periods": 41}, store=path)
    ds = gc.basins(twin_well(), *ARGS, **{**KW, "transient_periods": 41}, store=path,
                   overwrite=True)  # fmt: skip
    assert ds.attrs["transient_periods"] == 41
    (tmp_path / "foreign").mkdir()
    with pytest.raises(StoreError, match="not a gearchaos basin store"):
        gc.basins(twin_well(), *ARGS, **KW, store=tmp_path / "foreign")


def test_local_processes_and_dask_give_the_same_store(whole, tmp_path):
    assert_same(gc.basins(twin_well(), *ARGS, **KW, workers=2), whole)
    pytest.importorskip("dask.distributed")
    assert_same(gc.basins(twin_well(), *ARGS, **KW, store=tmp_path / "d.zarr", dask_local=2), whole)


def test_fractions_resume_and_executors(tmp_path):
    system = gc.duffing(1.0, delta=0.3, alpha=-1.0, beta=1.0, gamma=0.0)
    kw = {"starts": 30, "box": {"x": (-1.5, 1.5), "x_dot": (-1.5, 1.5)}, "chunk_points": 30,
          "transient_periods": 40, "periods": 8, "progress": False}  # fmt: skip
    whole = gc.basin_fractions(system, "delta=0.3:0.5:3", **kw)
    dask = gc.basin_fractions(system, "delta=0.3:0.5:3", **kw, store=tmp_path / "f.zarr",
                              workers=2)  # fmt: skip
    for name in ("attractor", "initial_state", "fraction", "fraction_low", "count"):
        np.testing.assert_array_equal(dask[name].values, whole[name].values)
    assert whole["initial_state"].dims == ("delta", "start", "state")
    # common random numbers: the same starts at every value
    np.testing.assert_array_equal(
        whole["initial_state"].values[0], whole["initial_state"].values[2]
    )
