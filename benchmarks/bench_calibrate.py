"""Benchmark (issue 34): seconds per candidate of the calibration objective.

Run as ``python benchmarks/bench_calibrate.py [--quick] [--sets sheng2016,variant]
[--reproduce]``.

For each gear set (``sheng2016``, today's default; ``sheng2016-v1``, the default before issue
34; ``hindawi2021``, the search's base; ``variant``, issue 34's sheng2016-v1 with A = 20 µm and
b_c = 5 µm, which reaches its back flanks)
the objective of :mod:`gearchaos.paper.objective` is timed on the packaged landmarks, after a
warm-up that compiles (or loads) every kernel, in three stages measured in this one process:

1. plain — the objective's sweeps (same grid, same 100 + 100 periods, λ₁ on) with
   ``verdicts=False``: the kind of sweep the old calibration ran, the baseline of the ratios;
2. verdicts — the same sweeps decided by the motion verdict (the report's evaluation);
3. objective — the whole candidate: verdict sweeps, the event landmarks' continued branches
   and the structural term.

Printed per set: the grid points, wall times and their ratios to the plain sweeps, the landmark
score, the landmarks that hold and the structure with its parts; then what a calibration of
``N`` trials costs (trials × seconds per candidate / parallel workers). ``--quick`` uses the CI
objective (:meth:`SweepSettings.quick`). With ``--reproduce`` also the wall time of
``gearchaos reproduce --all`` into a temporary folder (goal ≤ 3 min on the 2-core machine).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import replace

import gearchaos as gc
from gearchaos.paper.landmarks import load_landmarks
from gearchaos.paper.objective import SweepSettings, landmark_objective, sweep_plan
from gearchaos.paper.recipes import get_recipe


def gearset(name: str) -> gc.GearSet:
    if name == "variant":  # issue 34's hand-made variant of the default of that time
        return gc.preset("sheng2016-v1").evolve(
            {
                "transmission_error.sun_planet": 20e-6,
                "transmission_error.planet_ring": 20e-6,
                "clearance.characteristic_length": 5e-6,
            }
        )
    return gc.preset(name)


def plain_sweeps(gs: gc.GearSet, plan: dict, settings: SweepSettings) -> float:
    t = time.perf_counter()
    for run in plan.values():
        kw = run.sweep_kwargs(settings, get_recipe(run.figure).observe)
        gc.bifurcation(gs, progress=False, verdicts=False, **kw)
    return time.perf_counter() - t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the CI objective")
    ap.add_argument("--sets", default="sheng2016", help="comma-separated: sheng2016,variant,…")
    ap.add_argument("--reproduce", action="store_true", help="also time reproduce --all")
    a = ap.parse_args()
    marks = load_landmarks()
    full = SweepSettings.quick() if a.quick else SweepSettings()
    plan = sweep_plan(marks, full)
    points = sum(len(r.grid) for r in plan.values())
    warm = replace(SweepSettings.quick(), structure=True)
    landmark_objective(marks[:1], warm)(gc.preset("sheng2016"))  # compile / load the caches
    print(
        f"objective: {len(marks)} landmarks, {len(plan)} panels, {points} points, "
        f"{full.transient_periods} + {full.periods} periods, rtol {full.rtol:g}, "
        f"{os.cpu_count()} cores" + (" (quick)" if a.quick else "")
    )
    per: list[float] = []
    for name in a.sets.split(","):
        gs = gearset(name.strip())
        t_plain = plain_sweeps(gs, plan, full)
        sweeps_only = replace(full, branches=False, structure=False)
        t = time.perf_counter()
        landmark_objective(marks, sweeps_only)(gs)
        t_verd = time.perf_counter() - t
        ev = landmark_objective(marks, full)(gs)
        per.append(ev.seconds)
        p = ev.parts
        print(f"\n{name}:")
        print(f"  plain sweeps (baseline)   {t_plain:8.1f} s   1.00×")
        print(f"  verdict sweeps            {t_verd:8.1f} s   {t_verd / t_plain:.2f}×")
        print(f"  whole candidate           {ev.seconds:8.1f} s   {ev.seconds / t_plain:.2f}×")
        print(
            f"  landmark score {ev.score:.2f} of {len(marks)}, {p.get('holds')} hold; "
            f"structure {ev.structure:.3f} (double-sided {p.get('double_sided', 0):.2f} of "
            f"{p.get('region_points', 0)} chaotic/multi-periodic points, multipliers "
            f"{p.get('multipliers', 0):.2f})"
        )
        for b in p.get("branches", []):
            print(
                f"    branch over {b['axis']} at Ω = {b['omega']:g}: Δmax|μ| = {b['change']:.3g}, "
                f"{b['events']} event(s), score {b['score']:.2f} {b['reason']}"
            )
    mean = sum(per) / len(per)
    print(f"\nseconds per candidate: {mean:.0f} (mean of {len(per)})")
    for trials in (100, 300, 1000):
        hours = trials * mean / 3600
        print(f"  {trials:5d} trials: {hours:6.1f} h here; {hours / 8:5.1f} h on 8 such workers")
    if a.reproduce:
        exe = os.path.join(os.path.dirname(sys.executable), "gearchaos")
        with tempfile.TemporaryDirectory() as d:
            t = time.perf_counter()
            subprocess.run([exe, "reproduce", "--all", "-o", d], check=True, capture_output=True)
            print(f"\ngearchaos reproduce --all: {time.perf_counter() - t:.0f} s (goal ≤ 180 s)")


if __name__ == "__main__":
    main()
