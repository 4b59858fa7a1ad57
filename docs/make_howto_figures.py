"""Regenerate the how-to pages' figures: run each page's own commands, then shrink the PNGs
into docs/howto/.

Run from the repository root with the project's environment:
``.venv/bin/python docs/make_howto_figures.py [--work DIR] [PAGE ...]``. For every how-to
page that shows a figure (or only the PAGEs named, e.g. ``basins.md``) it runs the page's
``bash`` blocks in page order, as one shell script, in ``WORKDIR/<page>/`` (default
``howto-run/``, emptied first: the commands are a reader's in a fresh directory), with
the project's ``gearchaos`` on the PATH as after ``source .venv/bin/activate``; then it copies
every figure the page embeds (``![…](NAME.png)``) into ``docs/howto/``, resized and
palette-quantised like the tutorial's (``make_tutorial_figures.shrink``).

The commands are read from the page, never typed here: a block runs as the reader sees it,
up to the last block that makes one of the page's figures (the blocks after it show other
things, e.g. installing Chromium). Two kinds of command are not run as they stand:

* ``gearchaos explore STORE`` serves a web app until Ctrl-C; its figure is a screenshot. The
  script starts the page's command with ``--no-browser --port 0`` (options the page
  documents), loads it in headless Chromium (Playwright, as ``tests/explore/test_browser.py``
  does), clicks the point :data:`EXPLORE_CLICK` of the diagram, waits for the computed views
  and takes the screenshot;
* nothing else: a page whose figure no command of its own writes is refused by
  ``tests/docs/test_howto_figures.py``.
"""

from __future__ import annotations

import argparse
import os
import queue
import re
import shlex
import shutil
import subprocess
import sys
import threading
import time
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HOWTO = ROOT / "docs" / "howto"
sys.path.insert(0, str(ROOT / "tests" / "docs"))
sys.path.insert(0, str(ROOT / "tests" / "explore"))
sys.path.insert(0, str(ROOT / "docs"))

from bokeh_page import PIXEL_OF  # noqa: E402
from make_tutorial_figures import shrink  # noqa: E402
from tutorial_blocks import blocks  # noqa: E402


@dataclass(frozen=True)
class Page:
    """What the script knows of a how-to page: the minutes its commands take on 2 busy cores
    with the kernels compiled (0: the page shows no figure); files of the repository that its
    commands read, copied into the work directory first; and ``quick``, figures whose blocks
    take seconds, which the default test suite makes (the page's other blocks are slow tests).
    """

    minutes: float
    files: tuple[str, ...] = ()
    quick: tuple[str, ...] = ()


#: Every how-to page (``tests/docs/test_howto_figures.py`` checks that none is missing).
PAGES: dict[str, Page] = {
    "basins.md": Page(1.5),
    "cascade-and-impact.md": Page(1.5, quick=("cascade.png", "amplitude.png")),
    "dask.md": Page(0),  # commands need a Dask cluster; no figure
    "explore.md": Page(1),
    "gearset.md": Page(0),
    "hysteresis.md": Page(0.5),
    "maps.md": Page(0.5),
    "own-model.md": Page(1, files=("examples/kahraman_singh_1991.py",)),
    "rattle.md": Page(1.5),
    "reproduce.md": Page(0),
    "response.md": Page(0.5),
    "resume.md": Page(0),
    "stability-chart.md": Page(1),
}

#: The figure of a page that is a screenshot of its ``gearchaos explore`` command.
SCREENSHOTS = {"explore.md": "explore.png"}
#: The index of the swept value the explorer's screenshot clicks (Ω ≈ 1.528 on explore.md).
EXPLORE_CLICK = 16

_EMBED = re.compile(r"!\[[^\]]*\]\(([^)\s]+\.png)\)")
_OUTPUT = re.compile(r"(?:^|\s)(?:-o|--output)[ =](\S+\.png)(?=\s|$)")
_SERVE = re.compile(r"^gearchaos explore\b")


def embedded(page: str) -> list[str]:
    """The PNG files the page embeds, in page order."""
    return _EMBED.findall((HOWTO / page).read_text(encoding="utf-8"))


def _lines(code: str) -> list[str]:
    """The command lines of a bash block, continuation lines joined."""
    return [line.strip() for line in code.replace("\\\n", " ").splitlines() if line.strip()]


def bash_blocks(page: str) -> list[str]:
    """The page's bash blocks, in page order."""
    return [b.code for b in blocks(HOWTO / page) if b.lang == "bash"]


def figure_commands(page: str) -> dict[str, str]:
    """Each PNG a command of the page writes (``-o NAME.png``, or the screenshot of its
    ``gearchaos explore`` command) → that command line."""
    out: dict[str, str] = {}
    for code in bash_blocks(page):
        for line in _lines(code):
            for name in _OUTPUT.findall(line):
                out[name] = line
            if _SERVE.match(line) and page in SCREENSHOTS:
                out[SCREENSHOTS[page]] = line
    return out


def page_script(page: str, figures: Iterable[str] | None = None) -> str:
    """One bash script of the page's bash blocks, in order, through the last one that makes
    a figure, without its ``gearchaos explore`` commands (see :func:`screenshot`). With
    ``figures``, only those figures are made: a block that makes none of them but others is
    left out (blocks that make no figure, e.g. one that sets a variable, stay)."""
    codes = bash_blocks(page)
    commands = figure_commands(page)
    wanted = set(commands if figures is None else figures)
    if wanted - set(commands):
        raise ValueError(f"{page}: no command of the page makes {sorted(wanted - set(commands))}")
    makes = {commands[name] for name in wanted}
    other = set(commands.values()) - makes
    last = max((i for i, c in enumerate(codes) if makes & set(_lines(c))), default=-1)
    if last < 0:
        raise ValueError(f"{page}: no command of the page makes a figure")
    parts = ["set -euo pipefail"]
    for i, code in enumerate(codes[: last + 1]):
        if other & set(_lines(code)) and not makes & set(_lines(code)):
            continue
        parts.append(f"echo '### {page}: bash block {i + 1}' >&2")
        parts += [ln for ln in code.splitlines() if not _SERVE.match(ln)]
    return "\n".join(parts) + "\n"


def environment() -> dict[str, str]:
    """The reader's shell after ``source .venv/bin/activate``: this interpreter's scripts
    first on the PATH."""
    path = f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}"
    return {**os.environ, "PATH": path, "MPLBACKEND": "Agg", "COLUMNS": "120"}


def run_page(page: str, work: Path, figures: Iterable[str] | None = None) -> list[Path]:
    """Run the page's commands in ``work`` (emptied first: the commands are written for a
    fresh directory, e.g. ``gearchaos continue -o`` refuses an existing file) and return the
    figures it embeds (or only ``figures``), written there."""
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    for rel in PAGES[page].files:
        (work / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(ROOT / rel, work / rel)
    env = environment()
    script = page_script(page, figures)
    proc = subprocess.run(["bash", "-c", script], cwd=work, env=env, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(
            f"{page}: the page's commands failed with exit code {proc.returncode}\n"
            f"--- stdout (tail)\n{proc.stdout[-4000:]}\n--- stderr (tail)\n{proc.stderr[-4000:]}"
        )
    if page in SCREENSHOTS and (figures is None or SCREENSHOTS[page] in figures):
        screenshot(figure_commands(page)[SCREENSHOTS[page]], work / SCREENSHOTS[page], work, env)
    written = [work / name for name in (embedded(page) if figures is None else figures)]
    missing = [f.name for f in written if not f.is_file()]
    if missing:
        raise RuntimeError(f"{page}: its commands did not write {missing}")
    return written


def chromium() -> str | None:
    """A Chromium executable, as the explorer's browser tests find it."""
    found = (shutil.which("chromium"), shutil.which("chromium-browser"), "/usr/bin/chromium")
    return next((p for p in found if p and os.path.exists(p)), None)


def screenshot(command: str, target: Path, work: Path, env: dict[str, str]) -> None:
    """Serve the store of ``command`` (``gearchaos explore STORE``) without a browser of its
    own, click the point EXPLORE_CLICK of its diagram in headless Chromium, wait for the
    computed views and save the page as ``target``."""
    import numpy as np
    import xarray as xr
    from playwright.sync_api import sync_playwright

    executable = chromium()
    if executable is None:
        raise RuntimeError("no chromium executable (apt-get install -y chromium)")
    argv = [*shlex.split(command), "--no-browser", "--port", "0"]
    store = work / argv[2]
    ds = xr.open_zarr(store).load()
    omega = float(ds.omega.values[EXPLORE_CLICK])
    x = ds.delta_sp.isel(omega=EXPLORE_CLICK).sel(planet=1).values
    y = float(np.median(x[np.isfinite(x)]))
    proc = subprocess.Popen(argv, cwd=work, env=env, stdout=subprocess.PIPE, text=True)
    try:
        url = _url(proc)
        with sync_playwright() as p:
            browser = p.chromium.launch(
                executable_path=executable,
                args=["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run"],
            )
            page = browser.new_page(viewport={"width": 1400, "height": 1000})
            page.set_default_timeout(300_000)
            page.goto(url)
            page.wait_for_function(_PIXEL_READY, arg=["diagram-figure", omega, y])
            xy = page.evaluate(PIXEL_OF, ["diagram-figure", omega, y])
            page.mouse.click(*xy)
            page.get_by_text(f"computed at omega = {omega:.6g}").wait_for()
            page.locator("img").first.wait_for()
            time.sleep(2)  # let the images finish drawing
            page.screenshot(path=str(target), full_page=True)
            browser.close()
    finally:
        proc.terminate()
        proc.wait(timeout=60)


def _url(proc: subprocess.Popen[str], timeout: float = 300) -> str:
    """The address ``gearchaos explore`` prints."""
    lines: queue.Queue[str] = queue.Queue()
    assert proc.stdout is not None
    stdout = proc.stdout
    threading.Thread(target=lambda: [lines.put(ln) for ln in stdout], daemon=True).start()
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        try:
            line = lines.get(timeout=1)
        except queue.Empty:
            continue
        if "http://" in line:
            return line[line.index("http://") :].split()[0]
    raise RuntimeError("gearchaos explore printed no address")


_PIXEL_READY = (
    "(args) => window.Bokeh && Bokeh.documents.length > 0 && "
    f"Bokeh.documents[0].get_model_by_name(args[0]) !== null && ({PIXEL_OF})(args) !== null"
)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("pages", nargs="*", help="how-to pages (default: all with figures)")
    parser.add_argument("--work", type=Path, default=ROOT / "howto-run")
    args = parser.parse_args(argv)
    pages = args.pages or [p for p, info in PAGES.items() if info.minutes > 0]
    for page in pages:
        if page not in PAGES or PAGES[page].minutes == 0:
            parser.error(f"{page}: not a how-to page with figures")
        work = args.work.resolve() / Path(page).stem
        started = time.monotonic()
        print(f"{page}: running its commands in {work}", flush=True)
        for figure in run_page(page, work):
            shrink(figure, HOWTO / figure.name)
        print(f"{page}: done in {time.monotonic() - started:.0f} s", flush=True)


if __name__ == "__main__":
    main()
