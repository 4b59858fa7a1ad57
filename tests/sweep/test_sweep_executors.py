"""Every executor gives the same bytes, and every point equals a single `simulate` run.

The sweep runs each grid point with the integrator kernel that `simulate` uses, on the same
numbers, so results must not depend on where the points ran: in this process on all numba
threads or on one, in a pool of local processes, or on a Dask LocalCluster.
"""

from __future__ import annotations

import functools

import numba
import numpy as np
import pytest
from sweep_helpers import SHORT, assert_bitwise_equal, open_store

import gearchaos as gc

#: sweeps record one sample per period: compare with simulations that do too
_simulate = functools.partial(gc.simulate, samples_per_period=1)

VARY = {"omega": "0.5:3:12"}
FAMILY = {"xi": [0.03, 0.07]}


def sweep(gs: gc.GearSet, path, **executor) -> None:
    gc.bifurcation(gs, VARY, family=FAMILY, **SHORT, store=path, progress=False, **executor)


@pytest.fixture(scope="module")
def reference(sheng, tmp_path_factory):
    """The default executor: in this process, numba-parallel over all threads."""
    path = tmp_path_factory.mktemp("sweep") / "serial.zarr"
    sweep(sheng, path)
    return open_store(path)


def test_reference_sweep_is_complete_and_ok(reference):
    assert reference.attrs["complete"] is True
    assert reference.delta_sp.dims == ("xi", "omega", "section", "planet")
    assert reference.delta_sp.shape == (2, 12, SHORT["periods"], 1)
    assert np.all(reference.status.values == 0)
    assert np.all(np.isfinite(reference.delta_sp.values))


def test_one_numba_thread_gives_the_same_store(sheng, reference, tmp_path):
    old = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        sweep(sheng, tmp_path / "one_thread.zarr")
    finally:
        numba.set_num_threads(old)
    assert_bitwise_equal(open_store(tmp_path / "one_thread.zarr"), reference)


def test_local_processes_give_the_same_store(sheng, reference, tmp_path):
    sweep(sheng, tmp_path / "workers.zarr", workers=2)
    assert_bitwise_equal(open_store(tmp_path / "workers.zarr"), reference)


def test_dask_local_cluster_gives_the_same_store(sheng, reference, tmp_path):
    pytest.importorskip("dask.distributed")
    sweep(sheng, tmp_path / "dask.zarr", dask_local=2)
    assert_bitwise_equal(open_store(tmp_path / "dask.zarr"), reference)


def test_in_memory_result_equals_the_store(sheng, reference):
    ds = gc.bifurcation(sheng, VARY, family=FAMILY, **SHORT, progress=False).load()
    assert_bitwise_equal(ds, reference)


@pytest.fixture(scope="module")
def plain(sheng):
    """The same sweep without verdicts: every point's record is its protocol run's."""
    return gc.bifurcation(sheng, VARY, family=FAMILY, **SHORT, progress=False, verdicts=False)


def test_verdicts_keep_the_protocol_record_where_they_do_not_replace_it(reference, plain):
    # the verdict changes a point's record only where it says so (record != protocol)
    kept = reference.record.values == 0
    assert kept.any() and (~kept).any()
    for name in ("delta_sp", "delta_sp_dot", "final_state"):
        a, b = reference[name].values, plain[name].values
        np.testing.assert_array_equal(a[kept], b[kept])
    assert not np.array_equal(reference.delta_sp.values[~kept], plain.delta_sp.values[~kept])


@pytest.mark.parametrize(("i_xi", "i_omega"), [(0, 0), (0, 7), (1, 4), (1, 11)])
def test_points_equal_single_simulations(sheng, plain, i_xi, i_omega):
    pt = plain.isel(xi=i_xi, omega=i_omega)
    xi, omega = float(pt.xi), float(pt.omega)
    assert (xi, omega) == (FAMILY["xi"][i_xi], np.linspace(0.5, 3, 12)[i_omega])
    res = _simulate(sheng.evolve(xi=xi), omega=omega, **SHORT, rtol=1e-8, atol=1e-10)
    single = res.to_dataset()
    for name in ("delta_sp", "delta_sp_dot"):
        np.testing.assert_array_equal(
            pt[name].sel(planet=1).values, single[name].sel(planet=1).values
        )
    for name in ("delta_sp_min", "delta_sp_max", "delta_rp_min", "delta_rp_max"):
        np.testing.assert_array_equal(pt[name].values, single[name].values)
    np.testing.assert_array_equal(pt.final_state.values, res.final_state)
    assert int(pt.status) == int(res.status) == 0
    assert int(pt.steps_accepted) == res.steps_accepted
    assert int(pt.steps_rejected) == res.steps_rejected


@pytest.mark.slow
def test_continuation_is_executor_independent(tmp_path):
    """Chains of continuation run whole on one worker: same bytes as in-process."""
    system = gc.backlash_oscillator(1.0, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.02, omega_power=0)
    kw = dict(
        family={"f_alt": [0.02, 0.03]},
        initial_conditions="continuation",
        direction="both",
        observe=("x", "x_dot"),
        transient_periods=30,
        periods=8,
        progress=False,
    )
    here = gc.bifurcation(system, {"omega": "0.6:1.2:13"}, store=tmp_path / "a.zarr", **kw)
    pool = gc.bifurcation(
        system, {"omega": "0.6:1.2:13"}, store=tmp_path / "b.zarr", workers=2, **kw
    )
    assert_bitwise_equal(pool.load(), here.load())


def test_existing_dask_scheduler_gives_the_same_store() -> None:
    """``scheduler="tcp://…"`` (an existing dask.distributed cluster) equals in-process."""
    distributed = pytest.importorskip("dask.distributed")
    gs = gc.preset("hindawi2021")
    kw = {"transient_periods": 5, "periods": 8, "progress": False}
    local = gc.bifurcation(gs, "omega=0.5:3:6", **kw).load()
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, dashboard_address=None
    ) as cluster:
        remote = gc.bifurcation(gs, "omega=0.5:3:6", scheduler=cluster.scheduler_address, **kw)
        remote = remote.load()
    for name in local.data_vars:
        a, b = local[name].values, remote[name].values
        assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), name
