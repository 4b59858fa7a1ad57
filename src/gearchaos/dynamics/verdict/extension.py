"""Running on from recorded states: :func:`extend` integrates K states further, with one
random tangent vector (λ₁ and its error), and :class:`VerdictRecord` is the record that then
replaces the original one.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...integrate._chains import ChainRun, run_chains
from ...integrate.settings import SampleTimes, SolverSettings, default_step_budget
from ...model.system import System
from ..lyapunov import random_tangents
from ..orbits.shooting import section_fraction

__all__ = ["RECORD_SOURCES", "VerdictRecord", "extend"]


#: Where a point's shown record comes from (the flag values of a store's ``record``).
RECORD_SOURCES = {"protocol": 0, "extension": 1, "orbit": 2}


@dataclass(frozen=True, eq=False)
class VerdictRecord:
    """The section record that replaced the original one: ``states`` (m, n_state) and
    ``observables`` (m, n_obs) at the section, ``final_state``, the extrema ``obs_min`` /
    ``obs_max`` of the tracked observables over its window, and its ``source``:
    ``extension`` (the run continued) or ``orbit`` (the confirmed d-periodic orbit's own,
    onto which the original record was still converging: d periods integrated from its state
    and repeated to the record's length)."""

    states: np.ndarray
    observables: np.ndarray
    final_state: np.ndarray
    obs_min: np.ndarray
    obs_max: np.ndarray
    source: str = "extension"

    @property
    def code(self) -> int:
        return RECORD_SOURCES[self.source]


def extend(
    systems: Sequence[System],
    states: np.ndarray,
    settings: SolverSettings,
    periods: int,
    seed: int | None,
    *,
    tangent_tol: float = 1.0,
) -> Any:
    """Integrate K states (at the section of ``settings``) ``periods`` further, with one
    random tangent vector from ``default_rng(seed)`` (none when ``seed`` is None), the same
    start for every point, whose tolerances are ``tangent_tol`` times the state's; samples at
    the next ``periods`` section times."""
    ref = systems[0]
    K, n = len(systems), ref.n_state
    T = np.array([s.period for s in systems])
    t0 = (section_fraction(settings) * T)[:, None]
    # one sample at each of the next ``periods`` sections, the run ending on the last
    times = SampleTimes.over_periods(
        t0,
        T[:, None],
        first=1,
        periods=int(periods),
        end=int(periods),
        max_steps=default_step_budget(periods),
    )
    run = ChainRun.from_arrays(
        ref,
        np.array([s.params for s in systems])[:, None, :],
        np.array([s.switch_widths for s in systems])[:, None, :],
        t0,
        times,
        settings,
        y0=states,
        n_tangent=0 if seed is None else 1,
        # one start vector per seed for every point: a point's λ₁ must not depend on its
        # place in a batch (a sweep's task, a single simulate)
        tangent_start=None if seed is None else np.repeat(random_tangents(n, 1, seed=seed), K, 0),
        tangent_tol=tangent_tol,
    )
    return run_chains(run)
