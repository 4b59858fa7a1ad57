"""Write the reference results that ``test_reference.py`` compares against, bitwise.

Run from the repository root with ``.venv/bin/python tests/regression/make_reference.py``. The
files under ``tests/regression/reference/`` were written by this script *before* the
refactoring of issue 9 (one path from a parameter to the kernel), so the test proves that the
refactoring changed no number. Re-run it only when a change of the numerics is intended (a new
step-size controller, say) and say so in the commit message. Names of reference files as
arguments (``make_reference.py simulate.nc``) rewrite only those.
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

import gearchaos as gc

HERE = Path(__file__).resolve().parent
REF = HERE / "reference"

#: The calls whose results are kept; the test makes the same calls.
SIMULATE = {"omega": 1.37, "transient_periods": 12, "periods": 10, "samples_per_period": 8}
SWEEP_FRESH = {
    "vary": "omega=0.6:2.4:7",
    "family": {"xi": [0.03, 0.07]},
    "transient_periods": 15,
    "periods": 12,
    "lyapunov": True,
    "observe": ["delta_sp", "delta_sp_dot", "delta_rp", "x_s"],
    "planets": [1, 3],
    "progress": False,
}
SWEEP_CONTINUATION = {
    "vary": "backlash.sun_planet=1:5:6",
    "params": {"omega": 1.5, "xi": 0.05},
    "initial_conditions": "continuation",
    "direction": "both",
    "transient_periods": 10,
    "periods": 8,
    "progress": False,
}
SWEEP_OSCILLATOR = {
    "vary": "omega=0.5:2.5:9",
    "initial_conditions": "continuation",
    "transient_periods": 30,
    "periods": 16,
    "progress": False,
}


def gearset() -> gc.GearSet:
    return gc.preset("hindawi2021")


def oscillator() -> gc.System:
    return gc.backlash_oscillator(1.0, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.2)


def main(names: list[str]) -> None:
    """Write the reference files ``names`` (all of them if empty)."""
    stores = {
        "sweep_fresh.zarr": (gearset(), SWEEP_FRESH),
        "sweep_continuation.zarr": (gearset(), SWEEP_CONTINUATION),
        "sweep_oscillator.zarr": (oscillator(), SWEEP_OSCILLATOR),
    }
    unknown = sorted(set(names) - {"simulate.nc", *stores})
    if unknown:
        raise SystemExit(f"no such reference file: {', '.join(unknown)}")
    REF.mkdir(exist_ok=True)
    if not names or "simulate.nc" in names:
        res = gc.simulate(gearset(), **SIMULATE)
        res.save(REF / "simulate.nc")
    for name, (target, kw) in stores.items():
        if names and name not in names:
            continue
        path = REF / name
        if path.exists():
            shutil.rmtree(path)
        kw = dict(kw)
        gc.bifurcation(target, kw.pop("vary"), store=os.fspath(path), **kw)
    print(f"wrote {REF}")


if __name__ == "__main__":
    main(sys.argv[1:])
