"""Regenerate the tutorial's figures: run its Full commands, then shrink the PNGs into docs/.

Run from the repository root with the project's environment:
``.venv/bin/python docs/make_tutorial_figures.py [WORKDIR]``. It runs every command and code
block of ``docs/tutorial/index.md`` in its Full variant, in order, in WORKDIR (default
``tutorial-run/``, kept so that a rerun resumes the sweeps), exactly as a reader would after
``source .venv/bin/activate``, and copies the figures the page shows into ``docs/tutorial/``,
resized and palette-quantised to stay under 300 kB each.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from PIL import Image

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "docs"))

from tutorial_blocks import script  # noqa: E402

FIGURES = ("fig4a.png", "gallery.png", "sections.png", "window.png")
LIMIT = 300_000


def shrink(source: Path, target: Path) -> None:
    """Write ``source`` to ``target`` resized and quantised until it is under LIMIT bytes."""
    image = Image.open(source).convert("RGB")
    for width, colors in ((1400, 128), (1200, 96), (1100, 64), (1000, 64), (900, 48)):
        width = min(width, image.width)
        height = round(image.height * width / image.width)
        small = image.resize((width, height), Image.Resampling.LANCZOS)
        small.quantize(colors=colors, dither=Image.Dither.NONE).save(target, optimize=True)
        if target.stat().st_size < LIMIT:
            break
    print(f"wrote {target.relative_to(ROOT)} ({target.stat().st_size // 1000} kB)")


def main() -> None:
    work = Path(sys.argv[1] if len(sys.argv) > 1 else ROOT / "tutorial-run").resolve()
    work.mkdir(parents=True, exist_ok=True)
    venv = work / ".venv"
    if not venv.exists():
        venv.symlink_to(Path(sys.prefix))
    env = {**os.environ, "MPLBACKEND": "Agg"}
    subprocess.run(["bash", "-c", script("full")], cwd=work, env=env, check=True)
    for name in FIGURES:
        shrink(work / name, ROOT / "docs" / "tutorial" / name)


if __name__ == "__main__":
    main()
