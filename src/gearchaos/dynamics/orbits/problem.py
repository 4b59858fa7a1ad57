"""What the one Newton corrector (:mod:`.corrector`) is given and returns: the options shared by
the K points of one call (:class:`Problem`), each point's start (:class:`Start`), a solution
(:class:`Solution`) and the map evaluations a point asks for (:class:`Ask`).

Options (:class:`Problem`), and why the callers differ
-------------------------------------------------------
``jacobian``
    ``newton``: M afresh at every trial (:func:`~.batch.periodic_orbits` by default: K points
    evaluate M beside G in the same round). ``chord``: the last M kept while each accepted
    step shrinks max|G| tenfold, otherwise evaluated afresh at the next trial, in the round of
    its G (the motion verdict: most of its many candidates converge from a good guess in a few
    cheap steps without tangents, and its give-up counts rounds, which an evaluation of M
    alone would spend without progress). ``broyden``: the kept [M − I, G_λ] corrected along
    every accepted full step by Broyden's (good) rank-one update, and evaluated afresh at once
    at the accepted state when a step from a matrix not evaluated at its start shrank max|G|
    less than tenfold, so the next step is exact
    (continuation, whose points start from the previous point's M and G_λ extrapolated along
    the branch, a Jacobian no evaluation produced; where the map is barely smooth, near a
    grazing contact, a step from a stale matrix is refused more often than not; and
    :func:`~.orbit.periodic_orbit`, whose guesses from rest may lie off the orbit by its size:
    a fresh M at every slow step loses them). Its trials must lower max|G| sufficiently
    (Armijo: by 10⁻⁴ of the fraction of the step taken); the others', by any amount.
``fractions``
    Damped steps evaluated per round: 4 for one point (its chains run on otherwise idle
    cores: the whole damping costs one round), 1 for K points (they keep the cores busy; a
    fraction evaluated in vain would cost work).
``contraction``, ``tangent_tol``
    The verdict gives a point up when three rounds have not shrunk its best max|G| by this
    factor (Newton inside its basin shrinks it far faster), and computes M with looser
    tolerances (it recomputes the stated multipliers at the orbit); continuation runs each
    point to convergence and needs accurate M.
``fd_step``
    The step h of G_λ; 0 for a fixed parameter.
``keep_failed``
    Whether a point that did not converge is returned at its best state with its multipliers
    (the orbit doors report it) or only why (continuation retries with a shorter step: those
    multipliers would cost an evaluation with tangents for nothing).
"""

from __future__ import annotations

from collections.abc import Callable, Generator
from dataclasses import dataclass

import numpy as np

from ..._checks import check_int, check_real
from ...errors import ParameterError, Status
from ...integrate.settings import SolverSettings
from ...model.system import System
from .shooting import Shot

__all__ = [
    "JACOBIANS",
    "MIN_FRACTION",
    "TRUST_RADIUS",
    "Ask",
    "Iteration",
    "Problem",
    "Solution",
    "Start",
]

#: The largest Newton step, relative to max(1, ‖y‖_∞).
TRUST_RADIUS = 10.0
#: The shortest damped step, as a fraction of the Newton step.
MIN_FRACTION = 1.0 / 16.0
#: How the Jacobian is kept between evaluations (see the module docstring).
JACOBIANS = ("newton", "chord", "broyden")


@dataclass(frozen=True)
class Problem:
    """What all points of one :func:`correct_points` call share: the period n, the solver
    settings, the tolerance of residual and step, the rounds allowed per point
    (``max_iterations``) and the options of the module docstring."""

    period: int
    settings: SolverSettings
    tol: float
    max_iterations: int
    jacobian: str = "broyden"
    fractions: int = 4
    fd_step: float = 0.0
    contraction: float | None = None
    tangent_tol: float = 1.0
    keep_failed: bool = False

    def __post_init__(self) -> None:
        if self.jacobian not in JACOBIANS:
            raise ParameterError(
                f"jacobian must be one of {', '.join(JACOBIANS)}: got {self.jacobian!r}"
            )
        check_int("fractions", self.fractions, lo=1, hi=4)
        check_int("max_iterations", self.max_iterations, lo=1)
        check_real("tol", self.tol, lo=0.0, lo_open=True)
        if self.contraction is not None:
            check_real("contraction", self.contraction, lo=0.0, hi=1.0, lo_open=True)


@dataclass(frozen=True, eq=False)
class Start:
    """One point: its systems by parameter value, the start z = (y, λ), the border
    ⟨normal, z⟩ = offset and, from a nearby solution, M and G_λ to start from (no Jacobian
    evaluation then)."""

    system: Callable[[float], System]
    z: np.ndarray
    normal: np.ndarray
    offset: float
    monodromy: np.ndarray | None = None
    g_lam: np.ndarray | None = None

    @classmethod
    def fixed(cls, system: System, y: np.ndarray) -> Start:
        """A fixed-parameter orbit of ``system`` from y: z = (y, 0), border e_λ, offset 0."""
        y = np.asarray(y, dtype=np.float64)
        normal = np.zeros(y.size + 1)
        normal[-1] = 1.0
        return cls(lambda _lam: system, np.append(y, 0.0), normal, 0.0)


@dataclass(eq=False)
class Solution:
    """A point of the bordered shooting system: the state y, the parameter λ, the shot (with
    the monodromy) at (y, λ), G_λ, the residual, the work done (map evaluations, of which
    ``jacobians`` with tangents), the sorted multipliers, the Newton ``corrections`` (steps
    taken), whether it ``converged`` and the ``message`` and integration ``status`` it ended
    with; a continuation adds the unit ``tangent``, the arclength ``s`` and whether the point
    was ``landed`` on a grid value."""

    y: np.ndarray
    lam: float
    shot: Shot
    g_lam: np.ndarray
    residual: float
    evals: int
    jacobians: int
    mu: np.ndarray
    corrections: int = 0
    converged: bool = True
    message: str = "converged"
    status: Status = Status.OK
    tangent: np.ndarray | None = None
    s: float = 0.0
    landed: bool = False

    @property
    def monodromy(self) -> np.ndarray:
        assert self.shot.monodromy is not None
        return self.shot.monodromy[0]

    @property
    def z(self) -> np.ndarray:
        return np.append(self.y, self.lam)


@dataclass(frozen=True, eq=False)
class Ask:
    """Map evaluations a point asks for: ``states`` (C, n_state) of ``systems`` (C), with or
    without tangents. The answer is their :class:`~.shooting.Shot` (C chains)."""

    systems: list[System]
    states: np.ndarray
    tangents: bool


#: What a point's iteration yields, is sent, and returns.
Iteration = Generator[tuple[Ask, ...], tuple[Shot, ...], tuple[Solution | None, str]]
