"""Hangs and endless reads in place of a store's files (issue 33).

A FIFO in place of a store's ``.zattrs``, ``.zarray``, ``.zmetadata`` or ``_manifest.json``
hung ``plot``, ``export`` and ``bifurcation`` until they were killed; a FIFO lock file hung
``bifurcation``, and a lock linked to ``/dev/zero`` was read until a ``MemoryError``. Every
file gearchaos reads from a store or a lock is now the regular file itself, opened without
blocking and read up to a size cap, and a store holding anything but regular files and
directories is refused before Zarr (which opens files plainly) reads it.

Each case runs the command line in its own process, bounded by :data:`TIMEOUT` (generous for
a loaded CI machine) and by :data:`MEMORY` of address space, and must end with exit code 2 and
an ``error:`` line naming the culprit, with nothing written and nothing left running. The
readers, which take no lock, are not stopped by a strange lock file. The lock cases are also
run in-process through the store's lock (:class:`~gearchaos.sweep.integrity.StoreLock`), where
the fuzz harness's alarm bounds a blocking open.
"""

from __future__ import annotations

import os
import resource
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from fuzz_helpers import COUNTS, refused

from gearchaos.sweep.integrity import StoreLock, read_json

pytestmark = pytest.mark.skipif(
    not hasattr(os, "mkfifo") or not os.path.exists("/dev/zero"), reason="needs FIFOs (POSIX)"
)

#: Seconds a command may take before it counts as hung (it answers in seconds).
TIMEOUT = 120
#: Bytes of address space of a command (a read of /dev/zero ends in MemoryError, not swap).
MEMORY = 6 << 30

#: A small sweep of the default gear set, written and resumed by the same command.
SWEEP = ["bifurcation", "--vary", "omega=1.2:2.0:3", "--transient", "5", "--periods", "4"]


def _limit() -> None:  # pragma: no cover - runs in the child before exec
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY, MEMORY))


def gearchaos(args: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    """``gearchaos ARGS`` in its own process; a run past :data:`TIMEOUT` fails the test (the
    process is killed)."""
    env = {**os.environ, "COLUMNS": "1000", "NUMBA_NUM_THREADS": "2"}
    try:
        return subprocess.run(
            [sys.executable, "-m", "gearchaos", *args],
            cwd=cwd, env=env, capture_output=True, text=True, timeout=TIMEOUT,
            preexec_fn=_limit,
        )  # fmt: skip
    except subprocess.TimeoutExpired:
        COUNTS[f"{args[0]} [hang]"] += 1
        pytest.fail(f"gearchaos {' '.join(args)} hung for {TIMEOUT} s")


def assert_refused(entry: str, proc: subprocess.CompletedProcess[str], *culprits: str) -> None:
    """Exit code 2, no traceback, an ``error:`` line naming every culprit."""
    COUNTS[entry] += 1
    err = proc.stderr
    assert "Traceback" not in err, f"{entry}: a traceback:\n{err}"
    assert proc.returncode == 2, f"{entry}: exit {proc.returncode}\n{proc.stdout}\n{err}"
    lines = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert len(lines) == 1, f"{entry}: {err!r}"
    for culprit in culprits:
        assert culprit in lines[0], f"{entry}: {culprit!r} not in {lines[0]!r}"


@pytest.fixture(scope="module")
def base(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A complete store written by :data:`SWEEP` (so that the same command resumes it)."""
    root = tmp_path_factory.mktemp("fifo")
    proc = gearchaos([*SWEEP, "-o", "base.zarr"], root)
    assert proc.returncode == 0, proc.stderr
    return root / "base.zarr"


def _copy(base: Path, where: Path) -> Path:
    store = where / "run.zarr"
    shutil.copytree(base, store)
    return store


def fifo(path: Path) -> None:
    path.parent.mkdir(exist_ok=True)  # a task marker: its directory is gone once complete
    path.unlink(missing_ok=True)
    os.mkfifo(path)


def dev_zero(path: Path) -> None:
    path.parent.mkdir(exist_ok=True)
    path.unlink(missing_ok=True)
    path.symlink_to("/dev/zero")


def link_to_copy(path: Path) -> None:
    """A symbolic link to a copy of the same file: gearchaos never writes one in a store."""
    outside = next(p for p in path.parents if p.name == "run.zarr").parent
    copy = outside / f"copy-of-{path.parent.name}-{path.name}"
    shutil.copyfile(path, copy)
    path.unlink()
    path.symlink_to(copy)


PLACED: dict[str, Callable[[Path], None]] = {
    "fifo": fifo,
    "dev_zero": dev_zero,
    "link": link_to_copy,
}

#: The store's files gearchaos or Zarr read: root metadata, the manifest, arrays' metadata.
FILES = [".zattrs", ".zgroup", ".zmetadata", "_manifest.json", "omega/.zarray",
         "delta_sp/.zattrs", "status/.zarray"]  # fmt: skip

CASES = [
    *[("plot", "fifo", f) for f in FILES],
    *[("export", "fifo", f) for f in (".zattrs", "_manifest.json", "delta_sp/.zarray")],
    *[("bifurcation", "fifo", f) for f in (".zattrs", "_manifest.json", "omega/.zarray")],
    ("bifurcation", "fifo", "_progress/0.done"),
    ("bifurcation", "dev_zero", "_progress/1.done"),
    ("plot", "dev_zero", ".zattrs"),
    ("export", "dev_zero", "_manifest.json"),
    ("plot", "link", "delta_sp/.zarray"),
]


def _command(command: str, store: Path) -> list[str]:
    if command == "plot":
        return ["plot", store.name, "-o", "run.png"]
    if command == "export":
        return ["export", store.name, "-o", "run.csv"]
    return [*SWEEP, "-o", store.name]  # the same sweep again: a resume


@pytest.mark.parametrize(("command", "kind", "name"), CASES)
def test_a_store_file_that_is_no_regular_file_is_refused_at_once(
    base: Path, tmp_path: Path, command: str, kind: str, name: str
) -> None:
    store = _copy(base, tmp_path)
    PLACED[kind](store / name)
    before = sorted(p.name for p in tmp_path.iterdir())
    proc = gearchaos(_command(command, store), tmp_path)
    assert_refused(f"{command} with {kind} {name}", proc, "run.zarr", name, "damaged")
    assert sorted(p.name for p in tmp_path.iterdir()) == before, "something was written"


# ------------------------------------------------------------------------------- the lock
def _lock_fifo(lock: Path) -> None:
    os.mkfifo(lock)


def _lock_dev_zero(lock: Path) -> None:
    lock.symlink_to("/dev/zero")


def _lock_directory(lock: Path) -> None:
    lock.mkdir()


LOCKS: dict[str, Callable[[Path], None]] = {
    "fifo": _lock_fifo,
    "dev_zero": _lock_dev_zero,
    "directory": _lock_directory,
}


def _kind(lock: Path) -> str:
    if lock.is_symlink():
        return "link"
    if lock.is_dir():
        return "directory"
    return "fifo" if not lock.is_file() else "file"


@pytest.mark.parametrize("kind", sorted(LOCKS))
@pytest.mark.parametrize("resume", [False, True], ids=["new", "resume"])
def test_a_lock_that_is_no_regular_file_is_refused_by_the_writer(
    base: Path, tmp_path: Path, kind: str, resume: bool
) -> None:
    store = _copy(base, tmp_path) if resume else tmp_path / "run.zarr"
    lock = Path(f"{os.path.realpath(store)}.lock")
    LOCKS[kind](lock)
    expected = _kind(lock)
    proc = gearchaos([*SWEEP, "-o", store.name], tmp_path)
    assert_refused(f"bifurcation with a {kind} lock", proc, str(lock))
    assert _kind(lock) == expected, "the lock was replaced"
    assert store.exists() == resume, "a store was written"


@pytest.mark.parametrize("command", ["plot", "export"])
def test_readers_take_no_lock_so_a_fifo_lock_stops_none(
    base: Path, tmp_path: Path, command: str
) -> None:
    store = _copy(base, tmp_path)
    os.mkfifo(f"{os.path.realpath(store)}.lock")
    proc = gearchaos(_command(command, store), tmp_path)
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / ("run.png" if command == "plot" else "run.csv")
    assert out.is_file() and out.stat().st_size > 0


@pytest.mark.parametrize("kind", ["fifo", "directory"])  # /dev/zero: in its own process above
def test_the_store_lock_refuses_what_it_cannot_have_written(tmp_path: Path, kind: str) -> None:
    lock = StoreLock(str(tmp_path / "run.zarr"))
    LOCKS[kind](Path(lock.path))
    expected = _kind(Path(lock.path))
    refused(f"StoreLock with a {kind} lock", lock.acquire, lock.path)
    assert _kind(Path(lock.path)) == expected, "the lock was replaced"


@pytest.mark.parametrize("kind", ["fifo", "dev_zero"])
def test_a_metadata_read_never_blocks_nor_reads_without_end(tmp_path: Path, kind: str) -> None:
    path = tmp_path / ".zattrs"
    path.write_text("{}")
    PLACED[kind](path)
    with pytest.raises(OSError, match="not a regular file"):
        read_json(str(path), max_bytes=1 << 20)  # a cap, should the link ever be followed


def test_a_metadata_file_larger_than_its_cap_is_not_read_whole(tmp_path: Path) -> None:
    path = tmp_path / ".zattrs"
    path.write_bytes(b" " * 2048 + b"{}")
    assert read_json(str(path), max_bytes=4096) == {}
    with pytest.raises(OSError, match="larger than"):
        read_json(str(path), max_bytes=1024)
