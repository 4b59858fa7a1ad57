"""Frequency response: a continuation sweep that stores the dynamic mesh forces of every point.

:func:`response` is :func:`~gearchaos.sweep.run.bifurcation` with ``response=True``,
continuation along the swept axis (both directions by default, so jumps between coexisting
branches show) and :data:`~gearchaos.sweep.spec.RESPONSE_SOLVER` (32 samples per period). Per
point and mesh type ``m`` (``sp``, ``rp``; ``mesh`` for the backlash oscillator) the store gets,
besides the sections and extrema of every sweep (:mod:`gearchaos.model.response`):

* ``force_rms_m``, ``force_peak_m`` (per planet): √⟨F̄ᶜ²⟩ and max |F̄ᶜ| of the contact force
  F̄ᶜ = κ f(δ̄; b̄) + c̄ δ̄' where it presses the flanks together (0 while the teeth are apart
  or the damping would pull them, :func:`~gearchaos.model.response.compressive_contact_forces`),
  in k_m,sp b_c;
* ``load_factor_m``: max over the planets of max |F̄ᶜ| / (T̄_D/N), the dynamic load factor;
* ``dte_rms_m`` (per planet): √⟨(δ̄ − ⟨δ̄⟩)²⟩, the RMS dynamic transmission error, in b_c;
* ``contact_force_m_min``/``_max`` (per planet): the tracked extrema of F̄ᶜ.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

import numpy as np

from .._checks import check_real
from ..errors import ParameterError
from ..integrate.settings import SolverSettings, check_params, renamed_keyword
from ..model.target import Target, resolve
from .run import bifurcation

__all__ = ["find_jumps", "response"]


def response(
    target: Target,
    vary: Any,
    *,
    direction: str = "both",
    params: Mapping[str, Any] | None = None,
    settings: SolverSettings | None = None,
    store: str | os.PathLike[str] | None = None,
    overwrite: bool = False,
    progress: bool = True,
    fixed: Mapping[str, Any] | None = None,
    solver: SolverSettings | None = None,
    **options: Any,
) -> Any:
    """Frequency-response curves: dynamic mesh forces, load factors and transmission errors
    along a parameter (usually Ω), swept up and down by continuation.

    Parameters
    ----------
    target
        A :class:`~gearchaos.gearset.GearSet` or a :class:`~gearchaos.model.System`.
    vary
        One axis, e.g. ``"omega=0.5:2.5:201"`` (syntax of
        :func:`~gearchaos.sweep.run.bifurcation`).
    direction
        ``up``, ``down`` or ``both`` (default): each point starts from the final state of its
        neighbour in that direction, so coexisting branches and the jumps between them show.
    params, store, overwrite, progress
        As for :func:`~gearchaos.sweep.run.bifurcation`: fixed values by dotted name (and
        parameters by name among ``options``).
    settings
        A :class:`~gearchaos.integrate.settings.SolverSettings` (default
        :data:`~gearchaos.sweep.spec.RESPONSE_SOLVER`: 100 transient and 50 recorded periods,
        32 samples per period); settings by name among ``options`` override it.
    **options
        Further sweep options (``observe``, ``planets``, ``lyapunov``, ``family``), solver
        settings and parameters by name. ``fixed=`` and ``solver=`` are the deprecated
        spellings of ``params=`` and ``settings=``.

    Returns
    -------
    xarray.Dataset
        A sweep dataset (dimensions ``direction`` when both, then the axis) with, per point and
        mesh type m, ``force_rms_m`` = √⟨F̄ᶜ²⟩, ``force_peak_m`` = max |F̄ᶜ|,
        ``load_factor_m`` = max_i max |F̄ᶜ_i| / (T̄_D/N) and ``dte_rms_m`` = √⟨(δ̄ − ⟨δ̄⟩)²⟩
        (module docstring); the attribute ``kind`` is ``"response"``.
    """
    if fixed is not None:  # the spellings before the one vocabulary
        params = renamed_keyword(
            "response", "fixed", "params", check_params("fixed", fixed), params
        )
    if solver is not None:
        settings = renamed_keyword("response", "solver", "settings", solver, settings)
    model = resolve(target, {}, default_omega=1.0)  # what the target's model tracks
    if not model.force_groups:
        raise ParameterError(
            f"response needs a model that tracks mesh contact forces (its force_groups and "
            f"n_contact_forces): {model.name} tracks none; its section values' hysteresis "
            "is drawn by bifurcation with --initial-conditions continuation --direction both"
        )
    return bifurcation(
        target,
        vary,
        params=params,
        settings=settings,
        store=store,
        overwrite=overwrite,
        progress=progress,
        initial_conditions="continuation",
        direction=direction,
        response=True,
        **options,
    )


def find_jumps(x: Any, y: Any, *, rel: float = 0.25, where: Any = None) -> list[float]:
    """Where a response curve jumps: the midpoints (x_k + x_{k+1})/2 of the neighbouring
    points whose values differ by more than ``rel`` times the curve's range max y − min y.

    Parameters
    ----------
    x, y
        The swept values (in sweep order) and the response along one branch (``direction``
        ``up`` or ``down``); NaN points (failed) are skipped.
    rel
        Threshold as a fraction of the range (default 0.25).
    where
        Optional booleans, one per point: the points a jump may join. A jump is a jump between
        two *periodic* states (a chaotic curve scatters from point to point without jumping
        anywhere), so a response figure passes the points whose motion verdict is nT. With
        ``where`` only neighbours in the grid count — a point outside it (or NaN) breaks the
        curve instead of being skipped — and the range is still the whole curve's.

    Returns
    -------
    list of float
        The jump positions in increasing x.
    """
    check_real("rel", rel, lo=0.0, lo_open=True)
    xa = np.asarray(x, dtype=float)
    ya = np.asarray(y, dtype=float)
    ok = np.isfinite(ya)
    if where is not None:
        allowed = np.asarray(where, dtype=bool)
        if allowed.shape != ya.shape:
            raise ParameterError(
                f"where must have one entry per point ({ya.shape}): got shape {allowed.shape}"
            )
        order = np.argsort(xa, kind="stable")
        xs, ys, fine = xa[order], ya[order], (ok & allowed)[order]
        if not ok.any():
            return []
        span = float(np.nanmax(ya) - np.nanmin(ya))
        if span <= 0.0:
            return []
        pair = fine[:-1] & fine[1:]
        big = np.zeros(pair.shape, dtype=bool)
        big[pair] = np.abs(np.diff(ys))[pair] > rel * span
        return [float(0.5 * (xs[i] + xs[i + 1])) for i in np.nonzero(big)[0]]
    xa, ya = xa[ok], ya[ok]
    if ya.size < 2:
        return []
    order = np.argsort(xa)
    xa, ya = xa[order], ya[order]
    span = float(ya.max() - ya.min())
    if span <= 0.0:
        return []
    k = np.nonzero(np.abs(np.diff(ya)) > rel * span)[0]
    return [float(0.5 * (xa[i] + xa[i + 1])) for i in k]
