"""Benchmark (issue 25): the integrator split into pieces against a baseline revision, paired.

The compiled integrator's loop was split into pieces (one Runge–Kutta step from the tableau as
data and the error norm: ``integrate._step``; step-size control: ``_control``; switch landing
and extrema: ``_switch``; settling: ``_settle``; sampling: ``_sample``). This script checks
that the split costs no speed and no compile time, against a baseline checkout of the code
before it (``--baseline-src``, e.g. a ``git worktree add /tmp/old_integ <rev>`` and its
``src``), in the same session:

1. **Steps.** ``gearchaos.simulate`` of ``preset("hindawi2021")`` and of the seed's Fig. 4(a)
   gear set (``preset("sheng2016")``, ξ = 0.03, b̄_sp = 3, b̄_rp = 3.5, b̄_s = 2) at a few Ω,
   ``--periods`` transient + ``--periods`` recorded periods (default 2000: a case takes
   tenths of a second, so the clock's granularity is far below the difference sought),
   rtol 1e-8, atol 1e-10, one thread, and a Lyapunov exponent (tangent vectors on) of
   hindawi2021. Each case: the best process CPU time of ``--reps`` runs in a
   child process importing either code (its own ``NUMBA_CACHE_DIR``, warmed first); the
   children alternate (baseline, new, baseline, new, …) for ``--rounds`` rounds and the best
   of all rounds counts. Printed: seconds of both, the ratio new / baseline per case and the
   geometric mean, and whether the recorded states are bitwise identical.
2. **Compile time** (``--cold``): the first ``simulate`` (hindawi2021, Ω = 1.5, 1 + 2 periods)
   in a process with an empty numba cache, for both codes (alternating, ``--cold`` times), wall
   seconds (best and median).

Run as ``python benchmarks/bench_integrator_split.py --baseline-src /tmp/old_integ/src
[--rounds 3] [--reps 3] [--cold 2] [--periods 2000]``.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import tempfile
from pathlib import Path
from typing import Any

from child import run_child

ROOT = Path(__file__).resolve().parents[1]

_CHILD = r"""
import hashlib, json, os, sys, time
spec = json.loads(sys.argv[1])
t0 = time.perf_counter()
import numba
import gearchaos
numba.set_num_threads(1)
RT = dict(rtol=1e-8, atol=1e-10)
FIG4 = {"xi": 0.03, "backlash.sun_planet": 3.0, "backlash.planet_ring": 3.5,
        "clearance.sun_bearing": 2.0}
if spec["cold"]:
    gearchaos.simulate(gearchaos.preset("hindawi2021"), omega=1.5, transient_periods=1,
                       periods=2, **RT)
    print("RESULT" + json.dumps({"compile": time.perf_counter() - t0,
                                 "file": gearchaos.__file__}))
    sys.exit(0)
hind = gearchaos.preset("hindawi2021")
fig4 = gearchaos.preset("sheng2016").evolve(FIG4)
cases = [(f"hindawi2021 Ω={om}", hind, om) for om in (0.5, 1.5, 2.5, 3.5)]
cases += [(f"fig4a Ω={om}", fig4, om) for om in (0.3, 1.0, 2.0, 3.2)]
gearchaos.simulate(hind, omega=1.0, transient_periods=1, periods=2, **RT)  # warm (cache)
gearchaos.simulate(fig4, omega=1.0, transient_periods=1, periods=2, **RT)
gearchaos.lyapunov_spectrum(hind, omega=1.5, n_exponents=1, transient_periods=1, periods=2, **RT)
out = {"file": gearchaos.__file__, "cases": {}}
for name, gs, om in cases:
    best = 1e300
    for _ in range(spec["reps"]):
        c0 = time.process_time()
        r = gearchaos.simulate(gs, omega=om, transient_periods=spec["periods"],
                                periods=spec["periods"], **RT)
        best = min(best, time.process_time() - c0)
    h = hashlib.sha256(r.states.tobytes()).hexdigest()[:16]
    out["cases"][name] = [best, h, int(r.steps_accepted + r.steps_rejected)]
best = 1e300
for _ in range(spec["reps"]):
    c0 = time.process_time()
    ly = gearchaos.lyapunov_spectrum(hind, omega=1.5, n_exponents=1, transient_periods=20,
                                     periods=spec["periods"] * 3 // 5, **RT)
    best = min(best, time.process_time() - c0)
out["cases"]["hindawi2021 Lyapunov Ω=1.5"] = [best, repr(float(ly.exponents[0])), 0]
print("RESULT" + json.dumps(out))
"""


def child(
    src: Path, cache: str, *, reps: int = 1, cold: bool = False, periods: int = 2000
) -> dict[str, Any]:
    """Run the benchmark child importing gearchaos from ``src`` with numba cache ``cache``."""
    spec = {"reps": reps, "cold": cold, "periods": periods}
    return run_child(_CHILD, spec, src, NUMBA_CACHE_DIR=cache, NUMBA_NUM_THREADS="1")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline-src", type=Path, required=True, help="src/ of the baseline")
    ap.add_argument("--new-src", type=Path, default=ROOT / "src", help="src/ of the new code")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--cold", type=int, default=0, help="cold-cache compile runs of each")
    ap.add_argument("--periods", type=int, default=2000, help="transient and recorded periods")
    args = ap.parse_args()
    codes = {"baseline": args.baseline_src.resolve(), "new": args.new_src.resolve()}
    with tempfile.TemporaryDirectory() as d:
        if args.cold:
            comp: dict[str, list[float]] = {k: [] for k in codes}
            for i in range(args.cold):
                for name, src in codes.items():
                    cache = os.path.join(d, f"cold-{name}-{i}")
                    comp[name].append(child(src, cache, cold=True)["compile"])
            print("compile + first simulate, empty numba cache (wall s): best / median")
            for name, ts in comp.items():
                print(f"  {name:9} {min(ts):7.2f} / {statistics.median(ts):7.2f}")
            print(f"  ratio new / baseline (best): {min(comp['new']) / min(comp['baseline']):.3f}")
        caches = {name: os.path.join(d, f"warm-{name}") for name in codes}
        best: dict[str, dict[str, float]] = {k: {} for k in codes}
        digest: dict[str, dict[str, Any]] = {k: {} for k in codes}
        for _ in range(args.rounds):
            for name, src in codes.items():
                res = child(src, caches[name], reps=args.reps, periods=args.periods)["cases"]
                for case, (sec, h, att) in res.items():
                    best[name][case] = min(best[name].get(case, math.inf), sec)
                    digest[name][case] = (h, att)
    print(f"\nCPU seconds, best of {args.rounds} rounds × {args.reps} runs, one thread")
    print(f"  {'case':28} {'baseline':>9} {'new':>9} {'new/base':>9}  identical")
    logs = []
    for case in best["baseline"]:
        b, n = best["baseline"][case], best["new"][case]
        logs.append(math.log(n / b))
        same = digest["baseline"][case] == digest["new"][case]
        print(f"  {case:28} {b:9.3f} {n:9.3f} {n / b:9.3f}  {same}")
    print(f"  geometric mean new / baseline: {math.exp(sum(logs) / len(logs)):.3f}")


if __name__ == "__main__":
    main()
