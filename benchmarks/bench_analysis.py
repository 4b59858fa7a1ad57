"""Benchmark: the cost of Lyapunov exponents and motion labels in a sweep (issue 4).

Run as ``python benchmarks/bench_analysis.py [--points 100] [--repeat 3] [--quick]``.

The sweep: Ω ∈ [0.2, 4] in ``--points`` linearly spaced values of the MODEL.md §9 gear set
(``gearchaos.preset("hindawi2021")``), fresh zero initial state at every point, 100 transient +
100 recorded mesh periods, rtol 1e-8, atol 1e-10, in-process on all cores (the default
executor of :func:`gearchaos.bifurcation`), in memory (no store on disk).

Measured, best of ``--repeat`` runs each, after a warm-up of both variants (numba compile or
cache load excluded), the two variants alternating:

1. **integration** — :func:`gearchaos.sweep.run.run_sweep` with ``classify=False``, without and
   with ``lyapunov=True`` (one tangent vector integrated with the trajectory, Gram–Schmidt
   every mesh period). Their ratio is the cost of ``--lyapunov``; target ≤ 2.5× (the PASS/FAIL
   line).
2. **end to end** — :func:`gearchaos.bifurcation` as users call it (integration + labels), both
   variants, and their ratio.
3. **labels** — :func:`gearchaos.sweep.classify.classify_dataset` on the stored sections of
   both sweeps (with the LLE where stored): seconds per point, and how many points needed the
   0–1 test and the spectrum (no period ≤ 64 found).

``--quick``: 20 points, 20 + 20 periods, 2 repeats.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from typing import Any

import numpy as np

RTOL = 1e-8
ATOL = 1e-10
OMEGA_RANGE = (0.2, 4.0)
TARGET_RATIO = 2.5


def machine_info() -> str:
    import numba
    import scipy

    import gearchaos

    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return (
        f"machine: {cpu}; {os.cpu_count()} logical CPUs; numba threads "
        f"{numba.get_num_threads()}\n"
        f"software: Python {platform.python_version()} ({platform.system()} "
        f"{platform.release()}), numpy {np.__version__}, scipy {scipy.__version__}, "
        f"numba {numba.__version__}, gearchaos {gearchaos.__version__}"
    )


def _spec(omega: np.ndarray, tr: int, rec: int, lyapunov: bool) -> Any:
    from gearchaos.sweep.spec import SweepSpec

    return SweepSpec.build(
        {"omega": omega},
        observe=("delta_sp", "delta_sp_dot"),
        planets=(1,),
        transient_periods=tr,
        periods=rec,
        rtol=RTOL,
        atol=ATOL,
        lyapunov=lyapunov,
    )


def _best(times: list[float]) -> str:
    return f"best {min(times):7.3f} s  (runs: {', '.join(f'{t:.3f}' for t in times)})"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=100)
    ap.add_argument("--transient", type=int, default=100)
    ap.add_argument("--periods", type=int, default=100)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="20 points, 20 + 20 periods, 2 repeats")
    a = ap.parse_args(argv)
    if a.quick:
        a.points, a.transient, a.periods, a.repeat = 20, 20, 20, 2

    import gearchaos
    from gearchaos.sweep.classify import classify_dataset
    from gearchaos.sweep.run import run_sweep

    print("gearchaos benchmark: cost of Lyapunov exponents and motion labels in a sweep")
    print(machine_info())
    gs = gearchaos.preset("hindawi2021")
    omega = np.linspace(*OMEGA_RANGE, a.points)
    print(
        f"sweep: hindawi2021, {a.points} values of Ω in [{OMEGA_RANGE[0]:g}, {OMEGA_RANGE[1]:g}], "
        f"{a.transient} + {a.periods} mesh periods, fresh start, rtol {RTOL:g}, atol {ATOL:g}, "
        f"in-process on all cores, best of {a.repeat}"
    )

    # warm-up: compile (or load from the numba cache) both variants and the classifier
    t0 = time.perf_counter()
    for lyap in (False, True):
        gearchaos.bifurcation(
            gs, {"omega": np.array([1.0, 2.0])}, transient_periods=1, periods=8,
            lyapunov=lyap, progress=False,
        )  # fmt: skip
    print(f"warm-up (compile / cache load): {time.perf_counter() - t0:.2f} s")

    plain_t: list[float] = []
    lyap_t: list[float] = []
    plain_e2e: list[float] = []
    lyap_e2e: list[float] = []
    datasets: dict[bool, Any] = {}
    for r in range(a.repeat):
        order = (False, True) if r % 2 == 0 else (True, False)
        for lyap in order:
            spec = _spec(omega, a.transient, a.periods, lyap)
            t0 = time.perf_counter()
            ds = run_sweep(gs, spec, progress=False, classify=False)
            (lyap_t if lyap else plain_t).append(time.perf_counter() - t0)
            datasets[lyap] = ds
        for lyap in order:
            t0 = time.perf_counter()
            gearchaos.bifurcation(
                gs, {"omega": omega}, transient_periods=a.transient, periods=a.periods,
                rtol=RTOL, atol=ATOL, lyapunov=lyap, progress=False,
            )  # fmt: skip
            (lyap_e2e if lyap else plain_e2e).append(time.perf_counter() - t0)

    failed = {k: int(np.count_nonzero(ds["status"].values != 0)) for k, ds in datasets.items()}
    same = np.array_equal(
        datasets[False]["delta_sp"].values, datasets[True]["delta_sp"].values, equal_nan=True
    )
    print("\nintegration (run_sweep, classify=False):")
    print(f"  without lyapunov: {_best(plain_t)}  ({min(plain_t) / a.points * 1e3:.2f} ms/point)")
    print(f"  with lyapunov:    {_best(lyap_t)}  ({min(lyap_t) / a.points * 1e3:.2f} ms/point)")
    ratio = min(lyap_t) / min(plain_t)
    print(f"  ratio with/without: {ratio:.2f}x   (failed points: {failed[False]} / {failed[True]};"
          f" section values identical: {same})")  # fmt: skip
    print("end to end (gearchaos.bifurcation: integration + labels):")
    print(f"  without lyapunov: {_best(plain_e2e)}")
    print(f"  with lyapunov:    {_best(lyap_e2e)}")
    print(f"  ratio with/without: {min(lyap_e2e) / min(plain_e2e):.2f}x")

    print("labels (classify_dataset on the stored sections):")
    for lyap in (False, True):
        ds = datasets[lyap]
        times = []
        res: dict[str, Any] = {}
        for _ in range(a.repeat):
            t0 = time.perf_counter()
            res = classify_dataset(ds)
            times.append(time.perf_counter() - t0)
        aperiodic = int(np.count_nonzero(res["period"] == 0))
        table = ", ".join(f"{k} {v:.0%}" for k, v in res["regime_table"]["all"].items())
        print(
            f"  {'with LLE   ' if lyap else 'without LLE'}: {min(times) / a.points * 1e3:.2f} "
            f"ms/point ({_best(times)}); {aperiodic} of {a.points} points without a period "
            f"≤ 64 got the 0–1 test and spectrum; regimes: {table}"
        )
    mean_lle = float(np.nanmean(datasets[True]["lle"].values))
    print(f"  mean LLE over the sweep: {mean_lle:.4g} per unit τ")

    ok = ratio <= TARGET_RATIO
    print(
        f"\n{'PASS' if ok else 'FAIL'}: a sweep with lyapunov=True costs {ratio:.2f}x the same "
        f"sweep without (target ≤ {TARGET_RATIO:g}x; integration, best of {a.repeat})"
    )
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
