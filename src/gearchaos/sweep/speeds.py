"""A sweep's operating speeds: ``sun_rpm`` and ``mesh_hz`` axes and fixed values become Ω.

A sweep may give its operating point as the sun speed in rpm or the mesh frequency in Hz
(``--vary sun_rpm=1000:20000:200``, ``--set sun_rpm=7500``) wherever it may give Ω. Before a
sweep runs, :func:`omega_spec` converts such an axis or fixed value to Ω through the gear set
(:meth:`~gearchaos.gearset.GearSet.omega_at`, via
:func:`~gearchaos.model.target.speed_gearset`): the stored specification, its ``omega``
coordinate and everything that reads a sweep (figures, continuation, the explorer, exports)
see Ω as before. :func:`speed_coords` gives the speeds that the store of a sweep given by a
speed records beside Ω: the coordinates ``sun_rpm`` and ``mesh_hz`` along the ``omega``
dimension (a swept speed), or the attributes ``sun_rpm_fixed`` and ``mesh_hz_fixed`` (a fixed
one). A sweep given in Ω stores Ω alone, as before; its speeds follow from the stored gear set
(the figures' rpm axis, the ``sun_rpm`` and ``mesh_hz`` columns of ``gearchaos export``).

A speed is refused together with a swept parameter that changes the Ω of a given speed (a mesh
stiffness or a mass through ω_n, a tooth number): Ω would then differ from point to point
along a single speed, and the sweep is over Ω or over that parameter at fixed Ω.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..gearset.schema import SPEEDS
from ..model.target import (
    OMEGA,
    Target,
    check_one_operating_point,
    model_for,
    resolve,
    speed_gearset,
    speed_names,
    speeds_at,
    split_omega,
)
from .spec import Axis, SweepSpec

__all__ = ["given_speed", "omega_spec", "speed_coords"]

#: Relative difference of a speed per unit Ω that counts as a change (rounding is ~1e-16).
_SAME = 1e-12


def _moving(target: Target, spec: SweepSpec, changes: dict[str, Any]) -> str | None:
    """The first swept parameter along which the speeds per unit Ω change (ω_n along a mesh
    stiffness, a tooth number …), or None; every value of every axis is checked."""
    base = speeds_at(model_for(target, changes), 1.0)
    for axis in spec.axes:
        if axis.name == OMEGA or axis.name in SPEEDS:
            continue
        for v in axis.values:
            moved = speeds_at(model_for(target, {**changes, axis.name: v}), 1.0)
            if any(not math.isclose(moved[k], u, rel_tol=_SAME) for k, u in base.items()):
                return axis.name
    return None


def given_speed(target: Target, spec: SweepSpec) -> str | None:
    """The speed (``sun_rpm`` or ``mesh_hz``) by which ``spec`` gives its operating point,
    swept or fixed; ``None`` when it gives Ω (or nothing). Ω given twice is refused."""
    names = [a.name for a in spec.axes] + [k for k, _ in spec.fixed]
    check_one_operating_point(target, names)
    speeds = speed_names(target, names)
    return speeds[0] if speeds else None


def omega_spec(target: Target, spec: SweepSpec) -> SweepSpec:
    """``spec`` with its speed (a ``sun_rpm`` or ``mesh_hz`` axis or fixed value) replaced by
    Ω, converted through the gear set with the fixed values applied; ``spec`` itself when it
    gives Ω. Refused: Ω and a speed together, a target without a gear set, a swept parameter
    that changes Ω per unit speed, and a speed whose Ω lies outside its plausible range (each
    message names the speed and its value)."""
    name = given_speed(target, spec)
    if name is None:
        return spec
    fixed = dict(spec.fixed)
    speed = fixed.pop(name, None)
    speed_gearset(target, name, fixed)  # a target without a gear set is refused first
    other = _moving(target, spec, fixed)
    if other is not None:
        raise ParameterError(
            f"{name} cannot be given while {other} is swept: {other} changes ω_n or the tooth "
            f"numbers, so one {name} would be a different Ω at every value of {other}; sweep "
            f"omega (Ω) with {other}, or fix {other}",
            name=name,
        )

    def to_omega(v: float) -> float:
        return resolve(target, {**fixed, name: v}).omega

    if speed is not None:
        fixed[OMEGA] = to_omega(speed)

    def convert(axis: Axis | None) -> Axis | None:
        if axis is None or axis.name != name:
            return axis
        return Axis(OMEGA, tuple(to_omega(v) for v in axis.values))

    vary = tuple(a for a in (convert(a) for a in spec.vary) if a is not None)
    return dataclasses.replace(
        spec, vary=vary, family=convert(spec.family), fixed=tuple(sorted(fixed.items()))
    )


def speed_coords(
    target: Target, spec: SweepSpec, speed: str | None, omega: float | None = None
) -> tuple[dict[str, tuple[tuple[str, ...], np.ndarray]], dict[str, float]]:
    """The speeds the store of a sweep given by the speed ``speed`` (:func:`given_speed`)
    records beside Ω (``spec`` gives Ω: :func:`omega_spec`): coordinates ``sun_rpm`` and
    ``mesh_hz`` along a swept ``omega``, or the attributes ``sun_rpm_fixed`` and
    ``mesh_hz_fixed`` at the fixed Ω ``omega``; none for a sweep given in Ω (``speed`` None),
    a target without a gear set or where a swept parameter changes them."""
    if speed is None:
        return {}, {}
    _, changes = split_omega(dict(spec.fixed))
    base = model_for(target, changes)
    if not speeds_at(base, 1.0) or _moving(target, spec, changes) is not None:
        return {}, {}
    swept = [a for a in spec.axes if a.name == OMEGA]
    if swept:
        values = [float(w) for w in swept[0].values]
        dims: tuple[str, ...] = (OMEGA,)
        at = [speeds_at(base, w) for w in values]
        return {k: (dims, np.array([sp[k] for sp in at])) for k in SPEEDS}, {}
    if omega is None:
        return {}, {}
    return {}, {f"{k}_fixed": float(v) for k, v in speeds_at(base, omega).items()}
