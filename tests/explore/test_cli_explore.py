"""``gearchaos explore`` refuses what ``gearchaos plot`` refuses, with the same one-line error
and exit code 2, before anything listens."""

from __future__ import annotations

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
