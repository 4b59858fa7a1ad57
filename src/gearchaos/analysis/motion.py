"""What an attractor's motion is, as a value: :class:`Motion`, with one :meth:`Motion.parse`
and one :meth:`Motion.format`.

Every motion label the package writes — in a summary, a sweep store's ``motion`` variable, a
figure's legend, a table, a report — is the text of a :class:`Motion`:

========================  ==========================================================
text                      motion
========================  ==========================================================
``1T``, ``2T``, … ``nT``  periodic: the section sequence repeats after n forcing periods
``QP``                    quasi-periodic (a torus on the section)
``chaos``                 chaotic
``unresolved``            not decided (the reason is the verdict's, not the text's)
``failed``                the integration failed
``not run``               a point of an interrupted sweep that was never computed
========================  ==========================================================

A sweep store's fill value for a point not computed yet is the empty text
(:data:`UNSET_TEXT`); it reads as ``not run``. Code that needs the period of a label, or
whether it is periodic, parses it here; no module slices a label (``lab[:-1].isdigit()``), so
the vocabulary has one definition and an unknown text is refused with a message that names
it instead of being read as "not periodic".
"""

from __future__ import annotations

import enum
import re
from dataclasses import dataclass, field
from typing import Any

from .._checks import check_int
from ..errors import ParameterError

__all__ = ["LABEL_DTYPE", "UNSET_TEXT", "Motion", "MotionKind"]

#: Fixed-width string dtype of stored labels: ``unresolved`` is the longest word, and a period
#: label ``nT`` fits as long as n has at most 9 digits (:data:`MAX_PERIOD`).
LABEL_DTYPE = "<U10"
#: Largest period a label can name: its text ``nT`` must fit :data:`LABEL_DTYPE`.
MAX_PERIOD = 999_999_999
#: What a store holds for a point whose label is not written yet (its fill value).
UNSET_TEXT = ""

_PERIODIC_TEXT = re.compile(r"([1-9][0-9]*)T")


class MotionKind(enum.Enum):
    """The kinds of motion, in display order; the value of a non-periodic kind is its text."""

    PERIODIC = "nT"
    QUASI_PERIODIC = "QP"
    CHAOS = "chaos"
    UNRESOLVED = "unresolved"
    FAILED = "failed"
    NOT_RUN = "not run"


_ORDER = {kind: k for k, kind in enumerate(MotionKind)}
_BY_TEXT = {kind.value: kind for kind in MotionKind if kind is not MotionKind.PERIODIC}
_BY_TEXT[UNSET_TEXT] = MotionKind.NOT_RUN
_WITH_REASON = (MotionKind.UNRESOLVED, MotionKind.FAILED)


@dataclass(frozen=True)
class Motion:
    """One motion: its kind, its period n (periodic motion only) and, for an ``unresolved``
    or ``failed`` motion, why.

    Build it with the named constructors (:meth:`periodic`, :meth:`quasi_periodic`,
    :meth:`chaos`, :meth:`unresolved`, :meth:`failed`, :meth:`not_run`) or from a label's
    text with :meth:`parse`; ``str(motion)`` (:meth:`format`) is the label. Two motions are
    equal when their kind and period are: the reason is evidence, not part of the label.

    Attributes
    ----------
    kind
        A :class:`MotionKind`.
    period
        n of a periodic motion (1 ≤ n ≤ :data:`MAX_PERIOD`); 0 for every other kind.
    reason
        Why an ``unresolved`` or ``failed`` motion is so (may be empty); empty otherwise.
    """

    kind: MotionKind
    period: int = 0
    reason: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        if not isinstance(self.kind, MotionKind):
            raise ParameterError(f"kind must be a MotionKind: got {self.kind!r}", name="kind")
        if self.kind is MotionKind.PERIODIC:
            object.__setattr__(
                self, "period", check_int("period", self.period, lo=1, hi=MAX_PERIOD)
            )
        elif self.period != 0:
            raise ParameterError(
                f"period must be 0 for a {self.kind.value} motion (only nT has a period): "
                f"got {self.period!r}",
                name="period",
            )
        if not isinstance(self.reason, str):
            raise ParameterError(f"reason must be text: got {self.reason!r}", name="reason")
        if self.reason and self.kind not in _WITH_REASON:
            raise ParameterError(
                f"reason is given only for an unresolved or failed motion, not for "
                f"{self.format()}: got {self.reason!r}",
                name="reason",
            )

    # ------------------------------------------------------------------ constructors
    @classmethod
    def periodic(cls, n: int) -> Motion:
        """The nT-periodic motion (n ≥ 1)."""
        return cls(MotionKind.PERIODIC, check_int("period", n, lo=1, hi=MAX_PERIOD))

    @classmethod
    def quasi_periodic(cls) -> Motion:
        """``QP``."""
        return cls(MotionKind.QUASI_PERIODIC)

    @classmethod
    def chaos(cls) -> Motion:
        """``chaos``."""
        return cls(MotionKind.CHAOS)

    @classmethod
    def unresolved(cls, reason: str = "") -> Motion:
        """``unresolved``, with why."""
        return cls(MotionKind.UNRESOLVED, reason=reason)

    @classmethod
    def failed(cls, reason: str = "") -> Motion:
        """``failed``: the integration failed."""
        return cls(MotionKind.FAILED, reason=reason)

    @classmethod
    def not_run(cls) -> Motion:
        """``not run``: a point of an interrupted sweep that was never computed."""
        return cls(MotionKind.NOT_RUN)

    # ------------------------------------------------------------------ text
    @classmethod
    def parse(cls, text: Any) -> Motion:
        """The motion a label names: ``nT`` (n ≥ 1, no leading zero), ``QP``, ``chaos``,
        ``unresolved``, ``failed``, ``not run``, or the empty text of a store's unset point
        (``not run``). Anything else raises :class:`~gearchaos.errors.ParameterError` naming
        the text. A numpy string (a store's element) is text."""
        if not isinstance(text, str):
            raise ParameterError(
                f"a motion label must be text: got {type(text).__name__} {text!r}",
                name="motion",
            )
        kind = _BY_TEXT.get(text)
        if kind is not None:
            return cls(kind)
        m = _PERIODIC_TEXT.fullmatch(text)
        if m is not None and len(m.group(1)) <= len(str(MAX_PERIOD)):
            return cls(MotionKind.PERIODIC, int(m.group(1)))
        raise ParameterError(
            "a motion label must be nT (n an integer from 1 to "
            f"{MAX_PERIOD}, no leading zero), QP, chaos, unresolved, failed or not run: "
            f"got {str(text)!r}",
            name="motion",
        )

    def format(self) -> str:
        """The label: ``nT``, ``QP``, ``chaos``, ``unresolved``, ``failed`` or ``not run``."""
        if self.kind is MotionKind.PERIODIC:
            return f"{self.period}T"
        return self.kind.value

    def __str__(self) -> str:
        return self.format()

    # ------------------------------------------------------------------ questions
    @property
    def is_periodic(self) -> bool:
        """True for ``nT``."""
        return self.kind is MotionKind.PERIODIC

    @property
    def decided(self) -> bool:
        """True for a motion the evidence decided: ``nT``, ``QP`` or ``chaos``."""
        return self.kind in (MotionKind.PERIODIC, MotionKind.QUASI_PERIODIC, MotionKind.CHAOS)

    @property
    def regular(self) -> bool | None:
        """True for ``nT`` and ``QP``, False for ``chaos``, None for the undecided kinds."""
        if self.kind is MotionKind.CHAOS:
            return False
        return True if self.decided else None

    @property
    def sort_key(self) -> tuple[int, int]:
        """Display order: 1T, 2T, …, nT, QP, chaos, unresolved, failed, not run."""
        return (_ORDER[self.kind], self.period)
