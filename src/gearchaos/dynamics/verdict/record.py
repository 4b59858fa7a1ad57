"""The verdict's record mode: every point labelled from its record alone.

A sweep without verdicts (``verdicts=False``) and ``gearchaos classify`` label a point from
its stored section values with the rules of :func:`gearchaos.analysis.classify.classify_sections`
(the period of the section sequence; else the recorded λ₁ against its bound, the 0–1 test and
the spectrum) — pure, no integration, no orbit shot. :func:`decide_from_record` returns the
same :class:`~gearchaos.dynamics.verdict.evidence.Verdict` as the full procedure, with
evidence ``record``: its label is what the record suggests, not confirmed, and is stored and
shown as such. ``decide_motion`` with ``VerdictSettings(mode="record")`` comes here.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...analysis.classify import LLE_C, classify_sections
from ...errors import ParameterError
from .evidence import Verdict

__all__ = ["RECORD_REASON", "decide_from_record"]

#: How the reason of every record-mode verdict begins.
RECORD_REASON = "labelled from the record alone, not confirmed (no orbit shot, no λ₁ window run)"


def decide_from_record(
    sections: Any,
    ok: Any,
    *,
    lle: Any = None,
    run_periods: Any = None,
    forcing_period: Any = None,
    period_rtol: float = 1e-3,
    longest_period: int = 64,
    lle_c: float = LLE_C,
) -> list[Verdict]:
    """Record-mode verdicts of K points.

    Parameters
    ----------
    sections
        (K, m, d) the section values the label is read from (a sweep's: the first two observed
        section variables of the first observed planet).
    ok
        (K,) whether each integration succeeded (a failed point is labelled ``failed``, with
        evidence ``failed``).
    lle, run_periods, forcing_period
        The λ₁ the run recorded (per unit τ; None or NaN: none), the record's length in
        periods and the forcing period T, each a scalar or (K,), as in
        :func:`~gearchaos.analysis.classify.classify_sections`.
    period_rtol, longest_period, lle_c
        Recurrence tolerance relative to the attractor's size, the longest period recognised
        as nT, and c of the λ₁ bound θ = c / (run_periods · T).
    """
    sec = np.asarray(sections, dtype=np.float64)
    if sec.ndim != 3:
        raise ParameterError(f"sections must have shape (K, m, d): got {sec.shape}")
    K = sec.shape[0]
    okv = np.asarray(ok, dtype=bool).reshape(-1)
    if okv.shape != (K,):
        raise ParameterError(f"ok must hold one flag per point ({K}): got shape {okv.shape}")
    kw: dict[str, Any] = {"details": True, "rtol": period_rtol, "max_period": longest_period}
    if lle is not None:
        kw.update(lle=lle, run_periods=run_periods, forcing_period=forcing_period, lle_c=lle_c)
    details = classify_sections(sec, **kw) if K else np.empty(0, dtype=object)
    out: list[Verdict] = []
    for k in range(K):
        if not okv[k]:
            out.append(Verdict("failed", 0, "failed", reason="the integration failed"))
            continue
        mc: Any = details[k]
        why = f"{RECORD_REASON}: {mc.note}" if mc.note else RECORD_REASON
        out.append(
            Verdict(
                label=mc.label,
                period=int(mc.period or 0),
                evidence="record",
                lle=math.nan if mc.lle is None else float(mc.lle),
                k01=math.nan if mc.k01 is None else float(mc.k01),
                reason=why,
                agree=bool(mc.agree),
            )
        )
    return out
