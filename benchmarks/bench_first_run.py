"""Benchmark (issue 35): the README's quick start in a fresh numba cache, first and second run.

Run as ``python benchmarks/bench_first_run.py [-n N] [--src SRC ...] [--baseline REV]``.

The command is the one in README.md's "Quick start" section (``gearchaos simulate --preset
sheng2016 --set omega=1.5 -o out/``), run as the README says — the ``gearchaos`` command line in
its own process, writing ``out/`` in a fresh working directory — but with the package imported
from a given ``src/`` (a child process with ``PYTHONPATH=src``, see ``child.py``), so that a
baseline checkout can be compared with this tree. ``--command "simulate …"`` times another
command line instead.

Each repetition, for each ``src``:

1. **first run**: ``NUMBA_CACHE_DIR`` is a new, empty temporary directory (numba otherwise keeps
   its cache in ``__pycache__`` beside the sources, and every kernel of gearchaos is
   ``cache=True``). The directory is checked to be empty before and to hold cache files
   (``.nbi``/``.nbc``) after, and the run to have compiled at least one kernel: a first run that
   only loaded from some other cache is an error, not a measurement;
2. **second run**: the same command with that cache, now warm (a kernel it compiles again is
   listed: it is not loaded from the cache).

Printed: wall seconds of each run as the user sees them (process start to exit) and the child's
CPU seconds (user + system) — min, median and max over the repetitions, and the ratio first /
second; per run, where the time goes (importing gearchaos, time under numba's compiler lock =
compiling and saving, or loading from the cache, the rest: simulation, analysis, figure and
file); and the kernels the first run compiles (numba's ``numba:compile`` events, one per
dispatcher and signature), median over the repetitions, sorted: seconds of each, its own
(``self``, without the kernels compiled while typing it; wall, CPU of the compiling thread and
the part of that under llvmlite's lock, i.e. LLVM rather than numba's own passes) and with them
(``total``, outermost compiles only: they add up to the compile time); then the signatures of
the gearchaos kernels compiled more than once.

Goal (issue 35): first run ≤ 15 s wall on a quiet 2-core machine. Wall times depend on the load
(printed with them); compiling is single-threaded, so on a loaded machine the CPU seconds are
the better estimate of the quiet machine's wall seconds.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import shlex
import statistics
import subprocess
import tempfile
import time
from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from child import run_child

ROOT = Path(__file__).resolve().parents[1]
GOAL_FIRST_S = 15.0

# ----------------------------------------------------------------------------- child: one run
# Installs listeners for numba's compile events, then runs the command line as the
# `gearchaos` console script does (`gearchaos.cli:app`), in this process.
_RUN_CHILD = r"""
import json, os, sys, threading, time
from collections import defaultdict
from numba.core import event
spec = json.loads(sys.argv[1])
os.chdir(spec["cwd"])
stacks = defaultdict(list)
compiles = []

class Compiles(event.Listener):
    def on_start(self, ev):
        stacks[threading.get_ident()].append(
            [time.perf_counter(), time.thread_time(), 0.0, 0.0, 0.0])

    def on_end(self, ev):
        stack = stacks[threading.get_ident()]
        t0, c0, inner, inner_cpu, llvm = stack.pop()
        total = time.perf_counter() - t0
        cpu = time.thread_time() - c0
        if stack:
            stack[-1][2] += total
            stack[-1][3] += cpu
        f = ev.data["dispatcher"].py_func
        exc = getattr(ev, "_exc_details", None)
        compiles.append({
            "kernel": f"{f.__module__}.{f.__qualname__}",
            "args": ", ".join(str(a) for a in ev.data["args"]),
            "total": total, "self": total - inner, "depth": len(stack),
            "total_cpu": cpu, "self_cpu": cpu - inner_cpu, "self_llvm_cpu": llvm,
            "failed": bool(exc and exc[0] is not None),
        })

llvm_outside = [0.0]
llvm_start = {}

class LLVM(event.Listener):  # llvmlite's lock: LLVM's work (optimising, emitting code)
    def on_start(self, ev):
        llvm_start[threading.get_ident()] = time.thread_time()

    def on_end(self, ev):
        tid = threading.get_ident()
        cpu = time.thread_time() - llvm_start.pop(tid, time.thread_time())
        if stacks[tid]:
            stacks[tid][-1][4] += cpu
        else:
            llvm_outside[0] += cpu

lock = event.TimingListener()
event.register("numba:compile", Compiles())
event.register("numba:llvm_lock", LLVM())
event.register("numba:compiler_lock", lock)
t0 = time.perf_counter()
import gearchaos
from gearchaos.cli import app
t_import = time.perf_counter() - t0
code = 0
sys.argv = ["gearchaos", *spec["args"]]
try:
    app(prog_name="gearchaos")
except SystemExit as e:
    code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
if code != 0:
    sys.exit(f"gearchaos {' '.join(spec['args'])} exited with {code}")
out = {"file": gearchaos.__file__, "import": t_import, "lock": lock.duration,
       "after_import": time.perf_counter() - t0 - t_import, "compiles": compiles,
       "llvm_outside_cpu": llvm_outside[0]}
print("RESULT" + json.dumps(out))
"""


def quickstart_args(readme: Path = ROOT / "README.md") -> list[str]:
    """The arguments of the ``gearchaos`` command in README.md's "Quick start" section (its
    first ``gearchaos`` line in a code block)."""
    text = readme.read_text(encoding="utf-8")
    section = re.search(r"^## Quick start\s*$(.*?)(?=^## )", text, re.M | re.S)
    if section is None:
        raise ValueError(f"{readme} has no '## Quick start' section")
    for block in re.findall(r"^```[a-z]*\n(.*?)^```", section.group(1), re.M | re.S):
        for line in block.splitlines():
            words = shlex.split(line)
            if words and Path(words[0]).name == "gearchaos":
                return words[1:]
    raise ValueError(f"{readme}'s Quick start section has no code line starting 'gearchaos'")


def cache_files(directory: Path) -> list[Path]:
    """numba's cache files (index ``.nbi``, code ``.nbc``) under ``directory``."""
    if not directory.exists():
        return []
    return sorted(p for p in directory.rglob("*") if p.suffix in (".nbi", ".nbc"))


def timed_run(src: Path, args: Sequence[str], cache: Path, cwd: Path) -> dict[str, Any]:
    """One run of ``gearchaos ARGS`` importing from ``src``, numba's cache in ``cache``, in the
    working directory ``cwd``: the child's result plus ``wall`` (process start to exit) and
    ``cpu`` (the child's user + system seconds, which the machine's load inflates far less)."""
    cwd.mkdir(parents=True)
    spec = {"args": list(args), "cwd": str(cwd)}
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    out = run_child(_RUN_CHILD, spec, src, NUMBA_CACHE_DIR=str(cache))
    out["wall"] = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    out["cpu"] = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    return out


def first_and_second(src: Path, args: Sequence[str], tmp: Path) -> tuple[dict[str, Any], ...]:
    """The first run in a fresh numba cache and the second with it warm; checks that the first
    really compiled (empty cache before, cache files and compile events after)."""
    cache = tmp / "numba-cache"
    if cache_files(cache):
        raise RuntimeError(f"the fresh numba cache {cache} already holds cache files")
    first = timed_run(src, args, cache, tmp / "run1")
    written = cache_files(cache)
    compiled = [c for c in first["compiles"] if not c["failed"]]
    if not written or not compiled:
        raise RuntimeError(
            f"the first run did not compile into the fresh NUMBA_CACHE_DIR ({len(compiled)} "
            f"kernels compiled, {len(written)} cache files written to {cache})"
        )
    first["cache_files"] = len(written)
    second = timed_run(src, args, cache, tmp / "run2")
    return first, second


def _stats(xs: Sequence[float]) -> str:
    return f"{min(xs):6.2f} {statistics.median(xs):6.2f} {max(xs):6.2f}"


Row = tuple[str, int, float, float, float, float, float]
_KEYS = ("self", "self_cpu", "self_llvm_cpu", "total", "total_cpu")


def kernel_table(runs: Sequence[dict[str, Any]]) -> list[Row]:
    """(kernel, specialisations per run, then medians over ``runs`` of: self wall seconds, self
    CPU seconds of the compiling thread, the part of them under llvmlite's lock (LLVM
    optimising and emitting code), total wall and CPU seconds of its outermost compiles),
    sorted by self CPU seconds, largest first. *Self*: without the kernels compiled while
    typing it; *total*: with them."""
    width = 1 + len(_KEYS)
    per_run: list[dict[str, list[float]]] = []
    for r in runs:
        agg: dict[str, list[float]] = defaultdict(lambda: [0.0] * width)
        for c in r["compiles"]:
            row = agg[c["kernel"]]
            row[0] += 1
            for i, key in enumerate(_KEYS, 1):
                row[i] += c[key] if key.startswith("self") or c["depth"] == 0 else 0.0
        per_run.append(agg)
    rows: list[Row] = []
    for k in {k for agg in per_run for k in agg}:
        vals = [agg.get(k, [0.0] * width) for agg in per_run]
        med = [statistics.median(v[i] for v in vals) for i in range(width)]
        rows.append((k, int(med[0]), med[1], med[2], med[3], med[4], med[5]))
    return sorted(rows, key=lambda r: -r[3])


def baseline_src(rev: str) -> Path:
    """``src/`` of a git worktree of ``rev`` (kept in ``$TMPDIR`` for the next run, as
    ``bench_speed.py`` does)."""
    wt = Path(tempfile.gettempdir()) / f"gearchaos-bench-baseline-{rev}"
    if not (wt / "src").is_dir():
        subprocess.run(
            ["git", "-C", str(ROOT), "worktree", "add", "--detach", str(wt), rev],
            check=True, capture_output=True,
        )  # fmt: skip
    return wt / "src"


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(
        prog="bench_first_run.py",
        description=(__doc__ or "").splitlines()[0],
        epilog="Not a test: prints wall times, which depend on the machine and its load.",
    )
    ap.add_argument(
        "-n", "--repeat", type=int, default=3, metavar="N",
        help="repetitions, each a first run in a fresh cache and a second run (default 3)",
    )  # fmt: skip
    ap.add_argument(
        "--src", type=Path, action="append", metavar="SRC",
        help="a src/ directory to import gearchaos from (repeatable; default this tree's src/)",
    )  # fmt: skip
    ap.add_argument(
        "--baseline", metavar="REV",
        help="also time the git revision REV (a worktree in $TMPDIR, kept for the next run)",
    )  # fmt: skip
    ap.add_argument(
        "--command", metavar="ARGS",
        help="the gearchaos arguments to time, one string (default: README's quick start)",
    )  # fmt: skip
    ap.add_argument(
        "--json", type=Path, metavar="FILE",
        help="also write every run's measurements (each compile with its signature) to FILE",
    )  # fmt: skip
    ap.add_argument(
        "--kernels", type=int, default=25, metavar="K",
        help="rows of the per-kernel table (default 25; 0 for all)",
    )  # fmt: skip
    args = ap.parse_args(argv)
    if args.repeat < 1:
        ap.error(f"-n/--repeat must be >= 1: got {args.repeat}")
    if args.kernels < 0:
        ap.error(f"--kernels must be >= 0: got {args.kernels}")
    for src in args.src or []:
        if not (src / "gearchaos" / "__init__.py").is_file():
            ap.error(f"--src must be a directory holding gearchaos/__init__.py: got {src}")
    return args


def main(argv: Sequence[str] | None = None) -> None:
    args = parse_args(argv)
    cmd = shlex.split(args.command) if args.command else quickstart_args()
    srcs: dict[str, Path] = {str(s): s.resolve() for s in args.src or [ROOT / "src"]}
    if args.baseline:
        srcs[f"baseline {args.baseline}"] = baseline_src(args.baseline)
    print(f"bench_first_run: gearchaos {shlex.join(cmd)}; {args.repeat} repetitions; "
          f"{os.cpu_count()} cores; load {os.getloadavg()[0]:.1f}")  # fmt: skip
    results: dict[str, list[tuple[dict[str, Any], dict[str, Any]]]] = {k: [] for k in srcs}
    for rep in range(args.repeat):
        for name, src in srcs.items():  # alternated, so that drifting load hits each alike
            with tempfile.TemporaryDirectory(prefix="gearchaos-first-run-") as d:
                first, second = first_and_second(src, cmd, Path(d))
            results[name].append((first, second))
            print(f"  {rep + 1}/{args.repeat} {name}: first {first['wall']:.2f} s wall, "
                  f"{first['cpu']:.2f} s CPU ({len(first['compiles'])} compiles, "
                  f"{first['cache_files']} cache files), second {second['wall']:.2f} s wall, "
                  f"{second['cpu']:.2f} s CPU; load {os.getloadavg()[0]:.1f}")  # fmt: skip

    if args.json:
        args.json.write_text(json.dumps({"command": cmd, "results": results}, indent=1))
    for name, runs in results.items():
        report(name, runs, args.kernels)


def report(name: str, runs: Sequence[tuple[dict[str, Any], dict[str, Any]]], rows: int) -> None:
    """Print the wall and CPU seconds of the first and second runs of one ``src`` and the
    table of the kernels its first runs compiled (``rows`` of them, 0 for all)."""
    firsts, seconds = [r[0] for r in runs], [r[1] for r in runs]
    w1, w2 = [r["wall"] for r in firsts], [r["wall"] for r in seconds]
    print(f"\n{name}: {firsts[0]['file']}")
    print(f"  {'seconds (min median max)':34s} {'wall':^20s}   {'CPU (user + sys)':^20s}")
    for label, rs in (("first run (fresh cache)", firsts), ("second run (warm)", seconds)):
        print(f"  {label:34s} {_stats([r['wall'] for r in rs])}   {_stats([r['cpu'] for r in rs])}")
        print(f"    {'import gearchaos':32s} {_stats([r['import'] for r in rs])}")
        print(f"    {'under numba compiler lock':32s} {_stats([r['lock'] for r in rs])}")
        rest = [r["after_import"] - r["lock"] for r in rs]
        print(f"    {'rest (run, analysis, output)':32s} {_stats(rest)}")
    ratio = [a / b for a, b in zip(w1, w2, strict=True)]
    cpu_ratio = [a["cpu"] / b["cpu"] for a, b in zip(firsts, seconds, strict=True)]
    print(f"  {'ratio first / second':34s} {_stats(ratio)}   {_stats(cpu_ratio)}")
    verdict = "meets" if statistics.median(w1) <= GOAL_FIRST_S else "misses"
    print(f"  median first run {statistics.median(w1):.2f} s wall {verdict} the goal "
          f"≤ {GOAL_FIRST_S:g} s (on a quiet 2-core machine; this one: load above)")  # fmt: skip
    again = sorted({c["kernel"] for r in seconds for c in r["compiles"]})
    if again:
        print(f"  compiled again in a second run (not loaded from the cache): {again}")

    table = kernel_table(firsts)
    outer = [[c for c in r["compiles"] if c["depth"] == 0] for r in firsts]
    wall_s = statistics.median(sum(c["total"] for c in o) for o in outer)
    cpu_s = statistics.median(sum(c["total_cpu"] for c in o) for o in outer)
    llvm_s = statistics.median(sum(c["self_llvm_cpu"] for c in r["compiles"]) for r in firsts)
    failed = statistics.median(sum(c["failed"] for c in r["compiles"]) for r in firsts)
    print(f"\n  kernels compiled by the first run (numba:compile events, medians): {len(table)} "
          f"kernels, {statistics.median(len(r['compiles']) for r in firsts):.0f} compiles, "
          f"{wall_s:.2f} s wall, {cpu_s:.2f} s CPU in all, {llvm_s:.2f} s of it in LLVM; "
          f"{failed:.0f} compile attempts ended in an exception")  # fmt: skip
    print(f"  {'kernel':52s} {'n':>2s} {'self wall':>9s} {'self CPU':>8s} {'of it LLVM':>10s} "
          f"{'total wall':>10s} {'total CPU':>9s}")  # fmt: skip
    shown = table if rows == 0 else table[:rows]
    for kernel, n, self_w, self_c, llvm_c, total_w, total_c in shown:
        totals = f"{total_w:10.2f} {total_c:9.2f}" if total_w > 0 else f"{'-':>10s} {'-':>9s}"
        print(f"  {kernel[-52:]:52s} {n:2d} {self_w:9.2f} {self_c:8.2f} {llvm_c:10.2f} {totals}")
    if len(shown) < len(table):
        rest_w = sum(r[2] for r in table[len(shown) :])
        rest_c = sum(r[3] for r in table[len(shown) :])
        print(f"  … {len(table) - len(shown)} more kernels, {rest_w:.2f} s wall, {rest_c:.2f} s "
              "CPU self in all")  # fmt: skip
    multi = {k for k, n, *_ in table if n > 1 and k.startswith("gearchaos.")}
    if multi:
        print("  specialisations of the gearchaos kernels compiled more than once (first run 1):")
        for c in firsts[0]["compiles"]:
            if c["kernel"] in multi:
                print(f"    {c['kernel'].rsplit('.', 1)[-1]}({c['args'][:150]}) "
                      f"{c['self_cpu']:.2f} s CPU")  # fmt: skip


if __name__ == "__main__":
    main()
