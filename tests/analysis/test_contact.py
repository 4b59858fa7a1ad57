"""Contact regimes (MODEL.md §8) on synthetic numbers and on the backlash oscillator."""

from __future__ import annotations

import math

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.analysis.contact import (
    contact_fractions,
    contact_regime,
    contact_regimes,
    separation_fraction,
)
from gearchaos.errors import ParameterError


@pytest.mark.parametrize(
    ("delta_min", "b", "regime"),
    [
        (3.5, 3.0, "none"),
        (3.0, 3.0, "single_sided"),  # touching the edge of the gap is separation
        (0.0, 3.0, "single_sided"),
        (-3.0, 3.0, "single_sided"),
        (-3.0001, 3.0, "double_sided"),
        (1e-9, 0.0, "none"),
        (-1e-9, 0.0, "double_sided"),
        (math.nan, 1.0, "unknown"),
    ],
)
def test_contact_regime(delta_min: float, b: float, regime: str) -> None:
    assert contact_regime(delta_min, b) == regime


def test_contact_regime_rejects_bad_clearance() -> None:
    with pytest.raises(ParameterError, match="b"):
        contact_regime(1.0, -1.0)


def oscillator(omega: float, f_mean: float, f_alt: float, samples: int = 1) -> gc.SimulationResult:
    system = gc.backlash_oscillator(
        omega, zeta=0.1, b=1.0, f_mean=f_mean, f_alt=f_alt, omega_power=0
    )
    return gc.simulate(system, transient_periods=20, periods=20, samples_per_period=samples)


def test_exact_no_separation_case() -> None:
    # MODEL.md §10.5: x = b + F_m + F_a|H| cos(Ωτ − θ); at Ω = 1, |H| = 1/(2ζ) = 5, so
    # x_min = 1 + 2 − 1.5 = 1.5 > b: the drive flanks never part.
    r = oscillator(1.0, 2.0, 0.3, samples=64)
    assert contact_regimes(r) == {"mesh": "none"}
    assert r.extrema("x")[0] == pytest.approx(1.5, abs=1e-6)
    assert separation_fraction(r) == {"mesh": 0.0}


def test_back_flank_contact_is_double_sided() -> None:
    # small mean load, large alternating load near the softened resonance
    r = oscillator(0.8, 0.1, 1.0, samples=256)
    x = r.series("x")
    assert np.min(x) < -1.0  # back-flank contact really happens in the dense history
    assert contact_regimes(r) == {"mesh": "double_sided"}
    f = contact_fractions(r)["mesh"]
    assert f["back"] > 0 and f["gap"] > 0 and f["drive"] > 0
    assert f["drive"] + f["gap"] + f["back"] == pytest.approx(1.0)
    assert separation_fraction(r)["mesh"] == pytest.approx(f["gap"] + f["back"])


def test_gap_without_back_contact_is_single_sided() -> None:
    r = oscillator(0.9, 0.5, 0.3, samples=256)
    x = r.series("x")
    assert -1.0 < np.min(x) < 1.0
    assert contact_regimes(r) == {"mesh": "single_sided"}
    assert contact_fractions(r)["mesh"]["back"] == 0.0


def test_planetary_keys_and_order() -> None:
    gs = gc.preset("hindawi2021")
    r = gc.simulate(gs, omega=0.5, transient_periods=20, periods=10)
    regimes = contact_regimes(r)
    N = gs.n_planets
    assert list(regimes) == [f"sun_planet_{i}" for i in range(1, N + 1)] + [
        f"planet_ring_{i}" for i in range(1, N + 1)
    ]
    # far below resonance the meshes stay in contact
    assert set(regimes.values()) == {"none"}
    ds = r.to_dataset()
    b_sp = ds.attrs["clearance_sun_planet"]
    assert all(ds.delta_sp_min.values > b_sp)


def test_systems_without_meshes_raise() -> None:
    r = gc.simulate(gc.duffing(1.0), transient_periods=1, periods=2)
    with pytest.raises(ParameterError, match="mesh"):
        contact_regimes(r)
