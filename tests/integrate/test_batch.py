"""The batch entry point runs exactly the single-point code on every point, in parallel."""

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.errors import ParameterError, Status
from gearchaos.integrate import integrate, integrate_batch


@pytest.fixture(scope="module")
def systems():
    gs = gc.preset("hindawi2021")
    return [gc.planetary_system(gs, om) for om in (0.5, 1.5, 2.5)]


def test_batch_points_bitwise_equal_to_single_runs(systems):
    kw = dict(transient_periods=5, periods=6, samples_per_period=2)
    batch = integrate_batch(systems, **kw)
    assert [s.ok for s in batch.statuses()] == [True] * 3
    for i, s in enumerate(systems):
        single = integrate(s, **kw)
        np.testing.assert_array_equal(batch.states[i], single.states)
        np.testing.assert_array_equal(batch.tau[i], single.tau)
        np.testing.assert_array_equal(batch.obs_min[i], single.obs_min)
        np.testing.assert_array_equal(batch.obs_max[i], single.obs_max)
        assert batch.steps_accepted[i] == single.steps_accepted
        assert batch.steps_rejected[i] == single.steps_rejected
        assert batch.steps_switch[i] == single.steps_switch


def test_batch_independent_of_thread_count():
    import numba

    gs = gc.preset("hindawi2021")
    systems = [gc.planetary_system(gs, om) for om in np.linspace(0.6, 3.0, 7)]
    kw = dict(transient_periods=3, periods=4, samples_per_period=2)
    a = integrate_batch(systems, **kw)
    old = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        b = integrate_batch(systems, **kw)
    finally:
        numba.set_num_threads(old)
    for name in ("tau", "states", "observables", "obs_min", "obs_max", "final_state"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    np.testing.assert_array_equal(a.steps_accepted, b.steps_accepted)


def test_batch_one_bad_point_does_not_stop_the_others():
    good = gc.linear_oscillator(1.0, zeta=0.1)
    explode = gc.linear_system([[50.0, 0.0], [0.0, 50.0]], 1.0)
    res = integrate_batch(
        [good, explode], y0=np.array([[1.0, 0.0], [1.0, 1.0]]), transient_periods=0, periods=200
    )
    assert res.statuses()[0] is Status.OK
    assert res.statuses()[1] is not Status.OK
    assert np.all(np.isfinite(res.states[0]))


def test_batch_rejects_mixed_layouts():
    with pytest.raises(ParameterError, match="share kind and parameter layout"):
        integrate_batch([gc.linear_oscillator(1.0), gc.duffing(1.0)])
