"""Benchmark (issue 22): what the motion verdict costs, and what it changes, on the seed's
Fig. 4(a) sweep.

Run as ``python benchmarks/bench_verdicts.py [--points 1000] [--preset NAME] [--baseline SRC]
[--reproduce]``.

With ``--baseline SRC`` (the ``src/`` of an earlier checkout, e.g. a ``git worktree`` of the
commit before a change to the verdict) the same verdict sweep also runs there, in a child
process, and the table of label changes from those verdicts to these is printed (issue 32:
against the verdicts of before).

The sweep: Ω ∈ [0.05, 4] in ``--points`` values, the gear set ``--preset`` (default
``sheng2016``) at ξ = 0.03, 100 transient + 100 recorded periods, in memory on all cores. Three
sweeps in this one process, after a 4-point warm-up of each kind (compilation left out):

1. plain — ``verdicts=False``: labels from the record alone (the heuristic of old);
2. Lyapunov — ``verdicts=False, lyapunov=True``: λ₁ of every point from the recorded run;
3. verdicts — the default: shooting, Floquet multipliers, λ₁ ± σ from extensions.

Printed: wall times and their ratios to the plain sweep measured in this run (goal: verdicts
≤ 2× plain), the table of label changes (plain label → verdict label, counts), the share of
points decided by each kind of evidence, and the share left unresolved (goal ≤ 1 %). With
``--reproduce`` also the wall time of ``gearchaos reproduce --all`` into a temporary folder
(goal ≤ 3 min on the 2-core machine).
"""

from __future__ import annotations

import argparse
import collections
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import gearchaos as gc
from gearchaos import sweep
from gearchaos.dynamics import EVIDENCE

sys.path.insert(0, os.path.dirname(__file__))
from child import run_child

#: The verdict sweep of another checkout (a child importing gearchaos from its src/).
_BASELINE = """
import json, sys, time
import numpy as np
import gearchaos as gc
from gearchaos import sweep
spec = json.loads(sys.argv[1])
gs = gc.preset(spec["preset"])
sweep.bifurcation(gs, "omega=0.05:4:4", params={"xi": 0.03}, progress=False)
t = time.perf_counter()
ds = sweep.bifurcation(gs, f"omega=0.05:4:{spec['points']}", params={"xi": 0.03}, progress=False)
out = {"seconds": time.perf_counter() - t, "file": gc.__file__,
       "motion": [str(x) for x in np.asarray(ds.motion.values).ravel()]}
print("RESULT" + json.dumps(out))
"""


def _sweep(points: int, preset: str, **options: object) -> tuple[float, object]:
    gs = gc.preset(preset)
    t = time.perf_counter()
    ds = sweep.bifurcation(
        gs, f"omega=0.05:4:{points}", params={"xi": 0.03}, progress=False, **options
    )
    return time.perf_counter() - t, ds


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=1000)
    ap.add_argument("--reproduce", action="store_true", help="also time reproduce --all")
    ap.add_argument("--baseline", type=Path, help="src/ of an earlier checkout to compare")
    ap.add_argument(
        "--preset",
        default="sheng2016",
        help="built-in gear set (one the baseline also has, to compare with an earlier checkout)",
    )
    a = ap.parse_args()
    for kw in ({"verdicts": False}, {"verdicts": False, "lyapunov": True}, {}):
        _sweep(4, a.preset, **kw)  # compile / load the cache
    t_plain, plain = _sweep(a.points, a.preset, verdicts=False)
    t_lyap, _ = _sweep(a.points, a.preset, verdicts=False, lyapunov=True)
    t_verd, verd = _sweep(a.points, a.preset)
    print(
        f"Fig. 4(a) sweep of {a.preset}: {a.points} Ω in [0.05, 4], ξ = 0.03, 100 + 100 periods, "
        "all cores"
    )
    print(f"  plain (record labels)   {t_plain:7.2f} s   1.00×")
    print(f"  with Lyapunov exponents {t_lyap:7.2f} s   {t_lyap / t_plain:.2f}×")
    print(f"  with verdicts           {t_verd:7.2f} s   {t_verd / t_plain:.2f}×  (goal ≤ 3×)")
    old = [str(x) for x in np.asarray(plain.motion.values).ravel()]  # type: ignore[attr-defined]
    new = [str(x) for x in np.asarray(verd.motion.values).ravel()]  # type: ignore[attr-defined]
    changes = collections.Counter(zip(old, new, strict=True))
    print("\nlabel changes (record label → verdict), counts:")
    for (o, n), c in sorted(changes.items(), key=lambda kv: -kv[1]):
        print(f"  {o:>10s} → {n:<10s} {c:5d}{'' if o != n else '   (same)'}")
    codes = np.asarray(verd.verdict.values).ravel()  # type: ignore[attr-defined]
    names = {v: k for k, v in EVIDENCE.items()}
    print("\nshare of points by deciding evidence:")
    for code, c in sorted(collections.Counter(codes.tolist()).items()):
        print(f"  {names[int(code)]:<20s} {100.0 * c / codes.size:6.1f} %")
    unresolved = 100.0 * new.count("unresolved") / len(new)
    print(f"\nunresolved: {unresolved:.1f} % (goal ≤ 1 %)")
    omegas = np.asarray(verd.omega.values).ravel()  # type: ignore[attr-defined]
    lle = np.asarray(verd.lle.values).ravel()  # type: ignore[attr-defined]
    err = np.asarray(verd.lle_error.values).ravel()  # type: ignore[attr-defined]
    win = np.asarray(verd.window_periods.values).ravel()  # type: ignore[attr-defined]
    for i in [i for i, lab in enumerate(new) if lab == "unresolved"]:
        print(
            f"  unresolved at Ω = {omegas[i]:.4f}: {names[int(codes[i])]}, "
            f"λ₁ = {lle[i]:.4g} ± {err[i]:.2g} over {int(win[i])} periods"
        )
    extra = np.asarray(verd.extra_periods.values).ravel()  # type: ignore[attr-defined]
    print(f"periods added per point: mean {extra.mean():.1f}, max {int(extra.max())}")
    if a.baseline is not None:
        base = run_child(_BASELINE, {"points": a.points, "preset": a.preset}, a.baseline.resolve())
        print(
            f"\nbaseline verdict sweep ({a.baseline}): {base['seconds']:.2f} s, "
            f"this one / baseline {t_verd / base['seconds']:.3f}"
        )
        changes = collections.Counter(zip(base["motion"], new, strict=True))
        print("label changes (earlier verdict → this verdict), counts:")
        for (o, n), c in sorted(changes.items(), key=lambda kv: -kv[1]):
            print(f"  {o:>10s} → {n:<10s} {c:5d}{'' if o != n else '   (same)'}")
    if a.reproduce:
        exe = os.path.join(os.path.dirname(sys.executable), "gearchaos")
        with tempfile.TemporaryDirectory() as d:
            t = time.perf_counter()
            subprocess.run([exe, "reproduce", "--all", "-o", d], check=True, capture_output=True)
            print(f"\ngearchaos reproduce --all: {time.perf_counter() - t:.0f} s (goal ≤ 180 s)")


if __name__ == "__main__":
    main()
