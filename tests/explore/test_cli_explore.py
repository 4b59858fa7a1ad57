"""``gearchaos explore`` refuses what ``gearchaos plot`` refuses, with the same one-line error
and exit code 2, before anything listens."""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from gearchaos.cli import EXIT_INVALID, app


def _bad_stores(tmp_path: Path) -> list[Path]:
    empty = tmp_path / "empty.zarr"
    empty.mkdir()
    text = tmp_path / "file.zarr"
    text.write_text("not a store")
    return [tmp_path / "missing.zarr", empty, text]


def test_an_invalid_store_gives_the_same_error_as_plot(tmp_path: Path) -> None:
    runner = CliRunner()
    for store in _bad_stores(tmp_path):
        shown = runner.invoke(app, ["explore", str(store), "--no-browser"])
        drawn = runner.invoke(app, ["plot", str(store), "-o", str(tmp_path / "x.png")])
        assert shown.exit_code == drawn.exit_code == EXIT_INVALID
        assert shown.stderr.startswith("error: ")
        assert shown.stderr == drawn.stderr
        assert len(shown.stderr.strip().splitlines()) == 1
        assert "Traceback" not in shown.output


@pytest.mark.parametrize("port", ["-1", "70000"])
def test_a_port_out_of_range_is_refused(port: str, gear_store: Path) -> None:
    result = CliRunner().invoke(app, ["explore", str(gear_store), "--port", port, "--no-browser"])
    assert result.exit_code == EXIT_INVALID
    assert f"--port must be an integer in 0..65535: got {port}" in result.stderr


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_signal_stops_the_server_without_a_warning(gear_store: Path, sig: int) -> None:
    """Issue 35: Ctrl-C stopped the explorer with "warning: add_callback_from_signal is
    deprecated" (Tornado's call, made from the package's own signal handler)."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "gearchaos", "explore", str(gear_store), "--port", "0",
         "--no-browser"],
        stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        assert proc.stdout is not None
        for line in proc.stdout:  # the URL line: the server listens (no time is waited)
            if "http://" in line:
                break
        else:
            pytest.fail(f"the explorer ended ({proc.wait()}) without its URL")
        proc.send_signal(sig)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 0, err
    assert "explorer stopped" in out
    assert err == "", err
