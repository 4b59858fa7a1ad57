"""Benchmark: a 1000-point Ω sweep of the default gear set on all cores, against scipy RK45.

Run as ``python benchmarks/bench_sweep.py [--points 1000] [--quick]``.

The sweep: Ω ∈ [0.1, 4] in ``--points`` linearly spaced values, the MODEL.md §9 gear set
(``gearchaos.preset("hindawi2021")``), fresh zero initial state at every point, 100 transient +
100 recorded mesh periods, rtol 1e-8, atol 1e-10, run by :func:`gearchaos.bifurcation` with its
default executor (in-process, all cores) into a temporary Zarr store.

* Each sweep runs in a fresh child process, after a 2-point warm-up sweep in that process so
  numba compile time (or the on-disk cache load) is excluded. The child reports wall time,
  process CPU time (all threads, plus any worker processes) and the peak RSS of the sweep
  (Linux: the kernel's peak mark ``VmHWM``, reset after the warm-up through
  ``/proc/self/clear_refs`` so compilation is left out; elsewhere ``resource.getrusage``'s
  ``ru_maxrss`` since the start), and the time spent in the compiled kernel and in store writes.
* Memory flat in the number of points: the same sweep with a quarter of the points runs in
  another child; the peak RSS of the two is compared.
* Baseline in the same run: ``scipy.integrate.solve_ivp(method="RK45")`` on the plain,
  vectorised-numpy right-hand side of ``benchmarks/bench_simulate.py`` (checked against the
  compiled one at random states first), at 5 evenly spaced points of the sweep, over the same
  span and section times, one core. Reported: the per-point speed ratio (scipy seconds per point
  / gearchaos sweep wall seconds per point) and the same per core-second (scipy CPU seconds per
  point / gearchaos CPU seconds per point, all cores summed), and the section values of the two
  at those points (equal only where the motion is periodic).

Target (issue 3): ≤ 20 s wall for the 1000-point sweep on the 2-core machine; memory flat in
the number of points. ``--quick``: 100 points, 20 + 20 periods.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

RTOL = 1e-8
ATOL = 1e-10
OMEGA_RANGE = (0.1, 4.0)
N_SCIPY = 5
TARGET_WALL_S = 20.0
TARGET_POINTS = 1000
TARGET_CORES = 2
# "flat": the peak RSS of the full sweep exceeds the quarter sweep's by at most this much
FLAT_TOL_MIB = 32.0
FLAT_TOL_REL = 0.10

HERE = Path(__file__).resolve().parent


# --------------------------------------------------------------------------- child process
def _proc_status_mib(field: str) -> float | None:
    """``VmHWM`` (peak) or ``VmRSS`` (current) of this process from /proc, in MiB."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith(field + ":"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return None


def _reset_peak_rss() -> bool:
    """Reset the kernel's peak-RSS mark (Linux ≥ 4.0: ``echo 5 > /proc/self/clear_refs``), so
    that the peak after the sweep leaves out the warm-up (numba compilation, imports)."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
    except OSError:
        return False
    return _proc_status_mib("VmHWM") is not None


def _maxrss_mib(who: int) -> float:
    # Linux reports KiB, macOS bytes
    r = resource.getrusage(who).ru_maxrss
    return r / 1024.0 / (1024.0 if sys.platform == "darwin" else 1.0)


def _cpu_seconds() -> float:
    s, c = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return s.ru_utime + s.ru_stime + c.ru_utime + c.ru_stime


def _instrument() -> dict[str, float]:
    """Time the compiled kernel calls and the store writes of the in-process executor.

    Wraps ``gearchaos.sweep.execute.run_chains`` and ``SweepStore.write`` when they exist
    (engine internals: the breakdown is left out if they move)."""
    acc = {"kernel_wall": 0.0, "kernel_cpu": 0.0, "kernel_calls": 0.0, "write_wall": 0.0}
    try:
        from gearchaos.sweep import execute, store
    except ImportError:
        return {}
    run = getattr(execute, "run_chains", None)
    cls = getattr(store, "SweepStore", None)
    write = getattr(cls, "write", None)
    if run is None or write is None:
        return {}

    def timed_run(*a: Any, **k: Any) -> Any:
        c0, t0 = time.process_time(), time.perf_counter()
        try:
            return run(*a, **k)
        finally:
            acc["kernel_wall"] += time.perf_counter() - t0
            acc["kernel_cpu"] += time.process_time() - c0
            acc["kernel_calls"] += 1

    def timed_write(*a: Any, **k: Any) -> Any:
        t0 = time.perf_counter()
        try:
            return write(*a, **k)
        finally:
            acc["write_wall"] += time.perf_counter() - t0

    execute.run_chains = timed_run
    cls.write = timed_write  # type: ignore[union-attr]
    return acc


def child(points: int, tr: int, rec: int, store: str) -> dict[str, Any]:
    """Warm up, then run the sweep into ``store``; returns the measurements."""
    import gearchaos

    gs = gearchaos.preset("hindawi2021")
    common: dict[str, Any] = {"transient_periods": tr, "periods": rec, "rtol": RTOL, "atol": ATOL}
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as d:
        gearchaos.bifurcation(
            gs, {"omega": np.array([1.0, 2.0])}, store=os.path.join(d, "warm.zarr"),
            progress=False, transient_periods=1, periods=2, rtol=RTOL, atol=ATOL,
        )  # fmt: skip
    warm = time.perf_counter() - t0
    reset = _reset_peak_rss()
    rss0 = _proc_status_mib("VmRSS") if reset else None
    rss0 = _maxrss_mib(resource.RUSAGE_SELF) if rss0 is None else rss0
    omega = np.linspace(*OMEGA_RANGE, points)
    acc = _instrument()
    c0, t0 = _cpu_seconds(), time.perf_counter()
    load0 = os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan
    ds = gearchaos.bifurcation(gs, {"omega": omega}, store=store, progress=False, **common)
    wall = time.perf_counter() - t0
    cpu = _cpu_seconds() - c0
    load1 = os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan
    status = np.asarray(ds["status"].values)
    steps = np.asarray(ds["steps_accepted"].values) + np.asarray(ds["steps_rejected"].values)
    return {
        "points": points,
        "warm_s": warm,
        "wall_s": wall,
        "cpu_s": cpu,
        "rss_warm_mib": rss0,
        "rss_peak_mib": (_proc_status_mib("VmHWM") if reset else None)
        or _maxrss_mib(resource.RUSAGE_SELF),
        "rss_peak_reset": reset,
        "rss_children_mib": _maxrss_mib(resource.RUSAGE_CHILDREN),
        "failed": int(np.count_nonzero(status != 0)),
        "attempts": float(steps.sum()),
        "threads": _threads(),
        "load": [load0, load1],
        "breakdown": acc,
    }


def _threads() -> int:
    import numba

    return int(numba.get_num_threads())


def run_child(points: int, tr: int, rec: int, store: Path) -> dict[str, Any]:
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", str(points), str(tr), str(rec)]
    cmd.append(str(store))
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    for line in proc.stdout.splitlines()[::-1]:
        if line.startswith("RESULT "):
            return json.loads(line[len("RESULT ") :])
    sys.exit(
        f"ABORT: the {points}-point sweep failed (exit {proc.returncode}):\n"
        f"{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    )


# --------------------------------------------------------------------------- scipy baseline
def _bench_simulate() -> Any:
    """Import benchmarks/bench_simulate.py without letting it pin numba to one thread here."""
    saved = dict(os.environ)
    sys.path.insert(0, str(HERE))
    try:
        import bench_simulate
    finally:
        sys.path.remove(str(HERE))
        os.environ.clear()
        os.environ.update(saved)
    return bench_simulate


def scipy_points(omegas: np.ndarray, tr: int, rec: int) -> list[Any]:
    import gearchaos

    bs = _bench_simulate()
    gs = gearchaos.preset("hindawi2021")
    print("right-hand side check (numpy vs compiled System.derivative, 20 random states each):")
    for om in omegas:
        err = bs.check_rhs(gs, float(om))
        print(f"  Ω = {om:<8.4g} max |Δ|/(1+|f|) = {err:.2e}  (≤ {bs.RHS_TOL:g}: ok)")
    runs = []
    for om in omegas:
        r = bs.run_scipy(gs, float(om), tr, rec)
        print(
            f"  scipy RK45 at Ω = {om:<8.4g}: {r.wall:7.2f} s wall, {r.cpu:7.2f} s CPU, "
            f"nfev {r.nfev}, status {r.status}",
            flush=True,
        )
        runs.append(r)
    return runs


# --------------------------------------------------------------------------- report
def load() -> str:
    return ", ".join(f"{v:.2f}" for v in os.getloadavg()) if hasattr(os, "getloadavg") else "n/a"


def machine() -> None:
    import numba
    import scipy
    import xarray
    import zarr

    import gearchaos

    aff = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None
    print("machine")
    print(f"  platform     : {platform.platform()}")
    print(f"  processor    : {platform.processor() or platform.machine()}")
    print(f"  python       : {platform.python_version()}")
    print(f"  CPU count    : {os.cpu_count()} (usable: {aff})")
    print(
        f"  versions     : gearchaos {gearchaos.__version__}, numba {numba.__version__}, "
        f"numpy {np.__version__}, scipy {scipy.__version__}, xarray {xarray.__version__}, "
        f"zarr {zarr.__version__}"
    )
    print(f"  numba threads: {numba.get_num_threads()}")
    print(f"  load average : {load()} (1, 5, 15 min) at start")


def verdict(ok: bool) -> str:
    return "PASS" if ok else "FAIL"


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["--child"]:
        points, tr, rec, store = int(argv[1]), int(argv[2]), int(argv[3]), argv[4]
        print("RESULT " + json.dumps(child(points, tr, rec, store)), flush=True)
        return 0

    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--points", type=int, default=None, help="sweep points (default 1000)")
    ap.add_argument("--quick", action="store_true", help="100 points, 20 + 20 periods")
    args = ap.parse_args(argv)
    points = args.points or (100 if args.quick else TARGET_POINTS)
    if points < 8:
        ap.error(f"--points must be >= 8: got {points}")
    tr, rec = (20, 20) if args.quick else (100, 100)
    small = max(points // 4, 2)

    print(
        f"gearchaos.bifurcation: {points}-point Ω sweep over [{OMEGA_RANGE[0]:g}, "
        f"{OMEGA_RANGE[1]:g}], preset hindawi2021, fresh starts"
    )
    print(f"protocol: {tr} transient + {rec} recorded mesh periods, rtol {RTOL:g}, atol {ATOL:g}")
    machine()
    cores = (
        len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    )

    with tempfile.TemporaryDirectory(prefix="bench_sweep_") as tmp:
        print()
        print("sweeps (each in a fresh process, after a 2-point warm-up there)")
        runs = {}
        for n in (small, points):
            r = run_child(n, tr, rec, Path(tmp) / f"sweep{n}.zarr")
            runs[n] = r
            print(
                f"  {n:5d} points: {r['wall_s']:7.2f} s wall, {n / r['wall_s']:7.1f} points/s, "
                f"{r['cpu_s']:7.2f} s CPU ({r['cpu_s'] / r['wall_s']:.2f} cores busy, "
                f"{r['threads']} numba threads), warm-up {r['warm_s']:.2f} s, "
                f"failed {r['failed']}",
                flush=True,
            )
            b = r["breakdown"]
            if b:
                rest = r["wall_s"] - b["kernel_wall"] - b["write_wall"]
                print(
                    f"  {'':5s}         compiled kernel {b['kernel_wall']:6.2f} s wall in "
                    f"{b['kernel_calls']:.0f} calls ({b['kernel_cpu'] / b['kernel_wall']:.2f} "
                    f"cores busy there), store writes {b['write_wall']:5.2f} s, rest {rest:5.2f} s"
                )
            print(
                f"  {'':5s}         1-min load average {r['load'][0]:.2f} before, "
                f"{r['load'][1]:.2f} after"
            )
            print(
                f"  {'':5s}         peak RSS {r['rss_peak_mib']:7.1f} MiB during the sweep "
                f"({'peak mark reset after warm-up' if r['rss_peak_reset'] else 'since start'}; "
                f"RSS after warm-up {r['rss_warm_mib']:.1f} MiB; worker processes "
                f"{r['rss_children_mib']:.1f} MiB)"
            )
        big = runs[points]

        import xarray as xr

        ds = xr.open_zarr(Path(tmp) / f"sweep{points}.zarr").load()
        om_all = ds["omega"].values
        idx = np.unique(np.round(np.linspace(0, points - 1, N_SCIPY)).astype(int))
        print()
        print(f"scipy baseline at {idx.size} evenly spaced points of the sweep (one core)")
        sp = scipy_points(om_all[idx], tr, rec)
        gc_sec = ds["delta_sp"].sel(planet=1).values  # (omega, section)
        steps = ds["steps_accepted"].values + ds["steps_rejected"].values

    bs = _bench_simulate()
    print()
    print("per point at the scipy points")
    print(f"  {'Ω':>8s}{'gc attempts':>14s}{'scipy attempts':>16s}{'max|ΔX̄_sp1|':>14s}  motion")
    for k, i in enumerate(idx):
        x = gc_sec[i]
        n_per, res = bs.periodicity(x)
        scale = max(1.0, float(np.max(np.abs(x))))
        periodic = res < bs.PERIODIC_TOL * scale
        n_cmp = min(x.size, sp[k].section.size)
        diff = float(np.max(np.abs(x[:n_cmp] - sp[k].section[:n_cmp])))
        motion = f"{n_per}T-periodic" if periodic else "not periodic (no agreement expected)"
        print(f"  {om_all[i]:8.4g}{steps[i]:14.0f}{sp[k].attempts:16.0f}{diff:14.2e}  {motion}")

    sp_wall = sum(r.wall for r in sp) / len(sp)
    sp_cpu = sum(r.cpu for r in sp) / len(sp)
    gc_wall = big["wall_s"] / points
    gc_cpu = big["cpu_s"] / points
    mean_steps_all = float(steps.mean())
    mean_steps_5 = float(steps[idx].mean())
    gc_us_attempt = 1e6 * big["cpu_s"] / big["attempts"]
    sp_us_attempt = 1e6 * sum(r.cpu for r in sp) / sum(r.attempts for r in sp)
    growth = big["rss_peak_mib"] - runs[small]["rss_peak_mib"]
    flat = growth <= max(FLAT_TOL_MIB, FLAT_TOL_REL * runs[small]["rss_peak_mib"])

    print()
    print("summary")
    print(f"  load average : {load()} (1, 5, 15 min) at end")
    print(
        f"  sweep        : {points} points in {big['wall_s']:.2f} s wall "
        f"({points / big['wall_s']:.1f} points/s, {1e3 * gc_wall:.2f} ms wall per point, "
        f"{1e3 * gc_cpu:.2f} ms CPU per point on {cores} cores)"
    )
    print(
        f"  scipy RK45   : {sp_wall:.2f} s wall, {sp_cpu:.2f} s CPU per point "
        f"(mean of {len(sp)}; their gearchaos step attempts average {mean_steps_5:.0f}, "
        f"the whole sweep's {mean_steps_all:.0f})"
    )
    print(
        f"  speed ratio per point (scipy wall / gearchaos sweep wall): {sp_wall / gc_wall:.0f}×; "
        f"per core-second (CPU / CPU): {sp_cpu / gc_cpu:.0f}×; "
        f"per step attempt (CPU): {sp_us_attempt:.1f} / {gc_us_attempt:.3f} µs = "
        f"{sp_us_attempt / gc_us_attempt:.0f}×"
    )
    print(
        f"  memory       : peak RSS {runs[small]['rss_peak_mib']:.1f} MiB at {small} points, "
        f"{big['rss_peak_mib']:.1f} MiB at {points} points (growth {growth:+.1f} MiB for "
        f"{points / small:.0f}× the points)"
    )
    if hasattr(os, "getloadavg") and os.getloadavg()[0] > cores + 0.5:
        print("  WARNING: other processes were running: timings may be inflated")
    print("  targets:")
    scale_note = ""
    if points != TARGET_POINTS or (tr, rec) != (100, 100):
        scale_note = f" (not the target's sweep: {points} points, {tr}+{rec} periods)"
    elif cores != TARGET_CORES:
        scale_note = f" (this machine has {cores} cores, the target is for {TARGET_CORES})"
    print(
        f"  ≤ {TARGET_WALL_S:g} s wall for {TARGET_POINTS} points on the {TARGET_CORES}-core "
        f"machine: {verdict(big['wall_s'] <= TARGET_WALL_S)} ({big['wall_s']:.2f} s){scale_note}"
    )
    print(
        f"  memory flat in the number of points: {verdict(flat)} (peak RSS growth "
        f"{growth:+.1f} MiB from {small} to {points} points; allowed "
        f"{max(FLAT_TOL_MIB, FLAT_TOL_REL * runs[small]['rss_peak_mib']):.0f} MiB)"
    )
    if big["failed"] or runs[small]["failed"]:
        print(f"  WARNING: failed points: {big['failed']} of {points}")
    return 0 if math.isfinite(big["wall_s"]) else 1


if __name__ == "__main__":
    raise SystemExit(main())
