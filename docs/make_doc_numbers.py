"""Rewrite the numbers of the docs that a program printed, from the programs themselves.

Run from the repository root with the project's environment:
``.venv/bin/python docs/make_doc_numbers.py [--check] [--fast]``. Every number of README.md,
the tutorial, the reproduce, rattle, maps, hysteresis, basins, cascade, response and
stability-chart how-tos, docs/reproduction.md and the motion-labels page that a command printed
(or that the committed report holds, that a how-to's commands wrote, or that the verdict's
settings define) sits between markers, and this script rewrites what is between them::

    |μ| ≈ <!-- gen:gallery.mu-3.5 -->0.97<!-- /gen --> per two periods

    <!-- gen:chaos-point.excerpt -->

    ```text
    │ motion │ chaos │
    ```

    <!-- /gen -->

A marker's name is ``SOURCE.KEY``. Each source (:data:`SOURCES`) runs one command, shown
verbatim in a code block or in inline code of every page that quotes it (checked), in a fresh
directory with ``COLUMNS=100`` (the width of the excerpts), and reads its output; the
``report`` source reads ``docs/report/report.json`` instead, which ``gearchaos reproduce --all
-o docs/report`` wrote, and the ``verdict`` source the defaults of
:class:`~gearchaos.dynamics.verdict.decide.VerdictSettings` and the constants of the verdict's rules
(tolerances, window lengths, budgets). Window keys of the tutorial's Full sweep are
``fig4a.wN.LABEL.lo|hi`` (the N-th window the page's Python block prints, which must carry
LABEL, so that the prose around it stays true) with an optional format after ``|``.

A source whose output no longer supports the prose around its numbers (the README's two
attractors at Ω = 1.5, say) raises :class:`ProseOutOfDate` with what to rewrite.
``--check`` rewrites nothing and exits 1 listing the stale numbers; ``--fast`` leaves out the
sources marked slow (the tutorial's 800-point sweep, the how-tos' commands);
``--only=SOURCE[,SOURCE…]`` computes only those sources (the markers of the others are left as
they are, and are not checked).
``tests/docs/test_doc_numbers.py`` runs the fast sources and the report in CI and the slow ones
under ``-m slow``.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import re
import shlex
import subprocess
import sys
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "docs"))
sys.path.insert(0, str(ROOT / "docs"))

from calibration_numbers import Markdown, calibration_values  # noqa: E402
from tutorial_blocks import TUTORIAL, runnable  # noqa: E402

PAGES = (
    ROOT / "README.md",
    TUTORIAL,
    ROOT / "docs" / "howto" / "reproduce.md",
    ROOT / "docs" / "reproduction.md",
    ROOT / "docs" / "MODEL.md",
    ROOT / "docs" / "howto" / "rattle.md",
    ROOT / "docs" / "howto" / "maps.md",
    ROOT / "docs" / "howto" / "hysteresis.md",
    ROOT / "docs" / "concepts" / "motion-labels.md",
    ROOT / "docs" / "howto" / "basins.md",
    ROOT / "docs" / "howto" / "cascade-and-impact.md",
    ROOT / "docs" / "howto" / "response.md",
    ROOT / "docs" / "howto" / "stability-chart.md",
)
RATTLE = ROOT / "docs" / "howto" / "rattle.md"
MAPS = ROOT / "docs" / "howto" / "maps.md"
CASCADE = ROOT / "docs" / "howto" / "cascade-and-impact.md"
RESPONSE = ROOT / "docs" / "howto" / "response.md"
HYSTERESIS = ROOT / "docs" / "howto" / "hysteresis.md"
REPORT = ROOT / "docs" / "report" / "report.json"
MARK = re.compile(r"<!-- gen:(?P<name>[^ ]+) -->(?P<body>.*?)<!-- /gen -->", re.S)
COLUMNS = 100


class ProseOutOfDate(RuntimeError):
    """The program's output no longer says what the prose around its numbers says."""


class Block(str):
    """A value shown as a ``text`` code block (an excerpt of what a command printed)."""


# ---------------------------------------------------------------------- running commands
def _gearchaos() -> list[str]:
    exe = Path(sys.executable).parent / "gearchaos"
    return [str(exe)] if exe.exists() else [sys.executable, "-m", "gearchaos"]


def run(command: str, cwd: Path) -> str:
    """Run a ``gearchaos …`` command of a page (``.venv/bin/`` prefix or none) in ``cwd``;
    its stdout."""
    argv = shlex.split(command)
    if Path(argv[0]).name != "gearchaos":
        raise ValueError(f"not a gearchaos command: {command!r}")
    env = {**os.environ, "COLUMNS": str(COLUMNS), "MPLBACKEND": "Agg", "NO_COLOR": "1"}
    env.pop("FORCE_COLOR", None)
    proc = subprocess.run(
        [*_gearchaos(), *argv[1:]], cwd=cwd, env=env, capture_output=True, text=True
    )
    if proc.returncode != 0:
        raise RuntimeError(f"{command!r} failed ({proc.returncode}):\n{proc.stderr[-3000:]}")
    return proc.stdout


def table_rows(text: str) -> dict[str, list[str]]:
    """The body rows of the (first) two-column rich table in ``text``: quantity → its printed
    lines (a wrapped value continues on lines with an empty first cell)."""
    rows: dict[str, list[str]] = {}
    last: list[str] | None = None
    for line in text.splitlines():
        if not line.startswith("│"):
            continue
        cells = [c.strip() for c in line.strip("│").split("│")]
        if cells[0]:
            last = rows.setdefault(cells[0], [])
        if last is not None:
            last.append(line.rstrip())
    return rows


def cell(rows: dict[str, list[str]], name: str, column: int = 1) -> str:
    if name not in rows:
        raise ProseOutOfDate(f"the command no longer prints a {name!r} row")
    return " ".join(line.strip("│").split("│")[column].strip() for line in rows[name]).strip()


def excerpt(rows: dict[str, list[str]], names: tuple[str, ...]) -> Block:
    missing = [n for n in names if n not in rows]
    if missing:
        raise ProseOutOfDate(f"the command no longer prints the rows {missing}")
    return Block("\n".join(line for n in names for line in rows[n]) + "\n")


def printed_table(text: str) -> Block:
    """The first table of ``text`` with its title, as printed."""
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(("┏", "┌")))
    end = next(i for i in range(start, len(lines)) if lines[i].startswith(("└", "┗")))
    return Block("\n".join(line.rstrip() for line in lines[max(start - 1, 0) : end + 1]) + "\n")


# ---------------------------------------------------------------------- the sources
@dataclass(frozen=True)
class Source:
    """One command and the values read from its output (``produce(work dir) → values``)."""

    command: str | None
    produce: Callable[[Path], dict[str, str]]
    slow: bool = False


QUICKSTART_ROWS = (
    "distinct section points",
    "motion",
    "X̄_sp1 section min",
    "X̄_sp1 section max",
    "load factor sun_planet (max)",
    "contact sun_planet_1",
    "contact planet_ring_1",
)
LYAPUNOV_ROWS = (
    "motion",
    "decided by",
    "λ₁ [1/τ]",
    "periods added to finish the transient",
    "0–1 test K",
    "indicators agree",
    "motion note",
)
#: The README's quick start: the period of the orbit it shows, shot and continued in Ω.
QUICKSTART_PERIOD = 2
ORBIT_COMMAND = "gearchaos orbit --set omega=1.5 --period 2 -o orbit.nc"


def _quickstart(work: Path) -> dict[str, str]:
    """The README's quick start (and the tutorial's step 2): a 2T orbit, found stable by its
    multipliers, on which every mesh hits its back flank each period (X̄_sp1 swings across the
    whole dead zone ±b̄_sp) while the sun stays inside its bearing clearance."""
    import gearchaos as gc

    rows = table_rows(run(SOURCES["quickstart"].command or "", work))
    if cell(rows, "motion") != f"{QUICKSTART_PERIOD}T" or cell(rows, "decided by") != "floquet":
        raise ProseOutOfDate(
            f"the quick start is no longer a {QUICKSTART_PERIOD}T orbit confirmed by its Floquet "
            f"multipliers: {cell(rows, 'motion')} by {cell(rows, 'decided by')} (README "
            "'Quick start', tutorial step 2)"
        )
    contacts = {name: cell(rows, name) for name in rows if name.startswith("contact ")}
    if not contacts or set(contacts.values()) != {"double_sided"}:
        raise ProseOutOfDate(
            f"the quick start says every mesh hits its back flank (double-sided impact): {contacts}"
        )
    ds = gc.open_simulation(work / "out" / "simulation.nc")
    b_sp, b_s = float(ds.attrs["clearance_sun_planet"]), float(ds.attrs["clearance_sun_bearing"])
    lo = float(ds["delta_sp_min"].sel(planet=1))
    hi = float(ds["delta_sp_max"].sel(planet=1))
    section = ds["delta_sp"].sel(planet=1)
    if not (lo < -b_sp and hi > b_sp and float(section.max()) < -b_sp):
        raise ProseOutOfDate(
            f"the quick start says X̄_sp1 swings across the dead zone ±{b_sp:g} every period and "
            f"its section points lie beyond the back flank: it spans {lo:.2f} … {hi:.2f}, the "
            f"section {float(section.min()):.2f} … {float(section.max()):.2f}"
        )
    sun = max(abs(float(ds[k])) for k in ("x_s_min", "x_s_max", "y_s_min", "y_s_max"))
    if not sun < 0.1 * b_s:
        raise ProseOutOfDate(
            f"the quick start says the sun hardly moves, well inside its bearing clearance "
            f"{b_s:g}: it reaches {sun:.3g}"
        )
    load = float(cell(rows, "load factor sun_planet (max)"))
    if not load > 1:
        raise ProseOutOfDate(f"the quick start's peak load is not above the static: {load}")
    shown, recorded = cell(rows, "distinct section points").split(" of ")
    return {
        "excerpt": excerpt(rows, QUICKSTART_ROWS),
        "distinct": shown,
        "recorded": recorded,
        "mu": f"{float(cell(rows, 'max |μ| (Floquet)')):.3f}",
        "added": cell(rows, "periods added to finish the transient"),
        "swing.lo": f"{lo:.1f}",
        "swing.hi": f"{hi:.1f}",
        "b_sp": f"{b_sp:g}",
        "b_s": f"{b_s:g}",
        "load": f"{load:.0f}",
    }


_LAMBDA = re.compile(r"^(-?[\d.]+(?:e-?\d+)?) ± ([\d.]+(?:e-?\d+)?)$")


def _lyapunov(work: Path) -> dict[str, str]:
    """The tutorial's step 6: chaos, decided by λ₁, whose interval λ₁ ± 2σ excludes zero and
    lies above the bias bound in the last window and the one before."""
    rows = table_rows(run(SOURCES["chaos-point"].command or "", work))
    if cell(rows, "motion") != "chaos" or cell(rows, "decided by") != "lyapunov":
        raise ProseOutOfDate("Ω = 2.7 (xi = 0.03) is no longer chaos by λ₁ (tutorial step 6)")
    m = _LAMBDA.match(cell(rows, "λ₁ [1/τ]"))
    if m is None or not float(m.group(1)) - 2 * float(m.group(2)) > 0:
        raise ProseOutOfDate(
            f"tutorial step 6 says λ₁ ± 2σ excludes zero: λ₁ = {cell(rows, 'λ₁ [1/τ]')}"
        )
    if "and so in the" not in cell(rows, "motion note"):
        raise ProseOutOfDate("tutorial step 6 says λ₁ was above the bound in two windows")
    from gearchaos.analysis.classify import K_CHAOS

    k = float(cell(rows, "0–1 test K"))
    if not k > K_CHAOS or cell(rows, "indicators agree") != "yes":
        raise ProseOutOfDate(f"tutorial step 6 says the 0–1 test agrees (K near 1): K = {k}")
    return {"excerpt": excerpt(rows, LYAPUNOV_ROWS), "K": f"{k:.2f}", "K_chaos": f"{K_CHAOS:g}"}


#: The tutorial's gallery (step 5): Ω → the label its prose describes.
GALLERY = {"0.81": "QP", "0.88": "1T", "2.7": "chaos", "3.02": "3T"}


def _gallery(work: Path) -> dict[str, str]:
    out = run(SOURCES["gallery"].command or "", work)
    table = printed_table(out)
    labels: dict[str, tuple[str, ...]] = {}
    for line in table.splitlines():
        if line.startswith("│"):
            cells = [c.strip() for c in line.strip("│").split("│")]
            labels[cells[0]] = (cells[1].lstrip("■ "), *cells[2:])
    if {k: v[0] for k, v in labels.items()} != GALLERY:
        raise ProseOutOfDate(
            f"the tutorial's gallery (step 5) describes {GALLERY}; the command now labels "
            f"{ {k: v[0] for k, v in labels.items()} }"
        )
    # columns after the label: decided by, max |μ|, λ₁, K, agree, distinct points
    distinct = {k: int(v[6]) for k, v in labels.items()}
    if distinct["0.88"] != 1 or distinct["3.02"] != 3:
        raise ProseOutOfDate(f"step 5 says one section point at 0.88, three at 3.02: {distinct}")
    return {
        "table": table,
        "mu-0.88": f"{float(labels['0.88'][2]):.2f}",
        "mu-3.02": f"{float(labels['3.02'][2]):.2f}",
    }


_SEGMENT = re.compile(r"│ (stable|unstable) ([\d.]+) … ([\d.]+)")
_EVENT = re.compile(r"│ (\w+) +│ ([\d.]+) ±")


def _continuation(work: Path) -> dict[str, str]:
    """The README's continuation of the quick start's 2T orbit up in Ω: stable from Ω = 1.5
    up to a fold, where it ends (the branch turns back, unstable)."""
    run(ORBIT_COMMAND, work)
    out = run(SOURCES["continue"].command or "", work)
    segments = [(kind, float(a), float(b)) for kind, a, b in _SEGMENT.findall(out)]
    folds = [float(v) for kind, v in _EVENT.findall(out) if kind == "fold"]
    if (
        len(segments) < 2
        or segments[0][0] != "stable"
        or segments[0][1] != 1.5
        or segments[1][0] != "unstable"
        or not folds
    ):
        raise ProseOutOfDate(
            "the README says the 2T orbit of the quick start, continued up from Ω = 1.5, stays "
            f"stable up to a fold where the branch turns back unstable; now: {segments}, "
            f"folds {folds}"
        )
    fold = min(folds, key=lambda v: abs(v - segments[0][2]))
    if not abs(fold - segments[0][2]) < 1e-3:
        raise ProseOutOfDate(
            f"the stable stretch 1.5–{segments[0][2]} does not end at a fold ({folds})"
        )
    return {"fold": f"{fold:.3f}"}


def _attractors(work: Path) -> dict[str, str]:
    """The README: every one of the eight starts at Ω = 1.5 ends on the quick start's 2T orbit,
    which is stable."""
    out = run(SOURCES["attractors"].command or "", work)
    found = []
    for line in out.splitlines():
        if line.startswith("│"):
            cells = [c.strip() for c in line.strip("│").split("│")]
            found.append((cells[0], cells[2], cells[4]))
    shape = [(label, starts) for label, starts, _ in found]
    if shape != [(f"{QUICKSTART_PERIOD}T", "0, 1, 2, 3, 4, 5, 6, 7")]:
        raise ProseOutOfDate(
            "the README says 'gearchaos attractors --set omega=1.5' finds one attractor, the 2T "
            f"orbit, from all eight starts; it now finds {shape}"
        )
    mu = re.search(r"max \|μ\| = ([\d.]+), stable", found[0][2])
    if mu is None:
        raise ProseOutOfDate(f"the 2T attractor's orbit is no longer stable: {found[0][2]!r}")
    return {"mu": f"{float(mu.group(1)):.3f}"}


def _windows_block() -> str:
    (block,) = [b for b in runnable("full") if b.lang == "python" and "fig4a.zarr" in b.code]
    return block.code


def _fig4a(work: Path) -> dict[str, str]:
    """The tutorial's Full Ω sweep, and what the page's Python block prints about it."""
    run(SOURCES["fig4a"].command or "", work)
    proc = subprocess.run(
        [sys.executable, "-c", _windows_block()],
        cwd=work,
        capture_output=True,
        text=True,
        check=True,
    )
    values: dict[str, str] = {"windows": Block(proc.stdout)}
    line = re.compile(r"^Ω = ([\d.]+) … ([\d.]+): (\S+)$")
    for i, text in enumerate(proc.stdout.splitlines(), start=1):
        m = line.match(text)
        if m is None:
            raise ProseOutOfDate(f"unexpected line of the window listing: {text!r}")
        values[f"w{i}.{m.group(3)}.lo"], values[f"w{i}.{m.group(3)}.hi"] = m.group(1, 2)
    import gearchaos as gc

    ds = gc.open_sweep(work / "fig4a.zarr")
    x = ds["delta_sp"].sel(planet=1)
    values["static"] = repr(float(x.isel(omega=0).mean()))
    for key in [k for k in values if k.endswith(".1T.lo")]:
        lo, hi = float(values[key]), float(values[key.replace(".lo", ".hi")])
        values[key.replace(".lo", ".mean")] = repr(float(x.sel(omega=slice(lo, hi)).mean()))
    _fig4a_claims(ds, values)
    return values


#: What the tutorial's step 4 says of the Full sweep's windows (numbered as the page's block
#: lists them): window → (label, the contact regime of every mesh of every planet there).
FIG4A_WINDOWS = {1: ("1T", "none"), 9: ("1T", "double_sided"), 11: ("2T", "double_sided"),
                 23: ("1T", "single_sided")}  # fmt: skip
#: … and the stretches it calls mostly chaos (from window to window).
FIG4A_CHAOS = ((2, 10), (12, 21))


def _fig4a_claims(ds: Any, values: dict[str, str]) -> None:
    """Raise :class:`ProseOutOfDate` unless the Full sweep still shows what step 4 says: the
    contact regimes of its 1T and 2T windows, the quick start's Ω = 1.5 inside the 2T window,
    the last window up to the sweep's end, and chaos on most points of the two chaotic stretches,
    whose section points reach beyond the back flank (and, in the second, both flanks)."""
    import numpy as np

    def window(n: int, label: str) -> tuple[float, float]:
        key = f"w{n}.{label}.lo"
        if key not in values:
            raise ProseOutOfDate(f"tutorial step 4: window {n} of the listing is no longer {label}")
        return float(values[key]), float(values[key.replace(".lo", ".hi")])

    flags = dict(enumerate(str(ds["contact_sp"].attrs["flag_meanings"]).split(), start=-1))
    for n, (label, regime) in FIG4A_WINDOWS.items():
        lo, hi = window(n, label)
        for var in ("contact_sp", "contact_rp"):
            found = {flags[int(v)] for v in np.unique(ds[var].sel(omega=slice(lo, hi)).values)}
            if found != {regime}:
                raise ProseOutOfDate(
                    f"tutorial step 4 says {label} at Ω = {lo:.3f} … {hi:.3f} has {regime} on "
                    f"every mesh: {var} there is {sorted(found)}"
                )
    window(7, "5T")
    lo, hi = window(8, "QP")
    if not lo <= 0.81 <= hi:
        raise ProseOutOfDate(f"step 5 says its QP point Ω = 0.81 lies in the QP window {lo}–{hi}")
    lo, hi = window(11, "2T")
    if not lo <= 1.5 <= hi:
        raise ProseOutOfDate(f"step 4 says the 2T window {lo}–{hi} holds the quick start's Ω = 1.5")
    step = float(ds["omega"].values[1] - ds["omega"].values[0])
    if not window(12, "chaos")[0] - hi < 1.5 * step:
        raise ProseOutOfDate("step 4 says the runs from rest go from the 2T window into chaos")
    last = float(ds["omega"].values[-1])
    if not window(23, "1T")[1] == round(last, 3) or f"w24.{'1T'}.lo" in values:
        raise ProseOutOfDate("step 4 says the 1T of window 23 holds up to the sweep's end")
    b_sp = float(ds.attrs["clearance_sun_planet"])
    x = ds["delta_sp"].sel(planet=1)
    for first, end in FIG4A_CHAOS:
        lo, hi = window(first, "chaos")[0], window(end, "chaos")[1]
        stretch = ds["motion"].sel(omega=slice(lo, hi)).values.astype(str)
        xs = x.sel(omega=slice(lo, hi))
        if not (stretch == "chaos").mean() > 0.5 or not float(xs.min()) < -b_sp:
            raise ProseOutOfDate(
                f"step 4 says Ω = {lo} … {hi} is mostly chaos reaching below −b̄_sp: "
                f"{100 * (stretch == 'chaos').mean():.0f} % chaos, min X̄ {float(xs.min()):.2f}"
            )
    lo, hi = window(FIG4A_CHAOS[1][0], "chaos")[0], window(FIG4A_CHAOS[1][1], "chaos")[1]
    if not float(x.sel(omega=slice(lo, hi)).max()) > b_sp:
        raise ProseOutOfDate(f"step 4 says Ω = {lo} … {hi} spreads over both sides of ±b̄_sp")
    if not float(values["w9.1T.mean"]) < -b_sp:
        raise ProseOutOfDate("step 4 says window 9's 1T section point is beyond the back flank")


def _slug(verdict: str) -> str:
    """``holds (constant)`` → ``holds-constant``, ``does not hold`` → ``does-not-hold``."""
    return re.sub(r"[^a-z]+", "-", verdict.lower()).strip("-")


def titled_table(text: str, title: str) -> Block:
    """The table of ``text`` printed under the line ``title``, as printed."""
    lines = text.splitlines()
    start = next((i for i, line in enumerate(lines) if line.strip() == title), None)
    if start is None:
        raise ProseOutOfDate(f"the command no longer prints a table titled {title!r}")
    end = next(i for i in range(start, len(lines)) if lines[i].startswith(("└", "┗")))
    return Block("\n".join(line.rstrip() for line in lines[start : end + 1]) + "\n")


def run_howto(page: Path, work: Path, figures: tuple[str, ...] | None = None) -> str:
    """Run a how-to page's bash blocks (through its last figure, or the blocks of
    ``figures`` only) in ``work`` as a reader would (docs/make_howto_figures.py); their
    stdout."""
    from make_howto_figures import environment, page_script

    env = {**environment(), "COLUMNS": str(COLUMNS), "NO_COLOR": "1"}
    env.pop("FORCE_COLOR", None)
    script = page_script(page.name, figures)
    proc = subprocess.run(["bash", "-c", script], cwd=work, env=env, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"{page.name}: its commands failed:\n{proc.stderr[-3000:]}")
    return proc.stdout


def _period_doubling(work: Path) -> dict[str, str]:
    """Where the stability-chart how-to's branch (its first command) has its period doubling."""
    import gearchaos as gc

    run(SOURCES["period-doubling"].command or "", work)
    branch = gc.open_branch(work / "branch.nc")
    found = [
        float(v)
        for v, k in zip(branch.event_value.values, branch.event_kind.values, strict=True)
        if str(k) == "period_doubling"
    ]
    if not found:
        raise ProseOutOfDate("stability-chart.md: the branch no longer has a period doubling")
    return {"omega": f"{found[0]:.3f}"}


def _quick(_: Path) -> dict[str, str]:
    """The coarse protocol of ``gearchaos reproduce --quick`` (:mod:`gearchaos.paper.recipes`)."""
    from gearchaos.paper.recipes import QUICK_PERIODS, QUICK_POINTS

    transient, periods = QUICK_PERIODS
    return {"points": str(QUICK_POINTS), "transient": f"{transient:g}", "periods": str(periods)}


def _cascade(work: Path) -> dict[str, str]:
    """The period doublings of the cascade how-to's branches (its first block, as the page
    shows it): the one each branch of the cascade ends at, in the order of the cascade."""
    from gearchaos.dynamics.continuation.cascade import open_cascade

    if not (work / "cascade.nc").exists():
        run_howto(CASCADE, work, ("cascade.png",))
    pds = []
    for branch in open_cascade(work / "cascade.nc"):
        kinds = [str(k) for k in branch.event_kind.values]
        values = [float(v) for v, k in zip(branch.event_value.values, kinds, strict=True)]
        found = [v for v, k in zip(values, kinds, strict=True) if k == "period_doubling"]
        if found:
            pds.append(found[0])
    steps = [a - b for a, b in itertools.pairwise(pds)]
    if len(pds) != 4 or not all(d > 0 for d in steps) or sorted(steps, reverse=True) != steps:
        raise ProseOutOfDate(
            "cascade-and-impact.md says four period doublings, each beyond the one before at "
            f"shrinking distances: the cascade now gives {pds}"
        )
    return {f"pd{k + 1}": f"{v:.4f}" for k, v in enumerate(pds)}


def _maps(work: Path) -> dict[str, str]:
    """The 2-D map of the maps how-to (its commands, run as the page shows them): how many
    points, and the share of chaotic points at the lowest and the highest damping."""
    import numpy as np

    import gearchaos as gc

    if not (work / "map.zarr").exists():  # (already there when the figure was just made)
        run_howto(MAPS, work)
    ds = gc.open_sweep(work / "map.zarr")
    xi = np.asarray(ds["xi"].values, dtype=float)
    chaos = (ds["motion"].astype(str) == "chaos").mean("omega").values
    lo, hi = int(np.argmin(xi)), int(np.argmax(xi))
    if not chaos[hi] < chaos[lo]:
        raise ProseOutOfDate(
            f"maps.md says damping shrinks the chaotic region: {100 * chaos[lo]:.0f} % chaotic at "
            f"ξ = {xi[lo]:g}, {100 * chaos[hi]:.0f} % at ξ = {xi[hi]:g}"
        )
    return {
        "points": str(int(ds["motion"].size)),
        "omega.points": str(int(ds.sizes["omega"])),
        "xi.lo": f"{xi[lo]:g}",
        "xi.hi": f"{xi[hi]:g}",
        "chaos.lo": f"{round(chaos[lo] * ds.sizes['omega'])}",
        "chaos.hi": f"{round(chaos[hi] * ds.sizes['omega'])}",
    }


def _runs(labels: list[str], accept: Callable[[str], bool]) -> list[tuple[int, int]]:
    """Maximal runs [i, j] (inclusive) of neighbours whose label ``accept`` takes."""
    out: list[tuple[int, int]] = []
    start = None
    for k, label in enumerate([*labels, ""]):
        if k < len(labels) and accept(label):
            start = k if start is None else start
        elif start is not None:
            out.append((start, k - 1))
            start = None
    return out


def _hysteresis(work: Path) -> dict[str, str]:
    """The up/down sweeps of the hysteresis how-to (its commands, run as the page shows them):
    where the up branch holds the 1T orbit, where the down branch, coming from above, drops
    onto it, what it is on before, and the range where both exist."""
    import numpy as np

    import gearchaos as gc

    if not (work / "hysteresis.zarr").exists():
        run_howto(HYSTERESIS, work)
    ds = gc.open_sweep(work / "hysteresis.zarr")
    omega = np.asarray(ds["omega"].values, dtype=float)
    up = [str(v) for v in ds["motion"].sel(direction="up").values]
    down = [str(v) for v in ds["motion"].sel(direction="down").values]
    ones = _runs(up, lambda m: m == "1T")
    if not ones:
        raise ProseOutOfDate("hysteresis.md: the up sweep no longer holds a 1T orbit")
    i, j = max(ones, key=lambda r: r[1] - r[0])  # the 1T orbit the up sweep lands on
    held = [r for r in _runs(down, lambda m: m == "1T") if r[0] <= j and r[1] >= i]
    if not held:
        raise ProseOutOfDate("hysteresis.md: the down sweep never drops onto the up's 1T orbit")
    top = max(held, key=lambda r: r[1] - r[0])[1]  # where the down sweep drops onto it
    if not top < j:
        raise ProseOutOfDate(
            f"hysteresis.md: the down sweep holds the 1T orbit up to Ω = {omega[top]:.2f}, "
            f"as far as the up sweep ({omega[j]:.2f}): no hysteresis"
        )
    above = down[top + 1 : j + 1]  # both sweeps here: up on 1T, down on what?
    irregular = [m for m in above if m in ("QP", "chaos")]
    if len(irregular) < 0.75 * len(above):
        raise ProseOutOfDate(
            f"hysteresis.md: over Ω = {omega[top + 1]:.2f} … {omega[j]:.2f} the down sweep is "
            f"{above}, not mostly quasi-periodic or chaotic"
        )
    names = (("QP", "quasi-periodic"), ("chaos", "chaotic"))
    x = ds["delta_sp"].sel(direction="up", planet=1).isel(omega=slice(i, j + 1))
    return {
        "up.lo": f"{omega[i]:.2f}",
        "up.hi": f"{omega[j]:.2f}",
        "up.mean": f"{float(x.mean()):.2f}",
        "down.kind": " and ".join(w for m, w in names if m in irregular),
        "down.lo": f"{omega[top + 1]:.2f}",
        "down.drop": f"{omega[top]:.2f}",
    }


def _ranges(omega: Any, runs: list[tuple[int, int]]) -> str:
    """``0.70–1.04 and 1.16–2.20`` (a run of one value as that value)."""
    parts = [f"{omega[i]:.2f}" if i == j else f"{omega[i]:.2f}–{omega[j]:.2f}" for i, j in runs]
    return ", ".join(parts[:-1]) + (" and " if len(parts) > 1 else "") + parts[-1]


def _response(work: Path) -> dict[str, str]:
    """The frequency response of the response how-to (its commands, as the page shows them):
    the chaotic ranges of both sweeps, where one is periodic and the other not (nothing shaded
    there), and that every point is decided."""
    import numpy as np

    import gearchaos as gc
    from gearchaos.plot import response_figure

    if not (work / "response.zarr").exists():
        run_howto(RESPONSE, work)
    ds = gc.open_sweep(work / "response.zarr")
    omega = np.asarray(ds["omega"].values, dtype=float)
    labels = {d: [str(v) for v in ds["motion"].sel(direction=d).values] for d in ("up", "down")}
    every = sorted({m for m in labels["up"] + labels["down"]}, key=_label_order)
    if any(m in ("unresolved", "failed", "") for m in every):
        raise ProseOutOfDate(f"response.md says every point is decided: the labels are {every}")
    periodic = {d: [m.endswith("T") for m in ms] for d, ms in labels.items()}
    differ = _runs(
        [str(u != v) for u, v in zip(periodic["up"], periodic["down"], strict=True)],
        lambda t: t == "True",
    )
    if not differ or any(
        not (periodic["up"][k] and labels["down"][k] == "chaos") for i, j in differ
        for k in range(i, j + 1)
    ):  # fmt: skip
        raise ProseOutOfDate(
            "response.md says the branches differ where the up sweep is periodic and the down "
            f"sweep chaotic: up {labels['up']}, down {labels['down']}"
        )
    fig = response_figure(ds)
    if any(c.get_gid() == "hysteresis" for ax in fig.axes for c in ax.collections):
        raise ProseOutOfDate("response.md says nothing is shaded: the figure shades hysteresis")
    chaos = {d: _runs(ms, lambda m: m == "chaos") for d, ms in labels.items()}
    return {
        "chaos.up": _ranges(omega, chaos["up"]),
        "chaos.down": _ranges(omega, chaos["down"]),
        "differ": _ranges(omega, differ),
        "points": str(int(ds["motion"].size)),
        "labels": ", ".join(every[:-1]) + " or " + every[-1] if len(every) > 1 else every[0],
    }


def _label_order(label: str) -> tuple[int, int]:
    """nT by n, then QP, then chaos."""
    if label.endswith("T") and label[:-1].isdigit():
        return (0, int(label[:-1]))
    return (1, ("QP", "chaos").index(label) if label in ("QP", "chaos") else 2)


def _rattle(work: Path) -> dict[str, str]:
    """The rattle how-to's commands, run as the page shows them (its bash blocks, in a fresh
    directory), and what its table and its prose say about the store they write."""
    import numpy as np

    import gearchaos as gc
    from gearchaos.model.derived import gearset_info
    from gearchaos.plot.units import PhysicalScales
    from gearchaos.sweep import SweepResult, contact_ranges
    from gearchaos.sweep.spec import RESPONSE_SOLVER

    stdout = run_howto(RATTLE, work)
    res = SweepResult(gc.open_sweep(work / "rattle.zarr"))
    ranges = contact_ranges(res)
    scales = PhysicalScales.of_sweep(res)
    rpm, newton = scales.factor("omega"), scales.factor("force")
    if rpm is None or newton is None:
        raise ProseOutOfDate("the rattle store has no sun speed or force scale")

    def onset(direction: str) -> tuple[float, list[str]]:
        loud = [r for r in ranges if r.direction == direction and r.regime != "none"]
        if not loud:
            raise ProseOutOfDate(f"no mesh separates sweeping {direction} (rattle.md, step 3)")
        first = min(r.start for r in loud)
        return first, [r.mesh for r in loud if r.start == first]

    up, up_meshes = onset("up")
    down, _ = onset("down")
    if not down < up:
        raise ProseOutOfDate(
            "rattle.md says the run-down rattles below the run-up's first separation: "
            f"up from Ω = {up:g}, down from Ω = {down:g}"
        )
    ds = res.ds
    best = (-1.0, "", "", 0.0, 0.0)
    for key, mesh in (("sp", "sun_planet"), ("rp", "planet_ring")):
        peak = ds[f"force_peak_{key}"].max("planet_all")
        for direction in ("up", "down"):
            y = np.asarray(peak.sel(direction=direction).values, dtype=float)
            k = int(np.nanargmax(y))
            if y[k] > best[0]:
                factor = float(ds[f"load_factor_{key}"].sel(direction=direction).values[k])
                best = (float(y[k]), mesh, direction, float(ds.omega.values[k]), factor)
    force, mesh, direction, omega, factor = best
    words = {"sun_planet": "sun–planet", "planet_ring": "planet–ring"}
    static = gearset_info(res.gearset)["static_mesh_force_N"]
    return {
        "table": titled_table(stdout, "contact regimes of rattle.zarr"),
        "transient": f"{RESPONSE_SOLVER.transient_periods:g}",
        "periods": f"{RESPONSE_SOLVER.periods:d}",
        "up.rpm": f"{up * rpm[0]:.0f}",
        "up.meshes": " and ".join(words[m] for m in sorted(set(up_meshes), reverse=True)),
        "down.rpm": f"{down * rpm[0]:.0f}",
        "peak.N": f"{force * newton[0]:.0f}",
        "peak.mesh": words[mesh],
        "peak.rpm": f"{omega * rpm[0]:.0f}",
        "peak.direction": direction,
        "peak.factor": f"{factor:.1f}",
        "static": f"{static:.0f}",
    }


_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def power_text(value: float) -> str:
    """``10⁻⁴`` for an exact power of ten, else the number as Python writes it shortest."""
    if value > 0 and float(f"1e{round(math.log10(value))}") == value:
        return "10" + str(round(math.log10(value))).translate(_SUPERSCRIPT)
    return f"{value:g}"


def _verdict_settings(_: Path) -> dict[str, str]:
    """The verdict's tolerances, windows and budgets as the docs state them: the defaults of
    :class:`~gearchaos.dynamics.verdict.decide.VerdictSettings` and the constants its rules use."""
    from gearchaos.analysis.bands import MIN_BAND_POINTS
    from gearchaos.analysis.chaos01 import MIN_LENGTH
    from gearchaos.analysis.classify import K_CHAOS, K_REGULAR
    from gearchaos.dynamics.orbits.stability import FREE_TOL, STRUCTURAL_TOL
    from gearchaos.dynamics.verdict.decide import CONFIRM_PERIODS, VerdictSettings
    from gearchaos.dynamics.verdict.periodic import MEASURE_FALL, MEASURE_TARGET
    from gearchaos.dynamics.verdict.rules import K01_STRIDES, MAX_RETURN, MIN_ORDER, MIN_RETURN

    vs = VerdictSettings()
    windows = [vs.min_extension]  # a record of min_extension periods (a sweep's)
    while sum(windows) + (nxt := vs.next_window(windows[-1], len(windows))) <= vs.budget_periods:
        windows.append(nxt)
    return {
        "max_period": str(vs.max_period),
        "longest_period": str(vs.longest_period),
        "qp_record": str(2 * vs.longest_period),
        "period_rtol": power_text(vs.period_rtol),
        "noise_factor": power_text(vs.noise_factor),
        "margin": power_text(vs.margin),
        "structural_tol": power_text(STRUCTURAL_TOL),
        "free_tol": power_text(FREE_TOL),
        "same_orbit": f"{100 * vs.same_orbit:g} %",
        "reach": power_text(vs.reach),
        "approach": f"{100 * vs.approach:g} %",
        "min_extension": str(vs.min_extension),
        "max_window": str(vs.max_window),
        "budget_periods": str(vs.budget_periods),
        "windows": " + ".join(str(w) for w in windows),
        "windows_total": str(sum(windows)),
        "settle_budget": str(vs.settle_budget),
        "measure_fall": f"{math.exp(MEASURE_FALL):.6g}",
        "measure_target": f"{math.exp(MEASURE_TARGET):.6g}",
        "confirm_periods": str(CONFIRM_PERIODS),
        "max_bands": str(vs.max_bands),
        "strides": f"{min(K01_STRIDES)}–{max(K01_STRIDES)}",
        "min_order": f"{100 * MIN_ORDER:g} %",
        "max_return": f"{100 * MAX_RETURN:g} %",
        "min_return": power_text(MIN_RETURN),
        "band_points": str(MIN_BAND_POINTS),
        "k01_points": str(MIN_LENGTH),
        "k_chaos": f"{K_CHAOS:g}",
        "k_regular": f"{K_REGULAR:g}",
        "blocks": str(vs.blocks),
        "confidence": f"{vs.confidence:g}",
        "lle_c": f"{vs.lle_c:g}",
        "newton_tol": power_text(vs.newton_tol),
    }


def _report(_: Path) -> dict[str, str]:
    """Counts and run time of the committed report (``docs/report/report.json``), counted by
    the report's own code (:func:`gearchaos.paper.accounting.verdict_counts`): keys
    ``PART.VERDICT`` (``landmarks.holds``, ``landmarks.holds-constant`` — a hold where the
    swept parameter does not act, counted apart —, ``conclusions.does-not-hold`` …),
    ``PART.total``, ``PART.VERDICT-ids`` (the ids with that verdict; ``PART.not-ids`` those that
    do not hold) and the paper-protocol column as ``landmarks-paper.VERDICT``."""
    from gearchaos.paper.accounting import verdict_counts
    from gearchaos.paper.conclusions import VERDICTS as CONCLUSION_VERDICTS

    report = json.loads(REPORT.read_text(encoding="utf-8"))
    values: dict[str, str] = {"seconds": f"{report['seconds']:.0f}"}
    columns = {
        "landmarks": ("landmarks", "verdict", None),
        "landmarks-paper": ("landmarks", "paper_verdict", None),
        "conclusions": ("conclusions", "verdict", CONCLUSION_VERDICTS),
    }
    for part, (rows, key, order) in columns.items():
        verdicts = [str(item.get(key, "not evaluated")) for item in report[rows]]
        counts = verdict_counts(verdicts) if order is None else verdict_counts(verdicts, order)
        values[f"{part}.total"] = str(len(verdicts))
        for verdict, n in counts.items():
            values[f"{part}.{_slug(verdict)}"] = str(n)
            values[f"{part}.{_slug(verdict)}-ids"] = ", ".join(
                str(item["id"]) for item in report[rows] if item.get(key) == verdict
            )
        values[f"{part}.not-ids"] = ", ".join(
            str(item["id"]) for item in report[rows] if item.get(key) == "does not hold"
        )
    if values["conclusions.not-ids"] != "3, 7":
        raise ProseOutOfDate(
            "README ('Reproducing the paper') explains why conclusions 3 and 7 do not hold; the "
            f"report now says conclusions {values['conclusions.not-ids'] or 'none'} do not"
        )
    return values


#: Source name → the command whose output it reads (None: a committed file).
SOURCES: dict[str, Source] = {
    "quickstart": Source(
        "gearchaos simulate --preset sheng2016 --set omega=1.5 -o out/", _quickstart
    ),
    "chaos-point": Source("gearchaos simulate --set xi=0.03 --set omega=2.7", _lyapunov),
    "gallery": Source(
        "gearchaos poincare --set xi=0.03 --vary omega=0.81,0.88,2.7,3.02 --with phase "
        "-o gallery.png",
        _gallery,
    ),
    "continue": Source(
        "gearchaos continue --from orbit.nc --vary omega=1.5:1.8 -o branch.nc", _continuation
    ),
    "attractors": Source("gearchaos attractors --set omega=1.5", _attractors),
    "fig4a": Source(
        "gearchaos bifurcation --vary omega=0.05:4:800 --set xi=0.03 -o fig4a.zarr",
        _fig4a,
        slow=True,
    ),
    "report": Source(None, _report),
    "calibration": Source(None, lambda _: calibration_values()),
    "verdict": Source(None, _verdict_settings),
    "rattle": Source(
        "gearchaos plot rattle.zarr --contact --table -o rattle.png", _rattle, slow=True
    ),
    "map": Source(
        "gearchaos bifurcation --preset sheng2016-v1 --vary omega=0.5:3.5:31 --vary xi=0.03:0.11:5 "
        "-o map.zarr",
        _maps,
        slow=True,
    ),
    "quick": Source(None, _quick),
    "period-doubling": Source(
        "gearchaos continue --preset sheng2016-v1 --vary omega=3.3:3.45 -o branch.nc",
        _period_doubling,
        slow=True,
    ),
    "response": Source("gearchaos plot response.zarr -o response.png", _response, slow=True),
    "cascade": Source("gearchaos plot cascade.nc -o cascade.png", _cascade),
    "hysteresis": Source(
        "gearchaos plot hysteresis.zarr -o hysteresis.png", _hysteresis, slow=True
    ),
}


# ---------------------------------------------------------------------- the pages
def markers(text: str) -> list[tuple[str, str, str]]:
    """``(source, key, format)`` of every marker of a page, in order."""
    out = []
    for m in MARK.finditer(text):
        name, _, fmt = m["name"].partition("|")
        source, _, key = name.partition(".")
        out.append((source, key, fmt))
    return out


def shows_command(text: str, command: str) -> bool:
    """Whether the page shows ``command`` verbatim (in a code block or inline code, with or
    without the ``.venv/bin/`` prefix)."""
    pattern = rf"(?:^|`)(?:\s*)(?:\.venv/bin/)?{re.escape(command)}(?:$|`)"
    return re.search(pattern, text, flags=re.M) is not None


def compute(sources: list[str]) -> dict[str, dict[str, str]]:
    """Run each source once (in its own temporary directory); source → key → value."""
    values = {}
    for name in sources:
        with tempfile.TemporaryDirectory(prefix=f"doc-numbers-{name}-") as tmp:
            values[name] = SOURCES[name].produce(Path(tmp))
    return values


def _formatted(value: str, fmt: str) -> str:
    return format(float(value), fmt) if fmt else value


def render(text: str, values: dict[str, dict[str, str]]) -> str:
    """``text`` with every marker of a computed source filled in."""

    def fill(m: re.Match[str]) -> str:
        name, _, fmt = m["name"].partition("|")
        source, _, key = name.partition(".")
        if source not in values:
            return m.group(0)
        if key not in values[source]:
            raise ProseOutOfDate(
                f"gen:{m['name']}: {source} gives no {key!r} (it gives {sorted(values[source])})"
            )
        value = values[source][key]
        if isinstance(value, Block):
            body = f"\n\n```text\n{value}```\n\n"
        elif isinstance(value, Markdown):
            body = f"\n\n{value}\n\n"
        else:
            body = _formatted(value, fmt)
        return f"<!-- gen:{m['name']} -->{body}<!-- /gen -->"

    return MARK.sub(fill, text)


def problems(page: Path, text: str, values: dict[str, dict[str, str]]) -> list[str]:
    """Unknown sources, commands the page does not show, and numbers that differ from
    what the code gives now."""
    found = []
    for source, key, _ in markers(text):
        if source not in SOURCES:
            found.append(f"{page.name}: gen:{source}.{key}: no such source")
        elif (cmd := SOURCES[source].command) and not shows_command(text, cmd):
            found.append(f"{page.name}: gen:{source}.{key}: the page does not show {cmd!r}")
    want = render(text, values)
    old = {m.start(): m.group(0) for m in MARK.finditer(text)}
    new = [m.group(0) for m in MARK.finditer(want)]
    for (_, before), after in zip(sorted(old.items()), new, strict=True):
        if before != after:
            found.append(f"{page.name}: shows {before!r}, the code gives {after!r}")
    return found


def used_sources(pages: tuple[Path, ...] = PAGES) -> list[str]:
    names = {s for page in pages for s, _, _ in markers(page.read_text(encoding="utf-8"))}
    return [name for name in SOURCES if name in names]


def main(argv: list[str]) -> int:
    check, fast = "--check" in argv, "--fast" in argv
    only = next((a.split("=", 1)[1].split(",") for a in argv if a.startswith("--only=")), None)
    if only is not None and (unknown := sorted(set(only) - set(SOURCES))):
        raise SystemExit(f"--only: unknown sources {unknown}; known: {sorted(SOURCES)}")
    names = [
        n for n in used_sources() if not (fast and SOURCES[n].slow) and (only is None or n in only)
    ]
    values = compute(names)
    stale = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        stale += problems(page, text, values)
        if not check and (new := render(text, values)) != text:
            page.write_text(new, encoding="utf-8")
            print(f"rewrote {page.relative_to(ROOT)}")
    if check:
        print("\n".join(stale) or "every generated number is current")
        return 1 if stale else 0
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
