"""Physical scales of the two-stage train that tests build as a user model of their own
(``tests/model/test_capabilities.py``, ``tests/plot/test_user_model_figures.py``): b_c = 20 µm,
ω_n = 5000 rad/s, k = 1e8 N/m. ``tests/`` is on ``sys.path`` (its ``conftest.py``)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class StageScales:
    length: float = 20e-6
    omega_n: float = 5000.0
    stiffness: float = 1e8

    @property
    def velocity(self) -> float:
        return self.length * self.omega_n

    @property
    def force(self) -> float:
        return self.stiffness * self.length
