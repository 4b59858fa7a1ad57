from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import pytest

import gearchaos as gc


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="session")
def planetary() -> gc.SimulationResult:
    """1T response of the hindawi2021 (MODEL.md §9) set below its first resonance, 32 samples
    per period."""
    return gc.simulate(
        gc.preset("hindawi2021"), omega=0.5, transient_periods=20, periods=20, samples_per_period=32
    )


@pytest.fixture(scope="session")
def oscillator() -> gc.SimulationResult:
    """Backlash oscillator with back-flank contact, 32 samples per period."""
    system = gc.backlash_oscillator(0.8, zeta=0.1, b=1.0, f_mean=0.1, f_alt=1.0, omega_power=0)
    return gc.simulate(system, transient_periods=20, periods=20, samples_per_period=32)
