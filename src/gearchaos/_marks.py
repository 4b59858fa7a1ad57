"""The mark only gearchaos writes: how a file or store says "gearchaos wrote me, as I am".

A path that already exists is replaced only when it is gearchaos's own output
(:func:`gearchaos._output.check_replaceable`). Whether it is must not be judged by a mention
of the package: a user's ``notes.nc`` that reads "notes on my gearchaos runs", or a CSV whose
header mentions gearchaos, is the user's. Every writer therefore puts a structured mark,
:data:`MARK_KEY` = ``gearchaos_output``, holding the SHA-256 digest of the output's own
content or header, and a path counts as gearchaos's only when the mark is there *and* its
digest matches what is there now (a file edited since is the user's):

* **netCDF-4 / HDF5 files** (simulation, orbit, branch, cascade and curve files): a root
  attribute ``gearchaos_output = "sha256:…"``, the digest of the other root attributes as
  HDF5 stores them (:func:`mark_hdf5`, :func:`hdf5_is_marked`).
* **Zarr stores** (sweep, response, basin stores, Zarr branches): a root attribute
  ``gearchaos_output``, the digest of the store's header — its attributes among
  :data:`ZARR_HEADER`, written once when the store is created (:func:`zarr_mark`); the
  attributes a run updates (progress, classification) are not part of it.
* **PNG figures**: a ``tEXt`` chunk ``gearchaos_output`` before ``IEND`` with the digest of
  the file without that chunk (:func:`mark_png`).
* **Every other format** (PDF, SVG, HTML, TOML, MAT): the text
  ``gearchaos_output:sha256:<64 hex digits>`` written once in the file's own metadata or a
  comment, its digits the digest of the whole file with those 64 digits as zeros
  (:func:`placeholder`, :func:`fill_mark`).

:func:`file_is_marked` checks a PNG or a placeholder-marked file, :func:`hdf5_is_marked` a
netCDF file. Reading never follows a symbolic link, never opens a FIFO or a device, and reads
at most :data:`MAX_MARKED_BYTES`.

A leaf module: it imports nothing from the package but :mod:`gearchaos._files`.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
import struct
import zlib
from collections.abc import Mapping
from typing import Any

from ._files import open_regular_nofollow

__all__ = [
    "MARK_KEY",
    "MAX_MARKED_BYTES",
    "ZARR_HEADER",
    "file_is_marked",
    "fill_mark",
    "hdf5_is_marked",
    "mark_file",
    "mark_hdf5",
    "mark_hdf5_file",
    "mark_png",
    "placeholder",
    "zarr_is_marked",
    "zarr_mark",
]

#: The key of the mark (an attribute, a PNG text keyword, the start of the marked text).
MARK_KEY = "gearchaos_output"

#: The largest file whose mark is checked (figures, pages and exports are far smaller); a
#: larger file is not recognised as gearchaos's.
MAX_MARKED_BYTES = 256 * 1024 * 1024

#: The attributes of a Zarr store written once at its creation: its header, which the mark
#: of a store digests (those it has).
ZARR_HEADER = ("title", "version", "sweep_toml", "basin_spec", "parameter")

_DIGITS = 64
_PREFIX = f"{MARK_KEY}:sha256:"
_MARK_RE = re.compile(re.escape(_PREFIX.encode("ascii")) + rb"([0-9a-f]{64})")
_ZEROS = b"0" * _DIGITS
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _sha256(data: bytes | memoryview) -> str:
    return hashlib.sha256(data).hexdigest()


# ------------------------------------------------------------------ text in the file itself
def placeholder() -> str:
    """The mark as a writer puts it into a file's metadata or a comment before the digest is
    known: ``gearchaos_output:sha256:000…0``; :func:`fill_mark` fills in the digest."""
    return _PREFIX + "0" * _DIGITS


def fill_mark(data: bytes | memoryview) -> bytes:
    """``data`` (holding :func:`placeholder` exactly once) with the digest of ``data`` itself
    written over the zeros."""
    raw = bytes(data)
    found = [m for m in _MARK_RE.finditer(raw)]
    if len(found) != 1 or found[0].group(1) != _ZEROS:
        raise ValueError(f"the output must hold the mark placeholder once: found {len(found)}")
    start, end = found[0].span(1)
    return raw[:start] + _sha256(raw).encode("ascii") + raw[end:]


def _text_marked(raw: bytes) -> bool:
    found = [m for m in _MARK_RE.finditer(raw)]
    if len(found) != 1:
        return False
    start, end = found[0].span(1)
    return _sha256(raw[:start] + _ZEROS + raw[end:]).encode("ascii") == found[0].group(1)


# ------------------------------------------------------------------ PNG
def _chunks(raw: bytes) -> list[tuple[int, int, bytes, bytes]] | None:
    """(start, end, type, data) of every chunk of a PNG, or ``None`` when it is no PNG."""
    if not raw.startswith(_PNG_SIGNATURE):
        return None
    out = []
    pos = len(_PNG_SIGNATURE)
    while pos + 12 <= len(raw):
        (length,) = struct.unpack(">I", raw[pos : pos + 4])
        end = pos + 12 + length
        if end > len(raw):
            return None
        out.append((pos, end, raw[pos + 4 : pos + 8], raw[pos + 8 : pos + 8 + length]))
        pos = end
    return out if pos == len(raw) else None


def _png_chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def mark_png(data: bytes | memoryview) -> bytes:
    """A PNG with the mark: a ``tEXt`` chunk ``gearchaos_output`` = ``sha256:<digest of the
    file without it>`` inserted before ``IEND``."""
    raw = bytes(data)
    chunks = _chunks(raw)
    if not chunks or chunks[-1][2] != b"IEND":
        raise ValueError("not a complete PNG file")
    text = MARK_KEY.encode("ascii") + b"\0sha256:" + _sha256(raw).encode("ascii")
    at = chunks[-1][0]
    return raw[:at] + _png_chunk(b"tEXt", text) + raw[at:]


def _png_marked(raw: bytes) -> bool | None:
    """Whether a PNG carries a valid mark; ``None`` when ``raw`` is no PNG."""
    chunks = _chunks(raw)
    if chunks is None:
        return None
    key = MARK_KEY.encode("ascii") + b"\0sha256:"
    marks = [c for c in chunks if c[2] == b"tEXt" and c[3].startswith(key)]
    if len(marks) != 1:
        return False
    start, end, _, text = marks[0]
    return _sha256(raw[:start] + raw[end:]).encode("ascii") == text[len(key) :]


# ------------------------------------------------------------------ any file
def _read(path: str) -> bytes | None:
    """The bytes of the regular file ``path`` itself (no link, FIFO or device), or ``None``
    (missing, unreadable, or larger than :data:`MAX_MARKED_BYTES`)."""
    try:
        fd = open_regular_nofollow(path)
    except OSError:
        return None
    try:
        if os.fstat(fd).st_size > MAX_MARKED_BYTES:
            return None
        parts = []
        total = 0
        while True:
            block = os.read(fd, 1 << 20)
            if not block:
                break
            total += len(block)
            if total > MAX_MARKED_BYTES:
                return None
            parts.append(block)
        return b"".join(parts)
    except OSError:
        return None
    finally:
        os.close(fd)


def file_is_marked(path: str) -> bool:
    """Whether the regular file ``path`` carries gearchaos's mark with the digest of what it
    holds now (a PNG's mark chunk, or the marked text of any other format)."""
    raw = _read(path)
    if raw is None:
        return False
    png = _png_marked(raw)
    return png if png is not None else _text_marked(raw)


def mark_file(path: str) -> None:
    """Mark the file a writer has just written at ``path`` (its own temporary) in place: a PNG
    gets its mark chunk, any other file has its :func:`placeholder` filled in."""
    with open(path, "rb") as f:
        raw = f.read()
    marked = mark_png(raw) if raw.startswith(_PNG_SIGNATURE) else fill_mark(raw)
    with open(path, "wb") as f:
        f.write(marked)


# ------------------------------------------------------------------ netCDF-4 / HDF5
def _plain(value: Any) -> Any:
    """An HDF5 attribute value as plain JSON data, the same however it was written."""
    import numpy as np

    if isinstance(value, np.ndarray):
        return [_plain(v) for v in value.tolist()]
    if isinstance(value, np.generic):
        return _plain(value.item())
    if isinstance(value, bytes):
        return value.decode("utf-8", "surrogateescape")
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return repr(value)
    if isinstance(value, bool | int | float | str) or value is None:
        return value
    return repr(value)


def _attrs_digest(attrs: Mapping[str, Any]) -> str:
    body = {str(k): _plain(v) for k, v in attrs.items() if k != MARK_KEY}
    text = json.dumps(body, sort_keys=True, ensure_ascii=True, separators=(",", ":"))
    return "sha256:" + _sha256(text.encode("ascii"))


def _mark_root(where: Any) -> None:
    import h5py

    with h5py.File(where, "r+") as f:
        f.attrs[MARK_KEY] = _attrs_digest(dict(f.attrs.items()))


def mark_hdf5(data: bytes | memoryview) -> bytes:
    """The netCDF-4 file ``data`` (its bytes) marked: its root attribute :data:`MARK_KEY` set
    to the digest of its other root attributes, as HDF5 reads them back."""
    import io

    buffer = io.BytesIO(bytes(data))
    _mark_root(buffer)
    return buffer.getvalue()


def mark_hdf5_file(path: str) -> None:
    """Mark the netCDF-4 file a writer has just written at ``path`` (its own temporary) in
    place, as :func:`mark_hdf5`."""
    _mark_root(path)


def hdf5_is_marked(path: str) -> bool:
    """Whether the regular file ``path`` is a netCDF-4/HDF5 file whose root attribute
    :data:`MARK_KEY` is the digest of its other root attributes (a file that merely mentions
    gearchaos, or whose attributes were edited since, is not)."""
    import h5py

    try:
        fd = open_regular_nofollow(path)
    except OSError:
        return False
    try:
        with os.fdopen(os.dup(fd), "rb") as fh, h5py.File(fh, "r") as f:
            attrs = dict(f.attrs.items())
    except Exception:  # anything HDF5 cannot read is not gearchaos's file
        return False
    finally:
        os.close(fd)
    mark = attrs.get(MARK_KEY)
    if isinstance(mark, bytes):
        mark = mark.decode("ascii", "replace")
    return isinstance(mark, str) and mark == _attrs_digest(attrs)


# ------------------------------------------------------------------ Zarr stores
def zarr_mark(attrs: Mapping[str, Any]) -> str:
    """The mark of a Zarr store with root attributes ``attrs``: the digest of its header (its
    attributes among :data:`ZARR_HEADER`)."""
    return _attrs_digest({k: attrs[k] for k in ZARR_HEADER if k in attrs})


def zarr_is_marked(attrs: Mapping[str, Any]) -> bool:
    """Whether the root attributes ``attrs`` of a Zarr store carry its mark."""
    mark = attrs.get(MARK_KEY)
    return isinstance(mark, str) and mark == zarr_mark(attrs)
