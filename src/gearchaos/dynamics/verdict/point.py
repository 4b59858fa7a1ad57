"""One operating point examined end to end: simulate, the motion verdict, summary.

:func:`analyse_point` is the sequence behind ``gearchaos simulate``, every panel of a Poincaré
gallery (``gearchaos poincare``, the seed's Figs. 5, 7 and 10) and the explorer's point view:
resolve the target at the given parameter values, simulate it with the seed's protocol, decide
the motion (:func:`~gearchaos.dynamics.verdict.decide.decide_motion`: an orbit confirmed by
shooting,
or λ₁ with its error from an extension of the run), and summarise it. When the verdict had to
extend the run to finish a transient, the simulation is repeated with the transient lengthened
by the same number of periods, so the record shown is the one the verdict is about.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..._checks import check_bool
from ...analysis.summary import summarize as record_summary
from ...errors import ParameterError, Status
from ...integrate.result import SimulationResult
from ...integrate.settings import SIMULATION, SolverSettings
from ...integrate.simulate import run_simulation
from ...model.target import Target, resolve
from ..lyapunov import lyapunov_spectrum
from ..orbits.shooting import section_fraction
from .decide import VerdictSettings, decide_motion
from .evidence import Verdict

__all__ = ["PointAnalysis", "analyse_point", "point_verdict", "summarize"]


@dataclass(frozen=True)
class PointAnalysis:
    """What :func:`analyse_point` found at one point.

    Attributes
    ----------
    result
        The simulation (``result.system`` is the resolved system); its transient is the
        protocol's plus the periods the verdict added.
    lle
        Largest Lyapunov exponent λ₁ per unit τ (exact, ln max|μ|/(nT), for a confirmed
        orbit); ``None`` when not computed.
    lyapunov_status
        Status of the run behind λ₁ (``None`` when none ran).
    summary
        :func:`~gearchaos.analysis.summary.summarize` of the result with the verdict; its
        ``motion`` is ``failed`` when the simulation failed.
    verdict
        The :class:`~gearchaos.dynamics.verdict.decide.Verdict` (``None`` with ``lyapunov=False``).
    """

    result: SimulationResult
    lle: float | None
    lyapunov_status: Status | None
    summary: dict[str, Any]
    verdict: Verdict | None = None

    @property
    def ok(self) -> bool:
        return self.result.status.ok


def analyse_point(
    target: Target,
    values: Mapping[str, Any] | None = None,
    settings: SolverSettings | None = None,
    *,
    lyapunov: bool = True,
    default_omega: float | None = None,
    check: bool = False,
    verdict: VerdictSettings | bool = True,
) -> PointAnalysis:
    """Simulate ``target`` at ``values`` (dotted names, ``omega`` included), decide the motion,
    and summarise it.

    Parameters
    ----------
    target
        A :class:`~gearchaos.gearset.GearSet` or a :class:`~gearchaos.model.System`.
    values
        Parameter values by dotted name (:func:`~gearchaos.model.target.resolve`).
    settings
        Protocol and tolerances (default: :data:`~gearchaos.integrate.settings.SIMULATION`,
        as :func:`gearchaos.simulate` and ``gearchaos simulate``).
    lyapunov
        With ``verdict=False``: also compute λ₁ (seeded random tangent vector) for the
        record-based label (:func:`~gearchaos.analysis.classify.classify_motion`). Ignored
        by the verdict, which computes λ₁ itself.
    default_omega
        Ω when ``values`` has none (a gear set needs one).
    check
        Raise :class:`~gearchaos.errors.IntegrationError` when the simulation fails, instead of
        returning a result labelled ``failed``.
    verdict
        True (default) or :class:`~gearchaos.dynamics.verdict.decide.VerdictSettings`: decide the
        motion with the verdict (shooting and Floquet multipliers, λ₁ ± its error,
        transients finished), with the default or these tolerances and budget. False labels
        from the record alone (faster; the summary's ``evidence`` is ``record``).
    """
    cfg = SIMULATION if settings is None else SolverSettings.build(settings)
    want = check_bool("lyapunov", lyapunov)  # flags checked before any run
    check = check_bool("check", check)
    system = resolve(target, values, default_omega=default_omega)
    result = run_simulation(system, cfg, check=check)
    vs = _verdict_settings(verdict)
    if vs is None or not result.status.ok:
        lle: float | None = None
        lstatus: Status | None = None
        if want and result.status.ok:
            lr = lyapunov_spectrum(system, cfg.replace(samples_per_period=1), n_exponents=1)
            lstatus = lr.status
            if lr.status.ok and math.isfinite(lr.largest):
                lle = float(lr.largest)
        summary = record_summary(result, lle=lle)
        if not result.status.ok:
            summary["motion"] = "failed"
        return PointAnalysis(result, lle, lstatus, summary)
    v = point_verdict(target, values, result, vs)
    result, summary = _decided(result, v, check)
    lle = v.lle if math.isfinite(v.lle) else None
    return PointAnalysis(result, lle, Status.OK, summary, v)


def _decided(
    result: SimulationResult, v: Verdict, check: bool
) -> tuple[SimulationResult, dict[str, Any]]:
    """The result the verdict is about (the continuation's record where the run was
    continued) and its summary with the verdict."""
    if v.record is not None and v.label != "failed":
        result = _finished(result.system, result.solver, v, check)
    summary = record_summary(result, verdict=v.to_dict())
    if not result.status.ok:
        summary["motion"] = "failed"
    return result, summary


def summarize(
    result: SimulationResult,
    values: Mapping[str, Any] | None = None,
    *,
    verdict: VerdictSettings | bool = True,
) -> dict[str, Any]:
    """The summary of a simulation result with its motion verdict — the same as
    ``gearchaos simulate`` prints for the same call (``gearchaos.summarize(
    gearchaos.simulate(gs, omega=1.5))``).

    The verdict is decided from the result's record as :func:`analyse_point` decides it; where
    it continues the run, the summary's record quantities (section range, load factors, RMS
    transmission error, contact) are those of the continuation, as the command line's. With
    ``verdict=False`` the record alone is summarised: ``motion`` is None and the record's own
    label is ``record_label`` (:func:`gearchaos.analysis.summary.summarize`).

    Parameters
    ----------
    result
        A :class:`~gearchaos.SimulationResult` of :func:`gearchaos.simulate`.
    values
        Parameter values by name, for the verdict's record (Ω is read from the result).
    verdict
        True, False or :class:`~gearchaos.dynamics.verdict.decide.VerdictSettings`.
    """
    if not isinstance(result, SimulationResult):
        raise ParameterError(
            f"summarize needs a SimulationResult (gearchaos.simulate): got {type(result).__name__}"
        )
    vs = _verdict_settings(verdict)
    if vs is None or not result.status.ok:
        summary = record_summary(result)
        if not result.status.ok:
            summary["motion"] = "failed"
        return summary
    v = point_verdict(result.system, values, result, vs)
    return _decided(result, v, False)[1]


def _finished(system: Any, cfg: SolverSettings, v: Verdict, check: bool) -> SimulationResult:
    """The record the verdict is about, with the protocol's samples: the recorded window
    integrated again from ``periods`` sections before the end of the verdict's continuation of
    the run, at the section time; its settings are the protocol's and ``extra_periods`` the
    periods the verdict added to the protocol's transient before the record."""
    assert v.record is not None
    m = int(cfg.periods)
    start = v.record.states[max(0, v.record.states.shape[0] - m)]
    origin = (
        "the state the motion verdict's continuation of the run reached from rest (perturbed "
        f"by {cfg.perturbation:g})"
    )
    window = cfg.replace(transient_periods=0.0, section_phase=0.0)
    tau_s = section_fraction(cfg) * system.period
    result = run_simulation(system, window, y0=start, t0=tau_s, check=check)
    return dataclasses.replace(
        result, solver=cfg, extra_periods=int(v.extra_periods), origin=origin
    )


def _verdict_settings(verdict: Any) -> VerdictSettings | None:
    if isinstance(verdict, VerdictSettings):
        return verdict
    return VerdictSettings() if check_bool("verdict", verdict) else None


def point_verdict(
    target: Target,
    values: Mapping[str, Any] | None,
    result: SimulationResult,
    verdict: VerdictSettings | None = None,
) -> Verdict:
    """The verdict of one simulation result, from its full-state section record."""
    system = result.system
    secs = result.states[result.section_index]
    vals = dict(values or {})
    vals.setdefault("omega", float(system.omega))
    return decide_motion(
        target,
        [vals],
        [system],
        secs[None],
        np.asarray(result.final_state)[None],
        [result.status.ok],
        result.solver,
        verdict,
    )[0]
