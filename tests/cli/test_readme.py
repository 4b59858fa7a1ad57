"""The README's promises: its Python example runs, and CI runs its install and test commands."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"


def _blocks(lang: str) -> list[str]:
    text = README.read_text(encoding="utf-8")
    return re.findall(rf"```{lang}\n(.*?)```", text, flags=re.S)


def _section(title: str) -> str:
    text = README.read_text(encoding="utf-8")
    match = re.search(rf"^## {re.escape(title)}\n(.*?)(?=^## |\Z)", text, flags=re.S | re.M)
    assert match, f"README has no section {title!r}"
    return match.group(1)


def test_python_example_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    (code,) = _blocks("python")
    assert len([line for line in code.splitlines() if line.strip()]) <= 12
    monkeypatch.chdir(tmp_path)
    namespace: dict[str, object] = {"__name__": "readme_example"}
    try:
        exec(compile(code, str(README), "exec"), namespace)
    finally:
        plt.close("all")
    assert (tmp_path / "poincare.png").stat().st_size > 0
    ds = namespace["ds"]
    assert ds.attrs["status"] == "ok"  # type: ignore[attr-defined]
    assert namespace["x"].sizes["section"] == 200  # type: ignore[attr-defined]


def test_ci_runs_exactly_the_readme_commands() -> None:
    install = re.findall(r"```bash\n(.*?)\n```", _section("Install"), flags=re.S)
    (tests,) = re.findall(r"```bash\n(.*?)\n```", _section("Run the tests"), flags=re.S)
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    assert install and all(command in ci for command in install)
    assert tests in ci
    # Chromium is installed before the tests run, so that the browser tests run, not skip
    (chromium,) = [c for c in install if "apt-get install -y chromium" in c]
    assert ci.index(chromium) < ci.index(tests)
    assert "set -euo pipefail" in ci


def test_quickstart_figure_is_committable() -> None:
    (command,) = re.findall(r"```bash\n(.*?)\n```", _section("Quick start"), flags=re.S)
    assert command.startswith(".venv/bin/gearchaos simulate")
    png = ROOT / "docs" / "quickstart.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert png.stat().st_size < 300_000


def test_every_command_is_in_the_synopsis() -> None:
    """Issue 35: `export` (and `explore`) were missing from the README's command synopsis."""
    from typer.main import get_command

    from gearchaos.cli import app

    synopsis = next(b for b in _blocks("text") if b.startswith("gearchaos simulate"))
    names = sorted(get_command(app).commands)  # type: ignore[attr-defined]
    missing = [n for n in names if not re.search(rf"^gearchaos {re.escape(n)}\b", synopsis, re.M)]
    assert not missing, f"commands missing from the README's synopsis: {missing}"
