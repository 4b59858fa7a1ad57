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
   with this code and with a temporary copy of ``src/`` whose compiled kernel carries Tsit5's
   coefficients instead (the two extra terms a₇₂ and e₂ written into the stage and error
   sums); each in a child process after a warm-up (``bench_speed.run_sweep``). Printed: wall
   time and step attempts of both and their ratios.

Run as ``python benchmarks/bench_methods.py [--points N] [--skip-sweep]``.
"""

from __future__ import annotations

import argparse
import math
import shutil
import sys
import tempfile
from fractions import Fraction as Fr
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_speed import ATOL, FIG4_FIXED, ROOT, RTOL, run_sweep

SMOOTH_OMEGAS = (0.05, 0.2, 0.46)

#: Tsitouras (2011) 5(4), as published (floating-point coefficients): c, rows of A, b,
#: and e = b − b̂
TSIT5_C = (0.0, 0.161, 0.327, 0.9, 0.9800255409045097, 1.0, 1.0)
TSIT5_A = (
    (),
    (0.161,),
    (-0.008480655492356989, 0.335480655492357),
    (2.897153057105493, -6.359448489975075, 4.3622954328695815),
    (5.325864828439257, -11.748883564062828, 7.4955393428898365, -0.09249506636175525),
    (5.86145544294642, -12.92096931784711, 8.159367898576159, -0.071584973281401,
     -0.028269050394068383),
    (0.09646076681806523, 0.01, 0.4798896504144996, 1.379008574103742, -3.290069515436081,
     2.324710524099774),
)  # fmt: skip
TSIT5_E = (-0.00178001105222577714, -0.0008164344596567469, 0.007880878010261995,
           -0.1447110071732629, 0.5823571654525552, -0.45808210592918697, 1.0 / 66.0)  # fmt: skip


def tsit5_tableau() -> Any:
    """Tsit5 as a :class:`ButcherTableau` (exact binary fractions of the published floats),
    its order conditions checked to round-off (5 for b, 4 for b̂)."""
    from gearchaos.integrate.tableau import ButcherTableau

    b = (*TSIT5_A[-1], 0.0)
    tab = ButcherTableau(
        name="Tsitouras 5(4)",
        c=tuple(Fr(x) for x in TSIT5_C),
        a=tuple(tuple(Fr(x) for x in row) for row in TSIT5_A),
        b=tuple(Fr(x) for x in b),
        b_hat=tuple(Fr(x) - Fr(e) for x, e in zip(b, TSIT5_E, strict=True)),
        order=5,
        order_hat=4,
    )
    for w, p in ((tab.b, 5), (tab.b_hat, 4)):
        worst = max(abs(float(r)) for r in tab.order_residuals(w, p).values())
        assert worst < 1e-12, f"Tsit5 order-{p} conditions off by {worst:g}"
    for i, row in enumerate(tab.a):
        assert abs(float(sum(row, Fr(0)) - tab.c[i])) < 1e-14, f"row sum {i}"
    return tab


def pi_loop(f: Any, t0: float, y0: np.ndarray, t1: float, tab: Any) -> tuple[np.ndarray, int]:
    """The package's step control (its constants from dopri.py) around one embedded pair, in
    Python: returns y(t1) and the number of step attempts."""
    from gearchaos.integrate import dopri as D

    a = tab.a_matrix()
    c = np.array([float(x) for x in tab.c])
    e = np.array([float(x) for x in tab.error_weights])
    s = tab.stages
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
            h = hs * max(D.MIN_FACTOR, D.SAFETY * err**-D.ALPHA)
            last_rejected = True
            continue
        fac = D.MAX_FACTOR
        if err > 0.0:
            fac = D.SAFETY * err**-D.ALPHA * err_old**D.BETA
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
    from gearchaos.integrate.tableau import DOPRI5
    from gearchaos.model import kernels
    from gearchaos.model.target import resolve

    tsit5 = tsit5_tableau()
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
        for tab in (DOPRI5, tsit5):
            y, att = pi_loop(f, t0, y0, t1, tab)
            rows.append((tab.name, att, 6 * att, float(np.max(np.abs(y - ref)))))
        sol = solve_ivp(f, (t0, t1), y0, method="DOP853", rtol=RTOL, atol=ATOL)
        rows.append(("scipy DOP853 8(5,3)", sol.t.size - 1, sol.nfev,
                     float(np.max(np.abs(sol.y[:, -1] - ref)))))  # fmt: skip
        for name, att, nfev, err in rows:
            print(f"   {om:5.2f} {name:22} {att:9d} {nfev:12d} {err:13.2e}  "
                  f"{rows[0][2] / nfev:6.2f}")  # fmt: skip


_ANCHORS = (
    ("A71 * K[0, i] + A73 * K[2, i]", "A71 * K[0, i] + A72 * K[1, i] + A73 * K[2, i]"),
    ("E1 * K[0, i] + E3 * K[2, i]", "E1 * K[0, i] + E2 * K[1, i] + E3 * K[2, i]"),
)


def tsit5_copy(dst: Path) -> Path:
    """A copy of ``src/`` whose compiled kernel has Tsit5's coefficients; returns its src."""
    src = dst / "src"
    shutil.copytree(ROOT / "src", src, ignore=shutil.ignore_patterns("__pycache__"))
    path = src / "gearchaos" / "integrate" / "dopri.py"
    text = path.read_text()
    first = text.index("STAGES = DOPRI5.stages")
    last = text.index("SAFETY = 0.9")
    a = TSIT5_A
    consts = [
        "STAGES = 7",
        f"C2, C3, C4, C5 = {TSIT5_C[1]!r}, {TSIT5_C[2]!r}, {TSIT5_C[3]!r}, {TSIT5_C[4]!r}",
        f"A21 = {a[1][0]!r}",
        f"A31, A32 = {', '.join(map(repr, a[2]))}",
        f"A41, A42, A43 = {', '.join(map(repr, a[3]))}",
        f"A51, A52, A53, A54 = {', '.join(map(repr, a[4]))}",
        f"A61, A62, A63, A64, A65 = {', '.join(map(repr, a[5]))}",
        f"A71, A72, A73, A74, A75, A76 = {', '.join(map(repr, a[6]))}",
        f"E1, E2, E3, E4, E5, E6, E7 = {', '.join(map(repr, TSIT5_E))}",
    ]
    text = text[:first] + "\n".join(consts) + "\n\n" + text[last:]
    for old, new in _ANCHORS:
        if text.count(old) != 1:
            raise RuntimeError(f"dopri.py changed: cannot patch {old!r}; update this benchmark")
        text = text.replace(old, new)
    path.write_text(text)
    return src


def sweep_table(points: int) -> None:
    print(f"\n2. Fig. 4(a) sweep, {points} Ω in [0.05, 4], 100 + 100 periods, all cores")
    with tempfile.TemporaryDirectory() as d:
        tsit_src = tsit5_copy(Path(d))
        res = {}
        for name, src in (("Dormand–Prince 5(4)", ROOT / "src"), ("Tsitouras 5(4)", tsit_src)):
            res[name] = run_sweep(src, points, 100, 100, False, str(Path(d) / "s.npy"))
            r = res[name]
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
