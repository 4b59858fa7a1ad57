"""Integrity of sweep stores on disk: one writer at a time, and damage that is reported.

* :class:`StoreLock` — a lock file ``<store>.lock`` beside the store holding the writer's pid,
  host and start time, created atomically (``O_CREAT | O_EXCL``). A second process that wants to
  write the same store (resume, ``--overwrite`` or an identical sweep started at the same time)
  is refused with a message naming the owner; a lock left by a process that no longer runs on
  this host is stale and taken over.
  A lock that is no regular file (a FIFO, a device, a symbolic link, a directory) is refused
  with its path: it is neither read nor removed.
* Chunk checksums — every chunk file a task writes is recorded (size and CRC-32) in the task's
  marker; a complete store carries ``_manifest.json`` with every chunk of every array and a
  digest of every array's metadata (``.zarray`` and ``.zattrs``: element type, shape, fill
  value, compressor, dimensions). :func:`verify_manifest` finds a deleted, truncated or
  overwritten chunk, or an array whose metadata changed (re-typed ``<f8`` → ``<i8`` would read
  every float's bits as an integer), and names it, so no reader mistakes damage for data
  (Zarr reads a missing chunk as its fill value). A manifest of an older version has no
  metadata digests: its stores still open, and the element types the sweep's layout fixes are
  checked instead (:func:`~gearchaos.sweep.storecheck.verify_attributes`).
* Safe reads — every file of a store that gearchaos reads itself (metadata, the manifest, task
  markers, the lock) goes through :func:`read_json`: the file itself, never a symbolic link,
  a FIFO or a device, opened without blocking and read up to a size cap.
  :func:`check_store_tree` refuses a store that holds anything but regular files and
  directories before Zarr, which opens files plainly, reads it.
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

from .._files import irregular_entry, open_regular_nofollow, read_nofollow
from .._output import remove_stale_staging, staging_prefix, write_file
from ..errors import StoreError

__all__ = [
    "MANIFEST",
    "StoreLock",
    "all_chunks",
    "check_store_tree",
    "chunk_keys",
    "digest_chunks",
    "file_digest",
    "manifest_record",
    "read_json",
    "read_manifest",
    "verify_array_metadata",
    "verify_chunks",
    "verify_manifest",
    "write_json_atomic",
]

#: File of a complete store listing every chunk, {"chunks": {relative path: [size, crc32]},
#: "metadata": {array/.zarray or array/.zattrs: SHA-256 of its JSON}}.
MANIFEST = "_manifest.json"

#: The largest metadata file, task marker or attractor catalogue read (bytes).
METADATA_MAX_BYTES = 64 << 20
#: The largest chunk manifest read (bytes): about 40 bytes a chunk.
MANIFEST_MAX_BYTES = 1 << 30
#: The largest lock file read (bytes): gearchaos writes about 80.
LOCK_MAX_BYTES = 64 << 10


def read_json(path: str, max_bytes: int = METADATA_MAX_BYTES) -> Any:
    """The JSON value of the regular file ``path`` itself, read by
    :func:`~gearchaos._files.read_nofollow` (never through a symbolic link, never blocking on a
    FIFO, at most ``max_bytes``): ``OSError`` when it cannot be read so (``strerror`` says
    why: ``a FIFO (named pipe), not a regular file``), ``ValueError`` when it is not JSON."""
    return json.loads(read_nofollow(path, max_bytes))


def check_store_tree(root: str, what: str = "the sweep") -> None:
    """Raise :class:`StoreError` naming the first entry of the store ``root`` that is neither
    a regular file nor a directory (:func:`~gearchaos._files.irregular_entry`: a FIFO, a
    device, a socket, a symbolic link): gearchaos never writes one, and Zarr, which opens its
    files plainly, would block on a FIFO or read a device without end. Run before any Zarr
    read of the store."""
    found = irregular_entry(root)
    if found is not None:
        rel, kind = found
        name = rel.rsplit("/", 1)[-1]
        chunk = "/" in rel and not name.startswith(".") and not name.endswith(".done")
        raise StoreError(
            f"{root} is damaged: {'chunk' if chunk else 'the file'} {rel} cannot be read "
            f"({kind}, not a regular file: gearchaos writes only files and directories in a "
            f"store). It is not read; run {what} again with --overwrite (overwrite=True)"
        )


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
        """The owner recorded in the lock, ``None`` when there is no lock, ``{}`` when it
        names none (torn). A lock that is no regular file gearchaos could have written (a
        FIFO, a device, a symbolic link, a directory, a huge file) is refused by name: it is
        neither read (a FIFO would block, ``/dev/zero`` never ends) nor removed."""
        try:
            data = read_json(self.path, LOCK_MAX_BYTES)
        except FileNotFoundError:
            return None
        except OSError as exc:
            if exc.errno in (errno.ELOOP, errno.EINVAL, errno.EFBIG, errno.EISDIR):
                raise StoreError(
                    f"the lock file {self.path} of {self.store_path} is "
                    f"{exc.strerror or exc}: gearchaos writes its locks as small regular "
                    "files, so it is neither read nor replaced; remove it if no gearchaos "
                    "process writes that store"
                ) from None
            return {}
        except ValueError:
            return {}
        return data if isinstance(data, dict) else {}

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
            remove_stale_staging(self.path)  # what a killed taker of this lock left
            fd, tmp = tempfile.mkstemp(
                prefix=staging_prefix(self.path), suffix=".partial", dir=parent
            )
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
            with contextlib.suppress(StoreError):
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
    text = json.dumps(data, separators=(",", ":")).encode("utf-8")
    # task markers are written often into one directory: no scan for stale temporaries (the
    # store's own rerun or --overwrite takes care of them)
    write_file(path, text, what="record", clean=False)


def read_manifest(root: str) -> dict[str, Any] | None:
    """The manifest of a complete store, or ``None`` for a store without one (older stores)."""
    path = os.path.join(root, MANIFEST)
    try:
        data = read_json(path, MANIFEST_MAX_BYTES)
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise StoreError(
            f"{root}: the chunk manifest {MANIFEST} is not readable ({exc.strerror or exc})"
        ) from None
    except ValueError:
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
            complete = read_json(os.path.join(root, ".zattrs")).get("complete") is True
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
    if "metadata" in manifest:  # older versions recorded only the chunks
        problems += verify_array_metadata(root, manifest["metadata"], arrays)
    if problems:
        shown = "; ".join(problems[:5]) + (
            f"; and {len(problems) - 5} more" if len(problems) > 5 else ""
        )
        raise StoreError(
            f"{root} is damaged: {shown}. Its data cannot be trusted; run the sweep again "
            "with --overwrite (overwrite=True)"
        )


# ------------------------------------------------------------------------ metadata digests
def _metadata_digest(path: str) -> str:
    """SHA-256 of a metadata file's JSON value, written canonically (sorted keys), so that
    the same metadata written again with another layout of its text has the same digest."""
    import hashlib

    text = json.dumps(read_json(path), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def _array_metadata_files(root: str) -> list[str]:
    """``<array>/.zarray`` and ``<array>/.zattrs`` of every array of the store, sorted."""
    keys = []
    for dirpath, _, files in os.walk(root):
        if ".zarray" not in files:
            continue
        rel = os.path.relpath(dirpath, root).replace(os.sep, "/")
        keys += [f"{rel}/{name}" for name in (".zarray", ".zattrs") if name in files]
    return sorted(keys)


def manifest_record(root: str) -> dict[str, Any]:
    """The manifest of a complete store: the size and CRC-32 of every chunk, and the digest of
    every array's metadata."""
    return {
        "chunks": digest_chunks(root, all_chunks(root)),
        "metadata": {
            key: _metadata_digest(os.path.join(root, *key.split("/")))
            for key in _array_metadata_files(root)
        },
    }


def verify_array_metadata(
    root: str, recorded: Any, arrays: Iterable[str] | None = None
) -> list[str]:
    """The problems of the arrays' metadata against the digests of the manifest: a metadata
    file changed, missing or not recorded."""
    if not isinstance(recorded, Mapping) or not all(
        isinstance(k, str) and isinstance(v, str) for k, v in recorded.items()
    ):
        return ["the manifest's record of the array metadata is not readable"]
    on_disk = set(_array_metadata_files(root))
    keys = set(recorded) | on_disk
    if arrays is not None:
        wanted = set(arrays)
        keys = {k for k in keys if k.split("/", 1)[0] in wanted}
    problems = []
    for key in sorted(keys):
        array = key.rsplit("/", 1)[0]
        if key not in recorded:
            problems.append(f"the metadata {key} of the array {array} is not in the manifest")
            continue
        try:
            digest = _metadata_digest(os.path.join(root, *key.split("/")))
        except FileNotFoundError:
            problems.append(f"the metadata {key} of the array {array} is missing")
            continue
        except (OSError, ValueError) as exc:
            why = exc.strerror if isinstance(exc, OSError) and exc.strerror else "not JSON"
            problems.append(f"the metadata {key} of the array {array} cannot be read ({why})")
            continue
        if digest != recorded[key]:
            problems.append(
                f"the metadata {key} of the array {array} changed since it was written "
                "(element type, shape, fill value, compressor or dimensions)"
            )
    return problems
