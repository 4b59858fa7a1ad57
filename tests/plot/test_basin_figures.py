"""Titles, legends and axes of the basin figures name parameters and states by their symbols:
Ω, δ, α, β, γ of the Duffing oscillator and its state x, never the names ``omega``,
``delta`` … (docs/howto/basins.png, basin-fractions.png)."""

from __future__ import annotations

import re

import pytest

import gearchaos as gc
from gearchaos.plot.basins import basins_figure

SHORT = {"transient_periods": 40, "periods": 8, "progress": False}
#: A parameter or state written by its name where a symbol belongs.
RAW = re.compile(r"(?<![\\\w])(omega|delta|alpha|beta|gamma|x_dot)\b|(?<![$\w])x\b(?!\$)")


@pytest.fixture(scope="module")
def twin_well():
    return gc.duffing(1.0, delta=0.3, alpha=-1.0, beta=1.0, gamma=0.1)


def texts(fig):
    ax = fig.axes[0]
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    return ax.get_title(), legend, ax.get_xlabel(), ax.get_ylabel()


def test_basin_image_names_parameters_and_states_by_symbols(twin_well) -> None:
    ds = gc.basins(twin_well, "x=-1.5:1.5:6", "x_dot=-1.5:1.5:6", **SHORT)
    title, legend, xlabel, ylabel = texts(basins_figure(ds))
    first, second = title.splitlines()
    assert first.startswith(r"duffing: basins of attraction at $\Omega$ = 1 (36 starts")
    assert second == r"$\delta$ = 0.3, $\alpha$ = −1, $\beta$ = 1, $\gamma$ = 0.1"
    assert (xlabel, ylabel) == ("$x$", "$x'$")
    assert legend and all(t.startswith("1T ($x$ ≈ ") for t in legend)
    for text in (title, *legend):
        assert not RAW.search(text), text


def test_basin_fractions_name_parameters_and_states_by_symbols(twin_well) -> None:
    box = {"x": (-1.5, 1.5), "x_dot": (-1.5, 1.5)}
    ds = gc.basin_fractions(twin_well, "omega=0.9,1.1", starts=20, box=box, **SHORT)
    title, legend, xlabel, _ = texts(basins_figure(ds))
    assert title.splitlines() == [
        "duffing: basin fractions",
        r"$\delta$ = 0.3, $\alpha$ = −1, $\beta$ = 1, $\gamma$ = 0.1",  # a true minus
    ]
    assert xlabel == r"$\Omega = \omega/\omega_n$"
    attractors = [t for t in legend if t != "failed"]
    assert attractors and all(
        re.fullmatch(r"1T \(\$x\$ ≈ −?[0-9.]+ at \$\\Omega\$ = 0\.9\)", t) for t in attractors
    ), attractors
    for text in (title, *legend):
        assert not RAW.search(text), text
