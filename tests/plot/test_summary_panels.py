"""The summary figure of a model of one's own shows only what applies, and names its
variables (issue 35, item 6).

A model without sun coordinates or tracked mesh contact forces got two empty panels that
printed internal messages ("no sun orbit: … has no sun coordinates x_s, y_s",
"mesh_force_history needs a model that tracks mesh contact forces …"). Now such panels are
left out (the text takes the sun orbit's place, the figure loses its force row) and the text
names the model's variables by its own symbols (or their names).
"""

from __future__ import annotations

import gearchaos as gc
from gearchaos.plot import summary_figure


def _titles(fig) -> list[str]:
    return [ax.get_title() for ax in fig.axes if ax.get_title()]


def _texts(fig) -> str:
    return "\n".join(t.get_text() for ax in fig.axes for t in ax.texts)


def test_a_model_without_sun_or_forces_gets_no_empty_panels() -> None:
    result = gc.simulate(gc.duffing(1.2), transient_periods=20, periods=20, samples_per_period=16)
    assert not result.system.force_groups and "x_s" not in result.system.state_names
    fig = summary_figure(result)
    text = _texts(fig)
    for internal in ("needs", "no sun orbit", "force_groups", "tracks none"):
        assert internal not in text
    titles = _titles(fig)
    assert not any(t.startswith(("sun centre orbit", "mesh contact forces")) for t in titles)
    assert len([ax for ax in fig.axes if ax.get_visible()]) == 5  # 4 panels and the text
    assert fig.get_figheight() == 9.0  # no force row
    names = [n for n in result.system.state_names if not n.endswith("_dot")]
    line = next(ln for ln in text.splitlines() if ln.startswith("variables: "))
    assert all(n in line for n in names), (names, line)


def test_a_planetary_summary_keeps_sun_orbit_and_forces(planetary) -> None:
    fig = summary_figure(planetary)
    titles = _titles(fig)
    assert any(t.startswith("sun centre orbit") for t in titles)
    assert any(t.startswith("mesh contact forces") for t in titles)
    assert fig.get_figheight() == 13.0
    assert "variables: " not in _texts(fig)  # a gear set's variables are the paper's
