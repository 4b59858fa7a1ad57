"""Stores written with the default gear set before issue 34 (``sheng2016`` as it was then, named
``sheng2016`` in the store) still open and say which preset they used: ``sheng2016-v1`` once the
default is recalibrated (simulated here by a ``sheng2016`` of other values, ``recalibrated``).

``tests/regression/reference/old_default_sheng2016.zarr`` is a real store written by
``gearchaos bifurcation -v omega=1.0,1.5 --transient 20 --periods 8 --no-verdicts`` with the
default before the recalibration; nothing here rebuilds it with today's code."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot
import pytest

import gearchaos as gc
from gearchaos.gearset import GearSet, list_presets, preset, preset_of
from gearchaos.sweep.result import SweepResult

OLD = (
    Path(__file__).resolve().parents[1] / "regression" / "reference" / "old_default_sheng2016.zarr"
)


def _values(gs: GearSet) -> GearSet:
    return gs.evolve(name="x", description="x")


@pytest.fixture
def recalibrated(monkeypatch: pytest.MonkeyPatch) -> GearSet:
    """A default ``sheng2016`` whose values differ from the old one's (as after issue 34)."""
    from gearchaos.gearset import presets

    v1 = preset("sheng2016-v1")
    new = v1.evolve(
        {"transmission_error.sun_planet": 20e-6, "transmission_error.planet_ring": 20e-6},
        name="sheng2016",
        description="recalibrated",
    )
    real = presets._load
    monkeypatch.setattr(presets, "_load", lambda name: new if name == "sheng2016" else real(name))
    return new


def test_the_old_store_holds_the_v1_values_under_the_old_name() -> None:
    old = SweepResult.open(OLD).base_gearset
    assert old.name == "sheng2016"  # what the store itself says
    assert _values(old) == _values(preset("sheng2016-v1"))
    # today its values are a preset's (the default's while it is not recalibrated, or v1)
    assert SweepResult.open(OLD).preset in {"sheng2016", "sheng2016-v1"}


def test_old_store_opens_and_says_its_preset(recalibrated: GearSet) -> None:
    assert _values(preset("sheng2016")) != _values(preset("sheng2016-v1"))
    res = SweepResult.open(OLD)
    assert res.preset == "sheng2016-v1"
    assert res.ds.sizes["omega"] == 2  # the data is there, untouched
    gs = res.gearset
    # the stored gear set rebuilds the model it ran (its b_c, A, T_D are the old default's)
    v1 = preset("sheng2016-v1")
    assert gs.clearance.characteristic_length == v1.clearance.characteristic_length
    assert gs.transmission_error.sun_planet == v1.transmission_error.sun_planet
    assert gs.transmission_error.sun_planet != recalibrated.transmission_error.sun_planet


def test_old_store_figure_names_the_old_preset(recalibrated: GearSet) -> None:
    from gearchaos.plot import sweep_figure
    from gearchaos.plot._common import subject

    res = SweepResult.open(OLD)
    assert subject(res.ds.attrs) == "sheng2016-v1"
    fig = sweep_figure(res.ds)
    texts = [t.get_text() for t in fig.findobj(matplotlib.text.Text)]
    assert any("sheng2016-v1" in t for t in texts), texts
    assert not any("sheng2016" in t.replace("sheng2016-v1", "") for t in texts), texts
    matplotlib.pyplot.close(fig)


def test_preset_of_prefers_the_own_name_and_rejects_others() -> None:
    for name, _ in list_presets():
        assert preset_of(preset(name)) == name
    changed = preset("sheng2016").evolve({"torque.input": preset("sheng2016").torque.input * 1.01})
    assert preset_of(changed) is None
    with pytest.raises(gc.ParameterError, match="gearset must be a GearSet"):
        preset_of("sheng2016")  # type: ignore[arg-type]
