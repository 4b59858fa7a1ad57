"""Branch switching down a period-doubling cascade (``continuation(..., cascade=k)``).

The single-mesh backlash oscillator (ζ = 0.05, b = 1, F_m = F_a = 0.1, F_a Ω² forcing) doubles
1T → 2T → 4T → 8T as Ω falls from 2.1 to 1.8. Checked against what the theory of a period
doubling says, not against the code's own numbers:

* the period-2n branch starts at the PD's parameter value, on the period-n orbit there: its
  two section points per period-n point coincide, and a simulation from the parent's state
  at the PD comes back to it after n periods (an independent integration);
* its multipliers at the start are those of the period-n orbit squared: +1 (the PD's −1
  squared) and exp(−2ζ · 2nT) (Liouville: det M = exp(−∫ trace) for the damping 2ζ x');
* its own PD lies beyond the first (further along the direction the cascade runs), and the
  intervals between successive PDs shrink (the Feigenbaum-like ordering);
* the whole cascade is one netCDF file: ``open_branch`` reads the period-1 branch as before,
  ``open_cascade`` every branch with its parent.
"""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.dynamics.continuation.cascade import open_cascade
from gearchaos.dynamics.continuation.events import events
from gearchaos.errors import ParameterError

TIGHT = {"rtol": 1e-10, "atol": 1e-12}
ZETA = 0.05


def backlash() -> gc.System:
    return gc.backlash_oscillator(1.0, zeta=ZETA, f_alt=0.1, f_mean=0.1)


@pytest.fixture(scope="module")
def cascade(tmp_path_factory: pytest.TempPathFactory) -> tuple[list, str]:
    path = str(tmp_path_factory.mktemp("cascade") / "cascade.nc")
    return gc.continuation(backlash(), "omega=2.1:1.8", cascade=3, store=path, **TIGHT), path


def test_each_doubling_starts_the_period_2n_branch_on_the_period_n_orbit(cascade) -> None:
    branches, _ = cascade
    assert [int(b.attrs["period"]) for b in branches] == [1, 2, 4, 8]
    system = backlash()
    for parent, child in itertools.pairwise(branches):
        assert child.attrs["parent"] == parent.attrs["branch"]
        pd = events(parent)[int(child.attrs["parent_event"])]
        assert pd.kind == "period_doubling"
        n = int(parent.attrs["period"])
        # starts at the PD's value
        assert float(child.omega[0]) == pytest.approx(pd.value, abs=1e-12)
        # an independent simulation: the parent's state at the PD is a period-n orbit there
        res = gc.simulate(system.at(pd.value), y0=pd.state, transient_periods=0, periods=n, **TIGHT)
        assert np.max(np.abs(res.final_state - pd.state)) < 1e-6
        # the doubled orbit's points coincide pairwise at the start (x_k = x_{k+n}) and are
        # the simulated period-n orbit's section points
        x0 = child.x.values[0]
        assert np.max(np.abs(x0[:n] - x0[n:])) < 1e-6
        assert np.max(np.abs(x0[:n] - res.section("x"))) < 1e-6
        # multipliers: the PD's −1 squared, and the period-n orbit's other one squared
        mu = child.multiplier_re.values[0] + 1j * child.multiplier_im.values[0]
        near_one = mu[np.argmin(np.abs(mu - 1.0))]
        assert abs(near_one - 1.0) < 1e-3
        other = mu[np.argmax(np.abs(mu - 1.0))]
        period = 2 * n * 2 * math.pi / pd.value
        assert other.real == pytest.approx(math.exp(-2 * ZETA * period), rel=1e-3)
        # away from the start the orbit has 2n distinct points
        assert np.all(np.ptp(child.x.values[1:], axis=1) > 1e-6)


def test_the_doublings_accumulate_in_the_direction_of_the_cascade(cascade) -> None:
    branches, _ = cascade
    values = []
    for b in branches:
        pds = [e for e in events(b) if e.kind == "period_doubling"]
        assert len(pds) == 1, [(e.kind, e.value) for e in events(b)]
        values.append(pds[0].value)
        assert abs(pds[0].multiplier + 1.0) < 1e-3
    # each doubling lies beyond the one before (Ω falls), at shrinking distances
    assert all(a > b for a, b in itertools.pairwise(values))
    gaps = np.diff(values)
    assert np.all(np.abs(gaps[1:]) < np.abs(gaps[:-1]))
    assert abs(gaps[0] / gaps[1]) > 2.0  # Feigenbaum's 4.67 for smooth maps; > 1 here


def test_the_cascade_is_one_file_and_open_branch_still_reads_its_first_branch(cascade) -> None:
    branches, path = cascade
    again = open_cascade(path)
    assert [b.attrs["branch"] for b in again] == [b.attrs["branch"] for b in branches]
    assert [b.attrs["parent"] for b in again] == ["", "branch_0", "branch_1", "branch_2"]
    for a, b in zip(again, branches, strict=True):
        np.testing.assert_array_equal(a.event_value.values, b.event_value.values)
        np.testing.assert_array_equal(a.orbit_state.values, b.orbit_state.values)
    root = gc.open_branch(path)
    assert int(root.attrs["period"]) == 1
    assert json.loads(root.attrs["cascade"]) == ["branch_1", "branch_2", "branch_3"]
    assert json.loads(root.attrs["cascade_skipped"]) == []


def test_depth_and_branch_limits(tmp_path) -> None:
    one = gc.continuation(backlash(), "omega=2.1:1.9", cascade=0, **TIGHT)
    assert len(one) == 1 and json.loads(one[0].attrs["cascade"]) == []
    capped = gc.continuation(backlash(), "omega=2.1:1.8", cascade=3, max_branches=2, **TIGHT)
    assert [int(b.attrs["period"]) for b in capped] == [1, 2]
    skipped = json.loads(capped[0].attrs["cascade_skipped"])
    assert [s["reason"] for s in skipped] == ["max_branches (2) reached"]
    with pytest.raises(ParameterError, match="store of a cascade must be a netCDF file"):
        gc.continuation(backlash(), "omega=2.1:1.9", cascade=1, store=tmp_path / "c.zarr")
    with pytest.raises(ParameterError, match="max_branches need cascade=DEPTH"):
        gc.continuation(backlash(), "omega=2.1:1.9", max_branches=2)
    with pytest.raises(ParameterError, match="cascade"):
        gc.continuation(backlash(), "omega=2.1:1.9", cascade=-1)
