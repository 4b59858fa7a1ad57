"""Reading an input file safely: only a regular file of bounded size, as UTF-8 text.

A path given by a user may name a directory, a FIFO (whose ``open`` blocks until a writer
appears), a character device (``/dev/zero`` never ends), a symbolic-link loop, a huge or a
binary file. :func:`read_text_file` opens it without blocking, checks what the open file is,
reads at most ``max_bytes`` + 1 bytes and decodes them, so that each of these ends in one clear
error naming the file and the rule instead of a hang, a ``MemoryError`` or a traceback:

- :class:`MissingFileError` (a :class:`~gearchaos.errors.StoreError` and a
  :class:`FileNotFoundError`) when nothing is there;
- :class:`~gearchaos.errors.StoreError` when the path cannot be used as a file (a directory, a
  FIFO or device, a link loop, no permission, too large);
- :class:`~gearchaos.errors.ParameterError` when the path is not a path (wrong type, empty,
  a NUL character) or the contents are not UTF-8 text; the message starts with the path.

A leaf module: it imports nothing from the package but :mod:`gearchaos.errors`.
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path
from typing import Any

from .errors import ParameterError, StoreError

__all__ = [
    "MissingFileError",
    "check_output_file",
    "check_path",
    "check_regular_file",
    "irregular_entry",
    "open_regular_nofollow",
    "read_nofollow",
    "read_text_file",
]

_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def check_path(value: object, message: str, error: type[Exception] = ParameterError) -> str:
    """``value`` as the text of a file-system path, or ``error(message)``: the one rule for
    every argument that names a file or store — a ``str`` or path-like object whose path is
    text, not blank and without a NUL character."""
    text = os.fspath(value) if isinstance(value, str | os.PathLike) else None
    if not isinstance(text, str) or not text.strip() or "\0" in text:
        raise error(message)
    return text


class MissingFileError(StoreError, FileNotFoundError):
    """No file at the given path (both a :class:`StoreError` and a :class:`FileNotFoundError`)."""


def _size(n: int) -> str:
    """``100 bytes``, ``1048576 bytes (1 MiB)``."""
    if n < 1024:
        return f"{n} bytes"
    if n < 1024**2:
        return f"{n} bytes ({n / 1024:.4g} KiB)"
    return f"{n} bytes ({n / 1024**2:.4g} MiB)"


def _kind(mode: int) -> str:
    for test, name in _KINDS:
        if test(mode):
            return name
    return "not a regular file"  # pragma: no cover - every other type is listed above


def _open_regular(path: object, what: str) -> tuple[int, str, str]:
    """(open descriptor, path, path as shown) of a regular file; the errors of
    :func:`read_text_file`. The caller closes the descriptor."""
    if not isinstance(path, (str, os.PathLike)):
        raise ParameterError(f"{what} path must be a str or path-like: got {type(path).__name__}")
    try:
        name = os.fspath(path)
    except TypeError as exc:  # a PathLike whose __fspath__ returns neither str nor bytes
        raise ParameterError(f"{what} path must be a str or path-like: {exc}") from None
    if not isinstance(name, str):
        raise ParameterError(f"{what} path must be text: got {type(name).__name__}")
    if not name:
        raise ParameterError(f"{what} path must not be empty: got ''")
    if "\0" in name:
        raise ParameterError(f"{what} path must not contain a NUL character: got {name!r}")
    shown = str(Path(name))
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0)
    flags |= getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(name, flags)
    except FileNotFoundError:
        raise MissingFileError(f"{what} not found: '{shown}'") from None
    except OSError as exc:
        reason = exc.strerror or str(exc)
        if exc.errno == errno.ELOOP:
            reason = "a loop of symbolic links"
        raise StoreError(f"{what} '{shown}' cannot be opened: {reason}") from None
    try:
        mode = os.fstat(fd).st_mode
    except OSError as exc:  # pragma: no cover - fstat of an open descriptor
        os.close(fd)
        raise StoreError(f"{what} '{shown}' cannot be read: {exc.strerror or exc}") from None
    if not stat.S_ISREG(mode):
        os.close(fd)
        raise StoreError(f"{what} '{shown}' is {_kind(mode)}, not a regular file")
    return fd, name, shown


def open_regular_nofollow(path: str) -> int:
    """A read descriptor of the regular file at ``path`` itself, for files gearchaos wrote
    (chunks, figures it may replace): a symbolic link is never followed (``OSError`` ELOOP), a
    FIFO, device or directory is refused (``OSError`` EINVAL) before anything is read, and
    the open never blocks. The caller closes the descriptor."""
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise OSError(errno.ELOOP, "a symbolic link, not a regular file") from None
        raise
    try:
        mode = os.fstat(fd).st_mode
    except OSError:
        os.close(fd)
        raise
    if not stat.S_ISREG(mode):
        os.close(fd)
        raise OSError(errno.EINVAL, f"{_kind(mode)}, not a regular file")
    return fd


def read_nofollow(path: str, max_bytes: int) -> bytes:
    """The bytes of the regular file at ``path`` itself (a file gearchaos wrote: store
    metadata, a manifest, a lock, a task marker), opened by :func:`open_regular_nofollow` —
    so a symbolic link, a FIFO, a device or a directory raises ``OSError`` before anything is
    read and the open never blocks — and at most ``max_bytes`` of them: a larger file raises
    ``OSError`` ``EFBIG`` after ``max_bytes`` + 1 bytes, whatever size it claims."""
    fd = open_regular_nofollow(path)
    try:
        chunks: list[bytes] = []
        total = 0
        while total <= max_bytes:
            chunk = os.read(fd, min(1 << 20, max_bytes + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
        if total > max_bytes:
            raise OSError(errno.EFBIG, f"larger than the {_size(max_bytes)} allowed")
        return b"".join(chunks)
    finally:
        os.close(fd)


def irregular_entry(root: str) -> tuple[str, str] | None:
    """(path relative to ``root`` with ``/``, what it is) of the first entry under the
    directory ``root`` that is neither a regular file nor a directory — a FIFO, a device, a
    socket or a symbolic link, which gearchaos never writes in a store it makes — or ``None``.
    Checked before a library that opens files plainly (Zarr) reads the directory: it would
    block on a FIFO or read a device without end. Symbolic links are not followed; the types
    come from the directory listings (no call per file where the file system gives them)."""
    pending = [""]
    while pending:
        rel_dir = pending.pop()
        try:
            with os.scandir(os.path.join(root, rel_dir) if rel_dir else root) as it:
                entries = sorted(it, key=lambda e: e.name)
        except OSError as exc:
            return rel_dir or ".", f"not readable ({exc.strerror or exc})"
        for e in entries:
            rel = f"{rel_dir}/{e.name}" if rel_dir else e.name
            try:
                if e.is_symlink():
                    return rel, "a symbolic link"
                if e.is_dir(follow_symlinks=False):
                    pending.append(rel)
                    continue
                if e.is_file(follow_symlinks=False):
                    continue
                mode = e.stat(follow_symlinks=False).st_mode
            except FileNotFoundError:
                continue  # removed meanwhile (a writer's temporary)
            except OSError as exc:
                return rel, f"not readable ({exc.strerror or exc})"
            return rel, _kind(mode)
    return None


def check_regular_file(path: object, *, what: str) -> str:
    """The path of an existing regular file, as text, for readers that open it themselves
    (netCDF): refuses what :func:`read_text_file` refuses before reading (not a path, missing,
    a directory, FIFO, device or socket, a link loop, no permission)."""
    fd, name, _ = _open_regular(path, what)
    os.close(fd)
    return name


def read_text_file(path: object, *, what: str, max_bytes: int) -> str:
    """The text of a regular UTF-8 file of at most ``max_bytes`` bytes.

    Parameters
    ----------
    path : str or path-like
        The file. A symbolic link is followed (a loop is an error).
    what : str
        What the file is, for messages: ``"gear-set file"`` gives
        ``gear-set file 'x.toml' is a directory, not a regular file``.
    max_bytes : int
        Largest accepted size in bytes (≥ 1).

    Returns
    -------
    str
        The decoded text (strict UTF-8; a byte-order mark is kept as U+FEFF).

    Raises
    ------
    ParameterError
        ``path`` is not a ``str`` or path-like, is empty or holds a NUL character; or the
        contents are not UTF-8 (the message starts with the path).
    MissingFileError
        Nothing exists at ``path`` (``"{what} not found: '{path}'"``).
    StoreError
        ``path`` is not a regular file (directory, FIFO, device, socket), cannot be opened
        (permission, symbolic-link loop, a path component that is not a directory) or is
        larger than ``max_bytes``.

    Notes
    -----
    The file is opened with ``O_NONBLOCK`` so that opening a FIFO never waits for a writer,
    and its type is taken from the open descriptor (``fstat``), so it cannot change between
    the check and the read. At most ``max_bytes`` + 1 bytes are read whatever size the file
    claims, which also bounds files that grow or report size 0 (``/proc``).
    """
    fd, _, shown = _open_regular(path, what)
    try:
        size = os.fstat(fd).st_size
        if size > max_bytes:
            raise StoreError(
                f"{what} '{shown}' is {size} bytes, more than the {_size(max_bytes)} allowed"
            )
        chunks: list[bytes] = []
        total = 0
        while total <= max_bytes:
            chunk = os.read(fd, max_bytes + 1 - total)
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
        if total > max_bytes:
            raise StoreError(f"{what} '{shown}' is more than the {_size(max_bytes)} allowed")
    except OSError as exc:
        raise StoreError(f"{what} '{shown}' cannot be read: {exc.strerror or exc}") from None
    finally:
        os.close(fd)
    data = b"".join(chunks)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ParameterError(
            f"{shown}: not UTF-8 text ({what}): byte 0x{data[exc.start]:02x} at offset "
            f"{exc.start} cannot be decoded"
        ) from None


def check_output_file(path: object, *, what: str) -> str:
    """The path of a file about to be written (under a temporary name, then renamed over it),
    as text: refuses what is not a path (wrong type, empty, a NUL character) with
    :class:`~gearchaos.errors.ParameterError`, and an existing path that is not a regular file
    (a directory, a FIFO, a device such as ``/dev/null``, a socket) with
    :class:`~gearchaos.errors.StoreError` — a rename would replace it."""
    text = check_path(path, f"{what} must be a file path: got {path!r}")
    try:
        mode = os.stat(text).st_mode
    except FileNotFoundError:
        return text
    except OSError as exc:
        raise StoreError(f"{what} {text!r} cannot be written: {exc.strerror or exc}") from None
    if not stat.S_ISREG(mode):
        kind = next((k for test, k in _KINDS if test(mode)), "not a regular file")
        raise StoreError(f"{what} {text!r} is {kind}, not a regular file; choose another path")
    return text


def load_netcdf(path: object, *, what: str) -> tuple[str, Any]:
    """(the checked path, its :class:`xarray.Dataset` loaded into memory) of a netCDF-4 file
    gearchaos wrote: a path that is not a regular file, or a file that is not readable
    netCDF-4, raises :class:`~gearchaos.errors.StoreError` naming ``what`` and the file."""
    import xarray as xr

    name = check_regular_file(path, what=what)
    try:
        return name, xr.load_dataset(name, engine="h5netcdf")
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise StoreError(
            f"{what} {name!r} is not a readable netCDF-4 file ({type(exc).__name__})"
        ) from None
