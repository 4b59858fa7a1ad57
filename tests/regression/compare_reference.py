"""Compare ``reference/`` with an older copy of it, after a deliberate change of the numerics.

Run from the repository root with
``.venv/bin/python tests/regression/compare_reference.py OLD_REFERENCE_DIR``: prints, for every
stored result, the largest absolute difference of each floating-point variable and which
motion labels changed, so a commit that regenerates the reference can show that the results
moved only within the integration tolerance.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import xarray as xr
from make_reference import REF  # type: ignore[import-not-found]


def _open(path: Path) -> xr.Dataset:
    if path.suffix == ".nc":
        return xr.open_dataset(path)
    return xr.open_zarr(path, consolidated=True)


def compare(old_dir: Path) -> None:
    for new in sorted(REF.iterdir()):
        old = old_dir / new.name
        a, b = _open(old), _open(new)
        print(f"{new.name}:")
        for name in sorted(b.data_vars):
            if name not in a:
                print(f"  {name:24s} new")
                continue
            x, y = np.asarray(a[name].values), np.asarray(b[name].values)
            if x.dtype.kind == "f" and x.shape == y.shape:
                d = np.abs(x - y)
                scale = np.nanmax(np.abs(x)) if np.isfinite(x).any() else 0.0
                print(f"  {name:24s} max |Δ| {np.nanmax(d) if d.size else 0.0:.3g}"
                      f"  (max |value| {scale:.3g})")  # fmt: skip
            elif x.shape == y.shape and x.dtype.kind in "iUSb":
                changed = int(np.sum(x != y))
                if changed:
                    print(f"  {name:24s} {changed} of {x.size} values differ: "
                          f"{x[x != y].tolist()} -> {y[x != y].tolist()}")  # fmt: skip


if __name__ == "__main__":
    compare(Path(sys.argv[1]))
