"""Running benchmark code in a child process that imports gearchaos from a given ``src/``: the
paired benchmarks (``bench_speed.py``, ``bench_integrator_split.py``) time a baseline checkout
against the new code this way."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any


def run_child(code: str, spec: dict[str, Any], src: Path, **env: str) -> dict[str, Any]:
    """Run ``code`` with ``sys.argv[1]`` = ``spec`` as JSON, ``PYTHONPATH`` = ``src`` and the
    further environment ``env``; return the JSON of its line starting with ``RESULT``, after
    checking (its key ``file``) that it imported gearchaos from ``src``."""
    environ = dict(os.environ, PYTHONPATH=str(src), **env)
    proc = subprocess.run(
        [sys.executable, "-c", code, json.dumps(spec)],
        env=environ, capture_output=True, text=True, check=False,
    )  # fmt: skip
    for line in proc.stdout.splitlines():
        if line.startswith("RESULT"):
            out = dict(json.loads(line[6:]))
            if not str(out["file"]).startswith(str(src)):
                raise RuntimeError(f"the child imported {out['file']}, not the code in {src}")
            return out
    raise RuntimeError(f"benchmark child failed ({src}):\n{proc.stderr[-3000:]}")
