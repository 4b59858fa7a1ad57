"""Benchmark: periodic orbits and continued branches against simulations and brute-force sweeps.

Run as ``python benchmarks/bench_orbits.py [--points 400] [--quick] [--preset NAME]``.

Gear set: ``gearchaos.preset(NAME)`` (default ``sheng2016``: N = 5 planets, 16 states), rtol
1e-8, atol 1e-10.

* One periodic orbit: :func:`gearchaos.periodic_orbit` at the first Ω of :data:`CANDIDATES` where
  a stable 1T orbit exists (found in the warm-up), from rest (its default guess: 50 forcing
  periods of simulation, then Newton), against :func:`gearchaos.simulate` at the same Ω with
  100 transient + 100 recorded periods. Both median of ``--repeat`` runs. Target (issue 11):
  the converged orbit in less time than the simulation.
* A continued branch: :func:`gearchaos.continuation` over Ω ∈ [0.2, 4] (the 1T branch from
  rest at Ω = 0.2, events detected and located), with ``max_step`` chosen so the branch has
  about ``--points`` points, against a brute-force sweep :func:`gearchaos.bifurcation` of the
  same range with ``--points`` points (fresh zero start, 100 + 100 periods, in-process on all
  cores, no store). Reported: wall and process CPU time (all threads), seconds per point, map
  evaluations (Newton iterations) per branch point, and the ratios. Target: the branch of
  ``--points`` points faster than the ``--points``-point sweep.

Everything runs in this process after a warm-up that compiles (or loads) every kernel used,
so compile time is excluded; baselines are measured in the same run.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import gearchaos as gc

RTOL = 1e-8
ATOL = 1e-10
OMEGA_RANGE = (0.2, 4.0)
#: Ω tried in turn for a stable 1T orbit: 0.88 is the default gear set's (the tutorial's
#: gallery), the others ``sheng2016-v1``'s and earlier sets'.
CANDIDATES = (1.5, 3.0, 0.5, 0.88)


def timed(fn, *args, **kw):
    """(result, wall seconds, process CPU seconds) of one call."""
    w0, c0 = time.perf_counter(), time.process_time()
    out = fn(*args, **kw)
    return out, time.perf_counter() - w0, time.process_time() - c0


def warm_up(gs: gc.GearSet) -> float:
    """Compile or load every kernel used; return the Ω of a stable 1T orbit."""
    gc.simulate(gs, omega=1.0, transient_periods=1, periods=2)
    gc.bifurcation(gs, "omega=1:1.1:2", transient_periods=1, periods=2, progress=False)
    gc.continuation(gs, "omega=3.0:3.02", max_points=3)
    for omega in CANDIDATES:
        orbit = gc.periodic_orbit(gs, omega=omega, rtol=RTOL, atol=ATOL)
        if orbit.converged and orbit.stable:
            return omega
    raise SystemExit(f"no stable 1T orbit at Ω in {CANDIDATES}")


def bench_orbit(gs: gc.GearSet, omega: float, repeat: int) -> dict[str, float]:
    orbit_w, orbit_c, sim_w, sim_c = [], [], [], []
    orbit = None
    for _ in range(repeat):
        orbit, w, c = timed(gc.periodic_orbit, gs, omega=omega, rtol=RTOL, atol=ATOL)
        orbit_w.append(w)
        orbit_c.append(c)
        _, w, c = timed(
            gc.simulate, gs, omega=omega, transient_periods=100, periods=100, rtol=RTOL, atol=ATOL
        )
        sim_w.append(w)
        sim_c.append(c)
    assert orbit is not None and orbit.converged
    return {
        "omega": omega,
        "orbit_wall": statistics.median(orbit_w),
        "orbit_cpu": statistics.median(orbit_c),
        "sim_wall": statistics.median(sim_w),
        "sim_cpu": statistics.median(sim_c),
        "iterations": orbit.iterations,
        "residual": orbit.residual,
        "max_multiplier": orbit.max_multiplier,
    }


def bench_branch(gs: gc.GearSet, points: int) -> dict[str, float]:
    span = OMEGA_RANGE[1] - OMEGA_RANGE[0]
    vary = f"omega={OMEGA_RANGE[0]}:{OMEGA_RANGE[1]}"
    # arclength also counts the change of the orbit: max_step = span/(0.72 points) gives about
    # `points` points on this branch
    branch, bw, bc = timed(
        gc.continuation, gs, vary, max_step=span / (0.72 * points), rtol=RTOL, atol=ATOL
    )
    sweep, sw, sc = timed(
        gc.bifurcation,
        gs,
        f"{vary}:{points}",
        progress=False,
        rtol=RTOL,
        atol=ATOL,
        transient_periods=100,
        periods=100,
    )
    n_b = int(branch.sizes["point"])
    return {
        "branch_points": n_b,
        "branch_wall": bw,
        "branch_cpu": bc,
        "sweep_points": int(sweep.sizes["omega"]),
        "sweep_wall": sw,
        "sweep_cpu": sc,
        "evals_per_point": float(branch.iterations.mean()),
        "jacobians_per_point": float(branch.jacobians.mean()),
        "newton_per_point": float(branch.newton_steps.mean()),
        "all_evals_per_point": branch.attrs["map_evaluations"] / n_b,
        "events": int(branch.sizes["event"]),
        "stop_reason": branch.attrs["stop_reason"],
        "event_list": ", ".join(f"{e.kind} {e.value:.4f}" for e in gc.dynamics.events(branch)),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--points", type=int, default=400)
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--quick", action="store_true", help="100 points, 3 repeats")
    ap.add_argument("--preset", default="sheng2016", help="built-in gear set (default sheng2016)")
    args = ap.parse_args()
    points, repeat = (100, 3) if args.quick else (args.points, args.repeat)

    import numba

    gs = gc.preset(args.preset)
    print(
        f"gearchaos {gc.__version__}, numba {numba.__version__}, {platform.processor() or '?'}, "
        f"{os.cpu_count()} CPUs, numba threads {numba.get_num_threads()}"
    )
    omega = warm_up(gs)
    o = bench_orbit(gs, omega, repeat)
    b = bench_branch(gs, points)

    n = gs.geometry.planets
    print(f"\n## One periodic orbit ({args.preset}, N = {n}, median of", repeat, "runs)")
    print(f"Ω = {o['omega']}, max |μ| = {o['max_multiplier']:.4f}, residual {o['residual']:.1e}")
    print("| what | wall s | CPU s |")
    print("|---|---:|---:|")
    print(
        f"| periodic_orbit (50-period guess + Newton) | {o['orbit_wall']:.3f} | "
        f"{o['orbit_cpu']:.3f} |"
    )
    print(f"| simulate, 100 + 100 periods | {o['sim_wall']:.3f} | {o['sim_cpu']:.3f} |")
    print(
        f"| ratio simulate / orbit | {o['sim_wall'] / o['orbit_wall']:.2f} | "
        f"{o['sim_cpu'] / o['orbit_cpu']:.2f} |"
    )
    print(f"map evaluations (Newton iterations, with trial steps): {o['iterations']}")
    ok_o = o["orbit_wall"] < o["sim_wall"]
    print(
        f"target (orbit faster than 100 + 100 periods of simulate): {'met' if ok_o else 'MISSED'}"
    )

    print(f"\n## Branch over Ω ∈ [{OMEGA_RANGE[0]}, {OMEGA_RANGE[1]}] against a sweep")
    print("| what | points | wall s | CPU s | wall s/point |")
    print("|---|---:|---:|---:|---:|")
    print(
        f"| continuation (events located) | {b['branch_points']} | {b['branch_wall']:.2f} | "
        f"{b['branch_cpu']:.2f} | {b['branch_wall'] / b['branch_points']:.4f} |"
    )
    print(
        f"| bifurcation sweep, 100 + 100 periods | {b['sweep_points']} | {b['sweep_wall']:.2f} "
        f"| {b['sweep_cpu']:.2f} | {b['sweep_wall'] / b['sweep_points']:.4f} |"
    )
    print(
        f"| ratio sweep / branch | | {b['sweep_wall'] / b['branch_wall']:.2f} | "
        f"{b['sweep_cpu'] / b['branch_cpu']:.2f} | "
        f"{(b['sweep_wall'] / b['sweep_points']) / (b['branch_wall'] / b['branch_points']):.2f} |"
    )
    print(f"Newton steps per branch point: {b['newton_per_point']:.2f}")
    print(
        f"map evaluations per branch point: {b['evals_per_point']:.2f} in the corrector "
        f"({b['jacobians_per_point']:.2f} with tangents), {b['all_evals_per_point']:.2f} with "
        "event location"
    )
    print(f"events ({b['events']}): {b['event_list']}")
    print(f"stop: {b['stop_reason']}")
    per_point_ok = b["branch_wall"] / b["branch_points"] < b["sweep_wall"] / b["sweep_points"]
    ok_b = b["branch_wall"] < b["sweep_wall"] and b["branch_points"] >= 0.9 * points
    print(
        f"target (a branch of {points} points faster than a {points}-point sweep): "
        f"{'met' if ok_b else 'MISSED'}; per point: {'faster' if per_point_ok else 'SLOWER'}"
    )


if __name__ == "__main__":
    main()
