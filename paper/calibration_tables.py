"""Markdown tables of a calibration log, as quoted in docs/reproduction.md.

    .venv/bin/python paper/calibration_tables.py [paper/calibration.jsonl] [--top 8]

Prints: how many candidates were evaluated and in which phase; the top candidates with every
search variable; the base (MODEL.md §9) set's rank; how strongly each variable goes with the
score (Spearman rank correlation over all candidates); and, landmark by landmark, what the best
candidate gains and loses against the base set. Everything is read from the log, nothing is
re-run.
"""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path

import numpy as np
from scipy.stats import spearmanr

from gearchaos.paper.calibrate import ranked, read_results

SHORT = {
    "torque.input": ("T_D (N·m)", 1.0, "{:.0f}"),
    "transmission_error.amplitude": ("A (µm)", 1e6, "{:.2f}"),
    "stiffness.epsilon_sp": ("ε_sp", 1.0, "{:.3f}"),
    "stiffness.epsilon_rp": ("ε_rp", 1.0, "{:.3f}"),
    "stiffness.rp_sp_ratio": ("k_rp/k_sp", 1.0, "{:.2f}"),
    "inertia.sun_scale": ("s_s", 1.0, "{:.2f}"),
    "inertia.planet_scale": ("s_p", 1.0, "{:.2f}"),
    "inertia.carrier_scale": ("s_c", 1.0, "{:.2f}"),
    "clearance.characteristic_length": ("b_c (µm)", 1e6, "{:.1f}"),
}


def _teeth(v: dict) -> str:
    return f"{v['geometry.planets']}; {v['teeth.sun']}/{v['teeth.planet']}/{v['teeth.ring']}"


def _row(rank: str, r: dict) -> str:
    v = r["variables"]
    cells = [rank, str(r["index"]), r["origin"], f"{r['score']:.2f}", _teeth(v)]
    cells += [fmt.format(v[k] * scale) for k, (_, scale, fmt) in SHORT.items()]
    cells.append(v["torque.mode"].replace("constant_", "const. "))
    return "| " + " | ".join(cells) + " |"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("log", nargs="?", default=str(Path(__file__).with_name("calibration.jsonl")))
    ap.add_argument("--top", type=int, default=8)
    args = ap.parse_args()
    rows = sorted(read_results(args.log).values(), key=lambda r: r["index"])
    phases = Counter("refine" if r["origin"].startswith("refine") else r["origin"] for r in rows)
    secs = np.array([r["seconds"] for r in rows])
    print(
        f"{len(rows)} candidates ({', '.join(f'{k} {n}' for k, n in phases.items())}); "
        f"{secs.sum() / 60:.1f} min of evaluation, median {np.median(secs):.1f} s each"
    )
    scores = np.array([r["score"] for r in rows])
    base = next(r for r in rows if r["origin"] == "base")
    order = ranked(rows)
    base_rank = 1 + order.index(base)
    print(
        f"scores: max {scores.max():.2f}, median {np.median(scores):.2f}, min {scores.min():.2f}; "
        f"base {base['score']:.2f} (rank {base_rank} of {len(rows)})\n"
    )
    head = ["rank", "#", "origin", "score", "N; z_s/z_p/z_r"] + [s[0] for s in SHORT.values()]
    head.append("load")
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for i, r in enumerate(order[: args.top]):
        print(_row(str(i + 1), r))
    print(_row(str(base_rank), base))
    print("\nSpearman rank correlation of each variable with the score (all candidates):\n")
    print("| variable | ρ | p |")
    print("|---|---|---|")
    names = [*SHORT, "geometry.planets"]
    for k in names:
        x = np.array([float(r["variables"][k]) for r in rows])
        rho, p = spearmanr(x, scores)
        print(f"| {SHORT.get(k, (k,))[0]} | {rho:+.2f} | {p:.2g} |")
    power = np.array([r["variables"]["torque.mode"] == "constant_power" for r in rows])
    print(
        f"| load mode (constant power = 1) | {spearmanr(power, scores)[0]:+.2f} | "
        f"{spearmanr(power, scores)[1]:.2g} |"
    )
    best = order[0]
    print(f"\nLandmarks, best (#{best['index']}) against base:\n")
    print("| landmark | base | best |")
    print("|---|---|---|")
    for lid in sorted(best["landmarks"]):
        a, b = base["landmarks"].get(lid, 0.0), best["landmarks"][lid]
        if abs(a - b) > 0.05:
            print(f"| {lid} | {a:.2f} | {b:.2f} |")
    top10 = order[:10]
    always = [
        lid for lid in best["landmarks"] if all(r["landmarks"].get(lid, 0) >= 0.8 for r in rows)
    ]
    never = [
        lid for lid in best["landmarks"] if all(r["landmarks"].get(lid, 0) < 0.2 for r in rows)
    ]
    print(f"\nreproduced (≥ 0.8) by every candidate: {len(always)}: {', '.join(sorted(always))}")
    print(f"reproduced (≥ 0.2) by no candidate: {len(never)}: {', '.join(sorted(never))}")
    print(
        "top-10 spread: score "
        f"{min(r['score'] for r in top10):.2f}–{max(r['score'] for r in top10):.2f}"
    )


if __name__ == "__main__":
    main()
