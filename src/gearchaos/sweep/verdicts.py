"""The motion verdict of every sweep point.

Each task decides its points with :func:`gearchaos.dynamics.verdict.decide.decide_motion` right
after integrating them (in the worker, all points of a period together): with ``verdicts=True``
(the default) by the confirming procedure, with ``verdicts=False`` in its record mode (every
label from the point's stored section values alone, evidence ``record``, nothing integrated:
:mod:`gearchaos.dynamics.verdict.record`). Either way it writes per point

* ``motion`` — the label (1T … nT, QP, chaos, unresolved, failed);
* ``verdict`` — what decided it, a flag (:data:`~gearchaos.dynamics.verdict.decide.EVIDENCE`);
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

Each variable holds one attribute of the point's
:class:`~gearchaos.dynamics.verdict.evidence.Verdict`;
:data:`VERDICT_COLUMNS` is the one table of them (attribute, long name, element type, fill
value, flag legend), and :data:`NOT_STORED` names the verdict's fields no variable holds and
why, so a new field of the verdict is either stored or said not to be.

Where the verdict extended a run, the point's stored section values and final state are those
of the extension (the finished record), so the diagram never shows a label beside the
transient that preceded it (in a continuation sweep the next point still starts from the end
of the protocol's run, as without verdicts). The variables are written with the task's others,
so an interrupted sweep resumes with them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

from ..analysis.motion import LABEL_DTYPE, UNSET_TEXT
from ..dynamics.verdict.decide import VerdictSettings, decide_motion
from ..dynamics.verdict.evidence import EVIDENCE
from ..dynamics.verdict.extension import RECORD_SOURCES

__all__ = [
    "NOT_STORED",
    "RECORD_MODE",
    "RECORD_VARIABLES",
    "VERDICT_COLUMNS",
    "VERDICT_VARIABLES",
    "VerdictColumn",
    "record_sections",
    "task_verdicts",
    "verdict_attrs",
    "verdict_row",
]


@dataclass(frozen=True)
class VerdictColumn:
    """A store variable that holds one attribute of every point's verdict.

    Attributes
    ----------
    source
        The :class:`~gearchaos.dynamics.verdict.evidence.Verdict` attribute (a field, or a property
        of its fields) the variable holds.
    long_name, dtype, fill
        The variable's ``long_name``, element type and fill value (the value of a point not
        computed yet).
    flags
        Flag name → value of a coded variable (its ``flag_meanings`` and ``flag_values``).
    """

    source: str
    long_name: str
    dtype: str
    fill: Any
    flags: Mapping[str, int] | None = None


#: The verdict's per-point variables: name → the verdict attribute it holds, long name,
#: element type, fill value and flag legend.
VERDICT_COLUMNS: Mapping[str, VerdictColumn] = MappingProxyType(
    {
        "motion": VerdictColumn(
            "label",
            "motion verdict: 1T…nT, QP, chaos, unresolved or failed",
            LABEL_DTYPE,
            UNSET_TEXT,
        ),
        "verdict": VerdictColumn(
            "code", "what decided the motion label (see flag_meanings)", "int8", -1, EVIDENCE
        ),
        "max_multiplier": VerdictColumn(
            "max_multiplier",
            "largest Floquet multiplier modulus max |μ| of the orbit shot at the point",
            "float64",
            np.nan,
        ),
        "lle": VerdictColumn(
            "lle", "largest Lyapunov exponent λ_1 per unit τ = ω_n t", "float64", np.nan
        ),
        "lle_error": VerdictColumn(
            "lle_error",
            "standard error of λ_1 (block means; 0: exact from the multipliers)",
            "float64",
            np.nan,
        ),
        "k01": VerdictColumn(
            "k01", "0–1 test for chaos K of the record (non-periodic labels)", "float64", np.nan
        ),
        "extra_periods": VerdictColumn(
            "extra_periods", "periods added by the verdict to finish a transient", "int64", -1
        ),
        "window_start": VerdictColumn(
            "window_start",
            "first period of the window λ_1 was measured over, counted after the recorded "
            "ones (-1: none, λ_1 exact from the multipliers)",
            "int64",
            -1,
        ),
        "window_periods": VerdictColumn(
            "window_periods",
            "length of the window λ_1 was measured over, in periods",
            "int64",
            0,
        ),
        "record": VerdictColumn(
            "record_code",
            "where the stored section record comes from (see flag_meanings)",
            "int8",
            -1,
            RECORD_SOURCES,
        ),
    }
)

#: The verdict's fields no store variable holds, and why.
NOT_STORED: Mapping[str, str] = MappingProxyType(
    {
        "period": "the label's period (Motion.parse(motion).period)",
        "evidence": "stored as its flag value (verdict, from the property code)",
        "reason": "a sentence for the summary and the point view, rebuilt on demand",
        "record": "replaces the point's section values and final state; its source is record",
        "orbit_state": "the confirmed orbit's state: an orbit store (--orbits) holds orbits",
        "coexisting": "the stable orbits beside the motion: reported by attractors",
        "agree": "a record-mode label's indicators against it: indicators_agree, one of the "
        "RECORD_VARIABLES a record-mode task writes beside the verdict columns",
    }
)

#: Per-point variables (name → long name, dtype, fill value), from :data:`VERDICT_COLUMNS`.
VERDICT_VARIABLES: Mapping[str, tuple[str, str, Any]] = MappingProxyType(
    {name: (c.long_name, c.dtype, c.fill) for name, c in VERDICT_COLUMNS.items()}
)


#: What the record mode also stores per point (name → long name, dtype, fill value): the
#: period of the section sequence and whether the indicators agree with the label, which a
#: sweep's classification at its end then reads instead of deciding every point again.
RECORD_VARIABLES: Mapping[str, tuple[str, str, Any]] = MappingProxyType(
    {
        "period": ("period n of the section sequence (0: none ≤ max_period)", "int16", 0),
        "indicators_agree": (
            "whether every available indicator agrees with the label",
            "bool",
            False,
        ),
    }
)


def verdict_attrs(name: str) -> dict[str, Any]:
    """Extra attributes of a verdict variable (the flag legends of ``verdict`` and
    ``record``)."""
    column = VERDICT_COLUMNS.get(name)
    flags = None if column is None else column.flags
    if flags is None:
        return {}
    return {"flag_values": list(flags.values()), "flag_meanings": " ".join(flags)}


def verdict_row(v: Any) -> dict[str, Any]:
    """The value of every verdict variable (:data:`VERDICT_COLUMNS`) for the verdict ``v``."""
    return {name: getattr(v, col.source) for name, col in VERDICT_COLUMNS.items()}


#: The verdict settings of a sweep without verdicts (``verdicts=False``): the record mode.
RECORD_MODE = VerdictSettings(mode="record")


def record_sections(observed: Any, blocks: list[np.ndarray]) -> np.ndarray:
    """The section values a label is read from in record mode: the first two observed
    section variables (their first observed planet) as (..., section, 2), from their arrays
    ``blocks`` in the order of ``observed`` — in a task's block arrays and in a stored
    sweep alike (:func:`gearchaos.sweep.classify.section_pair`)."""
    cols = []
    for ob, v in list(zip(observed, blocks, strict=True))[:2]:
        cols.append(np.asarray(v[..., 0] if ob.per_planet else v, dtype=float))
    return np.stack(cols, axis=-1)


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
    store layout (its grid, observed and tracked variables). In record mode
    (:data:`RECORD_MODE`) the labels are read from the section values already in ``data``
    and the λ₁ the sweep recorded (``lle``), nothing is integrated nor replaced."""
    grid, observed = layout.grid, layout.observed
    spec = grid.spec
    where = task.points()
    systems = [grid.system(idx) for _, _, idx, _ in where]
    ok = [int(out.status[c, j]) == 0 for c, j, *_ in where]
    n = systems[0].n_state
    spp = int(spec.solver.samples_per_period)
    lle = None
    record_mode = verdict is not None and verdict.mode == "record"
    if record_mode:
        blocks = [[data[ob.name][pos] for ob in observed] for *_, pos in where]
        sections = np.stack([record_sections(observed, b) for b in blocks])
        finals = np.stack([data["final_state"][pos] for *_, pos in where])
        if "lle" in data:
            lle = np.array([data["lle"][pos] for *_, pos in where], dtype=float)
    else:
        sections = np.stack([out.states[c, j][::spp, :n] for c, j, *_ in where])
        finals = np.stack([out.final_state[c, j, :n] for c, j, *_ in where])
    values = [grid.values_at(idx) for _, _, idx, _ in where]
    verdicts = decide_motion(
        grid.target, values, systems, sections, finals, ok, spec.solver, verdict, lle=lle
    )
    for name, col in VERDICT_COLUMNS.items():
        if name not in data:
            data[name] = np.full(task.shape, col.fill, dtype=col.dtype)
    for name, (_, dtype, fill) in RECORD_VARIABLES.items() if record_mode else ():
        data[name] = np.full(task.shape, fill, dtype=dtype)
    for (*_, pos), v in zip(where, verdicts, strict=True):
        for name, value in verdict_row(v).items():
            data[name][pos] = value
        if record_mode:
            data["period"][pos], data["indicators_agree"][pos] = v.period, bool(v.agree)
        rec = v.record
        if rec is None or spp != 1:  # a record sampled more than once a period is not replaced
            data["record"][pos] = RECORD_SOURCES["protocol"]
            continue
        m = data[observed[0].name][pos].shape[0]
        for ob in observed:
            data[ob.name][pos] = ob.take(rec.states[-m:], rec.observables[-m:])
        layout.put_extrema(data, pos, rec.obs_min, rec.obs_max)
        data["final_state"][pos] = rec.final_state
