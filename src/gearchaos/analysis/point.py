"""One operating point examined end to end: simulate, largest Lyapunov exponent, summary.

:func:`analyse_point` is the sequence behind ``gearchaos simulate --lyapunov``, every panel of
a Poincaré gallery (``gearchaos poincare``, the seed's Figs. 5, 7 and 10) and the explorer's
point view: resolve the target at the given parameter values, simulate it with the seed's
protocol, compute λ₁ with the same settings, and summarise the motion.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from .._checks import check_bool
from ..errors import Status
from ..integrate.result import SimulationResult
from ..integrate.settings import SolverSettings
from ..integrate.simulate import run_simulation
from ..model.target import resolve
from .lyapunov import lyapunov_spectrum
from .summary import summarize

__all__ = ["PointAnalysis", "analyse_point"]


@dataclass(frozen=True)
class PointAnalysis:
    """What :func:`analyse_point` found at one point.

    Attributes
    ----------
    result
        The simulation (``result.system`` is the resolved system).
    lle
        Largest Lyapunov exponent λ₁ per unit τ; ``None`` when not asked for or not computable.
    lyapunov_status
        Status of the Lyapunov run (``None`` when none ran).
    summary
        :func:`~gearchaos.analysis.summary.summarize` of the result with λ₁; its ``motion`` is
        ``failed`` when the simulation failed.
    """

    result: SimulationResult
    lle: float | None
    lyapunov_status: Status | None
    summary: dict[str, Any]

    @property
    def ok(self) -> bool:
        return self.result.status.ok


def analyse_point(
    target: Any,
    values: Mapping[str, Any] | None = None,
    settings: SolverSettings | None = None,
    *,
    lyapunov: bool = True,
    default_omega: float | None = None,
    check: bool = False,
) -> PointAnalysis:
    """Simulate ``target`` at ``values`` (dotted names, ``omega`` included), measure λ₁ with the
    same transient, periods and tolerances, and summarise the motion.

    Parameters
    ----------
    target
        A :class:`~gearchaos.gearset.GearSet` or a :class:`~gearchaos.model.System`.
    values
        Parameter values by dotted name (:func:`~gearchaos.model.target.resolve`).
    settings
        Protocol and tolerances (default: :class:`~gearchaos.integrate.settings.SolverSettings`).
    lyapunov
        Also compute the largest Lyapunov exponent (it decides quasi-periodic vs chaotic).
    default_omega
        Ω when ``values`` has none (a gear set needs one).
    check
        Raise :class:`~gearchaos.errors.IntegrationError` when the simulation fails, instead of
        returning a result labelled ``failed``.
    """
    cfg = settings if settings is not None else SolverSettings()
    system = resolve(target, values, default_omega=default_omega)
    result = run_simulation(system, cfg, check=check_bool("check", check))
    lle: float | None = None
    lstatus: Status | None = None
    if check_bool("lyapunov", lyapunov) and result.status.ok:
        lr = lyapunov_spectrum(system, cfg.replace(samples_per_period=1), n_exponents=1)
        lstatus = lr.status
        if lr.status.ok and math.isfinite(lr.largest):
            lle = float(lr.largest)
    summary = summarize(result, lle=lle)
    if not result.status.ok:
        summary["motion"] = "failed"
    return PointAnalysis(result, lle, lstatus, summary)
