"""Regenerate ``docs/quickstart.png``: run the README's quick start, then shrink its figure.

Run from the repository root: ``.venv/bin/python docs/make_quickstart_png.py``. The figure is
``out/simulation.png`` of ``gearchaos simulate --preset sheng2016 --set omega=1.5 -o out/``,
resized and palette-quantised to stay under 300 kB so that it can be committed. It runs in a
temporary directory, so that an ``out/`` of the checkout is left alone.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

from PIL import Image

ROOT = Path(__file__).resolve().parents[1]
COMMAND = ["simulate", "--preset", "sheng2016", "--set", "omega=1.5", "-o", "out/"]
LIMIT = 300_000


def main() -> None:
    with tempfile.TemporaryDirectory(prefix="quickstart-") as work:
        subprocess.run([sys.executable, "-m", "gearchaos", *COMMAND], cwd=work, check=True)
        image = Image.open(Path(work) / "out" / "simulation.png").convert("RGB")
    target = ROOT / "docs" / "quickstart.png"
    for width, colors in ((1600, 128), (1400, 96), (1200, 64), (1000, 64)):
        height = round(image.height * width / image.width)
        small = image.resize((width, height), Image.Resampling.LANCZOS)
        small.quantize(colors=colors, dither=Image.Dither.NONE).save(target, optimize=True)
        if target.stat().st_size < LIMIT:
            break
    print(f"wrote {target.relative_to(ROOT)} ({target.stat().st_size // 1000} kB)")


if __name__ == "__main__":
    main()
