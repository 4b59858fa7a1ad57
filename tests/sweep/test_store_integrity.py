"""Damaged stores are reported, never read as data; one writer at a time (issue 10).

A complete store carries a manifest of every chunk (size and CRC-32); every reader checks it, so
a deleted chunk (which Zarr would read as its fill value), a truncated or 0-byte chunk (a blosc
error deep in a plot) or junk bytes (wrong numbers) are reported with the chunk's name. A second
process that wants to write a store another one is writing is refused, whatever its options.
"""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from sweep_helpers import SHORT, assert_bitwise_equal, open_store
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app
from gearchaos.errors import StoreError
from gearchaos.sweep.integrity import MANIFEST, StoreLock

KW = {"params": {"xi": 0.05}, "progress": False, **SHORT}


@pytest.fixture(scope="module")
def base_store(tmp_path_factory: pytest.TempPathFactory, sheng: gc.GearSet) -> Path:
    path = tmp_path_factory.mktemp("integrity") / "base.zarr"
    gc.bifurcation(sheng, "omega=0.8:2.4:9", store=path, **KW)
    return path


def _copy(src: Path, dst: Path) -> Path:
    import shutil

    shutil.copytree(src, dst)
    return dst


def _chunk(store: Path, var: str) -> Path:
    files = sorted(p for p in (store / var).iterdir() if not p.name.startswith("."))
    assert files, var
    return files[0]


def test_a_complete_store_lists_every_chunk(base_store: Path) -> None:
    manifest = json.loads((base_store / MANIFEST).read_text())["chunks"]
    on_disk = {
        f"{p.parent.name}/{p.name}"
        for p in base_store.glob("*/*")
        if not p.name.startswith(".") and (p.parent / ".zarray").exists()
    }
    assert set(manifest) == on_disk
    assert not (base_store / "_progress").exists()
    assert not Path(f"{base_store}.lock").exists()


@pytest.mark.parametrize(
    ("damage", "var"),
    [
        ("delete", "delta_sp"),
        ("truncate", "delta_sp"),
        ("empty", "final_state"),
        ("junk", "steps_accepted"),
    ],
)
def test_damaged_chunks_are_reported_by_every_reader(
    base_store: Path, tmp_path: Path, damage: str, var: str
) -> None:
    store = _copy(base_store, tmp_path / "s.zarr")
    chunk = _chunk(store, var)
    data = chunk.read_bytes()
    if damage == "delete":
        chunk.unlink()
    elif damage == "truncate":
        chunk.write_bytes(data[: len(data) // 2])
    elif damage == "empty":
        chunk.write_bytes(b"")
    else:  # same size, other bytes: a silent wrong value without the checksum
        chunk.write_bytes(bytes((b + 1) % 256 for b in data))
    name = f"{var}/{chunk.name}"
    with pytest.raises(StoreError, match=name.replace(".", r"\.")):
        gc.open_sweep(store)
    with pytest.raises(StoreError, match="damaged"):
        gc.sweep.classify_store(store)
    runner = CliRunner()
    for args in (["plot", str(store), "-o", str(tmp_path / "f.png")], ["classify", str(store)]):
        result = runner.invoke(app, args)
        assert result.exit_code == 2, result.output
        assert name in result.stderr and "damaged" in result.stderr
        assert "Traceback" not in result.output
    assert not (tmp_path / "f.png").exists()


def test_junk_metadata_and_foreign_paths_are_store_errors(base_store: Path, tmp_path: Path) -> None:
    store = _copy(base_store, tmp_path / "m.zarr")
    (store / "status" / ".zarray").write_text("{ not json")
    (store / ".zmetadata").unlink()
    with pytest.raises(StoreError, match="not a readable sweep store"):
        gc.open_sweep(store)
    (tmp_path / "empty.zarr").mkdir()
    (tmp_path / "file.zarr").write_text("x")
    for path, words in (
        (tmp_path / "empty.zarr", "no Zarr group"),
        (tmp_path / "file.zarr", "it is a file"),
        (tmp_path / "missing.zarr", "no sweep store"),
    ):
        with pytest.raises(StoreError, match=words):
            gc.open_sweep(path)


def test_labels_keep_their_types(base_store: Path) -> None:
    ds = xr.open_zarr(base_store)
    assert ds.indicators_agree.dtype == np.bool_
    assert ds.period.dtype.kind == "i"
    assert set(np.unique(ds.period.values)) <= set(range(0, 65))
    assert ds.motion.dtype.kind == "U"


def _hold_lock(store: Path) -> subprocess.Popen[str]:
    code = (
        "import sys, time\n"
        "from gearchaos.sweep.integrity import StoreLock\n"
        f"lock = StoreLock({str(store)!r}); lock.acquire()\n"
        "print('locked', flush=True)\n"
        "time.sleep(120)\n"
    )
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert proc.stdout is not None
    assert proc.stdout.readline().strip() == "locked"
    return proc


def test_a_second_writer_is_refused_also_with_overwrite(
    base_store: Path, tmp_path: Path, sheng: gc.GearSet
) -> None:
    store = _copy(base_store, tmp_path / "busy.zarr")
    before = open_store(store)
    proc = _hold_lock(store)
    try:
        for overwrite in (False, True):
            with pytest.raises(StoreError, match=rf"process {proc.pid} on host"):
                gc.bifurcation(sheng, "omega=0.8:2.4:9", store=store, overwrite=overwrite, **KW)
        result = CliRunner().invoke(
            app,
            [
                "bifurcation",
                "--vary",
                "omega=0.8:2.4:9",
                "--set",
                "xi=0.05",
                "--transient",
                str(SHORT["transient_periods"]),
                "--periods",
                str(SHORT["periods"]),
                "--overwrite",
                "-q",
                "-o",
                str(store),
            ],
        )
        assert result.exit_code == 2 and f"process {proc.pid}" in result.stderr
    finally:
        proc.kill()
        proc.wait()
    assert_bitwise_equal(open_store(store), before)  # the refused writers changed nothing


def test_a_stale_lock_is_taken_over(base_store: Path, tmp_path: Path, sheng: gc.GearSet) -> None:
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True
    )
    pid = int(dead.stdout)  # that process has ended
    store = tmp_path / "stale.zarr"
    Path(f"{store}.lock").write_text(
        json.dumps({"pid": pid, "host": socket.gethostname(), "started": time.time()})
    )
    ds = gc.bifurcation(sheng, "omega=0.8:2.4:9", store=store, **KW)
    assert int(np.sum(ds.status.values == 0)) == 9
    assert not Path(f"{store}.lock").exists()
    assert_bitwise_equal(open_store(store), open_store(base_store))


def test_the_lock_names_its_owner(tmp_path: Path) -> None:
    lock = StoreLock(str(tmp_path / "x.zarr"))
    with lock:
        owner = json.loads(Path(lock.path).read_text())
        assert owner["pid"] == os.getpid() and owner["host"] == socket.gethostname()
        with pytest.raises(StoreError, match=f"process {os.getpid()}"):
            StoreLock(str(tmp_path / "x.zarr")).acquire()
    assert not Path(lock.path).exists()


def test_a_damaged_finished_task_is_recomputed_on_resume(
    base_store: Path, tmp_path: Path, sheng: gc.GearSet
) -> None:
    """A store interrupted after some tasks: damage one finished task's chunk; the resume
    recomputes that task (its marker no longer matches) and ends bitwise equal."""
    from gearchaos.integrate import run_chains
    from gearchaos.sweep import SweepSpec
    from gearchaos.sweep.grid import Grid
    from gearchaos.sweep.run import _attrs, _coords, _Layout
    from gearchaos.sweep.store import SweepStore

    spec = SweepSpec.build("omega=0.8:2.4:9", params={"xi": 0.05}, **SHORT)
    grid = Grid(sheng, spec, chunk_points=3)
    layout = _Layout(grid)
    path = tmp_path / "partial.zarr"
    st = SweepStore(str(path))
    variables, chunks = layout.variables()
    st.create(_coords(grid, layout), variables, chunks, _attrs(sheng, grid))
    tasks = list(grid.tasks())
    for t in tasks[:2]:
        run = grid.task_run(t)
        st.write(t.index, t.block, layout.extract(t, run, run_chains(run)))
    assert st.done_tasks() == {tasks[0].index, tasks[1].index}
    victim = _chunk(path, "delta_sp")  # the first task's chunk
    victim.write_bytes(victim.read_bytes()[:10])
    assert st.done_tasks() == {tasks[1].index}
    from gearchaos.sweep.run import run_sweep

    run_sweep(sheng, spec, store=path, progress=False, chunk_points=3)
    ref = tmp_path / "ref.zarr"
    run_sweep(sheng, spec, store=ref, progress=False, chunk_points=3)
    assert_bitwise_equal(open_store(path), open_store(ref))


def test_a_classification_interrupted_before_it_consolidated_is_redone(
    base_store: Path, tmp_path: Path
) -> None:
    """A run killed in its classification (label arrays written, root attributes changed, not
    yet consolidated) is no damage: readers use .zmetadata, the next classification rewrites
    the labels and they equal the uninterrupted ones. Any other unlisted array still is."""
    store = _copy(base_store, tmp_path / "s.zarr")
    zmeta = json.loads((store / ".zmetadata").read_text())
    for key in [k for k in zmeta["metadata"] if k.startswith("contact_rp/")]:
        del zmeta["metadata"][key]  # as if contact_rp had been created after consolidation
    (store / ".zmetadata").write_text(json.dumps(zmeta))
    attrs = json.loads((store / ".zattrs").read_text())
    (store / ".zattrs").write_text(json.dumps({**attrs, "regime_table": "{}"}))
    gc.open_sweep(store)  # read as it was consolidated
    gc.sweep.classify_store(store)
    redone, base = gc.open_sweep(store), gc.open_sweep(base_store)
    for name in ("motion", "period", "contact_sp", "contact_rp"):
        np.testing.assert_array_equal(redone[name].values, base[name].values)
    assert redone.attrs["regime_table"] == base.attrs["regime_table"]
    other = _copy(base_store, tmp_path / "o.zarr")
    zmeta = json.loads((other / ".zmetadata").read_text())
    for key in [k for k in zmeta["metadata"] if k.startswith("steps_accepted/")]:
        del zmeta["metadata"][key]
    (other / ".zmetadata").write_text(json.dumps(zmeta))
    with pytest.raises(StoreError, match="steps_accepted"):
        gc.open_sweep(other)
