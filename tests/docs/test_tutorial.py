"""The tutorial (docs/tutorial/index.md) runs as written, and what it writes makes sense.

Every bash and Python block of the page is run in page order in an empty directory, as one
shell script (so ``source .venv/bin/activate`` carries over), in the Quick variant where the
page offers one; the Full variant is the same commands with larger counts (checked here) and
runs in the slow test and in ``docs/make_tutorial_figures.py``. The outputs are then checked
against the page's promises and against the physics: the quasi-static section value at small
Ω is the static mesh deflection b̄_sp + F/(k b_c) computed by hand from the gear set.
"""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from tutorial_blocks import ROOT, TUTORIAL, blocks, numbers_masked, runnable, script

import gearchaos as gc

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
LABEL = re.compile(r"^(\d+T|QP|chaos|unresolved|failed)$")


def _venv(work: Path) -> None:
    """``work/.venv``: this interpreter's environment, where ``source .venv/bin/activate``
    finds it (a stand-in activate script when the tests do not run in a venv)."""
    prefix = Path(sys.prefix)
    if (prefix / "bin" / "activate").exists():
        (work / ".venv").symlink_to(prefix)
        return
    bindir = work / ".venv" / "bin"
    bindir.mkdir(parents=True)
    (bindir / "activate").write_text(f'export PATH="{Path(sys.executable).parent}:$PATH"\n')


def _run_tutorial(work: Path, variant: str) -> subprocess.CompletedProcess[str]:
    _venv(work)
    env = {**os.environ, "MPLBACKEND": "Agg", "COLUMNS": "100"}
    proc = subprocess.run(
        ["bash", "-c", script(variant)], cwd=work, env=env, capture_output=True, text=True
    )
    assert proc.returncode == 0, (
        f"the tutorial ({variant}) failed with exit code {proc.returncode}\n"
        f"--- stdout (tail)\n{proc.stdout[-4000:]}\n--- stderr (tail)\n{proc.stderr[-4000:]}"
    )
    return proc


def _swept_count(command: str, name: str) -> int:
    """COUNT of ``--vary NAME=START:STOP:COUNT`` in a command of the page."""
    m = re.search(rf"--vary {re.escape(name)}=[-\d.]+:[-\d.]+:(\d+)", command)
    assert m, f"no --vary {name}=START:STOP:COUNT in {command!r}"
    return int(m.group(1))


def _block_with(text: str, variant: str) -> str:
    codes = [b.code for b in runnable(variant) if text in b.code]
    assert len(codes) == 1, f"expected one {variant} block containing {text!r}: got {len(codes)}"
    return codes[0]


def _static_section_value() -> float:
    """X̄_sp1 at the section of the quasi-static response (Ω → 0) of sheng2016, by hand.

    Quasi-statically every sun–planet mesh carries F = T_D/(N r_bs), r_bs = m z_s cos α_s / 2
    (MODEL.md §10 fact 1, with in-phase meshes); at the section Ωτ = 2πk the stiffness is
    k_m + k_a (phase 0), so δ̄ = b̄_sp + F/((k_m + k_a) b_c).
    """
    gs = gc.preset("sheng2016")
    assert gs.mesh_phasing.model == "in_phase" and gs.torque.mode == "constant_torque"
    r_bs = (
        gs.geometry.module
        * gs.teeth.sun
        / 2
        * math.cos(math.radians(gs.geometry.pressure_angle_sun))
    )
    force = gs.torque.input / (gs.geometry.planets * r_bs)
    k = gs.stiffness.sun_planet_mean + gs.stiffness.sun_planet_alternating
    return gs.backlash.sun_planet + force / (k * gs.clearance.characteristic_length)


def _is_png(path: Path, min_bytes: int = 10_000) -> bool:
    return path.is_file() and path.stat().st_size > min_bytes and path.read_bytes()[:8] == PNG_MAGIC


# ------------------------------------------------------------------------- the page itself
def test_page_blocks_follow_the_conventions() -> None:
    every = blocks()
    langs = {b.lang for b in every}
    assert langs <= {"bash", "python", "text"}, f"unexpected code block languages: {langs}"
    full = [b for b in every if b.variant == "full"]
    quick = [b for b in every if b.variant == "quick"]
    assert full and len(full) == len(quick), "every Full tab needs a Quick twin"
    for f, q in zip(full, quick, strict=True):
        assert numbers_masked(f.code) == numbers_masked(q.code), (
            f"Full block (line {f.line}) and Quick block (line {q.line}) differ in more than "
            f"numbers:\n{f.code}\n{q.code}"
        )
        assert f.code != q.code


def test_install_block_is_what_ci_runs() -> None:
    install = [b for b in blocks() if b.is_install]
    assert len(install) == 1
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    assert install[0].code.strip() in [line.strip() for line in ci]


def test_every_figure_of_the_page_exists_and_every_tutorial_png_is_shown() -> None:
    text = TUTORIAL.read_text(encoding="utf-8")
    shown = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text)
    assert shown
    for rel in shown:
        assert _is_png((TUTORIAL.parent / rel).resolve()), f"missing or empty figure {rel}"
    for png in TUTORIAL.parent.glob("*.png"):
        assert png.name in shown, f"{png.name} is committed but not shown on the page"


# ------------------------------------------------------------------------- running it
@pytest.fixture(scope="module")
def quick_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    work = tmp_path_factory.mktemp("tutorial")
    _run_tutorial(work, "quick")
    return work


def _check_outputs(work: Path, variant: str) -> None:
    # quick start: the files and the 200 recorded section points the page describes
    ds = gc.open_simulation(work / "out" / "simulation.nc")
    assert ds.attrs["status"] == "ok"
    assert ds.sizes["section"] == 200
    assert _is_png(work / "out" / "simulation.png")

    # the Ω sweep: the documented number of points, all integrated, all labelled
    sweep = gc.open_sweep(work / "fig4a.zarr")
    n = _swept_count(_block_with("-o fig4a.zarr", variant), "omega")
    assert sweep.sizes["omega"] == n
    assert sweep.sizes["section"] == 100
    assert np.all(sweep["status"].values == 0)
    assert all(LABEL.match(str(x)) for x in sweep["motion"].values)
    # physics: at Ω ≤ 0.06 the response is quasi-static, one section point at the static
    # deflection computed by hand from the gear set (the inertial correction grows as Ω²: with
    # the default's transmission error of 2.75 b_c it is 1.2e-4 at Ω = 0.05, 5e-4 at Ω = 0.1)
    slow = sweep.sel(omega=slice(None, 0.06))
    assert slow.sizes["omega"] >= 1
    x = slow["delta_sp"].sel(planet=1).values
    assert np.all(slow["motion"].values == "1T")
    np.testing.assert_allclose(x, _static_section_value(), atol=5e-4)
    assert _is_png(work / "fig4a.png")

    # the gallery, the zoomed sections and the Lyapunov window
    assert _is_png(work / "gallery.png")
    assert _is_png(work / "sections.png")
    window = gc.open_sweep(work / "window.zarr")
    assert window.sizes["omega"] == _swept_count(_block_with("-o window.zarr", variant), "omega")
    lle = window["lle"].values
    assert np.all(np.isfinite(lle))
    labels = window["motion"].values
    # by definition of the labels: chaos has λ₁ > 0, and QP a |λ₁| below the threshold,
    # here at most 10/(100 T) ≤ 10/(100 · 2π/3.2) ≈ 0.05
    assert np.all(lle[labels == "chaos"] > 0)
    assert np.all(np.abs(lle[labels == "QP"]) < 10 / (100 * 2 * math.pi / 3.2))
    assert _is_png(work / "window.png")


def test_quick_tutorial_runs_and_its_outputs_make_sense(quick_run: Path) -> None:
    _check_outputs(quick_run, "quick")


def test_quick_tutorial_prints_what_the_page_shows(quick_run: Path) -> None:
    """The quick start prints 2T with two distinct points and double-sided impact on every
    mesh, its section points beyond the back flank, as the page's excerpt says."""
    proc = subprocess.run(
        [sys.executable, "-m", "gearchaos", "simulate", "--preset", "sheng2016",
         "--set", "omega=1.5", "--json", "--no-plot"],
        cwd=quick_run, capture_output=True, text=True, check=True,
    )  # fmt: skip
    import json

    summary = json.loads(proc.stdout)
    assert summary["motion"] == "2T"
    assert summary["distinct_section_points"] == 2
    assert {c["regime"] for c in summary["contact"]} == {"double_sided"}
    # both section values lie beyond the back flank, X̄_sp1 < −b̄_sp
    b_sp = gc.preset("sheng2016").backlash.sun_planet
    assert summary["section_min"] <= summary["section_max"] < -b_sp


@pytest.mark.slow
def test_full_tutorial(tmp_path: Path) -> None:
    """The Full variant (the figures' commands)."""
    _run_tutorial(tmp_path, "full")
    _check_outputs(tmp_path, "full")
