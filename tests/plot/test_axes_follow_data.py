"""Axes follow the data (issue 12): an attractor spanning X̄ ∈ [2.8, 3.25] next to a backlash
b̄ = 3 fills its axes; the clearance inside the range is drawn, the one outside is an edge note
and never widens the axes."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.plot import poincare_map
from gearchaos.plot.units import CLEARANCE_NOTE_GID

LO, HI = 2.8, 3.25


class _Synthetic:
    """A simulation result whose section points are a synthetic attractor (a Hénon map
    rescaled into X̄ ∈ [2.8, 3.25]); everything else is the real result's."""

    def __init__(self, real: gc.SimulationResult, n: int) -> None:
        self._real = real
        x, y = 0.1, 0.1
        pts = []
        for _ in range(n + 100):
            x, y = 1.0 - 1.4 * x * x + y, 0.3 * x
            pts.append((x, y))
        h = np.array(pts[100:])
        u = (h[:, 0] - h[:, 0].min()) / np.ptp(h[:, 0])
        self._x = LO + (HI - LO) * u
        self._xd = 0.5 * h[:, 1]

    def section(self, name: str) -> np.ndarray:
        out = self._xd if name.endswith("_dot") else self._x
        return out[:, None] if np.ndim(self._real.section(name)) == 2 else out

    def __getattr__(self, name: str) -> Any:
        return getattr(self._real, name)


@pytest.mark.parametrize("n", [100, 10_000])
def test_poincare_axes_lie_within_ten_percent_of_the_data(
    planetary: gc.SimulationResult, n: int
) -> None:
    assert planetary.system.model.gearset.backlash_bar()[0] == pytest.approx(3.0)
    res = _Synthetic(planetary, n)
    ax = poincare_map(res)
    lo, hi = ax.get_xlim()
    span = HI - LO
    assert lo <= LO and hi >= HI  # every point shown
    assert lo >= LO - 0.1 * span and hi <= HI + 0.1 * span  # and nothing but the data
    # +b̄ = 3 lies inside the data: drawn; −b̄ = −3 lies far outside: a note at the edge
    notes = [t.get_text() for t in ax.texts if t.get_gid() == CLEARANCE_NOTE_GID]
    assert len(notes) == 1 and "3" in notes[0] and "−" in notes[0]
    xs = [line.get_xdata()[0] for line in ax.lines if len(line.get_xdata())]
    assert any(x == pytest.approx(3.0) for x in xs)
    # the point size shrinks with the number of points (structure of a dense attractor)
    sizes = ax.collections[0].get_sizes()
    assert sizes.size and (sizes[0] < 1.0 if n == 10_000 else sizes[0] > 4.0)


def test_sun_at_rest_shows_the_clearance_not_round_off() -> None:
    """Equally spaced planets meshing in phase cancel their transverse forces on the sun
    (Parker–Lin), so from rest the sun centre stays at the origin up to round-off; the panel
    must show the bearing clearance and say the sun is at rest, not magnify 1e-13 noise."""
    from gearchaos.plot.phase import sun_orbit

    gs = gc.preset("sheng2016-v1")
    # the exact symmetric start (the default perturbs it by 1e-6, which the sun then shows)
    res = gc.simulate(
        gs, omega=1.5, transient_periods=5, periods=5, samples_per_period=16, perturbation=0.0
    )
    b = float(gs.sun_bearing_clearance_bar())
    assert float(np.max(np.abs(res.series("x_s")))) < 1e-9 * b
    ax = sun_orbit(res)
    lo, hi = ax.get_xlim()
    assert lo <= -b and hi >= b
    assert any("at rest" in t.get_text() for t in ax.texts)
    import matplotlib.pyplot as plt

    plt.close(ax.figure)
