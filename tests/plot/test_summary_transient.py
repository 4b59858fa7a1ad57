"""The transient a figure, a file and an export state is the protocol's, and the periods the
verdict added are stated beside it (issue 35, item 6).

``gearchaos simulate`` printed "100 transient + 200 recorded" while its figure said
"transient 4564.0" and the simulation file and its CSV export transient_periods = 4564: the
verdict had continued the run 4464 periods to finish a transient, and the record's settings
carried the sum. Here a backlash oscillator with a 2-period transient, which the verdict
continues, must show 2 as the transient everywhere and the added periods separately.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.dynamics.verdict.point import analyse_point
from gearchaos.integrate.settings import SolverSettings
from gearchaos.plot import summary_figure

PROTOCOL = SolverSettings(transient_periods=2, periods=20, samples_per_period=16)


@pytest.fixture(scope="module")
def point():
    system = gc.backlash_oscillator(0.8, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.2)
    return analyse_point(system, {"omega": 0.8}, PROTOCOL, verdict=True)


def test_summary_and_result_keep_the_protocols_transient(point) -> None:
    s, result = point.summary, point.result
    added = s["extra_periods"]
    assert added > 0  # the case: the verdict continued the run
    assert s["transient_periods"] == 2.0
    assert result.solver.transient_periods == 2.0 and result.extra_periods == added


def test_figure_file_and_export_say_the_protocols_transient_and_the_added_periods(
    point, tmp_path
) -> None:
    s, result = point.summary, point.result
    added = s["extra_periods"]
    fig = summary_figure(result, summary=s)
    text = "\n".join(t.get_text() for ax in fig.axes for t in ax.texts)
    assert "transient 2 + recorded 20 periods" in text
    assert f"periods added by the verdict to finish the transient: {added}" in text
    nc = tmp_path / "simulation.nc"
    result.save(nc)
    ds = gc.open_simulation(nc)
    assert ds.attrs["transient_periods"] == 2.0 and ds.attrs["extra_periods"] == added
    from gearchaos.sweep.exports import export

    export(str(nc), tmp_path / "simulation.csv")
    side = json.loads((tmp_path / "simulation.csv.json").read_text(encoding="utf-8"))
    assert side["protocol"]["transient_periods"] == 2.0
    assert side["protocol"]["extra_periods"] == added
    assert np.isfinite(ds.attrs["omega"])
