"""Benchmark: the extra cost of ``orbits=True`` (``--orbits``) on a sweep.

Run as ``python benchmarks/bench_sweep_orbits.py [--points 100] [--preset sheng2016]
[--range 0.2:4]``.

The same sweep — Ω ∈ [0.2, 4] (``--range``) with ``--points`` points, fresh zero start,
100 transient + 100 recorded periods, in-process on all cores, no store — runs without and
with ``orbits=True``
(every point labelled nT, n ≤ 8, confirmed by shooting a period-n orbit from its final state).
Reported: wall and process CPU time of both, their ratio, the points shot and how their
orbits ended. The issue's rule: when the extra cost exceeds 30 %, the check is opt-in.

Everything runs in this process after a warm-up that compiles (or loads) every kernel used,
so compile time is excluded; the baseline is measured in the same run.
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

import gearchaos as gc
from gearchaos.sweep.orbits import ORBIT_STATUS


def timed(fn, *args, **kw):
    """(result, wall seconds, process CPU seconds) of one call."""
    w0, c0 = time.perf_counter(), time.process_time()
    out = fn(*args, **kw)
    return out, time.perf_counter() - w0, time.process_time() - c0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=100)
    ap.add_argument("--preset", default="sheng2016")
    ap.add_argument("--range", default="0.2:4", help="START:STOP of Ω")
    args = ap.parse_args()
    gs = gc.preset(args.preset)
    vary = f"omega={args.range}:{args.points}"
    # warm-up: every kernel compiled or loaded
    gc.bifurcation(gs, "omega=1:3:2", transient_periods=2, periods=4, orbits=True, progress=False)
    plain, w0, c0 = timed(gc.bifurcation, gs, vary, progress=False)
    checked, w1, c1 = timed(gc.bifurcation, gs, vary, orbits=True, progress=False)
    assert np.array_equal(plain.motion.values, checked.motion.values)
    names = {v: k for k, v in ORBIT_STATUS.items()}
    status = checked.orbit_status.values
    counts = {names[int(s)]: int(np.sum(status == s)) for s in np.unique(status)}
    shot = int(np.sum(checked.orbit_period.values > 0))
    print(f"machine: {platform.machine()} {os.cpu_count()} cores, {args.preset}, {vary}")
    print(f"sweep without orbits: wall {w0:.2f} s, CPU {c0:.2f} s")
    print(f"sweep with orbits:    wall {w1:.2f} s, CPU {c1:.2f} s")
    print(f"extra cost: wall {100 * (w1 / w0 - 1):.0f} %, CPU {100 * (c1 / c0 - 1):.0f} %")
    print(f"points shot: {shot} of {args.points}; outcomes: {counts}")


if __name__ == "__main__":
    main()
