"""What a motion verdict says: :class:`Verdict` (the label, what decided it and the numbers
behind it) and :data:`EVIDENCE` (the kinds of evidence, the flag values of a store's
``verdict`` variable). The decision procedure is :mod:`gearchaos.dynamics.verdict.decide`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ...analysis.motion import Motion, MotionKind
from ...errors import ParameterError
from .extension import RECORD_SOURCES, VerdictRecord

__all__ = ["EVIDENCE", "UNCONFIRMED", "Verdict", "evidence_words"]

#: What decided a label (the flag values of a store's ``verdict`` variable).
EVIDENCE = {
    "not_computed": -1,
    "floquet": 0,  # nT: a converged, stable orbit of minimal period n (multipliers)
    "lyapunov": 1,  # chaos or QP: the λ₁ interval, no period found or confirmed
    "record_contracting": 2,  # nT, n too long to shoot: the record repeats, λ₁ < 0
    "contracting": 3,  # unresolved: λ₁ < 0 but no period found within the budget
    "ambiguous": 4,  # unresolved: the λ₁ interval straddles the threshold
    "unstable_orbit": 5,  # unresolved: near an unstable orbit, not left within the budget
    "failed": 6,  # the integration failed
    "converging": 7,  # unresolved: approaching a stable orbit, not reached within the budget
    "record": 8,  # any label: from the record alone (mode "record"), nothing confirmed
}

#: Evidence codes whose label was read from the record alone, never checked by shooting or a
#: Lyapunov window: shown as such, never as confirmed.
UNCONFIRMED = frozenset({"record"})


def evidence_words(evidence: str) -> str:
    """What decided a label, in words for a table or the explorer: the :data:`EVIDENCE` key,
    and for a label read from the record alone that it is not confirmed."""
    if evidence in UNCONFIRMED:
        return "record (not confirmed)"
    return evidence


@dataclass(frozen=True, eq=False)
class Verdict:
    """What the motion is at one point, and what decided it.

    Attributes
    ----------
    label
        ``1T`` … ``nT``, ``QP``, ``chaos``, ``unresolved`` or ``failed``: the text of a
        :class:`~gearchaos.analysis.motion.Motion` (:attr:`motion`).
    period
        n of an nT label, else 0 (the motion's period: a label that does not parse, or a
        period that is not the label's, is refused).
    evidence
        Key of :data:`EVIDENCE`.
    max_multiplier
        max |μ| of the orbit that confirmed the label, or of the unstable orbit found near
        the record (NaN when none was shot).
    lle, lle_error
        λ₁ per unit τ and its standard error: exactly ln max|μ| / (nT) with error 0 for a
        confirmed orbit; from the last extension otherwise (NaN when none ran).
    k01
        0–1 test value of the record where computed (non-periodic labels), else NaN.
    extra_periods
        Periods integrated beyond the original record (extensions).
    reason
        One sentence: why this label.
    record
        The record that replaced the original one, else None: the extension's, or, when the
        original record was still converging onto the confirmed orbit, the orbit's own
        (integrated from its state for as many periods).
    orbit_state
        The confirmed orbit's state on the section (``floquet`` only).
    window_start, window_periods
        The window λ₁ was measured over: its first period counted after the protocol's record,
        and its length (−1, 0 when no window ran: a confirmed orbit's λ₁ is exact).
    coexisting
        ((period, max |μ|), …) the stable orbits found by shooting that the recorded motion
        does not approach: attractors beside it, evidence and not its label.
    agree
        False when an indicator of the record contradicts a label read from the record alone
        (evidence ``record``: :attr:`gearchaos.analysis.classify.MotionClass.agree`); True for
        the other evidence, which is its own check.
    """

    label: str
    period: int
    evidence: str
    max_multiplier: float = math.nan
    lle: float = math.nan
    lle_error: float = math.nan
    k01: float = math.nan
    extra_periods: int = 0
    reason: str = ""
    record: VerdictRecord | None = field(default=None, repr=False)
    orbit_state: np.ndarray | None = field(default=None, repr=False)
    window_start: int = -1
    window_periods: int = 0
    coexisting: tuple[tuple[int, float], ...] = ()
    agree: bool = True

    def __post_init__(self) -> None:
        motion = Motion.parse(self.label)
        if motion.period != self.period:
            raise ParameterError(
                f"period must be the label's ({motion.period} for {self.label}): "
                f"got {self.period!r}",
                name="period",
            )

    @property
    def motion(self) -> Motion:
        """The label as a :class:`~gearchaos.analysis.motion.Motion`; an ``unresolved`` or
        ``failed`` one carries the reason."""
        m = Motion.parse(self.label)
        if m.kind in (MotionKind.UNRESOLVED, MotionKind.FAILED):
            return replace(m, reason=self.reason)
        return m

    @property
    def code(self) -> int:
        """The :data:`EVIDENCE` flag value."""
        return EVIDENCE[self.evidence]

    @property
    def record_code(self) -> int:
        """Where the record the verdict is about comes from, as a flag value of
        :data:`~gearchaos.dynamics.verdict.extension.RECORD_SOURCES` (``protocol`` without a
        replacement record)."""
        return self.record.code if self.record is not None else RECORD_SOURCES["protocol"]

    @property
    def periodic(self) -> bool:
        return self.period > 0

    def lle_text(self) -> str:
        """λ₁ with its error as printed next to the label (``(exact)`` for Floquet)."""
        from ...analysis.summary import format_exponent

        return format_exponent(self.lle, self.lle_error)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields (NaN → None)."""

        def num(v: float) -> float | None:
            return float(v) if math.isfinite(v) else None

        return {
            "motion": self.label,
            "period": int(self.period),
            "evidence": self.evidence,
            "max_multiplier": num(self.max_multiplier),
            "lle": num(self.lle),
            "lle_error": num(self.lle_error),
            "k01": num(self.k01),
            "extra_periods": int(self.extra_periods),
            "record": self.record.source if self.record is not None else "protocol",
            "window_start": int(self.window_start),
            "window_periods": int(self.window_periods),
            "coexisting": [
                {"period": int(d), "max_multiplier": num(mu)} for d, mu in self.coexisting
            ],
            "reason": self.reason,
        }
