"""Small sweep stores for the explorer's tests (seconds to compute once the kernels are cached)."""

from __future__ import annotations

from pathlib import Path

import pytest

import gearchaos as gc

#: Eight Ω points of the default gear set with a short protocol (16 section points each).
GEAR_SWEEP = "omega=1.2:2.0:8"
GEAR_PROTOCOL = {"transient_periods": 20, "periods": 16}

#: A linear oscillator (Duffing with β = 0): x'' + δx' + αx = γ cos Ωτ, swept over Ω × γ.
LINEAR = {"delta": 0.2, "alpha": 1.0, "beta": 0.0}
LINEAR_SWEEP = ["omega=0.6:1.6:5", "gamma=0.1:0.3:3"]
LINEAR_PROTOCOL = {"transient_periods": 80, "periods": 8}


@pytest.fixture(scope="session")
def gear_store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("explore") / "gear.zarr"
    gc.bifurcation(
        gc.preset("sheng2016-v1"), GEAR_SWEEP, store=path, progress=False, **GEAR_PROTOCOL
    )
    return path


@pytest.fixture(scope="session")
def linear_map_store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("explore") / "linear.zarr"
    gc.bifurcation(
        gc.duffing(1.0, gamma=0.1, **LINEAR),
        LINEAR_SWEEP,
        observe=("x", "x_dot"),
        store=path,
        progress=False,
        **LINEAR_PROTOCOL,
    )
    return path


@pytest.fixture(scope="session")
def linear_parameters() -> dict[str, float]:
    """The linear oscillator's parameters (Duffing with β = 0) of :func:`linear_map_store`."""
    return dict(LINEAR)
