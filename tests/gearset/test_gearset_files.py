"""Reading gear-set files safely (``gearchaos._files.read_text_file`` and ``GearSet.from_toml``):
only regular UTF-8 files of bounded size, each refusal one clear error naming the file."""

from __future__ import annotations

import contextlib
import os
import re
import signal
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from gearchaos._files import MissingFileError, read_text_file
from gearchaos.errors import ParameterError, StoreError
from gearchaos.gearset import GearSet, preset
from gearchaos.gearset.records import MAX_FILE_BYTES

posix_only = pytest.mark.skipif(sys.platform == "win32", reason="POSIX file types")


class _Hung(Exception):
    pass


@contextlib.contextmanager
def _at_most(seconds: float) -> Iterator[None]:
    """Fail instead of hanging: SIGALRM after ``seconds`` (generous; only a hang trips it)."""

    def alarm(signum: int, frame: object) -> None:
        raise _Hung(f"still running after {seconds} s")

    old = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def test_size_limit_is_inclusive(tmp_path: Path) -> None:
    path = tmp_path / "f.txt"
    path.write_bytes(b"a" * 100)
    assert read_text_file(path, what="test file", max_bytes=100) == "a" * 100
    with pytest.raises(StoreError, match=r"^test file '.*f\.txt' is 100 bytes, more than the 99 "):
        read_text_file(path, what="test file", max_bytes=99)


def test_gearset_file_size_limit(tmp_path: Path) -> None:
    text = preset("hindawi2021").to_toml()
    path = tmp_path / "big.toml"
    path.write_text(text + "#" * (MAX_FILE_BYTES - len(text.encode())), encoding="utf-8")
    assert path.stat().st_size == MAX_FILE_BYTES == 1 << 20
    assert GearSet.from_toml(path) == preset("hindawi2021")  # exactly 1 MiB: read
    with path.open("a", encoding="utf-8") as f:
        f.write("#")
    message = r"big\.toml' is 1048577 bytes, more than the 1048576 bytes \(1 MiB\) allowed$"
    with pytest.raises(StoreError, match=message):
        GearSet.from_toml(path)


def test_missing_file_is_both_store_error_and_file_not_found(tmp_path: Path) -> None:
    with pytest.raises(MissingFileError) as info:
        GearSet.from_toml(tmp_path / "nope.toml")
    assert isinstance(info.value, StoreError) and isinstance(info.value, FileNotFoundError)
    assert str(info.value) == f"gear-set file not found: '{tmp_path / 'nope.toml'}'"


def test_symlink_to_a_regular_file_is_followed(tmp_path: Path) -> None:
    target = tmp_path / "real.toml"
    target.write_text(preset("sheng2016-v1").to_toml(), encoding="utf-8")
    link = tmp_path / "link.toml"
    link.symlink_to(target)
    assert GearSet.from_toml(link) == preset("sheng2016-v1")


@posix_only
@pytest.mark.parametrize(
    ("make", "kind", "error"),
    [
        ("directory", "is a directory, not a regular file", StoreError),
        ("loop", "cannot be opened: a loop of symbolic links", StoreError),
        ("fifo", "is a FIFO (named pipe), not a regular file", StoreError),
        ("under_file", "cannot be opened: Not a directory", StoreError),
    ],
)
def test_unusable_paths(tmp_path: Path, make: str, kind: str, error: type) -> None:
    path = tmp_path / "x.toml"
    if make == "directory":
        path.mkdir()
    elif make == "loop":
        path.symlink_to(tmp_path / "y.toml")
        (tmp_path / "y.toml").symlink_to(path)
    elif make == "fifo":
        os.mkfifo(path)  # no writer: a blocking open would wait forever
    else:
        (tmp_path / "file").write_text("")
        path = tmp_path / "file" / "x.toml"
    with _at_most(20.0), pytest.raises(error) as info:
        GearSet.from_toml(path)
    assert str(info.value) == f"gear-set file '{path}' {kind}"


@posix_only
@pytest.mark.parametrize(
    ("device", "kind"),
    [("/dev/zero", "a character device"), ("/dev/urandom", "a character device")],
)
def test_devices_are_refused_at_once(device: str, kind: str) -> None:
    if not os.path.exists(device):
        pytest.skip(f"no {device}")
    with _at_most(20.0), pytest.raises(StoreError, match=re.escape(f"'{device}' is {kind}")):
        GearSet.from_toml(device)


@pytest.mark.skipif(not os.path.exists("/proc/self/status"), reason="no /proc")
def test_file_claiming_size_zero_is_read_to_its_end() -> None:
    # /proc files report st_size 0; the reader reads them (bounded) and the TOML is invalid
    with pytest.raises(ParameterError, match=r"^/proc/self/status: invalid TOML"):
        GearSet.from_toml("/proc/self/status")


def test_binary_file_is_a_parameter_error_naming_the_file(tmp_path: Path) -> None:
    path = tmp_path / "bin.toml"
    path.write_bytes(b'name = "x"\n\xff\xfe\x00junk')
    with pytest.raises(ParameterError) as info:
        GearSet.from_toml(path)
    assert str(info.value) == (
        f"{path}: not UTF-8 text (gear-set file): byte 0xff at offset 11 cannot be decoded"
    )


def test_deep_nesting_is_a_parameter_error(tmp_path: Path) -> None:
    path = tmp_path / "deep.toml"
    path.write_text("x = " + "[" * 100_000, encoding="utf-8")
    with pytest.raises(ParameterError) as info:
        GearSet.from_toml(path)
    assert str(info.value) == (
        f"{path}: invalid TOML: arrays or inline tables nested too deeply to parse"
    )


@pytest.mark.parametrize(
    ("path", "message"),
    [
        (3, "gear-set file path must be a str or path-like: got int"),
        (b"x.toml", "gear-set file path must be a str or path-like: got bytes"),
        ("", "gear-set file path must not be empty: got ''"),
        ("a\0b.toml", "gear-set file path must not contain a NUL character: got 'a\\x00b.toml'"),
        (None, "gear-set file path must be a str or path-like: got NoneType"),
    ],
)
def test_paths_that_are_not_paths(path: object, message: str) -> None:
    with pytest.raises(ParameterError, match=re.escape(message)):
        GearSet.from_toml(path)  # type: ignore[arg-type]


@pytest.mark.skipif(hasattr(os, "geteuid") and os.geteuid() == 0, reason="root reads anything")
def test_unreadable_file(tmp_path: Path) -> None:
    path = tmp_path / "secret.toml"
    path.write_text("x = 1")
    path.chmod(0)
    try:
        with pytest.raises(StoreError, match=r"secret\.toml' cannot be opened: Permission denied"):
            GearSet.from_toml(path)
    finally:
        path.chmod(0o600)


def test_invalid_contents_start_with_the_path(tmp_path: Path) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(preset("hindawi2021").to_toml().replace("module = 0.004", "module = 4.0"))
    with pytest.raises(ParameterError) as info:
        GearSet.from_toml(path)
    assert str(info.value) == (
        f"{path}: geometry.module must lie in the plausible range [1e-06, 1] m: got 4.0"
    )
