"""Exceptions and status codes shared by every layer.

Kernels never raise: they return a :class:`Status`. Only the top-level API turns a
non-``OK`` status into an :class:`IntegrationError` (and only when asked to), so that a
sweep of thousands of points keeps going past one bad point.
"""

from __future__ import annotations

import enum

__all__ = ["IntegrationError", "ParameterError", "Status", "StoreError"]


class ParameterError(ValueError):
    """A parameter violates a physical or structural rule.

    The message always names the parameter (by its dotted name), the rule and the value,
    e.g. ``backlash.sun_planet must be >= 0: got -3.0``.

    Parameters
    ----------
    message
        What a person reads.
    name
        The dotted name of the parameter, setting or keyword that was refused
        (``"backlash.sun_planet"``, ``"rtol"``), where the check knows it; ``None`` otherwise.
        Front ends (the command line) map it to their own spelling of the option instead of
        reading the message.
    """

    def __init__(self, message: str = "", *, name: str | None = None) -> None:
        super().__init__(message)
        self.name = name

    def __reduce__(self) -> tuple[object, ...]:
        # keep the name when the error crosses a process boundary
        return (_parameter_error, (str(self), self.name))


def _parameter_error(message: str, name: str | None) -> ParameterError:
    return ParameterError(message, name=name)


class IntegrationError(RuntimeError):
    """The integrator stopped before the requested end time (see :class:`Status`)."""


class StoreError(RuntimeError):
    """A result store cannot be used as asked (wrong settings, corrupt, locked)."""


class Status(enum.IntEnum):
    """Integrator outcome codes. The integer values are what the numba kernels return
    (0–3) and what sweep stores hold per point (4: not computed yet)."""

    OK = 0
    MAX_STEPS = 1
    STEP_UNDERFLOW = 2
    NON_FINITE = 3
    NOT_RUN = 4  # a sweep point not computed yet (an interrupted store); never a kernel result

    def __str__(self) -> str:
        """The name a person reads (``ok``, ``max_steps``), not the code ``0``."""
        return self.name.lower()

    def __format__(self, spec: str) -> str:
        # f"{status}" reads as its name; a numeric format (f"{status:d}") gives the code
        return str(self) if not spec else format(int(self), spec)

    @property
    def message(self) -> str:
        return _MESSAGES[self]

    @property
    def ok(self) -> bool:
        return self is Status.OK

    @property
    def failed(self) -> bool:
        """An integration that ran and failed (not ``OK``, not ``NOT_RUN``)."""
        return self not in (Status.OK, Status.NOT_RUN)

    @classmethod
    def meanings(cls) -> str:
        """The members' names in code order, for the CF ``flag_meanings`` of status arrays."""
        return " ".join(s.name.lower() for s in cls)


_MESSAGES = {
    Status.OK: "integration reached the requested end time",
    Status.MAX_STEPS: (
        "the step budget was exhausted before the end time (by default 100 000 steps + "
        "50 000 per simulated period); loosen rtol/atol (--rtol, --atol), simulate fewer "
        "periods, or give a larger max_steps (a solver setting of the Python API)"
    ),
    Status.STEP_UNDERFLOW: (
        "the step size fell below the floating-point resolution of the time variable; "
        "the problem is too stiff or discontinuous for the requested rtol/atol"
    ),
    Status.NON_FINITE: (
        "the state became NaN or infinite; the response diverged "
        "(check for negative stiffness or an unstable parameter set)"
    ),
    Status.NOT_RUN: (
        "not computed yet (an interrupted sweep); run the same command again to resume"
    ),
}
