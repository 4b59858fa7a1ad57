"""The how-to pages' figures are made by the commands the pages show (docs/make_howto_figures.py).

Every figure a how-to page embeds (``![…](NAME.png)``) must be written by a command of that
same page (``-o NAME.png``; the explorer's screenshot by its ``gearchaos explore`` command),
so a page and its figure cannot drift apart; the script must know every page. The commands
themselves run here as well: the quick figures' blocks in the default suite (seconds), every
page's in full as slow tests (minutes each; ``pytest -m slow``).
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parents[2]
HOWTO = ROOT / "docs" / "howto"
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _script() -> ModuleType:
    spec = importlib.util.spec_from_file_location(
        "make_howto_figures", ROOT / "docs" / "make_howto_figures.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclass looks itself up there
    spec.loader.exec_module(module)
    return module


figures = _script()
FIGURE_PAGES = [page for page, info in figures.PAGES.items() if info.minutes > 0]


def _is_png(path: Path) -> bool:
    return path.is_file() and path.stat().st_size > 10_000 and path.read_bytes()[:8] == PNG_MAGIC


# ------------------------------------------------------------------------- the pages
def test_the_script_knows_every_howto_page() -> None:
    assert set(figures.PAGES) == {p.name for p in HOWTO.glob("*.md")}


@pytest.mark.parametrize("page", sorted(figures.PAGES))
def test_every_figure_of_a_page_is_made_by_a_command_of_that_page(page: str) -> None:
    shown = figures.embedded(page)
    made = figures.figure_commands(page)
    info = figures.PAGES[page]
    missing = [name for name in shown if name not in made]
    assert not missing, (
        f"{page} shows {missing}, but no command on the page writes it "
        f"(the page's commands write {sorted(made)})"
    )
    assert (info.minutes > 0) == bool(shown), f"{page}: PAGES says minutes={info.minutes}"
    assert set(info.quick) <= set(shown)
    for name in shown:
        assert _is_png(HOWTO / name), f"{page}: missing or empty figure {name}"
    for rel in info.files:
        assert (ROOT / rel).is_file(), rel


def test_every_howto_png_is_shown_by_a_page() -> None:
    shown = {name for page in figures.PAGES for name in figures.embedded(page)}
    for png in HOWTO.glob("*.png"):
        assert png.name in shown, f"{png.name} is committed but no how-to page shows it"


@pytest.mark.parametrize("page", FIGURE_PAGES)
def test_the_script_runs_the_pages_own_lines(page: str) -> None:
    """Every line the script runs is a line of the page's bash blocks (or its announcement),
    and it runs every command that writes a figure."""
    page_lines = {ln for code in figures.bash_blocks(page) for ln in code.splitlines()}
    script = figures.page_script(page)
    for line in script.splitlines()[1:]:
        assert line in page_lines or line.startswith("echo '### "), line
    for name, command in figures.figure_commands(page).items():
        if name not in figures.SCREENSHOTS.values():
            assert name in script and command.split()[1] in script


# ------------------------------------------------------------------------- running them
def test_the_quick_figures_are_written(tmp_path: Path) -> None:
    """The blocks of the cheap figures, as the pages show them (seconds)."""
    quick = {page: info.quick for page, info in figures.PAGES.items() if info.quick}
    assert quick
    for page, names in quick.items():
        written = figures.run_page(page, tmp_path / Path(page).stem, names)
        assert [p.name for p in written] == list(names)
        for path in written:
            assert _is_png(path), path


@pytest.mark.slow
@pytest.mark.parametrize("page", FIGURE_PAGES)
def test_every_figure_of_the_page_is_written(page: str, tmp_path: Path) -> None:
    """Every command of the page, in full (minutes), and every figure it embeds written."""
    if page in figures.SCREENSHOTS and figures.chromium() is None:
        pytest.skip("no chromium executable (apt-get install -y chromium)")
    written = figures.run_page(page, tmp_path / "work")
    assert [p.name for p in written] == figures.embedded(page)
    for path in written:
        assert _is_png(path), path
