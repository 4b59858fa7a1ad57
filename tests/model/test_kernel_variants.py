"""The planetary right-hand side compiled for a fixed planet count (issue 13) is the general one.

Gear sets with N ∈ PLANETARY_FIXED_N planets run a kernel compiled for that N (kind
KIND_PLANETARY_FIXED + N); it must compute exactly what the general kernel (kind KIND_PLANETARY,
N read from the parameters) computes: same operations in the same order, so bitwise equal
derivatives and observables, at every observable level and with the rare terms (eccentricities,
stiffness harmonics) too.
"""

from __future__ import annotations

import numpy as np
import pytest
from planetary_variants import variant_gearset

import gearchaos as gc
from gearchaos.model import kernels
from gearchaos.model.layout import (
    KIND_PLANETARY,
    KIND_PLANETARY_FIXED,
    PLANETARY_FIXED_N,
    planetary_kind,
)
from gearchaos.model.planetary import planetary_system


def test_kinds() -> None:
    for n in PLANETARY_FIXED_N:
        assert planetary_kind(n) == KIND_PLANETARY_FIXED + n
    assert planetary_kind(1) == planetary_kind(7) == KIND_PLANETARY
    assert planetary_system(gc.preset("hindawi2021"), 1.5).kind == planetary_kind(5)


@pytest.mark.parametrize("rare", [False, True])
@pytest.mark.parametrize("n", PLANETARY_FIXED_N)
def test_fixed_count_kernel_equals_general_kernel(n: int, rare: bool) -> None:
    system = planetary_system(variant_gearset(n, rare), 1.7)
    assert system.kind == KIND_PLANETARY_FIXED + n
    p = system.params
    rng = np.random.default_rng(n)
    # states on both sides of every clearance (b̄ ≈ 1): contact, separation, back contact
    for _ in range(20):
        y = rng.normal(scale=2.0, size=system.n_state)
        t = float(rng.uniform(0.0, 50.0))
        for level in (kernels.OBS_NONE, kernels.OBS_TRACK, kernels.OBS_ALL):
            d_fixed = np.full(system.n_state, np.nan)
            d_gen = np.full(system.n_state, np.nan)
            o_fixed = np.full(system.n_obs, np.nan)
            o_gen = np.full(system.n_obs, np.nan)
            kernels.rhs(system.kind, t, y, p, d_fixed, o_fixed, level)
            kernels.rhs(KIND_PLANETARY, t, y, p, d_gen, o_gen, level)
            assert np.all(np.isfinite(d_fixed))
            assert d_fixed.tobytes() == d_gen.tobytes()
            assert o_fixed.tobytes() == o_gen.tobytes()
