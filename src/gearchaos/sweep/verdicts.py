"""The motion verdict of every sweep point (``verdicts=True``, the default).

Each task decides its points with :func:`gearchaos.dynamics.verdict.decide_motion` right after
integrating them (in the worker, all points of a period together), and writes per point

* ``motion`` — the label (1T … nT, QP, chaos, unresolved, failed);
* ``verdict`` — what decided it, a flag (:data:`~gearchaos.dynamics.verdict.EVIDENCE`);
* ``max_multiplier`` — max |μ| of the orbit that confirmed an nT label, or of the unstable
  orbit the motion stayed near (NaN otherwise);
* ``lle`` and ``lle_error`` — λ₁ per unit τ and its standard error (exact, error 0, for a
  confirmed orbit);
* ``k01`` — the 0–1 test of the record behind a QP, chaos or unresolved label;
* ``extra_periods`` — periods the verdict added to finish a transient;
* ``window_start``, ``window_periods`` — the window λ₁ was measured over (chaos holds in it
  and in the window before it);
* ``record`` — where the stored section record comes from: ``protocol`` (the sweep's own
  run) or ``extension`` (that run continued by ``extra_periods``: a transient finished, or a
  record brought onto the orbit it approached); ``orbit`` marks stores of earlier versions,
  which showed a confirmed orbit's own points.

Where the verdict extended a run, the point's stored section values and final state are those
of the extension (the finished record), so the diagram never shows a label beside the
transient that preceded it (in a continuation sweep the next point still starts from the end
of the protocol's run, as without verdicts). The variables are written with the task's others,
so an interrupted sweep resumes with them.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..dynamics.evidence import EVIDENCE
from ..dynamics.extension import RECORD_SOURCES
from ..dynamics.verdict import VerdictSettings, decide_motion

__all__ = ["VERDICT_VARIABLES", "task_verdicts", "verdict_attrs"]

#: Per-point variables (name → long name, dtype, fill value).
VERDICT_VARIABLES: dict[str, tuple[str, str, Any]] = {
    "motion": ("motion verdict: 1T…nT, QP, chaos, unresolved or failed", "<U10", ""),
    "verdict": ("what decided the motion label (see flag_meanings)", "int8", -1),
    "max_multiplier": (
        "largest Floquet multiplier modulus max |μ| of the orbit shot at the point",
        "float64",
        np.nan,
    ),
    "lle": ("largest Lyapunov exponent λ_1 per unit τ = ω_n t", "float64", np.nan),
    "lle_error": (
        "standard error of λ_1 (block means; 0: exact from the multipliers)",
        "float64",
        np.nan,
    ),
    "k01": ("0–1 test for chaos K of the record (non-periodic labels)", "float64", np.nan),
    "extra_periods": ("periods added by the verdict to finish a transient", "int64", -1),
    "window_start": (
        "first period of the window λ_1 was measured over, counted after the recorded ones "
        "(-1: none, λ_1 exact from the multipliers)",
        "int64",
        -1,
    ),
    "window_periods": ("length of the window λ_1 was measured over, in periods", "int64", 0),
    "record": ("where the stored section record comes from (see flag_meanings)", "int8", -1),
}


def verdict_attrs(name: str) -> dict[str, Any]:
    """Extra attributes of a verdict variable (the flag legends of ``verdict`` and
    ``record``)."""
    flags = {"verdict": EVIDENCE, "record": RECORD_SOURCES}.get(name)
    if flags is None:
        return {}
    return {"flag_values": list(flags.values()), "flag_meanings": " ".join(flags)}


def task_verdicts(
    layout: Any,
    task: Any,
    out: Any,
    data: dict[str, np.ndarray],
    verdict: VerdictSettings | None = None,
) -> None:
    """Decide the motion of a task's points from the kernel outputs ``out`` and write the
    verdict variables into its block arrays ``data`` (replacing the record — sections,
    tracked extrema, final state — where the verdict replaced it). ``layout`` is the sweep's
    store layout (its grid, observed and tracked variables)."""
    grid, observed = layout.grid, layout.observed
    spec = grid.spec
    where = task.points()
    systems = [grid.system(idx) for _, _, idx, _ in where]
    values = [grid.values_at(idx) for _, _, idx, _ in where]
    n = systems[0].n_state
    spp = int(spec.solver.samples_per_period)
    sections = np.stack([out.states[c, j][::spp, :n] for c, j, *_ in where])
    finals = np.stack([out.final_state[c, j, :n] for c, j, *_ in where])
    ok = [int(out.status[c, j]) == 0 for c, j, *_ in where]
    verdicts = decide_motion(
        grid.target, values, systems, sections, finals, ok, spec.solver, verdict
    )
    for name, (_, dtype, fill) in VERDICT_VARIABLES.items():
        if name not in data:
            data[name] = np.full(task.shape, fill, dtype=dtype)
    for (*_, pos), v in zip(where, verdicts, strict=True):
        data["motion"][pos] = v.label
        data["verdict"][pos] = v.code
        data["max_multiplier"][pos] = v.max_multiplier
        data["lle"][pos] = v.lle
        data["lle_error"][pos] = v.lle_error
        data["k01"][pos] = v.k01
        data["extra_periods"][pos] = v.extra_periods
        data["window_start"][pos] = v.window_start
        data["window_periods"][pos] = v.window_periods
        rec = v.record
        if rec is None or spp != 1:
            data["record"][pos] = RECORD_SOURCES["protocol"]
            continue
        data["record"][pos] = rec.code
        m = data[observed[0].name][pos].shape[0]
        for ob in observed:
            data[ob.name][pos] = ob.take(rec.states[-m:], rec.observables[-m:])
        layout.put_extrema(data, pos, rec.obs_min, rec.obs_max)
        data["final_state"][pos] = rec.final_state
