"""Writing results safely: one overwrite rule and one way to put a file or directory in place.

**The overwrite rule.** A path that already exists is replaced only when it is gearchaos's own
output of the same kind, recognised by its own metadata (:func:`check_replaceable`, with the
writer's test ``ours``): every writer puts a structured mark, ``gearchaos_output``, holding the
digest of the output's own header or content (:mod:`gearchaos._marks`), and only a mark whose
digest matches counts — a sweep store that holds nothing else, a branch file, a figure, page or
export nobody edited since. A file that merely mentions gearchaos, a user's directory, a
thesis, a file of another program, a symbolic link — anything else is refused with
:class:`~gearchaos.errors.StoreError` naming the path.

**The one way to write.** :func:`staged_file` and :func:`staged_dir` give the writer a
temporary path beside the target with a unique name, created exclusively (``O_EXCL``: a
symbolic link planted under any name is never followed), and on success flush it to disk and
rename it over the target in one step (a directory, which cannot be renamed over another,
by :func:`replace_dir`: atomic against a concurrent writer of the same output); on every
error path the temporary is removed. Its name
says whose it is (``.NAME.HOST-PID-random.partial``: a digest of this host's name and the
writer's pid), so a later write of the same output removes what a killed writer (even by
SIGKILL) left (:func:`remove_stale_staging`), and nothing a live writer still fills. An
``ENOSPC`` becomes "no space left on device … N bytes free" instead of a crash or a truncated
file; writers whose libraries crash on a full disk (HDF5) serialise to memory first and write
the bytes with :func:`write_file`.

A leaf module: it imports nothing from the package but :mod:`gearchaos.errors`,
:mod:`gearchaos._files` and :mod:`gearchaos._marks`.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import shutil
import socket
import stat
import tempfile
import zlib
from collections.abc import Callable, Iterator

from ._files import read_nofollow
from ._marks import file_is_marked, zarr_is_marked
from .errors import StoreError

__all__ = [
    "check_replaceable",
    "file_has_mark",
    "is_own_zarr",
    "remove_stale_staging",
    "replace_dir",
    "staged_dir",
    "staged_file",
    "staging_prefix",
    "write_error",
    "write_file",
]


def _umask() -> int:
    old = os.umask(0o022)
    os.umask(old)
    return old


#: The mode of a new file (a temporary file is created 0600): what ``open`` would give.
_FILE_MODE = 0o666 & ~_umask()


def _free(directory: str) -> int | None:
    try:
        st = os.statvfs(directory)
    except (OSError, AttributeError):
        return None
    return int(st.f_bavail * st.f_frsize)


def write_error(exc: OSError, what: str, path: str, needed: int | None = None) -> StoreError:
    """A clear error for a failed write of ``what`` at ``path`` (a full disk says so, with
    the bytes free and, when known, needed)."""
    if exc.errno in (errno.ENOSPC, errno.EDQUOT):
        free = _free(os.path.dirname(os.path.abspath(path)) or ".")
        need = f"{needed} bytes needed, " if needed is not None else ""
        have = f"{free} bytes free" if free is not None else "free space unknown"
        return StoreError(f"no space left on device for {what} {path!r}: {need}{have}")
    return StoreError(f"cannot write {what} {path!r}: {exc.strerror or exc}")


def _fsync_dir(directory: str) -> None:
    with contextlib.suppress(OSError):
        fd = os.open(directory, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _remove(path: str) -> None:
    with contextlib.suppress(OSError):
        if os.path.isdir(path) and not os.path.islink(path):
            shutil.rmtree(path, ignore_errors=True)
        else:
            os.unlink(path)


def _parent(path: str) -> tuple[str, str]:
    full = os.path.abspath(path)
    return os.path.dirname(full), os.path.basename(full.rstrip(os.sep)) or "output"


def _host_tag() -> str:
    """Eight hex digits naming this host (CRC-32 of its name) in staging names."""
    return f"{zlib.crc32(socket.gethostname().encode('utf-8', 'replace')):08x}"


def staging_prefix(path: str) -> str:
    """The name prefix of this process's temporaries for the output ``path``:
    ``.NAME.HOST-PID-`` (followed by a random part and ``.partial``)."""
    return f".{_parent(path)[1]}.{_host_tag()}-{os.getpid()}-"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True
    return True


def remove_stale_staging(path: str) -> list[str]:
    """Remove the temporaries of the output ``path`` (files or directories named by
    :func:`staging_prefix`) whose writer on this host no longer runs — what a writer killed
    before it could clean up (``kill -9``) left beside the output; returns their paths.
    Temporaries of a live process, of another host (a shared file system) or of an older
    version (no pid in the name) are left alone."""
    parent, name = _parent(path)
    own = re.compile(re.escape(f".{name}.{_host_tag()}-") + r"([0-9]+)-[^/]*\.partial")
    try:
        entries = list(os.scandir(parent))
    except OSError:
        return []
    removed = []
    for e in entries:
        m = own.fullmatch(e.name)
        if m is None or _alive(int(m.group(1))):
            continue
        with contextlib.suppress(OSError):
            if e.is_dir(follow_symlinks=False):
                shutil.rmtree(e.path)
            else:
                os.unlink(e.path)
            removed.append(e.path)
    return removed


@contextlib.contextmanager
def staged_file(
    path: str, *, what: str, needed: int | None = None, clean: bool = True
) -> Iterator[str]:
    """A temporary file path beside ``path`` for a writer to fill; renamed over ``path`` when
    the block ends without error, removed otherwise. ``needed`` (bytes), when known, goes
    into the message of a full disk. With ``clean`` the temporaries of ``path`` that killed
    writers left are removed first (:func:`remove_stale_staging`; records written often in
    one directory, such as task markers, skip that scan)."""
    parent, _ = _parent(path)
    if clean:
        remove_stale_staging(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=staging_prefix(path), suffix=".partial", dir=parent)
    except OSError as exc:
        raise write_error(exc, what, path, needed) from None
    done = False
    try:
        # a replaced file keeps its permissions, a new one gets the usual ones
        try:
            mode = stat.S_IMODE(os.stat(path).st_mode)
        except OSError:
            mode = _FILE_MODE
        os.fchmod(fd, mode)
        os.close(fd)
        fd = -1
        yield tmp
        with open(tmp, "rb") as f:  # the writer closed it: flush its blocks to the disk
            os.fsync(f.fileno())
        os.replace(tmp, path)
        done = True
        _fsync_dir(parent)
    except OSError as exc:
        raise write_error(exc, what, path, needed) from None
    finally:
        if fd >= 0:
            os.close(fd)
        if not done:
            _remove(tmp)


def write_file(path: str, data: bytes | memoryview, *, what: str, clean: bool = True) -> str:
    """Write ``data`` to ``path`` through :func:`staged_file`; returns ``path``."""
    view = memoryview(data).cast("B")
    with staged_file(path, what=what, needed=view.nbytes, clean=clean) as tmp:
        flags = os.O_WRONLY | os.O_TRUNC | getattr(os, "O_NOFOLLOW", 0)
        fd = os.open(tmp, flags)
        try:
            done = 0
            while done < view.nbytes:
                done += os.write(fd, view[done:])
        finally:
            os.close(fd)
    return path


@contextlib.contextmanager
def staged_dir(path: str, *, what: str) -> Iterator[str]:
    """A temporary directory beside ``path`` for a writer to fill; put in place of ``path``
    when the block ends without error (by :func:`replace_dir`: an existing ``path`` — which
    the caller has checked with :func:`check_replaceable` — is moved aside into a temporary of
    this writer and removed after), removed otherwise. The temporaries of ``path`` that killed
    writers left are removed first (:func:`remove_stale_staging`)."""
    parent, _ = _parent(path)
    try:
        os.makedirs(parent, exist_ok=True)
        remove_stale_staging(path)
        tmp = tempfile.mkdtemp(prefix=staging_prefix(path), suffix=".partial", dir=parent)
    except OSError as exc:
        raise write_error(exc, what, path) from None
    done = False
    trash = None
    try:
        yield tmp
        trash = tempfile.mkdtemp(prefix=staging_prefix(path), suffix=".partial", dir=parent)
        replace_dir(tmp, path, trash)
        done = True
        _fsync_dir(parent)
    except OSError as exc:
        raise write_error(exc, what, path) from None
    finally:
        if not done:
            _remove(tmp)
        if trash is not None:
            shutil.rmtree(trash, ignore_errors=True)


#: What ``rename(directory, path)`` fails with when ``path`` is taken: a non-empty directory
#: (``ENOTEMPTY``, or ``EEXIST`` on some systems), a file (``ENOTDIR``).
_TAKEN = frozenset({errno.ENOTEMPTY, errno.EEXIST, errno.ENOTDIR, errno.EISDIR})
#: How often :func:`replace_dir` may find ``path`` taken again by another writer.
_RACES = 1000


def replace_dir(new: str, path: str, trash: str) -> None:
    """Rename the directory ``new`` to ``path`` in place of whatever is there, which is moved
    into ``trash`` (an empty directory of this writer on the same file system, that the caller
    removes afterwards).

    A directory cannot be renamed over a non-empty one, so a replace takes two renames — the
    old one aside, the new one in — and between them another writer of ``path`` may put its
    own in (or move the old one aside first). So the new directory is renamed in, and only when
    ``path`` is taken is what holds it moved aside (gone already: another writer moved it) and
    the rename tried again: each retry follows another writer's success, and the last rename
    leaves exactly one complete directory at ``path``, never a failure because of the other
    writer. The caller has checked that ``path`` may be replaced
    (:func:`check_replaceable`)."""
    name = os.path.basename(os.path.abspath(path).rstrip(os.sep)) or "output"
    for attempt in range(_RACES):
        try:
            os.rename(new, path)
            return
        except OSError as exc:
            if exc.errno not in _TAKEN:
                raise
        with contextlib.suppress(FileNotFoundError):  # another writer moved it aside first
            os.rename(path, os.path.join(trash, f"{attempt}-{name}"))
    raise OSError(errno.EBUSY, f"other writers replaced it {_RACES} times meanwhile")


def file_has_mark(path: str) -> bool:
    """Whether the regular file ``path`` carries gearchaos's mark with the digest of what it
    holds now (:func:`gearchaos._marks.file_is_marked`: a figure, page, gear-set file or
    export gearchaos wrote and nobody edited since); a file that merely mentions gearchaos
    does not. Never follows a symbolic link or opens a FIFO."""
    return file_is_marked(path)


def check_replaceable(path: str, *, what: str, ours: Callable[[str], bool]) -> None:
    """Refuse to replace ``path`` unless nothing is there or it is gearchaos's own ``what``
    (``ours(path)`` true): never a symbolic link, a foreign file or directory."""
    if not os.path.lexists(path):
        return
    if os.path.islink(path):
        raise StoreError(
            f"{path!r} is a symbolic link: a {what} is never written through one; "
            "choose another path"
        )
    if not ours(path):
        kind = "directory" if os.path.isdir(path) else "file"
        raise StoreError(
            f"{path!r} exists and is not a {what} gearchaos wrote (a {kind} without gearchaos's "
            "mark, or edited since): it is not replaced; move it away or choose another path"
        )


_CHUNK = re.compile(r"[0-9]+(\.[0-9]+)*")
#: The temporary files of an interrupted atomic write (``x.partial-PID``, ``.x.abc.partial``).
_OWN_TEMP = re.compile(r"\.partial(-[0-9]+)?$")


def _consolidated_root(meta: dict[str, object]) -> object:
    inner = meta.get("metadata")
    return inner.get(".zattrs") if isinstance(inner, dict) else None


def is_own_zarr(
    path: str,
    *,
    keys: tuple[str, ...],
    files: frozenset[str] = frozenset(),
    markers: str | None = None,
) -> bool:
    """Whether ``path`` is a Zarr (format 2) directory gearchaos wrote and nothing else: its
    ``.zattrs`` holds every attribute in ``keys`` and gearchaos's mark of its header
    (:func:`gearchaos._marks.zarr_is_marked`); its top level holds only Zarr metadata,
    the named ``files``, the ``markers`` directory of ``*.done`` files, temporaries of an
    interrupted write, and arrays (directories of ``.zarray``, ``.zattrs`` and chunk files).
    A file or directory a user put inside makes it no longer only gearchaos's."""
    if os.path.islink(path) or not os.path.isdir(path):
        return False
    try:
        entries = list(os.scandir(path))
    except OSError:
        return False
    # its attributes, or their consolidated copy when a damaged store lost the first (not
    # when they were edited: then the store is no longer as gearchaos wrote it)
    found = False
    for name, pick in ((".zattrs", lambda d: d), (".zmetadata", _consolidated_root)):
        try:  # never through a link, never blocking on a FIFO, never without end
            attrs = pick(json.loads(read_nofollow(os.path.join(path, name), 1 << 26)))
        except (OSError, ValueError, AttributeError, TypeError):
            continue
        if isinstance(attrs, dict):
            found = all(k in attrs for k in keys) and zarr_is_marked(attrs)
            break
    if not found:
        return False
    top = {".zattrs", ".zgroup", ".zmetadata", *files}
    for e in entries:
        if e.is_file(follow_symlinks=False) and (e.name in top or _OWN_TEMP.search(e.name)):
            continue
        if not e.is_dir(follow_symlinks=False):
            return False
        try:
            inner = os.listdir(e.path)
        except OSError:
            return False
        if e.name == markers:
            if not all(n.endswith(".done") or _OWN_TEMP.search(n) for n in inner):
                return False
            continue
        if ".zarray" not in inner:
            return False
        if not all(n in (".zarray", ".zattrs") or _CHUNK.fullmatch(n) for n in inner):
            return False
    return True
