"""The operating point on the command line: Ω given as ``--set omega=…`` or as a speed
(``--set sun_rpm=7500``, ``--vary sun_rpm=1000:20000:200``, ``mesh_hz``), converted through the
gear set by the model layer (:func:`~gearchaos.model.target.operating_omega`), and the speeds
written beside Ω in tables and messages."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..errors import ParameterError
from ..gearset.schema import SPEEDS
from ..model.target import OMEGA, Target

__all__ = [
    "one_point",
    "point_omega",
    "speed_note",
    "speed_range",
    "speeds_per_omega",
    "without_speeds",
]


def one_point(
    swept: set[str], values: Mapping[str, object], omega: float | None, verb: str
) -> bool:
    """Whether Ω is given (swept as ``omega`` or a speed, or a speed among ``values``) besides
    ``--set omega`` (``omega``); Ω given twice is refused, naming both."""
    if omega is not None and OMEGA in swept:
        raise ParameterError(f"omega is both {verb} and set with --set; choose one")
    points = sorted(n for n in (swept | set(values)) if n in SPEEDS or n == OMEGA)
    shown = (["--set omega"] if omega is not None else []) + [
        f"--vary {n}" if n in swept else f"--set {n}" for n in points
    ]
    if len(shown) > 1:
        raise ParameterError(
            f"{' and '.join(shown)} each set Ω (the operating point): give one of them"
        )
    return bool(points)


def without_speeds(changes: Mapping[str, object]) -> dict[str, object]:
    """``changes`` without the speeds (``sun_rpm``, ``mesh_hz``): the gear set's own changes."""
    return {k: v for k, v in changes.items() if k not in SPEEDS}


def point_omega(
    target: Target,
    omega: float | None,
    changes: Mapping[str, object],
    pending: Mapping[str, Any] | None = None,
) -> float | None:
    """Ω of ``--set``: ``omega``, or the speed among ``changes`` converted through
    ``target`` (built with the other changes) with the values ``pending`` not yet applied to it
    (a start file's; Ω among them is replaced); a model without a gear set refuses a speed,
    naming it. ``None`` when neither is set."""
    from ..model.target import operating_omega

    speeds = {k: v for k, v in changes.items() if k in SPEEDS}
    if not speeds:
        return omega
    rest = {k: v for k, v in (pending or {}).items() if k != OMEGA and k not in SPEEDS}
    return operating_omega(target, {**rest, **speeds})[0]


def speeds_per_omega(target: Target, values: Mapping[str, Any] | None = None) -> dict[str, float]:
    """The speeds (``sun_rpm``, ``mesh_hz``) per unit Ω of ``target`` with the parameter
    ``values`` (Ω and speeds among them ignored); ``{}`` for a model without a gear set."""
    from ..model.target import model_for, speeds_at

    rest = {k: v for k, v in (values or {}).items() if k != OMEGA and k not in SPEEDS}
    return speeds_at(model_for(target, rest), 1.0)


def speed_note(target: Target, omega: float, values: Mapping[str, Any] | None = None) -> str:
    """`` (n_s = 7500 rpm, f_m = 3078 Hz)`` at Ω for a model built from a gear set (with the
    parameter ``values``), else ``""``: the speeds that a line showing Ω writes beside it."""
    per = speeds_per_omega(target, values)
    if not per:
        return ""
    return f" (n_s = {omega * per['sun_rpm']:.5g} rpm, f_m = {omega * per['mesh_hz']:.5g} Hz)"


def speed_range(target: Target, vary: str, values: Mapping[str, Any]) -> str:
    """``omega=A:B`` for a continuation over a speed (``sun_rpm=2000:9000``): its ends
    converted through ``target`` with the fixed ``values`` (Ω among them dropped), so the
    branch, its file and its figure are in Ω like every other one; tables write the speeds
    beside it."""
    from ..dynamics.continuation.arclength import parse_vary
    from ..model.target import operating_omega

    name, a, b = parse_vary(vary)
    rest = {k: v for k, v in values.items() if k != OMEGA and k not in SPEEDS}
    lo, hi = (operating_omega(target, {**rest, name: x})[0] for x in (a, b))
    return f"{OMEGA}={lo!r}:{hi!r}"
