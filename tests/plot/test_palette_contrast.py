"""Colours that must not be mistaken for each other (issue 35, item 6).

Differences are CIEDE2000 ΔE₀₀ under normal colour vision and simulated protan-, deutan- and
tritanopia (``colour_checks``, checked here on Sharma et al.'s reference pairs). About 2 is a
just noticeable difference of large patches; small dots and thin bands need far more.

* 5T was brown (#8c564b): as close as 15.8 to the unresolved grey (deuteranopia) and 9.6 to
  chaos red (protanopia), so that a 5T cell read as unresolved or chaotic.
* The up and down branches of a continuation diagram were C0 and C3 — the palette's own 1T
  blue and chaos red (ΔE₀₀ = 0), so that a periodic down branch looked chaotic.
"""

from __future__ import annotations

import matplotlib.colors as mcolors
import numpy as np
import pytest
from colour_checks import VISIONS, ciede2000, difference, least_difference

import gearchaos as gc
from gearchaos.plot import bifurcation_figure
from gearchaos.plot.regimes import REGIME_COLOURS

#: Sharma, Wu & Dalal (2005), Table 1: pairs 1, 7, 17, 25 (L*, a*, b*) and their ΔE₀₀.
SHARMA = [
    ((50.0, 2.6772, -79.7751), (50.0, 0.0, -82.7485), 2.0425),
    ((50.0, 0.0, 0.0), (50.0, -1.0, 2.0), 2.3669),
    ((50.0, 2.5, 0.0), (73.0, 25.0, -18.0), 27.1492),
    ((60.2574, -34.0099, 36.2677), (60.4626, -34.1751, 39.4387), 1.2644),
]


@pytest.mark.parametrize(("lab1", "lab2", "want"), SHARMA)
def test_ciede2000_reproduces_the_reference_pairs(lab1, lab2, want) -> None:
    assert ciede2000(np.array(lab1), np.array(lab2)) == pytest.approx(want, abs=1e-4)


def test_simulated_dichromats_see_greys_as_greys() -> None:
    """Each simulation keeps the achromatic axis (its matrix rows sum to 1)."""
    for grey in ("#000000", "#7f7f7f", "#ffffff"):
        for vision in VISIONS:
            assert difference(grey, grey, vision) == 0.0
            assert difference(grey, "#7f7f7f", vision) == pytest.approx(
                difference(grey, "#7f7f7f"), abs=0.05
            )


def test_5t_stands_apart_from_unresolved_and_every_other_regime() -> None:
    five = REGIME_COLOURS["5T"]
    grey, vision = least_difference(five, REGIME_COLOURS["unresolved"])
    assert grey >= 25.0, f"5T vs unresolved: ΔE₀₀ {grey:.1f} ({vision})"
    for name, colour in REGIME_COLOURS.items():
        if name != "5T":
            d, vision = least_difference(five, colour)
            assert d >= 18.0, f"5T vs {name}: ΔE₀₀ {d:.1f} ({vision})"


@pytest.fixture(scope="module")
def both_directions():
    system = gc.backlash_oscillator(1.0, zeta=0.05, f_alt=0.1, f_mean=0.1)
    return gc.bifurcation(
        system, "omega=1.8:2.1:6", initial_conditions="continuation", direction="both",
        transient_periods=30, periods=8, progress=False,
    )  # fmt: skip


def test_up_and_down_branches_are_drawn_in_colours_outside_the_regime_palette(
    both_directions,
) -> None:
    fig = bifurcation_figure(both_directions, var="x")
    ax = fig.axes[0]
    drawn = {}
    for coll in ax.collections:
        label = str(coll.get_label())
        for direction in ("up", "down"):
            if label.startswith(f"{direction} ("):
                drawn[direction] = mcolors.to_hex(coll.get_facecolor()[0])
    assert set(drawn) == {"up", "down"}
    for direction, colour in drawn.items():
        for name, regime in REGIME_COLOURS.items():
            d, vision = least_difference(colour, regime)
            assert d >= 10.0, f"{direction} branch vs {name}: ΔE₀₀ {d:.1f} ({vision})"
    d, vision = least_difference(drawn["up"], drawn["down"])
    assert d >= 15.0, f"up vs down: ΔE₀₀ {d:.1f} ({vision})"
