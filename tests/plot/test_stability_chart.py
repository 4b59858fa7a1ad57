"""Stability charts: boundary curves over a brute-force regime map of the same parameters.

The period-doubling curve of the backlash oscillator in (Ω, ε) is drawn where the map's colour
changes from 1T to 2T: the distance, measured on the figure (the drawn line against the drawn
cells), is at most one cell.
"""

from __future__ import annotations

import json

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.dynamics.continuation.events import events
from gearchaos.plot.regimes import REGIME_COLOURS, REGIME_GID
from gearchaos.plot.stability import boundary_label, stability_chart, stability_figure

OMEGAS = "omega=1.3:1.65:36"  # cells 0.01 wide


@pytest.fixture(scope="module")
def chart_data(tmp_path_factory):
    s = gc.backlash_oscillator(1.0, zeta=0.05, f_alt=0.1, f_mean=0.1)
    where = tmp_path_factory.mktemp("chart")
    # rows where the period doubling is where the map changes colour (at ε = 0.15 the 2T
    # attractor is already reached from rest before the 1T orbit loses stability: the chart
    # shows both, the boundary is the loss of stability)
    sweep = gc.bifurcation(
        s, [OMEGAS, "eps=0.1:0.2:2"], transient_periods=200, periods=16, progress=False,
        store=where / "map.zarr",
    )  # fmt: skip
    branch = gc.continuation(s, "omega=1.1:1.6")
    pd = next(e for e in events(branch) if e.kind == "period_doubling")
    curve = gc.boundary_curve(s, pd, "eps=0:0.3", store=where / "pd.nc")
    return sweep, curve


def test_boundary_is_drawn_where_the_map_changes_colour(chart_data) -> None:
    sweep, curve = chart_data
    ax = stability_chart(curve, sweep)
    (mesh,) = [c for c in ax.collections if c.get_gid() == REGIME_GID]
    (line,) = [ln for ln in ax.lines if ln.get_gid() == "boundary:period_doubling"]
    om = np.unique(sweep.omega.values)
    eps = np.unique(sweep.eps.values)
    rgba = mesh.to_rgba(mesh.get_array()).reshape(eps.size, om.size, 4)
    one, two = (
        matplotlib.colors.to_rgba(REGIME_COLOURS["1T"]),
        matplotlib.colors.to_rgba(REGIME_COLOURS["2T"]),
    )
    x, y = line.get_data()
    x, y = np.asarray(x), np.asarray(y)
    cell = om[1] - om[0]
    for r, e in enumerate(eps):
        # the drawn curve's Ω at this ε, on its branch inside the map
        k = np.flatnonzero((np.diff(np.sign(y - e)) != 0) & (x[:-1] < om[-1]))[0]
        t = (e - y[k]) / (y[k + 1] - y[k])
        x_curve = x[k] + t * (x[k + 1] - x[k])
        changes = [
            0.5 * (om[i] + om[i + 1])
            for i in range(om.size - 1)
            if np.allclose(rgba[r, i], one) and np.allclose(rgba[r, i + 1], two)
        ]
        assert changes, (e, "no 1T → 2T change in the row")
        dist = min(abs(c - x_curve) for c in changes)
        assert dist <= cell, (e, x_curve, changes)


def test_legend_names_each_boundary_and_physical_axes(chart_data, tmp_path) -> None:
    sweep, curve = chart_data
    fig = stability_figure([curve], sweep)
    assert fig.get_suptitle().splitlines()[0] == "backlash_oscillator: stability chart"
    ax = fig.axes[0]
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "period doubling" in texts and "1T" in texts and "2T" in texts
    from figure_checks import assert_legends_clear_of_titles

    assert_legends_clear_of_titles(fig)  # beside the axes, under the title
    fig.savefig(tmp_path / "chart.png")
    # a reference system has no physical scales: no secondary axes
    assert len(fig.axes) == 1
    alone = stability_chart(curve)
    assert alone.get_xlabel() and alone.get_ylabel()
    grazing = curve.copy()
    grazing.attrs.update(curve_kind="grazing", contact="sun_planet_1:drive")
    assert boundary_label(grazing) == "grazing: sun–planet contact loss"
    grazing.attrs.update(contact="planet_ring_2:back")
    assert boundary_label(grazing) == "grazing: planet–ring contact loss (back flank)"


def test_title_writes_the_fixed_values_as_symbols(chart_data) -> None:
    """The values the curves hold fixed are written as the other figures write them (the
    shared helper: symbol = value, a true minus), not as the file's JSON ("fixed {…}")."""
    sweep, curve = chart_data
    title = stability_figure([curve], sweep).get_suptitle().splitlines()
    # the model's parameters but the two of the chart (Ω, ε), as the diagrams' titles
    assert title == [
        "backlash_oscillator: stability chart",
        r"at $\zeta$ = 0.05, $b$ = 1, $F_m$ = 0.1, $F_a$ = 0.1",
    ]
    other = curve.copy()
    other.attrs["fixed"] = json.dumps({"f_mean": -0.05, "zeta": 0.07})
    title = stability_figure([other]).get_suptitle().splitlines()
    assert title[1] == r"at $F_m$ = −0.05, $\zeta$ = 0.07, $b$ = 1, $F_a$ = 0.1"
    assert not any(c in "\n".join(title) for c in '{}"')


def test_chart_refuses_a_map_of_other_parameters(chart_data) -> None:
    sweep, curve = chart_data
    other = curve.copy()
    other.attrs["parameter2"] = "zeta"
    with pytest.raises(gc.ParameterError, match="same two parameters"):
        stability_chart(other, sweep)
    with pytest.raises(gc.ParameterError, match="boundary curves"):
        stability_chart(sweep)
