"""Never lose a user's file, never store wrong data as valid (issue 23): the overwrite rule,
the one staged write, full disks, planted links, the store lock and hostile chunk files.

Full-disk cases mount a small tmpfs, which needs root; they are skipped cleanly elsewhere.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import subprocess
import threading
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest

import gearchaos as gc
from gearchaos._output import file_has_mark, staged_file, write_file
from gearchaos.dynamics import open_branch, save_branch
from gearchaos.errors import StoreError
from gearchaos.sweep.integrity import StoreLock
from gearchaos.sweep.store import is_sweep_store

OSC = gc.backlash_oscillator(1.0, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.2)
QUICK = {"transient_periods": 5, "periods": 4, "progress": False}


def _sweep(path: Path, overwrite: bool = False):
    return gc.bifurcation(OSC, "omega=0.8:1.2:3", store=path, overwrite=overwrite, **QUICK)


def _branch():
    return gc.continuation(OSC, ("omega", 1.5, 1.6), max_points=4)


@contextlib.contextmanager
def _small_disk(tmp_path: Path, size: str) -> Iterator[Path]:
    """A tmpfs of ``size`` mounted under tmp_path (root only; skipped otherwise)."""
    mnt = tmp_path / "disk"
    mnt.mkdir()
    if os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip("a small tmpfs needs root")
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(mnt)])
    if r.returncode != 0:
        pytest.skip("this machine cannot mount a tmpfs")
    try:
        yield mnt
    finally:
        subprocess.run(["umount", "-l", str(mnt)], check=False)


def _fill(disk: Path, leave: int) -> None:
    """Fill ``disk`` until about ``leave`` bytes are free."""
    free = os.statvfs(disk).f_bavail * os.statvfs(disk).f_frsize
    if free > leave:
        with contextlib.suppress(OSError), open(disk / "ballast", "wb") as f:
            f.write(b"\0" * (free - leave))


# ------------------------------------------------------------------------- overwrite rule
def test_overwrite_never_deletes_a_directory_gearchaos_did_not_write(tmp_path: Path) -> None:
    # `bifurcation -o results_dir --overwrite` deleted results_dir/sub/notes.txt
    foreign = tmp_path / "results_dir"
    (foreign / "sub").mkdir(parents=True)
    (foreign / "sub" / "notes.txt").write_text("a month of notes")
    with pytest.raises(StoreError, match="not a gearchaos sweep store: it is never replaced"):
        _sweep(foreign, overwrite=True)
    assert (foreign / "sub" / "notes.txt").read_text() == "a month of notes"
    # a store the user put a file into is no longer only gearchaos's: refused too
    store = tmp_path / "run.zarr"
    _sweep(store)
    assert is_sweep_store(str(store))
    (store / "chapter1").mkdir()
    (store / "chapter1" / "draft.tex").write_text(r"\chapter{}")
    assert not is_sweep_store(str(store))
    with pytest.raises(StoreError, match="not a sweep store gearchaos wrote"):
        _sweep(store, overwrite=True)
    assert (store / "chapter1" / "draft.tex").exists()
    # a genuine store is replaced
    (store / "chapter1" / "draft.tex").unlink()
    (store / "chapter1").rmdir()
    ds = _sweep(store, overwrite=True)
    assert ds.sizes["omega"] == 3
    # and a symbolic link to a store is never written through
    link = tmp_path / "alias.zarr"
    link.symlink_to(store)
    with pytest.raises(StoreError, match="symbolic link"):
        _sweep(link, overwrite=True)
    assert is_sweep_store(str(store))


def test_a_branch_overwrite_replaces_only_a_branch(tmp_path: Path) -> None:
    # `continue -o thesis.zarr --overwrite` deleted thesis.zarr/chapter1/draft.tex
    br = _branch()
    thesis = tmp_path / "thesis.zarr"
    (thesis / "chapter1").mkdir(parents=True)
    (thesis / "chapter1" / "draft.tex").write_text("text")
    with pytest.raises(StoreError, match="not a zarr branch file gearchaos wrote"):
        save_branch(br, thesis, overwrite=True)
    assert (thesis / "chapter1" / "draft.tex").read_text() == "text"
    paper = tmp_path / "paper.nc"
    paper.write_bytes(b"\x89HDF\r\n\x1a\n someone else's data")
    with pytest.raises(StoreError, match="not a netcdf branch file gearchaos wrote"):
        save_branch(br, paper, overwrite=True)
    assert paper.read_bytes().endswith(b"someone else's data")
    for name in ("b.nc", "b.zarr"):
        save_branch(br, tmp_path / name)
        save_branch(br, tmp_path / name, overwrite=True)  # its own: replaced
        assert open_branch(tmp_path / name).sizes == br.sizes
    assert not [p for p in tmp_path.iterdir() if "partial" in p.name]


def test_concurrent_branch_writers_leave_one_complete_branch(tmp_path: Path) -> None:
    # two `continue -o b.nc --overwrite` at once left a b.nc with omega and every multiplier
    # 0 (both used the fixed name b.nc.partial): each writer now has its own temporary
    short, long = _branch(), gc.continuation(OSC, ("omega", 1.5, 1.7), max_points=6)
    target = tmp_path / "b.nc"
    errors: list[BaseException] = []

    def write(ds) -> None:
        try:
            for _ in range(5):
                save_branch(ds, target, overwrite=True)
        except BaseException as exc:  # pragma: no cover - reported below
            errors.append(exc)

    threads = [threading.Thread(target=write, args=(ds,)) for ds in (short, long)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    got = open_branch(target)
    assert any(got.sizes == ds.sizes for ds in (short, long))
    omega = got[str(got.attrs["parameter"])].values
    assert np.all(omega >= 1.5) and np.all(np.isfinite(got.multiplier_re.values))
    assert [p.name for p in tmp_path.iterdir()] == ["b.nc"]


def test_figures_and_exports_replace_only_their_own_files(tmp_path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from gearchaos.plot import savefig

    fig = plt.figure()
    for suffix in (".png", ".pdf", ".svg"):
        out = tmp_path / f"f{suffix}"
        savefig(fig, out)
        assert file_has_mark(str(out))
        savefig(fig, out)  # its own figure: replaced
        photo = tmp_path / f"holiday{suffix}"
        photo.write_bytes(b"not drawn by us")
        with pytest.raises(StoreError, match="not a figure gearchaos wrote"):
            savefig(fig, photo)
        assert photo.read_bytes() == b"not drawn by us"
    plt.close(fig)
    store = tmp_path / "run.zarr"
    _sweep(store)
    csv = tmp_path / "run.csv"
    gc.export(store, csv)
    gc.export(store, csv)  # its own export: replaced
    sheet = tmp_path / "budget.csv"
    sheet.write_text("a,b\n1,2\n")
    with pytest.raises(StoreError, match="not a export gearchaos wrote"):
        gc.export(store, sheet)
    assert sheet.read_text() == "a,b\n1,2\n"


def test_a_planted_link_at_the_old_temporary_names_is_never_followed(tmp_path: Path) -> None:
    # a symlink at out/simulation.nc.partial or f.png.partial made simulate/plot overwrite
    # the link's target
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    out = tmp_path / "out"
    out.mkdir()
    for name in ("simulation.nc.partial", ".simulation.nc.partial"):
        (out / name).symlink_to(victim)
    res = gc.simulate(OSC, omega=1.0, transient_periods=2, periods=2)
    res.save(out / "simulation.nc")
    res.save(out / "simulation.nc")  # its own file: replaced
    assert victim.read_text() == "precious"
    assert gc.open_simulation(out / "simulation.nc").attrs["title"].startswith("gearchaos")
    # and a branch file is not a simulation file
    save_branch(_branch(), tmp_path / "b.nc")
    with pytest.raises(StoreError, match=r"not a gearchaos simulation file.*open_branch"):
        gc.open_simulation(tmp_path / "b.nc")


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path: Path) -> None:
    target = tmp_path / "x.json"
    target.write_text("old")
    with pytest.raises(RuntimeError), staged_file(str(target), what="record") as tmp:
        Path(tmp).write_text("half")
        raise RuntimeError("killed")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["x.json"]
    write_file(str(target), b"new", what="record")
    assert target.read_text() == "new"
    assert (target.stat().st_mode & 0o777) == 0o644 or os.geteuid() != 0


# ----------------------------------------------------------------------------- full disk
def test_a_full_disk_is_a_clear_error_that_loses_nothing(tmp_path: Path) -> None:
    with _small_disk(tmp_path, "256k") as disk:
        # a simulation file (netCDF writers crashed here) and a branch
        res = gc.simulate(OSC, omega=1.0, transient_periods=2, periods=400)
        out = disk / "out"
        out.mkdir()
        keep = out / "simulation.nc"
        small = gc.simulate(OSC, omega=1.0, transient_periods=2, periods=2)
        small.save(keep)
        before = keep.read_bytes()
        _fill(disk, 16 * 1024)
        with pytest.raises(StoreError, match="no space left on device"):
            res.save(keep)
        assert keep.read_bytes() == before  # the old file is intact
        with pytest.raises(StoreError, match="no space left on device"):
            save_branch(gc.continuation(OSC, ("omega", 1.5, 1.9), max_points=40), disk / "b.nc")
        assert not [p for p in disk.rglob("*") if "partial" in p.name]
        # init-gearset --force keeps its old file whole
        (disk / "ballast").unlink()
        gs_file = disk / "g.toml"
        from typer.testing import CliRunner

        from gearchaos.cli import app

        assert CliRunner().invoke(app, ["init-gearset", str(gs_file)]).exit_code == 0
        before = gs_file.read_bytes()
        _fill(disk, 1024)
        r = CliRunner().invoke(app, ["init-gearset", str(gs_file), "--force"])
        assert r.exit_code != 0 and "no space left on device" in r.output
        assert gs_file.read_bytes() == before


def test_a_sweep_on_a_full_disk_leaves_no_lock_and_no_half_store(tmp_path: Path) -> None:
    # after running out of disk an empty r.zarr.lock blocked the next sweep for 60 s and
    # *.creating-PID directories were left behind
    with _small_disk(tmp_path, "4m") as disk:
        _fill(disk, 64 * 1024)
        with pytest.raises(StoreError, match="no space left on device"):
            _sweep(disk / "r.zarr")
        # what is left is the store (resumable: a task without its marker is recomputed),
        # no lock and no temporary
        assert sorted(p.name for p in disk.iterdir()) in (["ballast"], ["ballast", "r.zarr"])
        (disk / "ballast").unlink()
        done = _sweep(disk / "r.zarr")  # at once, no stale lock
        want = _sweep(tmp_path / "ref.zarr")
        np.testing.assert_array_equal(done.x.values, want.x.values)


def test_classify_on_a_full_disk_leaves_the_store_whole(tmp_path: Path) -> None:
    with _small_disk(tmp_path, "2m") as disk:
        store = disk / "run.zarr"
        _sweep(store)
        want = gc.open_sweep(store)
        _fill(disk, 0)
        with pytest.raises(StoreError):
            gc.sweep.classify_store(store)
        again = gc.open_sweep(store)  # every chunk still there, every check passes
        np.testing.assert_array_equal(again.motion.values, want.motion.values)
        (disk / "ballast").unlink()
        gc.sweep.classify_store(store)  # and it can be classified once there is space
        assert not [p for p in disk.iterdir() if "partial" in p.name]


# ---------------------------------------------------------------------------------- lock
def test_one_lock_per_store_whatever_its_spelling(tmp_path: Path) -> None:
    store = tmp_path / "run.zarr"
    store.mkdir()
    alias = tmp_path / "alias.zarr"
    alias.symlink_to(store)
    with StoreLock(str(store)):
        for spelling in (str(alias), str(store) + "/", os.path.relpath(store)):
            with pytest.raises(StoreError, match="is being written by process"):
                StoreLock(spelling).acquire()


def test_an_empty_lock_left_by_a_full_disk_does_not_block(tmp_path: Path) -> None:
    store = tmp_path / "run.zarr"
    lock = StoreLock(str(store))
    Path(lock.path).write_text("")  # what a full disk left behind (an owner never written)
    with lock:
        owner = json.loads(Path(lock.path).read_text())
        assert owner["pid"] == os.getpid()
    assert not Path(lock.path).exists()
    assert not [p for p in tmp_path.iterdir() if "partial" in p.name]


# ------------------------------------------------------------------------ hostile chunks
@pytest.mark.parametrize("kind", ["dev_zero", "fifo", "link"])
def test_a_chunk_that_is_no_regular_file_is_damage(tmp_path: Path, kind: str) -> None:
    # a chunk linked to /dev/zero got every reader OOM-killed; a FIFO hung them
    store = tmp_path / "run.zarr"
    _sweep(store)
    chunk = next(p for p in sorted((store / "x").iterdir()) if not p.name.startswith("."))
    chunk.unlink()
    if kind == "dev_zero":
        chunk.symlink_to("/dev/zero")
    elif kind == "fifo":
        os.mkfifo(chunk)
    else:
        other = tmp_path / "elsewhere"
        other.write_bytes(b"\0" * 64)
        chunk.symlink_to(other)
    with pytest.raises(StoreError, match=r"chunk x/\S+ cannot be read"):
        gc.open_sweep(store)


# --------------------------------------------------------------- damage read as data (4, 14)
def _edit_array_meta(store: Path, name: str, **changes: object) -> None:
    """Edit an array's metadata consistently in .zarray and .zmetadata (a careful forger)."""
    zarray = store / name / ".zarray"
    meta = {**json.loads(zarray.read_text()), **changes}
    zarray.write_text(json.dumps(meta))
    zmeta = json.loads((store / ".zmetadata").read_text())
    zmeta["metadata"][f"{name}/.zarray"] = meta
    (store / ".zmetadata").write_text(json.dumps(zmeta))


@pytest.mark.parametrize(
    ("changes", "words"),
    [
        ({"dtype": ">f8"}, "element type '>f8'"),
        ({"order": "F"}, "memory order 'F'"),
        ({"fill_value": 0.0}, "fill value 0.0"),
        ({"compressor": None}, "compressor None"),
    ],
)
def test_consistently_edited_metadata_is_damage(
    tmp_path: Path, changes: dict[str, object], words: str
) -> None:
    # plot, export and explore wrote garbage with exit 0 from such a store
    store = tmp_path / "run.zarr"
    _sweep(store)
    _edit_array_meta(store, "x", **changes)
    with pytest.raises(StoreError, match=f"the array x has the {words}"):
        gc.open_sweep(store)
    with pytest.raises(StoreError, match=f"the array x has the {words}"):
        _sweep(store)  # never resumed into


def test_a_complete_store_without_its_manifest_is_damage(tmp_path: Path) -> None:
    # deleting _manifest.json switched chunk verification off: a deleted chunk was then
    # plotted and exported as NaN with exit 0
    store = tmp_path / "run.zarr"
    _sweep(store)
    (store / "_manifest.json").unlink()
    with pytest.raises(StoreError, match=r"chunk manifest _manifest\.json is missing"):
        gc.open_sweep(store)
    with pytest.raises(StoreError, match=r"chunk manifest _manifest\.json is missing"):
        _sweep(store)
    assert _sweep(store, overwrite=True).sizes["omega"] == 3  # a damaged store of ours


def test_junk_metadata_is_reported_not_a_traceback(tmp_path: Path) -> None:
    # resume into a store with junk .zattrs/.zmetadata ended in a JSONDecodeError
    for name in (".zattrs", ".zmetadata"):
        store = tmp_path / f"run{name}.zarr"
        _sweep(store)
        (store / name).write_text("{not json")
        with pytest.raises(StoreError, match="not readable"):
            _sweep(store)


def test_command_line_paths_that_failed_with_a_traceback(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from gearchaos.cli import app

    r = CliRunner().invoke(app, ["simulate", "--set", "omega=1.5", "--transient", "1e-320"])
    assert r.exit_code != 0 and "transient_periods must be 0 or at least 1e-06" in r.output
    assert isinstance(r.exception, SystemExit)  # a clean exit, not a traceback
    long = tmp_path / ("a" * 305 + ".toml")
    r = CliRunner().invoke(app, ["init-gearset", str(long)])
    assert r.exit_code != 0 and "File name too long" in r.output
    assert isinstance(r.exception, SystemExit)


# ------------------------------------------------ every writer: foreign paths, concurrency
def _writers(tmp_path: Path):
    """(name, write(path), output path) for every kind of output a command writes."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from gearchaos.plot import savefig

    store = tmp_path / "src.zarr"
    _sweep(store)
    res = gc.simulate(OSC, omega=1.0, transient_periods=2, periods=3)
    br = _branch()
    fig = plt.figure()
    return [
        ("sweep store", lambda p: _sweep(p, overwrite=True), "run.zarr"),
        ("branch file", lambda p: save_branch(br, p, overwrite=True), "b.nc"),
        ("branch store", lambda p: save_branch(br, p, overwrite=True), "b.zarr"),
        ("simulation file", lambda p: res.save(p), "simulation.nc"),
        ("figure", lambda p: savefig(fig, p), "f.png"),
        ("export", lambda p: gc.export(store, p), "x.csv"),
    ]


def test_no_writer_replaces_a_path_that_is_not_its_own_output(tmp_path: Path) -> None:
    # the property: whatever the writer, a foreign file or directory at its output path is
    # refused and left byte for byte as it was
    for name, write, target in _writers(tmp_path):
        for kind in ("file", "dir"):
            path = tmp_path / f"{kind}-{target}"
            if kind == "file":
                path.write_bytes(b"the user's own bytes")
            else:
                path.mkdir()
                (path / "keep.txt").write_text("keep")
            with pytest.raises((StoreError, gc.ParameterError)):
                write(path)
            if kind == "file":
                assert path.read_bytes() == b"the user's own bytes", name
            else:
                assert (path / "keep.txt").read_text() == "keep", name
    assert not [p for p in tmp_path.rglob("*") if "partial" in p.name]


def test_concurrent_writers_of_one_output_leave_one_complete_result(tmp_path: Path) -> None:
    # two `simulate -o` into one directory failed both in 3 of 5; `plot -o` to one file
    # failed on the rename of f.png.partial: each writer now has its own temporary
    for name, write, target in _writers(tmp_path):
        if name == "sweep store":
            continue  # one writer at a time by its lock (test_one_lock_per_store_...)
        path = tmp_path / f"both-{target}"
        errors: list[BaseException] = []

        def run(write=write, path=path, errors=errors) -> None:  # type: ignore[no-untyped-def]
            try:
                for _ in range(3):
                    write(path)
            except BaseException as exc:  # pragma: no cover - reported below
                errors.append(exc)

        threads = [threading.Thread(target=run) for _ in range(2)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert not errors, (name, errors)
        assert path.exists(), name
    assert open_branch(tmp_path / "both-b.nc").sizes
    assert gc.open_simulation(tmp_path / "both-simulation.nc").attrs["title"]
    assert file_has_mark(str(tmp_path / "both-f.png"))
    assert not [p for p in tmp_path.rglob("*") if "partial" in p.name]


def _other_writer_at(
    monkeypatch: pytest.MonkeyPatch, target: Path, moment: str, write: Callable[[], None]
) -> list[str]:
    """Make ``write`` (another writer of ``target``) run whole at one moment of the next
    replace of ``target``: ``"in"`` just before the rename of a new directory onto it,
    ``"aside"`` just after the rename of what was there away from it — the two moments where
    a concurrent writer met ``Directory not empty`` under load. Returns the list that records
    that it ran."""
    real = os.rename
    fired: list[str] = []
    want = os.path.abspath(target)

    def rename(src, dst, *args, **kwargs):  # type: ignore[no-untyped-def]
        if fired:
            return real(src, dst, *args, **kwargs)
        if moment == "in" and os.path.abspath(dst) == want:
            fired.append(moment)
            write()
        elif moment == "aside" and os.path.abspath(src) == want:
            real(src, dst, *args, **kwargs)
            fired.append(moment)
            write()
            return None
        return real(src, dst, *args, **kwargs)

    monkeypatch.setattr(os, "rename", rename)
    return fired


@pytest.mark.parametrize(("moment", "existing"), [("in", False), ("in", True), ("aside", True)])
def test_a_writer_replacing_a_directory_meets_the_other_writer_s_new_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, moment: str, existing: bool
) -> None:
    # under load one `continue -o b.zarr` failed with "cannot write branch store …: Directory
    # not empty": between its two renames (the old store aside, its own in) the other writer
    # put its store in. The interleaving is forced here, the same in every run
    short, long = _branch(), gc.continuation(OSC, ("omega", 1.5, 1.7), max_points=6)
    target = tmp_path / "b.zarr"
    if existing:
        save_branch(short, target)
    fired = _other_writer_at(
        monkeypatch, target, moment, lambda: save_branch(short, target, overwrite=True)
    )
    save_branch(long, target, overwrite=True)
    monkeypatch.undo()
    assert fired == [moment]
    got = open_branch(target)  # complete: every chunk in its manifest, every digest right
    assert got.sizes == long.sizes  # the writer that renamed last holds the path
    np.testing.assert_array_equal(got.multiplier_re.values, long.multiplier_re.values)
    assert [p.name for p in tmp_path.iterdir()] == ["b.zarr"]  # nothing aside, no temporary


@pytest.mark.parametrize("moment", ["in", "aside"])
def test_replace_dir_leaves_exactly_the_last_directory(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, moment: str
) -> None:
    from gearchaos._output import replace_dir

    target, trash = tmp_path / "out", tmp_path / "trash"
    for d, text in ((target, "old"), (tmp_path / "a", "a"), (tmp_path / "b", "b")):
        d.mkdir()
        (d / "data").write_text(text)
    trash.mkdir()
    fired = _other_writer_at(
        monkeypatch,
        target,
        moment,
        lambda: replace_dir(str(tmp_path / "b"), str(target), str(trash / "b")),
    )
    (trash / "b").mkdir()
    replace_dir(str(tmp_path / "a"), str(target), str(trash))
    monkeypatch.undo()
    assert fired == [moment]
    assert (target / "data").read_text() == "a"
    # everything replaced went into the trash of the writer that moved it, nothing is lost
    moved = sorted(p.read_text() for p in trash.rglob("data"))
    assert moved == ["b", "old"]
