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
import errno
import json
import math
import os
import socket
import tempfile
import time
import zlib
from collections.abc import Iterable, Iterator, Mapping
from typing import Any

from .._files import open_regular_nofollow
from .._output import write_file
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
        # one lock per store whatever the spelling: a symbolic-link alias, a trailing slash or
        # a relative path name the same directory, and so the same lock
        real = os.path.realpath(os.path.abspath(store_path).rstrip(os.sep) or os.sep)
        self.path = f"{real}.lock"
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
        # a lock appears with its owner written (a hard link of a finished file), so one that
        # names no owner (empty, torn: left by an older version or a full disk) holds nothing
        return not isinstance(pid, int) or not isinstance(host, str)

    def acquire(self) -> None:
        parent = os.path.dirname(os.path.abspath(self.path))
        os.makedirs(parent, exist_ok=True)
        for _ in range(3):
            try:
                self._create()
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
            self._held = True
            return
        raise StoreError(f"cannot take the lock {self.path} (it keeps changing)")

    def _create(self) -> None:
        """Create the lock file with its owner in one step: written and flushed under a
        unique name, then hard-linked to the lock's name (which fails if it exists)."""
        owner = {"pid": os.getpid(), "host": socket.gethostname(), "started": time.time()}
        parent = os.path.dirname(self.path)
        try:
            os.makedirs(parent, exist_ok=True)
            fd, tmp = tempfile.mkstemp(prefix=".lock.", suffix=".partial", dir=parent)
        except OSError as exc:
            raise StoreError(f"cannot create the lock {self.path}: {exc.strerror or exc}") from None
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as f:
                json.dump(owner, f)
                f.flush()
                os.fsync(f.fileno())
            try:
                os.link(tmp, self.path)
            except OSError as exc:
                if exc.errno not in (errno.EPERM, errno.EOPNOTSUPP, errno.ENOTSUP, errno.EXDEV):
                    raise
                # no hard links on this file system: create exclusively, then write
                fd2 = os.open(self.path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
                with os.fdopen(fd2, "w", encoding="utf-8") as f:
                    json.dump(owner, f)
        except FileExistsError:
            raise
        except OSError as exc:
            raise StoreError(f"cannot create the lock {self.path}: {exc.strerror or exc}") from None
        finally:
            with contextlib.suppress(OSError):
                os.unlink(tmp)

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
def file_digest(path: str, max_bytes: int = 1 << 31) -> tuple[int, int]:
    """(size in bytes, CRC-32) of a regular file of at most ``max_bytes`` bytes: a symbolic
    link, a FIFO or a device is refused (``OSError``) before anything is read, and at most
    ``max_bytes`` + 1 bytes are read, so ``/dev/zero`` or a huge file never exhausts memory."""
    fd = open_regular_nofollow(path)
    try:
        crc, size = 0, 0
        while size <= max_bytes:
            block = os.read(fd, min(1 << 20, max_bytes + 1 - size))
            if not block:
                break
            crc = zlib.crc32(block, crc)
            size += len(block)
        if size > max_bytes:
            raise OSError(errno.EFBIG, f"larger than the {max_bytes} bytes written")
        return size, crc
    finally:
        os.close(fd)


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
    if not isinstance(chunks, Mapping):
        return ["the record of its chunks is not readable"]
    problems = []
    for rel, expected in chunks.items():
        if not isinstance(rel, str):
            problems.append(f"the record names a chunk {rel!r}")
            continue
        path = os.path.join(root, *rel.split("/"))
        if expected is not None and not (
            isinstance(expected, list)
            and len(expected) == 2
            and all(isinstance(v, int) and not isinstance(v, bool) for v in expected)
        ):
            problems.append(f"chunk {rel} has no readable size and checksum in the record")
            continue
        if expected is None:
            if os.path.exists(path):
                problems.append(f"chunk {rel} appeared after it was written as empty")
            continue
        try:
            size, crc = file_digest(path, max_bytes=expected[0])
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
    """Write JSON through the package's one staged write (unique temporary name, flushed to
    disk, renamed into place; a full disk is a clear error)."""
    write_file(path, json.dumps(data, separators=(",", ":")).encode("utf-8"), what="record")


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
        # a store is complete only with its manifest (written first): without it no chunk
        # could be checked, so a complete store that lost it is damage, not an older store
        try:
            with open(os.path.join(root, ".zattrs"), encoding="utf-8") as f:
                complete = json.loads(f.read(1 << 24)).get("complete") is True
        except (OSError, ValueError, AttributeError):
            complete = False
        if complete:
            raise StoreError(
                f"{root} is damaged: its chunk manifest {MANIFEST} is missing, so no chunk can "
                "be checked. Its data cannot be trusted; run the sweep again with --overwrite "
                "(overwrite=True)"
            )
        return
    listed: dict[str, Any] = manifest["chunks"]
    problems = []
    if arrays is not None:
        wanted = set(arrays)
        listed = {k: v for k, v in listed.items() if k.split("/", 1)[0] in wanted}
    else:  # a chunk the manifest does not know was not written by the sweep
        unknown = sorted(set(all_chunks(root)) - set(listed))
        problems += [f"chunk {key} is not in the manifest" for key in unknown]
    problems += verify_chunks(root, listed)
    if problems:
        shown = "; ".join(problems[:5]) + (
            f"; and {len(problems) - 5} more" if len(problems) > 5 else ""
        )
        raise StoreError(
            f"{root} is damaged: {shown}. Its data cannot be trusted; run the sweep again "
            "with --overwrite (overwrite=True)"
        )
