"""The how-to "Your own gear model in one file" (docs/howto/own-model.md) runs as written.

Its excerpts of the model file are verbatim parts of ``examples/kahraman_singh_1991.py``; its
Python blocks run one after the other in a temporary directory holding ``examples/``, and
their output makes physical sense (the quasi-static response computed by hand from the
parameters, a stable 1T orbit, λ₁ > 0 in the chaotic band, the period doubling); its
commands run there too, and the stores they write say what the page says.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import re
import shlex
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "howto" / "own-model.md"
EXAMPLE = ROOT / "examples" / "kahraman_singh_1991.py"
FENCE = re.compile(r"^```(\w+)([^\n]*)\n(.*?)^```", re.S | re.M)


def _blocks(lang: str, titled: bool) -> list[str]:
    text = PAGE.read_text(encoding="utf-8")
    return [
        code
        for found, header, code in FENCE.findall(text)
        if found == lang and bool(header.strip()) == titled
    ]


def _workdir(tmp_path: Path) -> Path:
    (tmp_path / "examples").mkdir()
    shutil.copy(EXAMPLE, tmp_path / "examples" / EXAMPLE.name)
    return tmp_path


def test_excerpts_are_the_example_file() -> None:
    excerpts = _blocks("python", titled=True)
    assert len(excerpts) >= 3
    source = EXAMPLE.read_text(encoding="utf-8")
    for code in excerpts:
        # class members are shown dedented
        found = code in source or textwrap.indent(code, "    ") in source
        assert found, f"the page's excerpt is not in {EXAMPLE.name}:\n{code}"


def test_python_blocks_run_and_make_physical_sense(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    blocks = _blocks("python", titled=False)
    assert len(blocks) == 3
    monkeypatch.chdir(_workdir(tmp_path))
    monkeypatch.setattr(sys, "path", list(sys.path))  # the page inserts "examples"
    namespace: dict[str, object] = {"__name__": "own_model_page"}
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        for code in blocks:
            exec(compile(code, str(PAGE), "exec"), namespace)
    printed = out.getvalue()

    model = namespace["model"]
    # quasi-static at Ω = 0.05: δ̄ = b̄_h + F̄_m/(1 + ε cos Ωτ), the pinion at −(b̄_p + F̄_m/κ_p)
    lo = model.b_h + model.f_mean / (1 + model.eps)
    hi = model.b_h + model.f_mean / (1 - model.eps)
    slow = namespace["slow"]
    assert slow.obs_min[2] == pytest.approx(lo, abs=2e-3)
    assert slow.obs_max[2] == pytest.approx(hi, abs=2e-3)
    assert f"{lo:.3f}" == "1.077" and f"{hi:.3f}" == "1.143"  # the numbers the page quotes
    assert slow.obs_min[0] == pytest.approx(-(model.b_p + model.f_mean / model.kappa_p), abs=2e-3)
    assert slow.obs_max[0] == pytest.approx(-(model.b_p + model.f_mean / model.kappa_p), abs=2e-3)

    orbit = namespace["orbit"]
    assert orbit.converged and orbit.period == 1
    assert 0.9 < np.abs(orbit.multipliers).max() < 1  # the page says 0.913…
    assert orbit.obs_min[2] < model.b_h  # the teeth separate on it
    lam = float(re.search(r"lambda_1 at 1.7: (\S+)", printed).group(1))
    assert 0.01 < lam < 0.06  # the page says ≈ 0.03

    motion = namespace["sweep"].motion.to_series()
    omega = motion.index.to_numpy()
    assert set(motion[omega < 0.9]) == {"1T"} and set(motion[omega > 2.2]) == {"1T"}
    assert "chaos" in set(motion[(omega > 1.55) & (omega < 1.9)])
    branch = namespace["branch"]
    kinds = list(branch.event_kind.values)
    assert kinds == ["period_doubling"]
    assert float(branch.event_value.values[0]) == pytest.approx(2.112, abs=1e-3)


def _commands() -> list[str]:
    lines = []
    for code in _blocks("bash", titled=False):
        lines += [line.strip() for line in code.replace("\\\n", " ").splitlines()]
    return [line for line in lines if line.startswith("gearchaos ")]


def test_commands_run_and_their_stores_say_what_the_page_says(tmp_path: Path) -> None:
    import gearchaos as gc

    work = _workdir(tmp_path)
    commands = _commands()
    assert [c.split()[1] for c in commands] == [
        "simulate",
        "orbit",
        "bifurcation",
        "continue",
        "plot",
    ]
    env = {**os.environ, "COLUMNS": "200", "NO_COLOR": "1"}
    outputs = {}
    for command in commands:
        argv = [sys.executable, "-m", "gearchaos", *shlex.split(command)[1:]]
        proc = subprocess.run(argv, cwd=work, env=env, capture_output=True, text=True)
        assert proc.returncode == 0, f"{command}\n{proc.stderr[-3000:]}"
        outputs[command.split()[1]] = proc.stdout
    assert re.search(r"motion\s*│\s*1T", outputs["simulate"])
    assert re.search(r"stable \(\|μ\| < 1 − 0\.0001\)\s*│\s*yes", outputs["orbit"])
    assert (work / "out" / "simulation.nc").is_file()
    assert (work / "own-model.png").stat().st_size > 10_000

    sweep = gc.open_sweep(work / "ks.zarr")
    motion = sweep.motion.to_series()
    omega = motion.index.to_numpy()
    assert set(motion[omega < 0.9]) == {"1T"} and set(motion[omega > 2.2]) == {"1T"}
    assert "chaos" in set(motion[(omega > 1.55) & (omega < 1.9)])
    # the pinion lifts off its bearing in the chaotic band (q̄1 rises above −b̄_p)
    chaotic = (omega > 1.55) & (omega < 1.9)
    assert np.any(sweep.y_p_max.values[chaotic] > -0.5)
    branch = gc.open_branch(work / "branch.nc")
    assert list(branch.event_kind.values) == ["period_doubling"]
    assert math.isclose(float(branch.event_value.values[0]), 2.112, abs_tol=1e-3)
