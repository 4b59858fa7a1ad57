"""The types of the parameter registry (:mod:`gearchaos.gearset.schema`): :class:`Rule`, a
range of numbers, and :class:`Field`, the description of one dotted parameter. A leaf module."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

__all__ = ["ANGLE", "AT_LEAST_ONE", "NON_NEGATIVE", "POSITIVE", "Field", "Rule"]


@dataclass(frozen=True)
class Rule:
    """A range: ``lo`` < or ≤ value < or ≤ ``hi`` (``None``: unbounded on that side)."""

    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False

    def holds(self, x: float) -> bool:
        if self.lo is not None and (x < self.lo or (self.lo_open and x == self.lo)):
            return False
        return not (self.hi is not None and (x > self.hi or (self.hi_open and x == self.hi)))

    def text(self) -> str:
        """``> 0``, ``>= 0`` or ``in (0, 45)``."""
        if self.hi is None:
            return f"{'>' if self.lo_open else '>='} {self.lo:g}"
        if self.lo is None:
            return f"{'<' if self.hi_open else '<='} {self.hi:g}"
        return (
            f"in {'(' if self.lo_open else '['}{self.lo:g}, {self.hi:g}"
            f"{')' if self.hi_open else ']'}"
        )


POSITIVE: Final = Rule(lo=0.0, lo_open=True)
NON_NEGATIVE: Final = Rule(lo=0.0)
AT_LEAST_ONE: Final = Rule(lo=1.0)
ANGLE: Final = Rule(lo=0.0, hi=45.0, lo_open=True, hi_open=True)


@dataclass(frozen=True)
class Field:
    """One addressable parameter.

    Attributes
    ----------
    name
        Dotted name (``backlash.sun_planet``), the same in Python, TOML, the CLI and stores.
    kind
        ``int``, ``float``, ``str`` or ``floats`` (a tuple of floats).
    unit
        Unit as written in TOML comments (``m``, ``N/m``, ``deg``, ``1`` for dimensionless).
    symbol
        Plain (Unicode) symbol of MODEL.md, e.g. ``b_sp``; empty for switches.
    tex
        Matplotlib mathtext symbol without ``$``, e.g. ``\\bar b_{sp}``.
    meaning
        One line for templates and documentation.
    rule
        Range of a number that the model needs (``None``: any finite value); checked first.
    choices
        Allowed values of a string field.
    limits
        Plausible range of a number, checked after ``rule`` (for ``floats``: of each item);
        ``None`` where a relation bounds the value instead (:data:`MODULE_BOUNDED`,
        k_a + Σ|k_h| < k_m) or where any value is plausible.
    """

    name: str
    kind: str
    unit: str
    symbol: str
    tex: str
    meaning: str
    rule: Rule | None = None
    choices: tuple[str, ...] = ()
    limits: Rule | None = None

    @property
    def table(self) -> str:
        return self.name.split(".", 1)[0]

    @property
    def key(self) -> str:
        return self.name.split(".", 1)[-1]

    @property
    def unit_label(self) -> str:
        """``[N/m]`` for dimensional units, empty for dimensionless ones and switches."""
        if self.unit in ("", "1") or " or " in self.unit:
            return ""
        return f"[{self.unit.replace('m^2', 'm²')}]"
