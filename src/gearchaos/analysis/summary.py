"""A JSON-serialisable summary of one simulation, and its table for humans.

:func:`summarize` condenses a :class:`~gearchaos.SimulationResult` into the numbers a reader
wants first: where it ran (Ω, and ω_n with the speeds where the model has them), what motion it
found (distinct Poincaré points of the model's section variables, X̄_sp1 and X̄'_sp1 for the
planetary model, named 1T, 2T, … or ``many``), the contact regime of every contact and whether
the integration succeeded (the command line renders it as a table). Every key is the same for
every model, or named by the model's own words (its section variable, its mesh types, its
contacts); none names the planetary model unless the model is one.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..model.response import mesh_contacts, response_quantities, transmission_error
from ..model.target import speeds_at
from .classify import classify_motion
from .contact import contact_regimes, separation_fraction
from .motion import Motion
from .poincare import count_distinct, section_points, section_variables

__all__ = ["SUMMARY_KEYS", "format_exponent", "motion_name", "motion_text", "summarize"]

#: Keys every summary has, of any model (in this order); extras follow them.
SUMMARY_KEYS = (
    "omega",
    "omega_n_rad_s",
    "distinct_section_points",
    "motion",
    "record_label",
    "section_min",
    "section_max",
    "contact",
    "status",
    "steps_accepted",
    "steps_rejected",
)


def motion_name(n: int, max_count: int = 64) -> str:
    """``nT`` for n distinct section points, ``many`` beyond ``max_count``, ``unknown`` for 0."""
    if n <= 0:
        return "unknown"
    if n > max_count:
        return "many"
    return Motion.periodic(n).format()


def _num(x: Any) -> float | None:
    """A plain float, or None for NaN/inf (JSON has no NaN)."""
    if x is None:
        return None
    v = float(x)
    return v if math.isfinite(v) else None


def summarize(
    result: Any,
    *,
    tol: float = 1e-3,
    max_count: int = 64,
    lle: float | None = None,
    verdict: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """JSON-serialisable summary of a simulation result.

    Parameters
    ----------
    result
        A :class:`~gearchaos.SimulationResult` (planetary or a reference system).
    tol, max_count
        Passed to :func:`~gearchaos.analysis.poincare.count_distinct`.
    lle
        Largest Lyapunov exponent of the run (per unit τ), if computed
        (:func:`~gearchaos.dynamics.lyapunov.max_lyapunov`); it decides quasi-periodic vs
        chaotic motion, confirmed by the 0–1 test and the spectrum. Ignored with ``verdict``.
    verdict
        The motion verdict's fields (:meth:`gearchaos.dynamics.verdict.decide.Verdict.to_dict`):
        then ``motion`` is its label, ``lle``/``lle_error`` its λ₁ and error, and
        ``evidence``, ``max_multiplier``, ``extra_periods``, ``window_start`` and
        ``window_periods`` (the window λ₁ was measured over), ``coexisting`` (stable orbits
        beside the motion) and ``motion_note`` (its reason) say what decided it. Without it
        ``motion`` is None: the label from the record alone
        (:func:`~gearchaos.analysis.classify.classify_motion`) is ``record_label``, never the
        motion, ``evidence`` is ``record`` and no window ran (``window_start`` −1).
        :func:`gearchaos.summarize` decides the motion of a result with the verdict, as
        ``gearchaos simulate`` does.

    Returns
    -------
    dict
        ``omega`` (Ω), ``omega_n_rad_s`` (ω_n; None for a model without scales),
        ``distinct_section_points`` (``max_count + 1`` means many), ``motion`` (the verdict's
        ``1T``, ``2T``, …, ``QP``, ``chaos``, ``unresolved``; None without a verdict),
        ``record_label`` (the record-only label of
        :func:`~gearchaos.analysis.classify.classify_motion`) with ``lle``, ``k01`` (0–1 test),
        ``indicators_agree`` and ``motion_note``, ``section_min``/``section_max`` (range of the
        section values of ``section_variable``), ``contact`` (a list of
        ``{"mesh": "sun_planet_1", "regime": "none|single_sided|double_sided"}``, one per
        contact of the model in its order: sun–planet meshes first, then planet–ring, for the
        planetary model), ``status`` (lower-case :class:`~gearchaos.Status` name),
        ``steps_accepted``, ``steps_rejected``; then the extras ``section_variable`` (the
        variable whose section ``section_min``/``section_max`` give: the first of the model's
        default observables, ``delta_sp_1`` for the planetary model), ``gearset``,
        ``omega_hz`` (Ω in Hz, Ω ω_n/2π: a gear train's mesh frequency; None without
        scales), ``sun_speed_rpm`` (only for a model that has speeds: one built from a gear
        set), ``load_factor_<m>_max`` for each mesh type ``m`` of the model's force groups
        when it has a static load (``sp``, ``rp`` for the planetary model: dynamic load factor
        max |Fᶜ| / (T_D/(N r_bs)) over the planets, Fᶜ the mesh *contact* force, 0 while the
        teeth are apart, its extrema tracked inside every integration step so that it does not
        depend on ``samples_per_period``), ``dte_rms`` (RMS dynamic transmission error
        √⟨(δ̄ − ⟨δ̄⟩)²⟩ over the samples of the deflection δ̄ that the model's first mesh
        contact is judged on, in the model's dimensionless length: b_c for the planetary
        model) and ``dte_contact`` (that contact: ``sun_planet_1``; both None for a model
        without mesh contacts), ``transient_periods``, ``periods``, ``samples_per_period``.
    """
    system = result.system
    x, xd = section_points(result)
    pts = np.column_stack([x, xd])
    n_recorded = int(np.sum(np.all(np.isfinite(pts), axis=1)))
    # the true count, up to the number of recorded points: never a cap that reads as data
    n = count_distinct(pts, tol=tol, max_count=max(n_recorded, 1))
    mc = classify_motion(
        np.column_stack([x, xd]),
        lle=None if verdict is not None else lle,
        run_periods=int(result.solver.periods),
        forcing_period=system.period,
        compute_indicators=verdict is None,
    )
    finite = x[np.isfinite(x)]
    caps = system.capabilities
    scales, gs = caps.scales, caps.gearset
    omega = float(system.omega)
    try:
        regimes = contact_regimes(result)
        sep = separation_fraction(result) if result.samples_per_period > 1 else {}
        contact = [
            {"mesh": k, "regime": v, "separation_fraction": _num(sep[k]) if k in sep else None}
            for k, v in regimes.items()
        ]
    except ParameterError:  # no meshes (linear, Duffing, Lorenz)
        contact = []
    out: dict[str, Any] = {
        "omega": omega,
        "omega_n_rad_s": _num(scales.omega_n) if scales is not None else None,
        "distinct_section_points": int(n),
        # the motion is the verdict's; the record alone gives only a record label
        "motion": None,
        "record_label": mc.label,
        "section_min": _num(finite.min()) if finite.size else None,
        "section_max": _num(finite.max()) if finite.size else None,
        "contact": contact,
        "status": result.status.name.lower(),
        "steps_accepted": int(result.steps_accepted),
        "steps_rejected": int(result.steps_rejected),
    }
    out["recorded_section_points"] = n_recorded
    out["section_variable"] = section_variables(result)[0]
    if verdict is not None:
        out["motion"] = verdict["motion"]
        out["lle"] = verdict["lle"]
        out["lle_error"] = verdict["lle_error"]
        out["k01"] = verdict["k01"]
        out["evidence"] = verdict["evidence"]
        out["max_multiplier"] = verdict["max_multiplier"]
        out["extra_periods"] = verdict["extra_periods"]
        out["record"] = verdict["record"]
        out["window_start"] = verdict["window_start"]
        out["window_periods"] = verdict["window_periods"]
        out["coexisting"] = verdict["coexisting"]
        out["indicators_agree"] = True
        out["window_start"] = verdict.get("window_start", -1)
        out["window_periods"] = verdict.get("window_periods", 0)
        out["coexisting"] = list(verdict.get("coexisting", []))
        out["motion_note"] = verdict["reason"]
    else:
        out["lle"] = _num(mc.lle) if mc.lle is not None else None
        out["lle_error"] = None
        out["k01"] = _num(mc.k01) if mc.k01 is not None else None
        out["evidence"] = "record"
        out["max_multiplier"] = None
        out["extra_periods"] = 0
        out["record"] = "protocol"
        out["window_start"] = -1
        out["window_periods"] = 0
        out["coexisting"] = []
        out["indicators_agree"] = bool(mc.agree)
        out["motion_note"] = mc.note
    out["gearset"] = gs.name if gs is not None else None  # gear-set switch: names its gear set
    out["omega_hz"] = _num(omega * scales.omega_n / (2.0 * math.pi)) if scales is not None else None
    rpm = speeds_at(system.model, omega).get("sun_rpm")  # a model built from a gear set
    if rpm is not None:
        out["sun_speed_rpm"] = _num(rpm)
    meshes = mesh_contacts(system)
    if meshes and caps.static_mesh_force is not None:
        # each mesh type whose contact forces the model tracks, against its static load:
        # peak contact forces from the extrema tracked inside every step (not from samples)
        rq = response_quantities(system, result.obs_min, result.obs_max, result.observables)
        for mesh in meshes:
            out[f"load_factor_{mesh}_max"] = _num(rq[f"load_factor_{mesh}"])
    # the transmission error of the model's first mesh contact (sun_planet_1 of a train),
    # from the deflection it is judged on
    first = next((c for c in caps.contacts if c.kind == "mesh"), None)
    dte = None
    if first is not None and result.observables.shape[0]:
        dte = _num(transmission_error(result.observables[:, first.column]))
    out["dte_rms"] = dte
    out["dte_contact"] = first.name if first is not None else None
    s = result.solver
    out["transient_periods"] = _num(s.transient_periods)
    out["periods"] = int(s.periods)
    out["samples_per_period"] = int(s.samples_per_period)
    return out


def motion_text(summary: dict[str, Any]) -> str:
    """The motion of a summary as shown: the verdict's label, or the record-only label named
    as such."""
    motion = summary.get("motion")
    if motion is not None:
        return str(motion)
    return f"record label {summary.get('record_label', '—')} (no verdict)"


def format_exponent(value: float | None, error: float | None) -> str:
    """``0.0412 ± 0.0031``, ``-0.0125 (exact)`` for error 0 (from Floquet multipliers), the
    value alone when the error is unknown, ``—`` without a value."""
    if value is None or not math.isfinite(value):
        return "—"
    if error is None or not math.isfinite(error):
        return f"{value:.4g}"
    if error == 0:
        return f"{value:.4g} (exact)"
    return f"{value:.4g} ± {error:.2g}"
