"""Period-doubling cascades: the period-2n branches born at the period doublings of a branch.

At a period doubling (PD) of a branch of period-n orbits a Floquet multiplier passes through
−1; a branch of period-2n orbits is born there, whose two section points per period-n orbit
point coincide at the PD and separate along the critical eigenvector. :func:`follow_cascade`
starts that branch at every PD of a continued branch (``continuation(start=event)``, the
switch of :mod:`gearchaos.dynamics.continuation.arclength`), then at every PD of those, down to a
chosen
depth, breadth first — so a period-doubling route 1T → 2T → 4T … is drawn as branches with
their own events, not inferred from the dots of a brute-force sweep.

Which PDs spawn a branch: by default those where the parent branch is stable on at least one
side (the attractor doubles); ``every=True`` also takes those of branches unstable on both
sides (whose period-2n branches are unstable). A PD that an already continued sibling branch
ends on (a period-doubling bubble: the period-2n branch born at one PD dies at the next) is
not continued twice.

The branches of a cascade share one netCDF file (:func:`save_cascade`): the first branch is
the file's root group, so :func:`~gearchaos.dynamics.continuation.branch.open_branch` reads it as
before,
and each period-2n branch is a group ``branch_1``, ``branch_2`` … (breadth first) whose
attributes name its ``parent`` group, the index of the ``parent_event`` in the parent's event
table, its ``parent_value`` and ``cascade_depth``. The root lists them in ``cascade`` (JSON)
and the PDs that gave no branch, with the reason, in ``cascade_skipped``.
:func:`open_cascade` returns them all.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable
from typing import Any

import numpy as np

from ..._checks import check_int, check_real
from ..._files import check_path
from ..._marks import mark_hdf5_file
from ..._output import staged_file
from ...errors import IntegrationError, ParameterError, StoreError

__all__ = ["ROOT", "check_cascade", "follow_cascade", "open_cascade", "save_cascade"]

#: The name of the first branch of a cascade (the file's root group).
ROOT = "branch_0"


def check_cascade(
    cascade: int | None,
    cascade_range: Any,
    max_branches: int | None,
    store: Any,
    a: float,
    b: float,
) -> tuple[float, float]:
    """The (start, stop) of the period-2n branches of a cascade (stop the end the branch
    heads for), with the cascade's arguments checked before any run."""
    if cascade is None:
        given = [
            k for k, v in (("cascade_range", cascade_range), ("max_branches", max_branches))
            if v is not None
        ]  # fmt: skip
        if given:
            raise ParameterError(f"{' and '.join(given)} need cascade=DEPTH: got cascade=None")
        return a, b
    check_int("cascade", cascade, lo=0, hi=16)
    if max_branches is not None:
        check_int("max_branches", max_branches, lo=1)
    if store is not None and not os.fspath(store).endswith((".nc", ".nc4", ".h5")):
        raise ParameterError(
            "store of a cascade must be a netCDF file (.nc): its branches are groups of one "
            f"file: got {os.fspath(store)!r}"
        )
    if cascade_range is None:
        lo, hi = min(a, b), max(a, b)
    else:
        if not isinstance(cascade_range, tuple | list) or len(cascade_range) != 2:
            raise ParameterError(f"cascade_range must be (lo, hi): got {cascade_range!r}")
        lo = check_real("cascade_range lo", cascade_range[0])
        hi = check_real("cascade_range hi", cascade_range[1])
        if not lo < hi:
            raise ParameterError(f"cascade_range must have lo < hi: got {cascade_range!r}")
    return (lo, hi) if b >= a else (hi, lo)


def _spawning(branch: Any, every: bool) -> list[tuple[int, Any]]:
    """(index, Event) of the period doublings of ``branch`` that start a period-2n branch."""
    from .events import events

    stable = np.asarray(branch["stable"].values, dtype=bool)
    out = []
    for k, ev in enumerate(events(branch)):
        if ev.kind != "period_doubling":
            continue
        i = min(max(int(ev.point), 0), stable.size - 1)
        j = min(i + 1, stable.size - 1)
        if every or stable[i] or stable[j]:
            out.append((k, ev))
    return out


def _covered(children: list[Any], ev: Any, span: float) -> bool:
    """Whether one of ``children`` (period-2n branches of the same parent) passes through the
    period-n orbit of the period doubling ``ev`` (its two section points one there)."""
    scale = max(1.0, float(np.max(np.abs(ev.state))))
    for ch in children:
        name = str(ch.attrs["parameter"])
        lam = np.asarray(ch[name].values, dtype=float)
        degenerate = np.asarray(ch["minimal_period"].values) * 2 == int(ch.attrs["period"])
        near = degenerate & (np.abs(lam - ev.value) <= 1e-3 * span)
        for p in np.flatnonzero(near):
            y = np.asarray(ch["orbit_state"].values[p], dtype=float)
            if float(np.max(np.abs(y - ev.state))) <= 1e-3 * scale:
                return True
    return False


def follow_cascade(
    main: Any,
    run_child: Callable[[Any], Any],
    depth: int,
    *,
    every: bool = False,
    max_branches: int | None = None,
) -> list[Any]:
    """The branches of a period-doubling cascade, breadth first, the given branch first.

    Parameters
    ----------
    main
        A continued branch (:func:`gearchaos.continuation`).
    run_child
        Continues the period-2n branch from a period-doubling
        :class:`~gearchaos.dynamics.Event` (``continuation(..., start=event)``); an
        :class:`~gearchaos.errors.IntegrationError` or
        :class:`~gearchaos.errors.ParameterError` it raises skips that event (the reason is
        kept in ``cascade_skipped``).
    depth
        How many doublings to follow: 1 the period-2n branches of ``main``'s PDs, 2 also
        their period-4n branches, …; 0 none.
    every
        Also switch at PDs where the parent is unstable on both sides.
    max_branches
        Most branches in all, ``main`` included (default: no limit).

    Returns
    -------
    list of xarray.Dataset
        ``main`` first; every branch has the attributes ``branch`` (its group name),
        ``parent`` (``""`` for ``main``), ``parent_event`` (−1 for ``main``),
        ``parent_value`` and ``cascade_depth``; ``main`` also ``cascade`` (the other
        branches' names, JSON) and ``cascade_skipped`` (JSON list of ``{"parent", "event",
        "value", "reason"}``).
    """
    depth = check_int("cascade", depth, lo=0, hi=16)
    limit = math.inf if max_branches is None else check_int("max_branches", max_branches, lo=1)
    span = abs(float(main.attrs["range_stop"]) - float(main.attrs["range_start"]))
    main.attrs.update(branch=ROOT, parent="", parent_event=-1, parent_value=math.nan)
    main.attrs["cascade_depth"] = 0
    out = [main]
    skipped: list[dict[str, Any]] = []
    level = [main]
    for d in range(1, depth + 1):
        born: list[Any] = []
        for parent in level:
            children: list[Any] = []
            for k, ev in _spawning(parent, every):
                where = {"parent": parent.attrs["branch"], "event": k, "value": ev.value}
                if len(out) >= limit:
                    skipped.append({**where, "reason": f"max_branches ({max_branches}) reached"})
                    continue
                if _covered(children, ev, span):
                    skipped.append({**where, "reason": "a sibling branch ends on this PD"})
                    continue
                try:
                    child = run_child(ev)
                except (IntegrationError, ParameterError) as exc:
                    skipped.append({**where, "reason": f"{type(exc).__name__}: {exc}"})
                    continue
                child.attrs.update(
                    branch=f"branch_{len(out)}",
                    parent=str(parent.attrs["branch"]),
                    parent_event=int(k),
                    parent_value=float(ev.value),
                    cascade_depth=int(d),
                )
                children.append(child)
                out.append(child)
            born.extend(children)
        level = born
    main.attrs["cascade"] = json.dumps([str(b.attrs["branch"]) for b in out[1:]])
    main.attrs["cascade_skipped"] = json.dumps(skipped)
    main.attrs["cascade_requested"] = int(depth)
    return out


def save_cascade(
    branches: list[Any], path: str | os.PathLike[str], *, overwrite: bool = False
) -> str:
    """Write the branches of :func:`follow_cascade` to one netCDF-4 file (``*.nc``): the
    first in the root group, each other in the group named by its ``branch`` attribute.
    The file appears under its name only when complete."""
    from .branch import check_store

    kind = check_store(path, overwrite)
    path = os.fspath(path)
    if kind != "netcdf":
        raise ParameterError(
            "store of a cascade must be a netCDF file (.nc): its branches are groups of one "
            f"file: got {path!r}"
        )
    if not branches or "cascade" not in branches[0].attrs:
        raise ParameterError("save_cascade needs the branches of follow_cascade: got none")
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with staged_file(path, what="branch file") as tmp:
        for k, ds in enumerate(branches):
            encoding = {
                nm: {"fletcher32": True}
                for nm, var in ds.variables.items()
                if var.ndim and var.size and var.dtype.kind in "biuf"
            }
            ds.to_netcdf(
                tmp,
                mode="w" if k == 0 else "a",
                group=None if k == 0 else str(ds.attrs["branch"]),
                engine="h5netcdf",
                encoding=encoding,
            )
        mark_hdf5_file(tmp)  # the mark of its root attributes: what overwrite may replace
    return path


def open_cascade(path: str | os.PathLike[str]) -> list[Any]:
    """All branches of a branch file: the root branch, then the period-2n branches of its
    cascade (:func:`save_cascade`) in the order they were continued; a file of one branch
    gives a list of one."""
    import xarray as xr

    from .branch import open_branch

    root = open_branch(path)
    path = check_path(path, f"branch must be a path: got {path!r}")
    try:
        names = json.loads(str(root.attrs.get("cascade", "[]")))
    except ValueError:
        raise StoreError(f"branch {path} is damaged: its cascade attribute is no JSON") from None
    out = [root]
    for nm in names:
        try:
            ds = xr.load_dataset(path, group=str(nm), engine="h5netcdf")
        except Exception as exc:  # h5py raises many types for damaged files
            raise StoreError(
                f"branch {path} is damaged: its cascade branch {nm} cannot be read "
                f"({type(exc).__name__})"
            ) from None
        ds.encoding["source"] = path
        out.append(ds)
    return out
