"""Benchmark (issue 13): what another Runge–Kutta pair would save on the seed's Fig. 4(a) sweep.

MODEL.md §8 prescribes Dormand–Prince 5(4) (the seed's ``ode45``). This script measures how much
of the sweep's cost is the method's and how much another explicit pair would remove, at the
sweep's tolerances (rtol 1e-8, atol 1e-10):

1. **Smooth points.** Ω = 0.05, 0.2, 0.46 of the Fig. 4(a) gear set, where every mesh stays in
   contact (checked: no contact changes over the two periods), at the sweep's low-Ω end, where
   about 40 % of its step attempts go (Ω < 0.5). From the state ``gearchaos.simulate`` reaches
   after 100 periods, two periods are integrated in a Python loop over the compiled right-hand
   side with the package's PI controller (β = 0.04, same norm, same limits), for the package's
   Dormand–Prince 5(4) tableau and for Tsitouras' 5(4) pair (Tsit5, 2011). Printed: step
   attempts, right-hand-side evaluations and the global error against scipy's DOP853 at rtol
   1e-13; and the same for scipy's DOP853 (an 8(5,3) pair) at the sweep's tolerances.
2. **The sweep.** The Fig. 4(a) sweep (``--points``, default 200, 100 + 100 periods, all cores)
   with the package's Dormand–Prince kernel and with the same compiled code run on Tsit5's
   tableau (:data:`gearchaos.integrate.tableau.TSIT5`, as data:
   :func:`gearchaos.integrate.methods.use_tableau`); each in a child process after a warm-up.
   Printed: wall time and step attempts of both and their ratios.

Run as ``python benchmarks/bench_methods.py [--points N] [--skip-sweep]``.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_speed import ATOL, FIG4_FIXED, FIG4_RANGE, RTOL

SMOOTH_OMEGAS = (0.05, 0.2, 0.46)


def pi_loop(f: Any, t0: float, y0: np.ndarray, t1: float, tab: Any) -> tuple[np.ndarray, int]:
    """The package's step control (its constants from ``integrate._control``) around one
    embedded pair, in Python: returns y(t1) and the number of step attempts."""
    from gearchaos.integrate import _control as D

    a, _, _, c, e = tab.arrays()
    s = tab.stages
    alpha = D.pi_alpha(tab.order_hat)
    t, y, h = t0, y0.copy(), 0.01
    k = np.zeros((s, y.size))
    k[0] = f(t, y)
    attempts, err_old, last_rejected = 0, D.ERR_OLD_MIN, False
    while t < t1:
        hs = min(h, t1 - t)
        for i in range(1, s):
            k[i] = f(t + c[i] * hs, y + hs * (a[i, :i] @ k[:i]))
        y_new = y + hs * (a[s - 1, : s - 1] @ k[: s - 1])
        sc = ATOL + RTOL * np.maximum(np.abs(y), np.abs(y_new))
        err = float(np.sqrt(np.mean((hs * (e @ k) / sc) ** 2)))
        attempts += 1
        if err > 1.0:
            h = hs * max(D.MIN_FACTOR, D.SAFETY * err**-alpha)
            last_rejected = True
            continue
        fac = D.MAX_FACTOR
        if err > 0.0:
            fac = D.SAFETY * err**-alpha * err_old**D.BETA
            fac = min(D.MAX_FACTOR, max(D.MIN_FACTOR, fac))
        if last_rejected:
            fac = min(fac, 1.0)
        last_rejected = False
        err_old = max(err, D.ERR_OLD_MIN)
        t, y, h = t + hs, y_new, hs * fac
        k[0] = k[s - 1]
    return y, attempts


def smooth_table() -> None:
    from scipy.integrate import solve_ivp

    import gearchaos
    from gearchaos.integrate.tableau import DOPRI5, TSIT5
    from gearchaos.model import kernels
    from gearchaos.model.target import resolve

    gs = gearchaos.preset("sheng2016").evolve(FIG4_FIXED)
    print("1. smooth points (every mesh in contact), 2 periods after 100, Python loop over the "
          "compiled right-hand side")  # fmt: skip
    print(f"   {'Ω':>5} {'method':22} {'attempts':>9} {'evaluations':>12} {'global error':>13}"
          "  DP5's evaluations / these")  # fmt: skip
    for om in SMOOTH_OMEGAS:
        system = resolve(gs, {"omega": om})
        p = system.params
        fn = kernels._KERNELS[system.model.kind]
        r = gearchaos.simulate(gs, omega=om, transient_periods=100, periods=2, rtol=RTOL,
                               atol=ATOL)  # fmt: skip
        # every dead-zone argument stays outside its clearance over the two periods
        sw = np.asarray(system.switch_widths, dtype=float)
        on = sw < np.inf
        lo, hi = r.obs_min[: sw.size][on], r.obs_max[: sw.size][on]
        b = sw[on]
        if not np.all((lo > b) | (hi < -b) | ((lo > -b) & (hi < b))):
            print(f"   {om:5.2f} skipped: a contact changes within the two periods")
            continue
        y0 = np.asarray(r.states[0], dtype=float)
        t0 = float(r.tau[0])
        t1 = t0 + 2.0 * 2.0 * math.pi / om
        obs = np.zeros(system.n_obs)

        def f(t: float, y: np.ndarray, fn: Any = fn, p: Any = p, obs: Any = obs) -> np.ndarray:
            d = np.empty_like(y)
            fn(t, y, p, d, obs, 0)
            return d

        ref = solve_ivp(f, (t0, t1), y0, method="DOP853", rtol=1e-13, atol=1e-15).y[:, -1]
        rows = []
        for tab in (DOPRI5, TSIT5):
            y, att = pi_loop(f, t0, y0, t1, tab)
            rows.append((tab.name, att, 6 * att, float(np.max(np.abs(y - ref)))))
        sol = solve_ivp(f, (t0, t1), y0, method="DOP853", rtol=RTOL, atol=ATOL)
        rows.append(("scipy DOP853 8(5,3)", sol.t.size - 1, sol.nfev,
                     float(np.max(np.abs(sol.y[:, -1] - ref)))))  # fmt: skip
        for name, att, nfev, err in rows:
            print(f"   {om:5.2f} {name:22} {att:9d} {nfev:12d} {err:13.2e}  "
                  f"{rows[0][2] / nfev:6.2f}")  # fmt: skip


_SWEEP_CHILD = r"""
import json, os, sys, tempfile, time
import numpy as np
import gearchaos
from gearchaos.integrate import tableau
from gearchaos.integrate.methods import use_tableau
spec = json.loads(sys.argv[1])
gs = gearchaos.preset("sheng2016")
common = dict(rtol=spec["rtol"], atol=spec["atol"], progress=False, params=spec["fixed"])
with use_tableau(getattr(tableau, spec["tableau"])), tempfile.TemporaryDirectory() as d:
    gearchaos.bifurcation(gs, {"omega": np.array([1.0, 2.0])}, store=os.path.join(d, "w.zarr"),
                          transient_periods=1, periods=2, **common)
    omega = np.linspace(spec["lo"], spec["hi"], spec["points"])
    t0 = time.perf_counter()
    ds = gearchaos.bifurcation(gs, {"omega": omega}, store=os.path.join(d, "s.zarr"),
                               transient_periods=100, periods=100, **common)
    wall = time.perf_counter() - t0
    steps = ds["steps_accepted"].values.sum() + ds["steps_rejected"].values.sum()
    rejected = ds["steps_rejected"].values.sum()
    if "steps_switch" in ds:
        steps += ds["steps_switch"].values.sum()
print("RESULT" + json.dumps({"wall": wall, "steps": float(steps), "rejected": float(rejected)}))
"""


def run_sweep(points: int, tableau: str) -> dict[str, Any]:
    """The Fig. 4(a) sweep with the compiled integrator on ``tableau`` (a name in
    ``gearchaos.integrate.tableau``), in a child process."""
    spec = {"points": points, "lo": FIG4_RANGE[0], "hi": FIG4_RANGE[1], "rtol": RTOL,
            "atol": ATOL, "fixed": FIG4_FIXED, "tableau": tableau}  # fmt: skip
    proc = subprocess.run(
        [sys.executable, "-c", _SWEEP_CHILD, json.dumps(spec)],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    for line in proc.stdout.splitlines():
        if line.startswith("RESULT"):
            return dict(json.loads(line[6:]))
    raise RuntimeError(f"sweep child failed ({tableau}):\n{proc.stderr[-3000:]}")


def sweep_table(points: int) -> None:
    print(f"\n2. Fig. 4(a) sweep, {points} Ω in [0.05, 4], 100 + 100 periods, all cores")
    res = {}
    for name, tab in (("Dormand–Prince 5(4)", "DOPRI5"), ("Tsitouras 5(4)", "TSIT5")):
        res[name] = r = run_sweep(points, tab)
        print(f"   {name:22} {r['wall']:7.2f} s wall, {r['steps']:.3g} attempts, "
              f"{r['rejected'] / r['steps']:.1%} rejected")  # fmt: skip
    dp, ts = res["Dormand–Prince 5(4)"], res["Tsitouras 5(4)"]
    print(f"   Tsit5 / DP5: wall {ts['wall'] / dp['wall']:.2f}, "
          f"attempts {ts['steps'] / dp['steps']:.2f}")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=200)
    ap.add_argument("--skip-sweep", action="store_true")
    args = ap.parse_args()
    print(f"bench_methods: rtol {RTOL:g}, atol {ATOL:g}")
    smooth_table()
    if not args.skip_sweep:
        sweep_table(args.points)


if __name__ == "__main__":
    main()
