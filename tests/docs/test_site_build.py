"""``mkdocs build --strict`` succeeds offline, and the built site renders the whole public API.

The inventory the build writes (``objects.inv``, Sphinx format) lists every object the API
reference rendered; every name of ``gearchaos.__all__`` and of each documented subpackage's
``__all__`` must be in it. The pages load nothing from the network (no CDN scripts, styles or
fonts) and the model's equations are rendered as MathML.
"""

from __future__ import annotations

import importlib
import os
import re
import subprocess
import sys
import zlib
from pathlib import Path

import pytest

import gearchaos

ROOT = Path(__file__).resolve().parents[2]
SUBPACKAGES = ("gearset", "model", "integrate", "analysis", "sweep", "plot", "paper")
REMOTE_ASSET = re.compile(r"<(?:script|link|img)\b[^>]*(?:src|href)=\"(?:https?:)?//", re.I)


def _inventory(path: Path) -> set[str]:
    """Object names of a Sphinx v2 inventory (4 header lines, then zlib-compressed lines)."""
    raw = path.read_bytes()
    body = raw.split(b"\n", 4)[4]
    lines = zlib.decompress(body).decode("utf-8").splitlines()
    return {line.split(" ", 1)[0] for line in lines if line.strip()}


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("site")
    mkdocs = Path(sys.executable).parent / "mkdocs"
    cmd = [str(mkdocs)] if mkdocs.exists() else [sys.executable, "-m", "mkdocs"]
    proc = subprocess.run(
        [*cmd, "build", "--strict", "--site-dir", str(out)],
        cwd=ROOT,
        env={**os.environ, "NO_MKDOCS_2_WARNING": "1"},
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, f"mkdocs build --strict failed:\n{proc.stderr[-6000:]}"
    return out


def test_site_has_its_entry_page_and_sections(site: Path) -> None:
    for page in (
        "index.html",
        "tutorial/index.html",
        "concepts/model.html",
        "concepts/sections.html",
        "concepts/motion-labels.html",
        "howto/gearset.html",
        "howto/maps.html",
        "howto/hysteresis.html",
        "howto/resume.html",
        "howto/dask.html",
        "howto/reproduce.html",
        "reference/index.html",
        "MODEL.html",
        "reproduction.html",
        "figures.html",
        "report/index.html",
    ):
        assert (site / page).is_file(), f"the built site lacks {page}"


def test_api_reference_renders_every_public_name(site: Path) -> None:
    names = _inventory(site / "objects.inv")
    expected = {f"gearchaos.{n}" for n in gearchaos.__all__ if n != "__version__"}
    for package in SUBPACKAGES:
        module = importlib.import_module(f"gearchaos.{package}")
        expected |= {f"gearchaos.{package}.{n}" for n in module.__all__}
    missing = sorted(expected - names)
    assert not missing, f"public names the API reference does not render: {missing}"


def test_pages_load_nothing_from_the_network(site: Path) -> None:
    offenders = [
        str(page.relative_to(site))
        for page in site.rglob("*.html")
        if REMOTE_ASSET.search(page.read_text(encoding="utf-8", errors="replace"))
    ]
    assert not offenders, f"pages that load scripts, styles or images from the network: {offenders}"


def test_equations_are_rendered_as_mathml(site: Path) -> None:
    html = (site / "concepts" / "model.html").read_text(encoding="utf-8")
    assert html.count("<math") >= 10
    assert 'class="arithmatex"' not in html  # every formula was converted
