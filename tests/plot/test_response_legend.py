"""The response figure names its hysteresis shading in the legend (issue 35, item 6).

The backlash oscillator swept up and down over Ω = 0.7–1.1 has two coexisting periodic (2T)
branches between Ω ≈ 0.78 and 1.0; the figure shades between them (``gid="hysteresis"``).
The shading had no legend entry: a reader could not tell what the grey band meant.
"""

from __future__ import annotations

import numpy as np
from matplotlib.colors import to_rgba

import gearchaos as gc
from gearchaos.plot import response_figure
from gearchaos.plot.response import HYSTERESIS_LABEL


def _shading(fig) -> list:
    return [c for ax in fig.axes for c in ax.collections if c.get_gid() == "hysteresis"]


def test_the_legend_names_the_hysteresis_shading_when_there_is_one() -> None:
    system = gc.backlash_oscillator(1.0, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.2)
    grid = np.round(np.linspace(0.7, 1.1, 9), 12)
    both = gc.response(system, {"omega": grid}, transient_periods=40, periods=6, progress=False)
    fig = response_figure(both)
    shades = _shading(fig)
    assert shades  # the case: two coexisting periodic branches
    legend = fig.axes[0].get_legend()
    texts = [t.get_text() for t in legend.get_texts()]
    assert HYSTERESIS_LABEL in texts and "hysteresis" in HYSTERESIS_LABEL
    patch = legend.legend_handles[texts.index(HYSTERESIS_LABEL)]
    want = to_rgba(shades[0].get_facecolor()[0])
    assert np.allclose(to_rgba(patch.get_facecolor()), want, atol=0.02)  # the shading's look
    # one branch only: nothing shaded, nothing named
    up = both.sel(direction=["up"])
    fig = response_figure(up)
    assert not _shading(fig)
    assert HYSTERESIS_LABEL not in [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
