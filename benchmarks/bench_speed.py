"""Benchmark (issue 13): cost per step, rejected steps, the Fig. 4(a) sweep against a baseline
revision, and the first and warm run of ``gearchaos simulate``.

Run as ``python benchmarks/bench_speed.py [--baseline REV] [--quick] [--skip-first-run]``.

Printed, in one run:

1. **Steps.** ``gearchaos.simulate`` of ``preset("hindawi2021")`` (N = 5) and the same set with
   N = 3 planets (teeth 35/31/97 so that the planets are equally spaced) at Ω = 0.5, 1.5, 2.5,
   3.5, 100 + 100 periods, rtol 1e-8, atol 1e-10, one thread: µs of process CPU time per step
   attempt (best of 3 after a warm-up) and the fraction of attempts rejected (error test failed
   or step retried to end on a contact switch).
2. **Reference chain** (``benchmarks/refchain.py``): a textbook compiled DOPRI5 loop over a
   16-state chain with 8 dead zones, the floor for this kind of problem; µs per step attempt and
   the ratio gearchaos / chain for N = 5 (mean over the Ω values).
3. **Fig. 4(a) sweep**: ``gearchaos.bifurcation`` of ``preset("sheng2016")`` with ξ = 0.03,
   b̄_sp = 3, b̄_rp = 3.5, b̄_s = 2 over 1000 Ω values in [0.05, 4], 100 + 100 periods, rtol
   1e-8, atol 1e-10, all cores, into a temporary store. The same sweep runs with the code of
   ``--baseline REV`` (default ``f8038c0``, main before the speed work), checked out with
   ``git worktree add`` into ``$TMPDIR/gearchaos-bench-baseline-REV`` (kept, with its numba
   cache, for the next run; ``--remove-baseline`` removes it) and imported from there by a
   child process of this one. Each sweep runs in its own child process after a 2-point warm-up
   (compilation excluded); the ratio baseline / this code is printed, and the largest
   difference of the section values over the points that are 1T in both (section spread
   < 1e-4: a change within the integration tolerance, not of the attractor).
4. **``--settle auto``**: the same sweep with the transient ended early once the section
   sequence repeats (only if this code has the ``settle`` setting; otherwise "not available").
5. **First run**: ``gearchaos simulate --set omega=1.5`` in a fresh ``NUMBA_CACHE_DIR``,
   then again with that cache warm; wall seconds of each, as separate processes.

``--quick``: 100 sweep points, 20 + 20 periods; 20 + 20 periods and one repetition for the steps.
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from child import run_child

ROOT = Path(__file__).resolve().parents[1]
RTOL = 1e-8
ATOL = 1e-10
OMEGAS = (0.5, 1.5, 2.5, 3.5)
FIG4_RANGE = (0.05, 4.0)
FIG4_FIXED = {
    "xi": 0.03,
    "backlash.sun_planet": 3.0,
    "backlash.planet_ring": 3.5,
    "clearance.sun_bearing": 2.0,
}
DEFAULT_BASELINE = "f8038c0"

# ----------------------------------------------------------------------------- child: a sweep
_SWEEP_CHILD = r"""
import json, os, sys, tempfile, time
import numpy as np
import gearchaos
spec = json.loads(sys.argv[1])
gs = gearchaos.preset("sheng2016")
common = dict(rtol=spec["rtol"], atol=spec["atol"], progress=False, fixed=spec["fixed"])
extra = {"settle": "auto"} if spec["settle"] else {}
with tempfile.TemporaryDirectory() as d:
    gearchaos.bifurcation(gs, {"omega": np.array([1.0, 2.0])}, store=os.path.join(d, "w.zarr"),
                          transient_periods=1, periods=2, **common, **extra)
    omega = np.linspace(spec["lo"], spec["hi"], spec["points"])
    t0 = time.perf_counter()
    ds = gearchaos.bifurcation(gs, {"omega": omega}, store=os.path.join(d, "s.zarr"),
                               transient_periods=spec["tr"], periods=spec["rec"], **common,
                               **extra)
    wall = time.perf_counter() - t0
    out = {"wall": wall,
           "steps": float(np.sum(ds["steps_accepted"].values)
                          + np.sum(ds["steps_rejected"].values)),
           "rejected": float(np.sum(ds["steps_rejected"].values)),
           "status": [int(s) for s in np.asarray(ds["status"].values).ravel()]}
    names = sorted(v for v in ds.data_vars if "section" in ds[v].dims)
    np.save(spec["npy"], np.stack([np.asarray(ds[v].values, dtype=float) for v in names]))
    if "transient_skipped" in ds:
        out["settled"] = int(np.sum(np.asarray(ds["transient_skipped"].values) > 0))
out["file"] = gearchaos.__file__
print("RESULT" + json.dumps(out))
"""


def run_sweep(src: Path, points: int, tr: int, rec: int, settle: bool, npy: str) -> dict[str, Any]:
    """The Fig. 4(a) sweep in a child process importing gearchaos from ``src``."""
    spec = {
        "points": points, "tr": tr, "rec": rec, "lo": FIG4_RANGE[0], "hi": FIG4_RANGE[1],
        "rtol": RTOL, "atol": ATOL, "fixed": FIG4_FIXED, "settle": settle, "npy": npy,
    }  # fmt: skip
    return run_child(_SWEEP_CHILD, spec, src)


def _diff_1t(a: Any, b: Any) -> tuple[float, int]:
    """Largest |a − b| over the points whose sections are 1T in both (spread < 1e-4), and
    their number; arrays (variables, points, section, …)."""
    import numpy as np

    def spread(x: Any) -> Any:
        s = np.nanmax(x, axis=2) - np.nanmin(x, axis=2)
        return np.nanmax(s.reshape(s.shape[0], s.shape[1], -1), axis=(0, 2))

    ok = (spread(a) < 1e-4) & (spread(b) < 1e-4)
    if not ok.any():
        return math.nan, 0
    return float(np.nanmax(np.abs(a[:, ok] - b[:, ok]))), int(ok.sum())


# ----------------------------------------------------------------------------- steps
def step_table(tr: int, rec: int, reps: int) -> list[tuple[int, float, float, float]]:
    """(N, Ω, µs per attempt, rejected fraction) in this process, one thread."""
    import gearchaos

    base = gearchaos.preset("hindawi2021")
    sets = {5: base, 3: base.evolve({"geometry.planets": 3, "teeth.sun": 35, "teeth.ring": 97})}
    rows = []
    for n_pl in (3, 5):
        gs = sets[n_pl]
        gearchaos.simulate(gs, omega=1.0, transient_periods=1, periods=2, rtol=RTOL, atol=ATOL)
        for om in OMEGAS:
            best = math.inf
            res = None
            for _ in range(reps):
                c0 = time.process_time()
                res = gearchaos.simulate(
                    gs, omega=om, transient_periods=tr, periods=rec, rtol=RTOL, atol=ATOL
                )
                best = min(best, time.process_time() - c0)
            assert res is not None
            att = res.steps_accepted + res.steps_rejected
            rows.append((n_pl, om, 1e6 * best / att, res.steps_rejected / att))
    return rows


def refchain_us(tr: int, rec: int, reps: int) -> float:
    """µs per step attempt of the reference chain over the Ω values (mean)."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import numpy as np

    import refchain

    us = []
    for om in OMEGAS:
        p = refchain.parameters(om)
        y0 = np.zeros(refchain.N_STATE)
        t_end = (tr + rec) * 2.0 * math.pi / om
        refchain.integrate(p, y0, 1.0, RTOL, ATOL)
        best = math.inf
        att = 1.0
        for _ in range(reps):
            c0 = time.process_time()
            out = refchain.integrate(p, y0, t_end, RTOL, ATOL)
            best = min(best, time.process_time() - c0)
            att = float(out[0] + out[1])
        us.append(1e6 * best / att)
    return sum(us) / len(us)


# ----------------------------------------------------------------------------- first run
def first_run() -> tuple[float, float]:
    """Wall seconds of ``gearchaos simulate`` in a fresh numba cache, then warm."""
    exe = Path(sys.executable).with_name("gearchaos")
    cmd = [str(exe), "simulate", "--set", "omega=1.5"]
    times = []
    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, NUMBA_CACHE_DIR=os.path.join(d, "cache"))
        for _ in range(2):
            t0 = time.perf_counter()
            subprocess.run(cmd, env=env, cwd=d, capture_output=True, check=True)
            times.append(time.perf_counter() - t0)
    return times[0], times[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", default=DEFAULT_BASELINE, help="git revision to compare with")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--skip-first-run", action="store_true")
    ap.add_argument("--skip-steps", action="store_true")
    ap.add_argument("--skip-sweep", action="store_true")
    ap.add_argument(
        "--remove-baseline", action="store_true", help="remove the baseline worktree afterwards"
    )
    args = ap.parse_args()
    os.environ["NUMBA_NUM_THREADS"] = os.environ.get("NUMBA_NUM_THREADS", str(os.cpu_count()))
    tr, rec, reps = (20, 20, 1) if args.quick else (100, 100, 3)
    points = 100 if args.quick else 1000
    print(f"bench_speed: this tree {ROOT} vs --baseline {args.baseline}; rtol {RTOL:g}, "
          f"atol {ATOL:g}; {os.cpu_count()} cores; load {os.getloadavg()[0]:.1f}")  # fmt: skip

    if not args.skip_steps:
        print(f"\n1. steps ({tr} + {rec} periods, one thread, process CPU time, best of {reps})")
        print(f"  {'N':>2s} {'Ω':>5s} {'µs/attempt':>11s} {'rejected':>9s}")
        rows = step_table(tr, rec, reps)
        for n_pl, om, us, rej in rows:
            print(f"  {n_pl:2d} {om:5.2f} {us:11.3f} {100 * rej:8.1f}%")
        worst = max(r[3] for r in rows)
        print(f"  largest rejected fraction: {100 * worst:.1f} % (target ≤ 10 %)")
        ref = refchain_us(tr, rec, reps)
        us5 = sum(r[2] for r in rows if r[0] == 5) / len(OMEGAS)
        print(f"\n2. reference chain (16 states, 8 dead zones): {ref:.3f} µs/step; "
              f"N = 5 mean {us5:.3f} µs/attempt = {us5 / ref:.2f}× the chain (target ≤ 1.5×, "
              f"≤ 0.5 µs)")  # fmt: skip

    if not args.skip_sweep:
        print(f"\n3. Fig. 4(a) sweep: {points} Ω in [{FIG4_RANGE[0]}, {FIG4_RANGE[1]}], "
              f"ξ = 0.03, {tr} + {rec} periods, all cores")  # fmt: skip
        with tempfile.TemporaryDirectory() as d:
            # the baseline's worktree is kept between runs (its numba cache with it)
            wt = Path(tempfile.gettempdir()) / f"gearchaos-bench-baseline-{args.baseline}"
            if not (wt / "src").is_dir():
                subprocess.run(
                    ["git", "-C", str(ROOT), "worktree", "add", "--detach", str(wt),
                     args.baseline], check=True, capture_output=True,
                )  # fmt: skip
            try:
                import numpy as np

                base = run_sweep(wt / "src", points, tr, rec, False, f"{d}/b.npy")
                new = run_sweep(ROOT / "src", points, tr, rec, False, f"{d}/n.npy")
                sb, sn = np.load(f"{d}/b.npy"), np.load(f"{d}/n.npy")
                diff = _diff_1t(sb, sn)
                for name, r in (("baseline " + args.baseline, base), ("this code", new)):
                    print(f"  {name:22s} {r['wall']:8.2f} s wall, {r['steps']:.3g} attempts, "
                          f"{100 * r['rejected'] / r['steps']:.1f} % rejected")  # fmt: skip
                print(f"  speed-up: {base['wall'] / new['wall']:.2f}× (target ≥ 3×)")
                print(f"  largest |Δ section value| over the {diff[1]} points that are 1T in "
                      f"both: {diff[0]:.3g}")  # fmt: skip
                try:
                    st = run_sweep(ROOT / "src", points, tr, rec, True, f"{d}/s.npy")
                    ss = np.load(f"{d}/s.npy")
                    dd = _diff_1t(ss, sn)
                    print(f"\n4. --settle auto: {st['wall']:.2f} s wall, "
                          f"{base['wall'] / st['wall']:.2f}× the baseline (target ≥ 6×), "
                          f"settled early {st.get('settled', '?')} of {points}, "
                          f"largest |Δ section| over {dd[1]} 1T points {dd[0]:.3g}")  # fmt: skip
                except RuntimeError as e:
                    print(f"\n4. --settle auto: not available ({str(e).splitlines()[-1][:120]})")
            finally:
                if args.remove_baseline:
                    subprocess.run(
                        ["git", "-C", str(ROOT), "worktree", "remove", "--force", str(wt)],
                        check=False, capture_output=True,
                    )  # fmt: skip
                    shutil.rmtree(wt, ignore_errors=True)

    if not args.skip_first_run:
        cold, warm = first_run()
        print("\n5. gearchaos simulate --set omega=1.5: first run (fresh NUMBA_CACHE_DIR) "
              f"{cold:.1f} s (target ≤ 15 s), second {warm:.1f} s (target ≤ 2 s)")  # fmt: skip


if __name__ == "__main__":
    main()
