"""Benchmark of a boundary curve against the brute-force regime map (issue 26); not a test.

``curve_benchmark()``: the time of one period-doubling curve of ``sheng2016`` in (Ω, ξ) with
about ``points`` points (:func:`gearchaos.boundary_curve`, ξ ∈ [0.01, 0.04], Ω ∈ [3.2, 3.7], the
closed tongue of the period doubling of the 1T branch near Ω = 3.39) against the time of the
brute-force 2-D regime map (:func:`gearchaos.bifurcation`, 150 transient + 16 recorded periods,
motion verdicts, the protocol whose map shows the tongue) that resolves the same boundary at the
same resolution: ``points`` × ``points`` cells over the same ranges. The map is timed on
``sample`` × ``sample`` cells and scaled by the number of cells (sweep points are independent
and cost the same on average); ``--full`` times the whole map. Goal: the curve ≥ 20× cheaper.
Both after a warm-up that compiles every kernel, in this process, on all cores.

Run: ``python benchmarks/bench_curves.py [--points 100] [--sample 20] [--full]`` (or
``python benchmarks/bench_charts.py``, which runs every chart benchmark).
"""

from __future__ import annotations

import argparse
import time

import gearchaos as gc
from gearchaos.dynamics.continuation.events import events

MAP = {"transient_periods": 150, "periods": 16, "progress": False}


def curve_benchmark(points: int = 100, sample: int = 20, full: bool = False) -> dict[str, float]:
    """Seconds of a PD curve of about ``points`` points and of the ``points``² regime map."""
    gs = gc.preset("sheng2016")
    branch = gc.continuation(gs, "omega=3.3:3.45", max_step=0.01)
    pd = next(e for e in events(branch) if e.kind == "period_doubling")
    kw = {"within": "omega=3.2:3.7"}
    gc.boundary_curve(gs, pd, "xi=0.01:0.04", max_points=3, **kw)  # warm-up
    gc.bifurcation(gs, ["omega=3.2:3.7:3", "xi=0.01:0.04:2"], **MAP)
    # the closed tongue is ~1.8 range units long: steps for about `points` points
    step = 1.8 / points
    t0 = time.perf_counter()
    curve = gc.boundary_curve(
        gs, pd, "xi=0.01:0.04", step=step, max_step=step, max_points=10 * points, **kw
    )
    t_curve = time.perf_counter() - t0
    n = points if full else sample
    t0 = time.perf_counter()
    gc.bifurcation(gs, [f"omega=3.2:3.7:{n}", f"xi=0.01:0.04:{n}"], **MAP)
    t_map = (time.perf_counter() - t0) * (points * points) / (n * n)
    got = int(curve.sizes["point"])
    how = "measured" if full else f"from {n} x {n} cells, scaled"
    print(f"PD curve in (Ω, ξ), {got} points: {t_curve:.2f} s "
          f"({curve.attrs['map_evaluations']} batched map evaluations)")  # fmt: skip
    print(f"regime map {points} x {points} ({how}): {t_map:.1f} s")
    print(f"ratio map / curve: {t_map / t_curve:.0f}x (goal >= 20x)")
    return {"curve": t_curve, "map": t_map, "points": got}


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=100)
    ap.add_argument("--sample", type=int, default=20)
    ap.add_argument("--full", action="store_true")
    a = ap.parse_args()
    curve_benchmark(a.points, a.sample, a.full)
