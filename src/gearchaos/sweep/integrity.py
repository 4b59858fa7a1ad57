"""Integrity of sweep stores on disk: one writer at a time, and damage that is reported.

* :class:`StoreLock` — a lock file ``<store>.lock`` beside the store holding the writer's pid,
  host and start time, created atomically (``O_CREAT | O_EXCL``). A second process that wants to
  write the same store (resume, ``--overwrite`` or an identical sweep started at the same time)
  is refused with a message naming the owner; a lock left by a process that no longer runs on
  this host is stale and taken over.
* Chunk checksums — every chunk file a task writes is recorded (size and CRC-32) in the task's
  marker; a complete store carries ``_manifest.json`` with every chunk of every array.
  :func:`verify_manifest` finds a deleted, truncated or overwritten chunk and names it, so no
  reader mistakes a damaged chunk for data (Zarr reads a missing chunk as its fill value).
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import socket
import time
import zlib
from collections.abc import Iterable, Iterator, Mapping
from typing import Any

from ..errors import StoreError

__all__ = [
    "MANIFEST",
    "StoreLock",
    "all_chunks",
    "chunk_keys",
    "digest_chunks",
    "file_digest",
    "read_manifest",
    "verify_chunks",
    "verify_manifest",
    "write_json_atomic",
]

#: File of a complete store listing every chunk: {relative path: [size, crc32]}.
MANIFEST = "_manifest.json"


# ------------------------------------------------------------------------------------ lock
def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


class StoreLock:
    """Exclusive writer lock of a store path (a context manager)."""

    def __init__(self, store_path: str):
        self.store_path = store_path
        self.path = f"{store_path}.lock"
        self._held = False

    def _owner(self) -> dict[str, Any] | None:
        try:
            with open(self.path, encoding="utf-8") as f:
                data = json.load(f)
            return data if isinstance(data, dict) else {}
        except FileNotFoundError:
            return None
        except (OSError, ValueError):
            return {}

    def _stale(self, owner: Mapping[str, Any]) -> bool:
        pid, host = owner.get("pid"), owner.get("host")
        if host == socket.gethostname() and isinstance(pid, int):
            return not _alive(pid)
        if not owner:  # unreadable (a writer killed while writing it): stale after a minute
            try:
                return time.time() - os.stat(self.path).st_mtime > 60.0
            except FileNotFoundError:
                return True
        return False

    def acquire(self) -> None:
        parent = os.path.dirname(os.path.abspath(self.path))
        os.makedirs(parent, exist_ok=True)
        for _ in range(3):
            try:
                fd = os.open(self.path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
            except FileExistsError:
                owner = self._owner()
                if owner is None:
                    continue  # released meanwhile
                if self._stale(owner):
                    with contextlib.suppress(FileNotFoundError):
                        os.remove(self.path)
                    continue
                since = owner.get("started")
                when = (
                    time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(since))
                    if isinstance(since, int | float) and math.isfinite(since)
                    else "an unknown time"
                )
                raise StoreError(
                    f"{self.store_path} is being written by process {owner.get('pid', '?')} on "
                    f"host {owner.get('host', '?')} since {when}; wait for it to finish, or "
                    f"remove {self.path} if that process no longer runs"
                ) from None
            with os.fdopen(fd, "w", encoding="utf-8") as f:
                json.dump(
                    {"pid": os.getpid(), "host": socket.gethostname(), "started": time.time()}, f
                )
            self._held = True
            return
        raise StoreError(f"cannot take the lock {self.path} (it keeps changing)")

    def release(self) -> None:
        if self._held:
            owner = self._owner()
            if owner is not None and owner.get("pid") == os.getpid():
                with contextlib.suppress(FileNotFoundError):
                    os.remove(self.path)
            self._held = False

    def __enter__(self) -> StoreLock:
        self.acquire()
        return self

    def __exit__(self, *exc: Any) -> None:
        self.release()


# ------------------------------------------------------------------------------- checksums
def file_digest(path: str) -> tuple[int, int]:
    """(size in bytes, CRC-32) of a file."""
    with open(path, "rb") as f:
        data = f.read()
    return len(data), zlib.crc32(data)


def chunk_keys(
    name: str, shape: tuple[int, ...], chunks: tuple[int, ...], block: Any = None
) -> Iterator[str]:
    """Relative paths (Zarr format 2, ``.`` separator) of the chunks of array ``name`` that
    cover ``block`` (slices over its leading dimensions; all chunks when ``None``)."""
    import itertools

    ranges = []
    for d, (n, c) in enumerate(zip(shape, chunks, strict=True)):
        if block is not None and d < len(block):
            lo, hi = block[d].start, block[d].stop
        else:
            lo, hi = 0, n
        ranges.append(range(lo // c, -(-hi // c)) if n else range(0))
    if not shape:
        yield f"{name}/0"
        return
    for idx in itertools.product(*ranges):
        yield f"{name}/" + ".".join(str(i) for i in idx)


def digest_chunks(root: str, keys: Iterable[str]) -> dict[str, list[int] | None]:
    """{key: [size, crc32]} of the chunk files ``keys`` under ``root``; ``None`` for a chunk
    that was not written (Zarr leaves out chunks that hold only the fill value)."""
    out: dict[str, list[int] | None] = {}
    for key in keys:
        try:
            out[key] = list(file_digest(os.path.join(root, *key.split("/"))))
        except FileNotFoundError:
            out[key] = None
    return out


def all_chunks(root: str) -> list[str]:
    """Every chunk file of every array of a store (Zarr format 2): files beside a ``.zarray``
    that are not metadata."""
    keys = []
    for dirpath, _, files in os.walk(root):
        if ".zarray" not in files:
            continue
        rel = os.path.relpath(dirpath, root).replace(os.sep, "/")
        keys += [f"{rel}/{f}" for f in sorted(files) if not f.startswith(".")]
    return sorted(keys)


def verify_chunks(root: str, chunks: Mapping[str, Any]) -> list[str]:
    """The problems of the listed chunks under ``root``: a chunk written then deleted, or with
    another size or checksum; a chunk listed as not written (``None``) that appeared."""
    problems = []
    for rel, expected in chunks.items():
        path = os.path.join(root, *rel.split("/"))
        if expected is None:
            if os.path.exists(path):
                problems.append(f"chunk {rel} appeared after it was written as empty")
            continue
        try:
            size, crc = file_digest(path)
        except FileNotFoundError:
            problems.append(f"chunk {rel} is missing")
            continue
        except OSError as exc:
            problems.append(f"chunk {rel} cannot be read ({exc.strerror or exc})")
            continue
        if [size, crc] != list(expected):
            problems.append(f"chunk {rel} is damaged (size or checksum differs from when written)")
    return problems


def write_json_atomic(path: str, data: Any) -> None:
    """Write JSON to a temporary file, flush it to disk and rename it into place."""
    tmp = f"{path}.partial-{os.getpid()}"
    with open(tmp, "w", encoding="utf-8") as f:
        json.dump(data, f, separators=(",", ":"))
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def read_manifest(root: str) -> dict[str, Any] | None:
    """The manifest of a complete store, or ``None`` for a store without one (older stores)."""
    path = os.path.join(root, MANIFEST)
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except FileNotFoundError:
        return None
    except (OSError, ValueError):
        raise StoreError(f"{root}: the chunk manifest {MANIFEST} is not readable") from None
    if not isinstance(data, dict) or not isinstance(data.get("chunks"), dict):
        raise StoreError(f"{root}: the chunk manifest {MANIFEST} is not a manifest")
    return data


def verify_manifest(root: str, arrays: Iterable[str] | None = None) -> None:
    """Raise :class:`StoreError` naming every missing or damaged chunk of a complete store."""
    manifest = read_manifest(root)
    if manifest is None:
        return
    listed: dict[str, Any] = manifest["chunks"]
    if arrays is not None:
        wanted = set(arrays)
        listed = {k: v for k, v in listed.items() if k.split("/", 1)[0] in wanted}
    problems = verify_chunks(root, listed)
    if problems:
        shown = "; ".join(problems[:5]) + (
            f"; and {len(problems) - 5} more" if len(problems) > 5 else ""
        )
        raise StoreError(
            f"{root} is damaged: {shown}. Its data cannot be trusted; run the sweep again "
            "with --overwrite (overwrite=True)"
        )
