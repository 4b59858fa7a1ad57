"""Regenerate ``docs/quickstart.png``: run the README's quick start, then shrink its figure.

Run from the repository root: ``.venv/bin/python docs/make_quickstart_png.py``. The figure is
``out/simulation.png`` of ``gearchaos simulate --preset sheng2016 --set omega=1.5 -o out/``,
resized and palette-quantised to stay under 300 kB so that it can be committed. It runs in a
temporary directory, so that an ``out/`` of the checkout is left alone.

The PNG carries the run's numbers that its text panel prints (:data:`RECORDED`: the steps, the
transient and the periods the verdict added, read from ``out/simulation.nc``) in a text chunk
``gearchaos:run``, so that ``tests/docs/test_quickstart_png.py`` can compare them with what the
same command gives today: a figure that no longer shows today's run fails that test.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

from PIL import Image, PngImagePlugin

ROOT = Path(__file__).resolve().parents[1]
COMMAND = ["simulate", "--preset", "sheng2016", "--set", "omega=1.5", "-o", "out/"]
LIMIT = 300_000
#: The PNG text chunk holding the run's numbers.
CHUNK = "gearchaos:run"
#: The attributes of the simulation file that the figure's text shows.
RECORDED = ("steps_accepted", "steps_rejected", "transient_periods", "extra_periods", "periods")


def run_numbers(nc: Path) -> dict[str, float]:
    """The numbers of :data:`RECORDED` of a simulation file."""
    import gearchaos as gc

    attrs = gc.open_simulation(nc).attrs
    return {k: float(attrs[k]) for k in RECORDED}


def main() -> None:
    with tempfile.TemporaryDirectory(prefix="quickstart-") as work:
        subprocess.run([sys.executable, "-m", "gearchaos", *COMMAND], cwd=work, check=True)
        image = Image.open(Path(work) / "out" / "simulation.png").convert("RGB")
        numbers = run_numbers(Path(work) / "out" / "simulation.nc")
    info = PngImagePlugin.PngInfo()
    info.add_text(CHUNK, json.dumps(numbers, sort_keys=True))
    target = ROOT / "docs" / "quickstart.png"
    for width, colors in ((1600, 128), (1400, 96), (1200, 64), (1000, 64)):
        height = round(image.height * width / image.width)
        small = image.resize((width, height), Image.Resampling.LANCZOS)
        small.quantize(colors=colors, dither=Image.Dither.NONE).save(
            target, optimize=True, pnginfo=info
        )
        if target.stat().st_size < LIMIT:
            break
    print(f"wrote {target.relative_to(ROOT)} ({target.stat().st_size // 1000} kB)")


if __name__ == "__main__":
    main()
