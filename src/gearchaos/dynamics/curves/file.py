"""The dataset of a two-parameter boundary curve, its file, and reading it back for a resume.

A curve file is a branch file (:func:`gearchaos.dynamics.save_branch`: netCDF-4 with
checksums, or Zarr) with the layout of :func:`curve_dataset`:

dimensions
    ``point`` (curve points in arclength order: the backward end first), ``state``,
    ``unknown`` (the state names, then both parameters), ``multiplier``, ``section``,
    ``track`` (tracked observables), ``event`` (codimension-2 points).
coordinates
    both parameters by their dotted names (point), ``arclength`` (point; 0 at the start, the
    event the curve was started from).
per point
    ``orbit_state`` (point, state) y* at the section; ``orbit_sections`` (point, section,
    state); ``multiplier_re``/``_im``/``_abs`` (point, multiplier); ``critical_re``/``_im``
    (the critical multiplier); ``max_multiplier``; ``unstable`` (|μ| > 1 among the others);
    ``stable`` (int8: all multipliers but the critical one inside the unit circle: the orbit is
    stable on one side of the boundary); ``test_value`` (g); ``residual``; ``iterations`` (map
    evaluations of the corrector); ``direction`` (−1 backward, 0 start, +1 forward);
    ``on_grid`` (int8: landed on a value of ``at``); ``uncertainty``, ``uncertainty2`` (of λ₁
    and λ₂: the point's shift when corrected again 100 times tighter, a landed point on its
    own λ₂, any other on its tangent hyperplane; NaN where not assessed, see the attribute
    ``assessed``); ``tangent`` (point, unknown); ``obs_min``,
    ``obs_max`` (point, track) extrema of the tracked observables over the orbit.
events
    ``event_kind`` (cusp, fold_flip, resonance_1_2, … see
    :mod:`gearchaos.dynamics.curves.defining`), ``event_value`` (first parameter),
    ``event_value2`` (second), ``event_point`` (index of the point before it),
    ``event_arclength``, ``event_multiplier_re``/``_im`` (the critical multiplier there),
    ``event_state``, ``event_vector`` (zeros), ``event_detail``, ``event_located`` (int8),
    ``event_uncertainty``, ``event_uncertainty2`` (in each parameter: half the final bracket,
    plus, unless ``assessed`` is ``none``, the shift when located again on the curve corrected
    100 times tighter).
attributes
    ``kind`` = ``boundary_curve``, ``curve_kind`` (fold, period_doubling, neimark_sacker,
    grazing), ``parameter`` and ``parameter2``, ``period``, ``vary`` and ``within`` (the two
    ranges), ``fixed`` (JSON), ``start`` (the event it was started from), ``contact`` (grazing),
    ``stop_reason_forward``/``_backward``, ``assessed`` (which points state their
    uncertainty: landed, all or none), ``tol``, steps, solver settings, model provenance
    (gear set TOML …) and versions.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from ..._version import provenance
from ...errors import StoreError
from ..continuation.branch import fixed_json, open_branch
from ..orbits.orbit import model_attrs

__all__ = ["CURVE_TITLE", "RESUMABLE", "curve_dataset", "open_curve"]

#: The title every curve file starts with.
CURVE_TITLE = "gearchaos boundary curve"
#: Stop reasons of an end that a resume continues.
RESUMABLE = ("max_points", "interrupted")


def curve_dataset(
    curve: Any,
    backward: list[Any],
    forward: list[Any],
    reasons: tuple[str, str],
    attrs: dict[str, Any],
) -> Any:
    """The :class:`xarray.Dataset` of a curve: ``backward`` and ``forward`` both start at the
    start point (layout in the module docstring)."""
    import xarray as xr

    pts = [*backward[:0:-1], *forward]
    direction = np.array([-1] * (len(backward) - 1) + [0] + [1] * (len(forward) - 1))
    n1, n2 = curve.names
    ref = curve.system(pts[0].z[-2], pts[0].z[-1])
    names = list(ref.state_names)
    m = len(names)
    mu = np.array([p.mu for p in pts])
    crit = np.array([curve.fn.critical(p.mu) for p in pts], dtype=complex)
    others = np.array(
        [np.delete(np.abs(p.mu), int(np.argmin(np.abs(p.mu - c)))) if np.isfinite(c) else
         np.abs(p.mu) for p, c in zip(pts, crit, strict=True)]
    )  # fmt: skip
    coords: dict[str, Any] = {
        n1: ("point", np.array([p.z[-2] for p in pts])),
        n2: ("point", np.array([p.z[-1] for p in pts])),
        "arclength": ("point", np.array([p.s for p in pts])),
        "point": ("point", np.arange(len(pts))),
        "state": ("state", np.array(names, dtype="U16")),
        "unknown": ("unknown", np.array([*names, n1, n2], dtype="U40")),
        "multiplier": ("multiplier", np.arange(m)),
        "section": ("section", np.arange(curve.n)),
        "track": ("track", np.arange(pts[0].obs_min.size)),
    }
    st = curve.steps
    ds = xr.Dataset(
        coords=coords,
        attrs={
            "title": f"{CURVE_TITLE} ({curve.fn.kind}) of period-{curve.n} orbits of {ref.name}",
            **model_attrs(ref),
            "kind": "boundary_curve",
            "curve_kind": curve.fn.kind,
            "parameter": n1,
            "parameter2": n2,
            "period": int(curve.n),
            "fixed": fixed_json(curve.fixed),
            "contact": "" if curve.fn.contact is None else ":".join(curve.fn.contact),
            "stop_reason_backward": reasons[0],
            "stop_reason_forward": reasons[1],
            "stop_reason": f"backward: {reasons[0]}; forward: {reasons[1]}",
            "n_points": len(pts),
            "map_evaluations": int(curve.evals),
            "tol": float(curve.tol),
            "step": st.initial,
            "min_step": st.minimum,
            "max_step": st.maximum,
            "max_points": st.max_points,
            "scale": json.dumps([float(v) for v in curve.scale]),
            **attrs,
            **curve.cfg.attrs(),
            **provenance(),
        },
    )
    ds[n1].attrs["long_name"] = f"first parameter {n1}"
    ds[n2].attrs["long_name"] = f"second parameter {n2}"
    ds["arclength"].attrs["long_name"] = "weighted pseudo-arclength (1 = a whole range)"
    ds["orbit_state"] = (("point", "state"), np.array([p.z[:-2] for p in pts]))
    ds["orbit_sections"] = (("point", "section", "state"), np.array([p.sections for p in pts]))
    ds["multiplier_re"] = (("point", "multiplier"), mu.real)
    ds["multiplier_im"] = (("point", "multiplier"), mu.imag)
    ds["multiplier_abs"] = (("point", "multiplier"), np.abs(mu))
    ds["critical_re"] = ("point", crit.real)
    ds["critical_im"] = ("point", crit.imag)
    ds["max_multiplier"] = ("point", np.abs(mu).max(axis=1))
    ds["unstable"] = ("point", (others > 1.0).sum(axis=1).astype(np.int64))
    ds["stable"] = ("point", (others.max(axis=1) < 1.0).astype(np.int8))
    ds["stable"].attrs["long_name"] = "1 where every multiplier but the critical one is inside"
    ds["test_value"] = ("point", np.array([p.g for p in pts]))
    ds["test_value"].attrs["long_name"] = f"defining test function g of the {curve.fn.kind} curve"
    ds["residual"] = ("point", np.array([p.residual for p in pts]))
    ds["iterations"] = ("point", np.array([p.evals for p in pts], dtype=np.int64))
    ds["direction"] = ("point", direction.astype(np.int8))
    ds["on_grid"] = ("point", np.array([p.landed for p in pts], dtype=np.int8))
    for var, name, which in (("uncertainty", n1, 0), ("uncertainty2", n2, 1)):
        ds[var] = ("point", np.array([(p.uncertainty, p.uncertainty2)[which] for p in pts]))
        ds[var].attrs["long_name"] = (
            f"uncertainty of {name}: its shift when the point is corrected again with the "
            "integrator and corrector 100 times tighter (a landed point on its own "
            f"{n2}; NaN: not assessed)"
        )
    ds["tangent"] = (("point", "unknown"), np.array([p.tangent for p in pts]))
    ds["obs_min"] = (("point", "track"), np.array([p.obs_min for p in pts]))
    ds["obs_max"] = (("point", "track"), np.array([p.obs_max for p in pts]))
    _put_events(ds, curve.events, pts, m)
    return ds


def _put_events(ds: Any, found: list[dict[str, Any]], pts: list[Any], m: int) -> None:
    index = {id(p): k for k, p in enumerate(pts)}
    found = sorted(found, key=lambda e: e["s"])
    E = len(found)
    ds.coords["event"] = ("event", np.arange(E))
    ds["event_kind"] = ("event", np.array([e["kind"] for e in found], dtype="U24"))
    ds["event_value"] = ("event", np.array([e["z"][-2] for e in found], dtype=float))
    ds["event_value2"] = ("event", np.array([e["z"][-1] for e in found], dtype=float))
    ds["event_point"] = (
        "event",
        np.array([index.get(id(e["p"]), -1) for e in found], dtype=np.int64),
    )
    ds["event_arclength"] = ("event", np.array([e["s"] for e in found], dtype=float))
    mu = np.array([e["mu"] for e in found], dtype=complex)
    ds["event_multiplier_re"] = ("event", mu.real)
    ds["event_multiplier_im"] = ("event", mu.imag)
    ds["event_state"] = (
        ("event", "state"),
        np.array([e["z"][:-2] for e in found]).reshape(E, m),
    )
    ds["event_vector"] = (("event", "state"), np.zeros((E, m)))
    ds["event_detail"] = ("event", np.array([e.get("detail", "") for e in found], dtype="U80"))
    ds["event_located"] = ("event", np.array([e["located"] for e in found], dtype=np.int8))
    ds["event_uncertainty"] = ("event", np.array([e["uncertainty"][0] for e in found]))
    ds["event_uncertainty2"] = ("event", np.array([e["uncertainty"][1] for e in found]))


def open_curve(path: Any) -> Any:
    """Open a curve file written by :func:`gearchaos.boundary_curve` (refusing branch files
    of one parameter, naming what they are)."""
    ds = open_branch(path)
    if ds.attrs.get("kind") != "boundary_curve":
        raise StoreError(
            f"{path} is a branch of one parameter, not a boundary curve: continue one of its "
            "events in a second parameter with gearchaos boundary --from BRANCH.nc"
        )
    return ds


def is_curve(ds: Any) -> bool:
    """Whether a dataset opened by :func:`~gearchaos.dynamics.open_branch` is a curve."""
    return ds.attrs.get("kind") == "boundary_curve"
