"""The README's quick start writes no warning to stderr, and no line there twice.

``gearchaos simulate --preset sheng2016 --set omega=1.5 -o out/`` logged matplotlib's
"Ignoring fixed y limits to fulfill fixed data aspect with adjustable data limits." twice
(issue 24): the sun-centre panel fixed its limits and asked for an equal aspect by adjusting
them (``adjustable="datalim"``), which matplotlib overruled, with the message, at each of the
two draws of ``savefig``. The command is run as the reader runs it, with ``MPLBACKEND`` unset.
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
COMMAND = "gearchaos simulate --preset sheng2016 --set omega=1.5 -o out/"


def test_the_quick_start_is_the_readmes() -> None:
    assert f".venv/bin/{COMMAND}\n" in (ROOT / "README.md").read_text(encoding="utf-8")


def test_quick_start_stderr_has_no_warning_and_no_repeated_line(tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    proc = subprocess.run(
        [sys.executable, "-m", "gearchaos", *COMMAND.split()[1:]],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert (tmp_path / "out" / "simulation.png").is_file()
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    repeated = [line for line, n in Counter(lines).items() if n > 1]
    assert not repeated, f"stderr repeats {repeated}"
    assert not [line for line in lines if "Ignoring fixed" in line or "Warning" in line], lines
