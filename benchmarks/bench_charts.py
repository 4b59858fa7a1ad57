"""Benchmarks of the design charts (issue 26); not a timed test.

``basin_benchmark()``: the time of a 200 × 200 basin image per 1000 starts against the time of
one plain sweep point (``gc.bifurcation`` over 1000 values near the same operating point, same
protocol), per start. Goal: ≤ 1.2×. The system is the forced twin-well Duffing oscillator
(δ = 0.25, γ = 0.1, Ω = 1.2: two coexisting 1T orbits), 200 transient + 32 recorded periods.

``curve_benchmark()`` (in ``bench_curves.py``): one period-doubling curve of sheng2016 in
(Ω, ξ) with 100 points against the 100 × 100 brute-force regime map that shows the same
boundary. Goal: ≥ 20× cheaper.

Run: ``python benchmarks/bench_charts.py``.
"""

from __future__ import annotations

import time

import gearchaos as gc

PROTOCOL = {"transient_periods": 200, "periods": 32, "progress": False}


def basin_benchmark(n: int = 200) -> dict[str, float]:
    """Seconds per 1000 starts of an n × n basin image and per 1000 plain sweep points."""
    system = gc.duffing(1.2, delta=0.25, alpha=-1.0, beta=1.0, gamma=0.1)
    gc.basins(system, "x=-2:2:8", "x_dot=-2:2:8", **PROTOCOL)  # compile and warm the caches
    gc.bifurcation(system, "omega=1.19:1.21:8", **PROTOCOL)
    t0 = time.perf_counter()
    ds = gc.basins(system, f"x=-2:2:{n}", f"x_dot=-2:2:{n}", **PROTOCOL)
    basin = (time.perf_counter() - t0) / (n * n) * 1000
    t0 = time.perf_counter()
    gc.bifurcation(system, "omega=1.19:1.21:1000", **PROTOCOL)
    sweep = time.perf_counter() - t0
    t0 = time.perf_counter()
    gc.bifurcation(system, "omega=1.19:1.21:1000", **PROTOCOL, verdicts=False)
    plain = time.perf_counter() - t0
    shares = {int(k): float((ds["attractor"].values == k).mean()) for k in (0, 1)}
    print(f"basin image {n} x {n} (twin-well Duffing, Ω = 1.2): {basin:.3f} s per 1000 starts")
    print(f"sweep point (same protocol, verdicts):    {sweep:.3f} s per 1000 points")
    print(f"sweep point (same protocol, no verdicts): {plain:.3f} s per 1000 points")
    print(f"ratio per start: {basin / sweep:.2f} (verdicts), {basin / plain:.2f} (no verdicts);"
          f" goal <= 1.2; basin shares {shares}")  # fmt: skip
    return {"basin": basin, "sweep": sweep, "plain": plain}


if __name__ == "__main__":
    from bench_curves import curve_benchmark  # the boundary-curve part (its own file)

    curve_benchmark()
    basin_benchmark()
