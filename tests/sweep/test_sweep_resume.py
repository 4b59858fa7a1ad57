"""Interrupted sweeps resume to the uninterrupted result; stores of other settings are refused.

A sweep runs in a subprocess and is stopped at a random moment (seeded) with SIGKILL — no
chance to clean up — or with SIGTERM/SIGINT; the same call run again must finish the store,
recompute nothing already committed, and give exactly the bytes of an uninterrupted run.
"""

from __future__ import annotations

import json
import os
import random
import shutil
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from sweep_helpers import assert_bitwise_equal, file_snapshot, open_store

import gearchaos as gc
from gearchaos.sweep import SweepSpec
from gearchaos.sweep.grid import Grid
from gearchaos.sweep.store import SweepStore

#: A sweep of ~1-3 s of work: long enough to be killed mid-run, short enough for CI.
KILL_SWEEP = {
    "vary": {"omega": "0.2:4:120"},
    "transient_periods": 40,
    "periods": 24,
}

# The default SIGINT handler is restored first: a test run started as a background job of a
# non-interactive shell hands its children SIGINT ignored, as a terminal user's process is not.
SCRIPT = """
import json, signal, sys
signal.signal(signal.SIGINT, signal.default_int_handler)
import gearchaos as gc
kw = json.loads(sys.argv[2])
gc.bifurcation(gc.preset("hindawi2021"), kw.pop("vary"), store=sys.argv[1], progress=False, **kw)
"""


def start(path) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-c", SCRIPT, os.fspath(path), json.dumps(KILL_SWEEP)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )


def wait_for_store(proc: subprocess.Popen, path, timeout: float = 120.0) -> float:
    """Block until the subprocess has created the store directory; return that moment."""
    t0 = time.perf_counter()
    while not os.path.isdir(path):
        if proc.poll() is not None:
            raise AssertionError(f"sweep exited ({proc.returncode}) early:\n{proc.stderr.read()}")
        if time.perf_counter() - t0 > timeout:
            proc.kill()
            raise AssertionError("sweep did not create its store in time")
        time.sleep(0.005)
    return time.perf_counter()


def is_complete(path) -> bool:
    return os.path.isdir(path) and bool(open_store(path).attrs.get("complete"))


def points_written(path) -> int:
    status = open_store(path).status.values  # 4 (not run) is also the fill value: may read NaN
    return int(np.sum(np.isfinite(status) & (status != 4)))


@pytest.fixture(scope="module")
def warm_cache(sheng):
    """Compile (or load) the kernels once so that subprocesses hit numba's on-disk cache."""
    gc.bifurcation(sheng, {"omega": "1,2"}, transient_periods=1, periods=2, progress=False)


@pytest.fixture(scope="module")
def uninterrupted(warm_cache, tmp_path_factory):
    """The reference store, written by the same command, and how long its sweep ran."""
    path = tmp_path_factory.mktemp("resume") / "uninterrupted.zarr"
    proc = start(path)
    t_created = wait_for_store(proc, path)
    assert proc.wait(timeout=300) == 0, proc.stderr.read()
    window = time.perf_counter() - t_created
    ds = open_store(path)
    assert ds.attrs["complete"] is True
    assert np.all(ds.status.values == 0)
    return ds, window


def interrupt(path, sig: int, rng: random.Random, window: float) -> bool:
    """Start the sweep, send ``sig`` after a random delay; True when it stopped mid-run."""
    proc = start(path)
    wait_for_store(proc, path)
    time.sleep(rng.uniform(0.05, 0.9) * window)
    if proc.poll() is None:
        proc.send_signal(sig)
    try:
        proc.wait(timeout=60)  # SIGTERM/SIGINT must stop the sweep promptly
    except subprocess.TimeoutExpired:
        proc.kill()
        raise AssertionError(f"sweep ignored signal {sig}") from None
    return not is_complete(path)


def resume_recording_writes(path, monkeypatch) -> list[int]:
    """Run the same sweep to completion here, recording which tasks it computes."""
    written: list[int] = []
    original = SweepStore.write_tasks

    def write_tasks(self, tasks):
        written.extend(index for index, _, _ in tasks)
        return original(self, tasks)

    monkeypatch.setattr(SweepStore, "write_tasks", write_tasks)
    kw = dict(KILL_SWEEP)
    gc.bifurcation(gc.preset("hindawi2021"), kw.pop("vary"), store=path, progress=False, **kw)
    monkeypatch.undo()
    return written


def n_tasks() -> int:
    kw = dict(KILL_SWEEP)
    return Grid(gc.preset("hindawi2021"), SweepSpec.build(kw.pop("vary"), **kw)).n_tasks


def test_sigkill_at_random_moments_then_resume_equals_uninterrupted(
    uninterrupted, tmp_path, monkeypatch
):
    reference, window = uninterrupted
    rng = random.Random(20240603)
    path = tmp_path / "killed.zarr"
    # 1. kill a fresh run mid-way (retry with other delays if it finished first)
    for _ in range(6):
        if interrupt(path, signal.SIGKILL, rng, window):
            break
        shutil.rmtree(path)
    else:
        pytest.fail("the sweep always finished before SIGKILL; lengthen KILL_SWEEP")
    # interrupted: not complete; it may hold every point when the kill landed after the last
    # task (during the end-of-sweep classification), so only "at most all" is certain
    assert not is_complete(path)
    assert points_written(path) <= reference.status.size
    # 2. the same command again, killed again at a random moment (it may also finish)
    interrupt(path, signal.SIGKILL, rng, window)
    # 3. run to completion; committed tasks must not be computed again
    done_before = SweepStore(path).done_tasks()
    complete_before = is_complete(path)
    written = resume_recording_writes(path, monkeypatch)
    assert len(written) == len(set(written)), "a task was computed twice"
    assert not set(written) & done_before, "committed tasks were recomputed"
    if not complete_before:
        assert set(written) | done_before == set(range(n_tasks())), "tasks lost"
    resumed = open_store(path)
    assert resumed.attrs["complete"] is True
    assert_bitwise_equal(resumed, reference)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_sigterm_and_sigint_stop_the_sweep_and_it_resumes(uninterrupted, tmp_path, sig):
    reference, window = uninterrupted
    rng = random.Random(int(sig))
    path = tmp_path / "stopped.zarr"
    for _ in range(6):
        if interrupt(path, sig, rng, window):
            break
        shutil.rmtree(path)
    else:
        pytest.fail("the sweep always finished before the signal; lengthen KILL_SWEEP")
    kw = dict(KILL_SWEEP)
    gc.bifurcation(gc.preset("hindawi2021"), kw.pop("vary"), store=path, progress=False, **kw)
    assert_bitwise_equal(open_store(path), reference)


def test_killed_while_the_store_is_being_created_resumes(uninterrupted, tmp_path):
    """The first moments of a run (store directory just made, metadata being written)."""
    reference, _ = uninterrupted
    for k, delay in enumerate((0.0, 0.02, 0.05)):
        path = tmp_path / f"early{k}.zarr"
        proc = start(path)
        wait_for_store(proc, path)
        time.sleep(delay)
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=60)
        kw = dict(KILL_SWEEP)
        gc.bifurcation(gc.preset("hindawi2021"), kw.pop("vary"), store=path, progress=False, **kw)
        assert_bitwise_equal(open_store(path), reference)


# --------------------------------------------------------------------------- settings identity

BASE = {"vary": {"omega": "0.5:2.5:5"}, "transient_periods": 10, "periods": 8}


def run(target, path, *, overwrite=False, **changes):
    kw = {**BASE, **changes}
    return gc.bifurcation(
        target, kw.pop("vary"), store=path, overwrite=overwrite, progress=False, **kw
    )


@pytest.fixture()
def base_store(sheng, tmp_path):
    path = tmp_path / "base.zarr"
    run(sheng, path, params={"backlash.sun_planet": 3.0})
    return path


def test_rerun_with_same_settings_changes_no_file(sheng, base_store):
    before = file_snapshot(base_store)
    ds = run(sheng, base_store, params={"backlash.sun_planet": 3.0})
    assert file_snapshot(base_store) == before
    assert_bitwise_equal(ds.load(), open_store(base_store))


@pytest.mark.parametrize(
    ("changes", "named"),
    [
        ({"periods": 9}, "periods"),
        ({"transient_periods": 11}, "transient_periods"),
        ({"rtol": 1e-9}, "rtol"),
        ({"vary": {"omega": "0.5:2.5:6"}}, "omega"),
        (
            {"vary": {"backlash.planet_ring": "2:4:5"}, "params": {"omega": 1.5}},
            "backlash.planet_ring",
        ),
        ({"params": {"backlash.sun_planet": 2.5}}, "backlash.sun_planet"),
        ({"observe": ("delta_sp", "delta_rp")}, "observe"),
        ({"planets": (1, 2)}, "planets"),
    ],
    ids=lambda v: v if isinstance(v, str) else None,
)
def test_other_settings_are_refused_naming_what_differs(sheng, base_store, changes, named):
    before = file_snapshot(base_store)
    changes = {"params": {"backlash.sun_planet": 3.0}, **changes}
    with pytest.raises(gc.StoreError, match="overwrite") as info:
        run(sheng, base_store, **changes)
    assert named in str(info.value)
    assert file_snapshot(base_store) == before, "a refused run modified the store"


def test_another_gear_set_is_refused(sheng, base_store):
    with pytest.raises(gc.StoreError, match=r"mass\.planet"):
        run(sheng.evolve({"mass.planet": 9.0}), base_store, params={"backlash.sun_planet": 3.0})


def test_overwrite_replaces_the_store(sheng, base_store, tmp_path):
    new = {"periods": 9, "params": {"backlash.sun_planet": 2.5}}
    ds = run(sheng, base_store, overwrite=True, **new).load()
    fresh = run(sheng, tmp_path / "fresh.zarr", **new).load()
    assert ds.sizes["section"] == 9
    assert_bitwise_equal(ds, fresh)
    assert_bitwise_equal(open_store(base_store), fresh)


def test_a_directory_that_is_not_a_store_is_never_deleted(sheng, tmp_path):
    path = tmp_path / "results"
    path.mkdir()
    (path / "notes.txt").write_text("precious")
    with pytest.raises((gc.StoreError, gc.ParameterError), match="overwrite"):
        run(sheng, path)
    assert (path / "notes.txt").read_text() == "precious"
