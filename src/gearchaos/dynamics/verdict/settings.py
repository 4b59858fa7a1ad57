"""The settings of the motion verdict (:func:`~gearchaos.dynamics.verdict.decide.decide_motion`):
:class:`VerdictSettings`, its tolerances, windows and budgets, and :func:`confirmed_settings`,
those of the attractor tools (``attractors``, ``basins``, ``basin_fractions``), whose chaos
and QP need a last window of :data:`CONFIRM_PERIODS`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..._checks import check_choice, check_int, check_real
from ...analysis.classify import LLE_C
from ..lyapunov import LYAPUNOV_BLOCKS
from ..orbits.stability import STABILITY_MARGIN

__all__ = ["CONFIRM_PERIODS", "MODES", "VerdictSettings", "confirmed_settings"]

#: The verdict's modes: ``confirm`` (labels checked by shooting, Floquet multipliers and
#: Lyapunov windows) and ``record`` (labels from the record alone, evidence ``record``:
#: :mod:`~gearchaos.dynamics.verdict.record`).
MODES = ("confirm", "record")

#: Default length of the last window behind a chaos or QP entry of ``attractors``, ``basins``
#: and ``basin_fractions``: a long continuation that a chaotic transient rarely survives.
CONFIRM_PERIODS = 2000


@dataclass(frozen=True)
class VerdictSettings:
    """Tolerances and budget of :func:`decide_motion`.

    Parameters
    ----------
    mode
        ``confirm`` (default): the procedure of :mod:`~gearchaos.dynamics.verdict.decide`;
        ``record``: every label read from the record alone, with evidence ``record``
        (:func:`~gearchaos.dynamics.verdict.record.decide_from_record`, with ``period_rtol``,
        ``longest_period`` and ``lle_c``; the other settings do not apply), nothing integrated.
    max_period
        Longest period confirmed by shooting (Newton with the full monodromy over n periods).
    longest_period
        Longest period recognised in a record at all; QP is considered only once the record
        is at least twice this long.
    period_rtol
        Recurrence tolerance relative to the attractor's size S.
    noise_factor
        The noise floor ε = noise_factor · (atol + rtol · max|x|) of the section points.
    margin
        Stability margin: a stable orbit has every non-structural |μ| < 1 − margin
        (:data:`~gearchaos.dynamics.orbits.stability.STABILITY_MARGIN`).
    same_orbit
        Largest distance (∞-norm, relative to max(1, ‖y*‖)) between the final state and an
        unstable orbit's section points for the motion to sit on it.
    reach
        A record lies on its orbit when every recorded section is within reach ·
        max(1, ‖y*‖) (∞-norm) of the orbit's section points: the tolerance of every nT
        label's record.
    approach
        A record whose recurrence gaps over its last quarter stay within this fraction of
        max(1, max|x|) lingers near a periodic orbit: that period is shot.
    extension_periods
        Length of the first window (None: the record's length, at least ``min_extension``).
    min_extension
        Shortest first window when ``extension_periods`` is None.
    max_window
        Longest window (each window is twice as long as the one before).
    budget_periods
        Most periods added to a point by windows.
    settle_budget
        Most periods integrated without tangents to bring a record that approaches a stable
        orbit onto it: first, where the record is too short to measure the approach at the
        slowest rate the multipliers predict, until it is long enough (the history a point
        keeps grows to that length, :func:`~gearchaos.dynamics.verdict.periodic.measure_periods`),
        then for as long as the measured rate says the record needs to lie on the orbit. A
        point that would need more ends ``unresolved`` (``converging``), its reason stating
        the periods predicted against this budget.
    confirm_periods
        Chaos and QP need a last window at least this long (0: any; ``attractors`` and the
        basin tools use 2000, a long continuation that a chaotic transient rarely survives).
    max_bands
        Most curves or bands of the section the torus test looks for.
    newton_iterations, newton_contraction, newton_tol
        The shooting's iteration limit, early give-up factor over three iterations and
        tolerance (relative to max(1, ‖y‖)).
    tangent_tol
        Factor on the integrator's tolerances for the Newton iteration's monodromy columns
        (cheap tangents for Newton; the multipliers stated are computed once more at the
        state's tolerances, factor 1).
    lyapunov_tol
        The same factor for a window's Lyapunov vector (infinite: the vector takes the state's
        steps, and the state is bitwise that of a plain run).
    blocks, confidence
        Block means of the λ₁ error estimate, and the half-width c of its interval in
        standard errors.
    lle_c
        c_θ of the finite-time bias bound θ = c_θ / t.
    seed
        Seed of the random initial tangent vectors.
    """

    mode: str = "confirm"
    max_period: int = 8
    longest_period: int = 64
    period_rtol: float = 1e-3
    noise_factor: float = 1e3
    margin: float = STABILITY_MARGIN
    same_orbit: float = 1e-2
    reach: float = 1e-3
    approach: float = 2e-2
    extension_periods: int | None = None
    min_extension: int = 100
    max_window: int = 1600
    budget_periods: int = 6300
    settle_budget: int = 6000
    confirm_periods: int = 0
    max_bands: int = 8
    tangent_tol: float = 1000.0
    lyapunov_tol: float = math.inf
    newton_tol: float = 1e-7
    newton_iterations: int = 10
    newton_contraction: float = 0.25
    blocks: int = LYAPUNOV_BLOCKS
    confidence: float = 2.0
    lle_c: float = LLE_C
    seed: int = 0

    def __post_init__(self) -> None:
        check_choice("mode", self.mode, MODES)
        check_int("max_period", self.max_period, lo=1, hi=64)
        check_int("longest_period", self.longest_period, lo=self.max_period, hi=10_000)
        check_real("period_rtol", self.period_rtol, lo=0.0, hi=0.5, lo_open=True)
        check_real("noise_factor", self.noise_factor, lo=1.0)
        check_real("margin", self.margin, lo=0.0, hi=0.5)
        check_real("same_orbit", self.same_orbit, lo=0.0, hi=1.0, lo_open=True)
        check_real("reach", self.reach, lo=0.0, hi=1.0, lo_open=True)
        check_real("approach", self.approach, lo=0.0, hi=1.0)
        if self.extension_periods is not None:
            check_int("extension_periods", self.extension_periods, lo=2 * self.blocks + 1)
        check_int("min_extension", self.min_extension, lo=2 * self.blocks + 1, hi=10**6)
        check_int("max_window", self.max_window, lo=2 * self.blocks + 1, hi=10**7)
        check_int("budget_periods", self.budget_periods, lo=0, hi=10**7)
        check_int("settle_budget", self.settle_budget, lo=0, hi=10**7)
        check_int("confirm_periods", self.confirm_periods, lo=0, hi=10**7)
        check_int("max_bands", self.max_bands, lo=1, hi=64)
        check_real("tangent_tol", self.tangent_tol, lo=1.0, hi=1e6)
        if not (isinstance(self.lyapunov_tol, int | float) and self.lyapunov_tol == math.inf):
            check_real("lyapunov_tol", self.lyapunov_tol, lo=1.0, hi=1e8)
        check_real("newton_tol", self.newton_tol, lo=0.0, hi=1e-3, lo_open=True)
        check_int("newton_iterations", self.newton_iterations, lo=1, hi=100)
        check_real("newton_contraction", self.newton_contraction, lo=0.0, hi=1.0, lo_open=True)
        check_int("blocks", self.blocks, lo=2, hi=1000)
        check_real("confidence", self.confidence, lo=0.0, lo_open=True)
        check_real("lle_c", self.lle_c, lo=0.0, lo_open=True)
        check_int("seed", self.seed, lo=0)

    def extension_for(self, record_periods: int) -> int:
        """Periods of the first window after a record of ``record_periods``."""
        if self.extension_periods is not None:
            return int(self.extension_periods)
        return min(max(int(record_periods), self.min_extension), self.max_window)

    def next_window(self, previous: int, count: int) -> int:
        """Periods of the window after ``count`` windows, the last of ``previous`` periods:
        the second as long as the first (a later window to confirm what the first says),
        each one after it twice as long (θ and σ shrink for a weak exponent), at most
        ``max_window``, and at least ``confirm_periods`` once a window has run."""
        grow = 1 if count == 1 else 2
        return max(min(grow * int(previous), self.max_window), self.confirm_periods)


def confirmed_settings(confirm_periods: int = CONFIRM_PERIODS) -> VerdictSettings:
    """The verdict of the attractor tools: chaos and QP need a last window of at least
    ``confirm_periods`` (and the budget for two such windows after the first)."""
    c = check_int("confirm_periods", confirm_periods, lo=0, hi=10**6)
    base = VerdictSettings()
    return VerdictSettings(confirm_periods=c, budget_periods=max(base.budget_periods, 2 * c + 600))
