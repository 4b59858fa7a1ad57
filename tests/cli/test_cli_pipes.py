"""A broken pipe ends silently (issue 35, item 7): ``gearchaos --help | head`` ended with
"error: Broken pipe" (or exit code 1 without a word, depending on whether Click, Rich or the
command met the closed pipe). Now every command ends without a word and with exit code 141,
what a Unix tool ended by SIGPIPE returns, wherever the write failed."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from gearchaos.cli import EXIT_BROKEN_PIPE


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX pipes")
@pytest.mark.parametrize(
    "args",
    [
        ["--help"],  # Typer's help (Rich)
        ["simulate", "--help"],
        ["--version"],
        ["presets"],  # a command's table (Rich)
        ["info", "--json"],  # a command's JSON (Click's echo)
    ],
    ids=lambda a: " ".join(a),
)
def test_a_closed_pipe_ends_the_command_silently(args: list[str]) -> None:
    read, write = os.pipe()
    os.close(read)  # the reader is gone before anything is written: every write fails
    try:
        proc = subprocess.run(
            [sys.executable, "-m", "gearchaos", *args],
            stdout=write,
            stderr=subprocess.PIPE,
            stdin=subprocess.DEVNULL,
            text=True,
            timeout=300,
        )
    finally:
        os.close(write)
    assert EXIT_BROKEN_PIPE == 141
    assert proc.returncode == EXIT_BROKEN_PIPE, proc.stderr
    assert proc.stderr == ""


def test_output_to_a_reader_still_exits_0() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "gearchaos", "presets"], capture_output=True, text=True, timeout=300
    )
    assert proc.returncode == 0 and "sheng2016" in proc.stdout
