"""``docs/quickstart.png`` shows today's run of the README's quick start (issue 35, item 5).

The committed figure said 640 rejected steps where the command gave 200: it had not been
regenerated after the integrator changed. ``docs/make_quickstart_png.py`` writes the run's
numbers that the figure's text shows into the PNG (text chunk ``gearchaos:run``); this test
runs the same command and compares them, so a stale figure fails here. Regenerate it with
``.venv/bin/python docs/make_quickstart_png.py``.
"""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path
from types import ModuleType

from PIL import Image

ROOT = Path(__file__).resolve().parents[2]


def _script() -> ModuleType:
    spec = importlib.util.spec_from_file_location(
        "make_quickstart_png", ROOT / "docs" / "make_quickstart_png.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_committed_figure_shows_todays_run(tmp_path: Path) -> None:
    script = _script()
    with Image.open(ROOT / "docs" / "quickstart.png") as png:
        chunk = png.text.get(script.CHUNK)
    assert chunk, "docs/quickstart.png has no run numbers: run docs/make_quickstart_png.py"
    shown = json.loads(chunk)
    cmd = [sys.executable, "-m", "gearchaos", *script.COMMAND]
    subprocess.run(cmd, cwd=tmp_path, check=True, capture_output=True)
    today = script.run_numbers(tmp_path / "out" / "simulation.nc")
    assert shown == today, (
        f"docs/quickstart.png shows {shown}, the quick start gives {today} today: "
        "run .venv/bin/python docs/make_quickstart_png.py"
    )
    assert today["transient_periods"] == 100  # the protocol's, as the command's footer says
