"""The mesh-force time history of ``simulate`` figures (issue 12): contact forces, zero while
the teeth are apart, separations shaded exactly there, force axis in N."""

from __future__ import annotations

import matplotlib
import numpy as np

import gearchaos as gc
from gearchaos.plot import summary_figure
from gearchaos.plot.timeseries import mesh_force_history

matplotlib.use("Agg")


def test_separations_are_shaded_where_the_contact_force_vanishes() -> None:
    osc = gc.backlash_oscillator(1.0, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.2)
    res = gc.simulate(osc, transient_periods=40, periods=4, samples_per_period=256)
    ax = mesh_force_history(res)
    spans = [p for p in ax.patches if p.get_gid() == "separation"]
    assert spans
    t = res.tau * res.system.omega / (2 * np.pi)
    x = res.series("x")
    apart = np.abs(x) <= 1.0  # the dead zone, recomputed here
    inside = np.zeros(t.size, bool)
    for p in spans:
        x0 = p.get_x() if hasattr(p, "get_x") else p.get_xy()[0][0]
        w = p.get_width() if hasattr(p, "get_width") else p.get_xy()[2][0] - x0
        inside |= (t >= x0) & (t <= x0 + w)
    assert np.all(inside[apart])  # every separated sample is shaded
    # and the shading does not reach deep into contact: at most one sample on each side
    assert inside.sum() <= apart.sum() + 2 * len(spans)


def test_summary_figure_has_the_force_panel_with_newtons() -> None:
    res = gc.simulate(gc.preset("sheng2016-v1"), omega=1.5, transient_periods=20, periods=6)
    fig = summary_figure(res)
    force = [a for a in fig.axes if "contact force" in a.get_ylabel()]
    assert len(force) == 1
    ax = force[0]
    assert any("[N]" in c.get_ylabel() for c in ax.child_axes)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("sun–planet" in s for s in labels) and any("planet–ring" in s for s in labels)
