"""A user model of the tests' own whose forcing has two frequencies (issue 36, item 3): a
two-stage gear train written outside the package, stage 1 meshing at Ω and stage 2 at 3Ω/5,
so that its forcing repeats after T = 5·2π/Ω and the model declares ``period_factor`` 5.

Each stage is a backlash oscillator x'' + 2ζx' + f(x; b_k) = 0.1 + 0.2 cos(w_k τ) with
w_1 = Ω, w_2 = 3Ω/5; its deflections ``x_1``, ``x_2`` are lengths in units of b_0 = 20 µm with
ω_0 = 5000 rad/s (:class:`~stage_scales.StageScales`), its contacts are named ``stage1`` and
``stage2``, its period is the *train* period and its group members are stages. None of its
words is the planetary model's. ``tests/`` is on ``sys.path`` (its ``conftest.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numba
import numpy as np

from gearchaos.model.contract import Contact, UserModel
from stage_scales import StageScales

#: The forcing period in units of 2π/Ω: the stages' frequencies Ω and 3Ω/5 meet after 5.
PERIOD_FACTOR = 5.0


@numba.njit(cache=True)
def _two_frequency_rhs(t, y, p, dydt, obs, level):  # pragma: no cover - compiled
    for s in range(2):
        x, v = y[s], y[2 + s]
        b = p[2 + s]
        f = x - b if x > b else (x + b if x < -b else 0.0)
        w = p[0] if s == 0 else 0.6 * p[0]
        dydt[s] = v
        dydt[2 + s] = -2.0 * p[1] * v - f + 0.1 + 0.2 * math.cos(w * t)
        obs[s] = x
        obs[2 + s] = v


@dataclass(frozen=True)
class TwoFrequencyTrain(UserModel):
    zeta: float = 0.05
    b_1: float = 1.0
    b_2: float = 0.5

    name = "two_frequency_train"
    state_names = ("x_1", "x_2", "x_1_dot", "x_2_dot")
    obs_names = ("x_1", "x_2", "x_1_dot", "x_2_dot")
    n_track = 2
    rhs = _two_frequency_rhs
    quantities: ClassVar[dict[str, str]] = {"x": "length", "x_dot": "velocity"}
    symbols: ClassVar[dict[str, Any]] = {"x": (r"\bar{q}_{%d}", r"q_{%d}/b_0", None, None)}
    parameter_symbols: ClassVar[dict[str, str]] = {"zeta": r"\zeta"}
    period_factor = PERIOD_FACTOR
    period_name = "train"
    member_name = "stage"
    default_observables = ("x", "x_dot")  # the group: x_1 first
    scales = StageScales()

    @property
    def contacts(self) -> tuple[Contact, ...]:
        return (Contact("stage1", 0, self.b_1), Contact("stage2", 1, self.b_2))

    @property
    def switch_widths(self) -> np.ndarray:
        return np.array([self.b_1, self.b_2])

    def pack(self, omega: float) -> np.ndarray:
        return np.array([omega, self.zeta, self.b_1, self.b_2])
