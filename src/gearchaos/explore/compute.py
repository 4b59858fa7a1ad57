"""What the explorer computes off the server: one point examined, one finer sweep.

Both functions run in a worker process (the compiled kernels hold the GIL, so a thread would
stall the web server) and return plain, picklable values: numbers, text and PNG bytes. They
reuse the library's front doors — :func:`~gearchaos.dynamics.verdict.point.analyse_point`
(simulation,
λ₁ and the motion label), :func:`~gearchaos.dynamics.orbits.orbit.periodic_orbit` (Floquet
multipliers of an nT orbit), the plots of :mod:`gearchaos.plot` (phase portrait, time
histories, spectrum with the mesh harmonics labelled) and :func:`~gearchaos.sweep.run_sweep`
(a resumable sweep into a store).
"""

from __future__ import annotations

import dataclasses
import io
import math
import os
import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..analysis.motion import Motion
from ..errors import ParameterError, StoreError
from ..gearset.schema import OMEGA
from ..model.target import Target

__all__ = ["POINT_SAMPLES", "compute_point", "point_target", "run_zoom"]

#: Samples per forcing period of the on-demand simulation (smooth orbits, a spectrum up to
#: 32 mesh harmonics).
POINT_SAMPLES = 64
#: Longest period n whose orbit is looked for by shooting (multipliers).
MAX_ORBIT_PERIOD = 8


def point_target(res: Any, values: Mapping[str, float]) -> tuple[Any, dict[str, float]]:
    """The gear set and parameter values (dotted names, Ω included) of one point of a store.

    ``values`` are the point's swept values; Ω is added from the store's fixed values when it
    was not swept. A store of another model gives that model at Ω = 1 (the values set Ω) when
    it records how to build it (``model_class``, ``model_fields``: built-in reference systems
    and models from outside the package); else :class:`~gearchaos.errors.StoreError` (its
    points can be read, not recomputed).
    """
    target = res.base_target
    if target is None:
        raise StoreError(
            "this store records no model it can build again (no model_class, no gear set): "
            "its stored sections can be explored, but points cannot be recomputed from it"
        )
    fixed = {k: v for k, v in res.fixed.items() if k != OMEGA}
    if fixed:
        from ..model.record import with_values

        try:
            target = with_values(target, fixed)
        except ParameterError as exc:
            raise StoreError(f"the store's fixed values do not apply to its model: {exc}") from None
    out = {str(k): float(v) for k, v in values.items()}
    if OMEGA not in out:
        omega = res.fixed_value(OMEGA)
        if omega is None:
            raw = res.ds.attrs.get("omega_fixed")
            omega = float(raw) if raw is not None else None
        if omega is None:
            raise StoreError("the store neither sweeps omega nor records a fixed value of it")
        out[OMEGA] = omega
    return target, out


def compute_point(
    store: str,
    values: Mapping[str, float],
    var: str | None = None,
    planet: int = 1,
    history_periods: float = 10.0,
    models: tuple[str, ...] = (),
) -> dict[str, Any]:
    """Examine one point of a sweep store: simulate, λ₁, motion, multipliers, one figure.

    The point is simulated from rest with the store's protocol (its transient, recorded
    periods and tolerances; :data:`POINT_SAMPLES` samples per forcing period T = 2π/Ω instead
    of one), as ``gearchaos simulate`` would, and its largest Lyapunov exponent λ₁ is
    integrated with the same settings (:func:`~gearchaos.dynamics.verdict.point.analyse_point`).
    When
    the motion is nT with n ≤ 8, the period-n orbit is found by shooting from the simulation
    and its Floquet multipliers μ (eigenvalues of the monodromy matrix) are returned.

    Parameters
    ----------
    store
        Path of the sweep store.
    values
        The point's swept values by dotted name (``{"omega": 1.43}``).
    var, planet
        The variable of the phase portrait and the first time history (default: the model's
        section variable, ``delta_sp`` of planet 1, X̄_sp1 = δ_sp1/b_c, for a gear set); the
        second time history is the contact force of its mesh (of the first mesh type when the
        variable is no mesh deflection).
    history_periods
        Forcing periods shown in the time histories (the last ones recorded).
    models
        The models the user named in the calling process
        (:func:`~gearchaos.model.loading.named_models`): a worker process names them again,
        so that a store of the user's own model is built again only with that consent.

    Returns
    -------
    dict
        ``values``, ``motion``, ``lle`` (λ₁ per unit τ, or ``None``), ``status``,
        ``distinct`` (distinct section points), ``summary`` (of
        :func:`~gearchaos.analysis.summary.summarize`), ``multipliers`` (a list of
        ``(re, im)``, largest modulus first, or ``None``), ``orbit_note`` and ``png``
        (a 2×2 figure: phase portrait, X̄ and contact force against time, spectrum).
    """
    from ..dynamics.verdict.point import analyse_point
    from ..model.loading import name_models
    from ..sweep.result import open_result

    name_models(models)
    res = open_result(store)
    target, vals = point_target(res, values)
    settings = res.spec.solver.replace(samples_per_period=POINT_SAMPLES)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        point = analyse_point(target, vals, settings, lyapunov=True)
    summary = point.summary
    motion = str(summary.get("motion", ""))
    multipliers, note = None, ""
    n = _period(summary.get("motion"))
    if n is not None and point.ok and n <= MAX_ORBIT_PERIOD:
        multipliers, note = _multipliers(target, vals, settings, n, point.result)
    return {
        "values": dict(vals),
        "motion": motion,
        "lle": point.lle,
        "status": point.result.status.name.lower(),
        "distinct": summary.get("distinct_section_points"),
        "summary": _plain(summary),
        "multipliers": multipliers,
        "orbit_note": note,
        "png": _figure_png(point.result, var, planet, history_periods) if point.ok else b"",
    }


def _period(motion: Any) -> int | None:
    """n of an nT motion label, else None (also without a label)."""
    return None if motion is None else Motion.parse(str(motion)).period or None


def _multipliers(
    target: Target, values: dict[str, float], settings: Any, n: int, guess: Any
) -> tuple[list[tuple[float, float]] | None, str]:
    from ..dynamics.orbits.orbit import periodic_orbit

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        orbit = periodic_orbit(
            target,
            period=n,
            guess=guess,
            settings=settings.replace(samples_per_period=1),
            params=values,
        )
    if not orbit.converged:
        return None, f"no period-{n} orbit found by shooting ({orbit.message})"
    mu = np.asarray(orbit.multipliers)
    stable = "stable" if orbit.stable else "unstable"
    return [(float(m.real), float(m.imag)) for m in mu], f"period-{n} orbit, {stable}"


def _plain(obj: Any) -> Any:
    """A copy with numpy scalars turned into Python ones (picklable, printable)."""
    if isinstance(obj, Mapping):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


def _figure_png(result: Any, var: str | None, planet: int, periods: float) -> bytes:
    """The figure of one point (:func:`~gearchaos.plot.sources.figure_for`, ``panels="point"``:
    phase portrait, the variable and its mesh's contact force against time, spectrum), as PNG
    bytes."""
    from ..plot.sources import figure_for

    fig = figure_for(result, var=var, planet=planet, history_periods=periods, panels="point")
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    return buf.getvalue()


def zoom_path(store: str, axes: Mapping[str, tuple[float, float, int]]) -> str:
    """Where the finer sweep over ``axes`` (name → (lo, hi, count)) of ``store`` is written:
    a sibling store in ``<store stem>.zoom/`` next to it, named by the ranges, so that the
    same zoom resumes the same store."""
    root = os.path.abspath(os.fspath(store)).rstrip(os.sep)
    parent, name = os.path.split(root)
    stem = name[:-5] if name.endswith(".zarr") else name
    parts = [f"{k}_{lo:.6g}_{hi:.6g}_{n}" for k, (lo, hi, n) in axes.items()]
    return os.path.join(parent, f"{stem}.zoom", "__".join(parts) + ".zarr")


def run_zoom(
    store: str, axes: Mapping[str, tuple[float, float, int]], models: tuple[str, ...] = ()
) -> str:
    """A finer sweep of ``store`` over the ranges ``axes`` (name → (lo, hi, count)) of its
    varied parameters, into the sibling store :func:`zoom_path` (resumable: an interrupted
    zoom continues when asked again). Every other setting — family, fixed values, observed
    variables, initial conditions, protocol, tolerances, Lyapunov — is the store's own.

    ``models``: the models the user named, as for :func:`compute_point`. Returns the path of
    the finer store.
    """
    from ..model.loading import name_models
    from ..sweep.result import open_result
    from ..sweep.run import run_sweep
    from ..sweep.spec import Axis

    name_models(models)  # the user's consent, named again in a worker (compute_point)
    res = open_result(store)
    spec = res.spec
    target = res.base_target  # the fixed values apply through the specification
    if spec is None or target is None:
        raise StoreError(
            "a finer sweep needs a store of a gear set, or of a model it records how to build, "
            "with its sweep specification"
        )
    vary = []
    for axis in spec.vary:
        if axis.name in axes:
            lo, hi, n = axes[axis.name]
            if not (math.isfinite(lo) and math.isfinite(hi) and hi > lo and n >= 2):
                raise ParameterError(
                    f"zoom range of {axis.name} must be finite with hi > lo and >= 2 points: "
                    f"got {lo!r}..{hi!r} ({n} points)"
                )
            vary.append(Axis(axis.name, tuple(float(v) for v in np.linspace(lo, hi, int(n)))))
        else:
            vary.append(axis)
    finer = dataclasses.replace(spec, vary=tuple(vary))
    path = zoom_path(store, axes)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    run_sweep(target, finer, store=path, progress=False)
    return path
