"""The peak contact force a branch stores at every point (issue 26, item 5):
``force_peak_<mesh>`` = max |F̄ᶜ| over the orbit, from the extrema tracked while shooting.

* Backlash oscillator (MODEL.md §10.5): the orbit at a stable and an unstable branch point is
  simulated again from its stored state over one period, densely sampled, and its contact
  force recomputed from the state alone — Fᶜ = f(x; b) + 2ζx' where it presses the flanks
  together (Fᶜ x > 0), else 0 —; its largest |Fᶜ| is the stored peak to the sampling
  resolution, and the sweep's own path (``response_quantities`` of that run) gives the stored
  value to the integration tolerance.
* Planetary gear set (sheng2016, N = 5): per mesh and per planet, the stored peak equals the
  sweep's ``force_peak_sp``/``force_peak_rp`` of the orbit simulated again over its period.
"""

from __future__ import annotations

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.model.response import response_quantities
from gearchaos.model.target import resolve

TIGHT = {"rtol": 1e-10, "atol": 1e-12}
ZETA, B = 0.05, 1.0


def _again(system: gc.System, y0: np.ndarray, periods: int, samples: int):
    return gc.simulate(
        system, y0=y0, transient_periods=0, periods=periods, samples_per_period=samples, **TIGHT
    )


def test_oscillator_branch_peak_force_is_the_orbits_contact_force_of_model_md() -> None:
    system = gc.backlash_oscillator(1.0, zeta=ZETA, b=B, f_alt=0.1, f_mean=0.1)
    branch = gc.continuation(system, "omega=0.75:1.25", **TIGHT)
    stored = branch["force_peak_mesh"]
    assert stored.dims == ("point",)
    assert stored.attrs["mesh"] == "mesh" and stored.attrs["deflection"] == "x"
    stable = np.flatnonzero(branch.stable.values == 1)
    unstable = np.flatnonzero(branch.stable.values == 0)
    assert stable.size and unstable.size  # past the period doubling the 1T orbit is unstable
    for k in (stable[0], stable[stable.size // 2], unstable[unstable.size // 2]):
        lam = float(branch.omega[k])
        run = _again(system.at(lam), branch.orbit_state.values[k], 1, 4096)
        x, v = run.series("x"), run.series("x_dot")
        mesh = np.where(x > B, x - B, np.where(x < -B, x + B, 0.0)) + 2 * ZETA * v
        contact = np.where((np.abs(x) > B) & (mesh * x > 0), mesh, 0.0)
        assert contact.max() > 0.1  # the teeth carry load on this orbit
        peak = float(stored[k])
        # sampled: below the tracked peak, and within the sampling resolution of it
        assert np.abs(contact).max() <= peak * (1 + 1e-8)
        assert peak == pytest.approx(np.abs(contact).max(), rel=1e-5)
        swept = response_quantities(run.system, run.obs_min, run.obs_max, run.observables)
        assert peak == pytest.approx(float(swept["force_peak_mesh"]), rel=1e-7)


def test_planetary_branch_stores_each_planets_peak_force_of_both_meshes() -> None:
    gs, fixed = gc.preset("sheng2016-v1"), {"xi": 0.05}
    branch = gc.continuation(gs, "omega=1.35:1.45", params=fixed, **TIGHT)
    for mesh in ("sp", "rp"):
        assert branch[f"force_peak_{mesh}"].dims == ("point", "planet_all")
        assert branch[f"force_peak_{mesh}"].attrs["deflection"] == f"delta_{mesh}"
    n = int(branch.attrs["period"])
    for k in (0, branch.sizes["point"] - 1):
        lam = float(branch.omega[k])
        system = resolve(gs, {"omega": lam, **fixed})
        run = _again(system, branch.orbit_state.values[k], n, 64)
        swept = response_quantities(run.system, run.obs_min, run.obs_max, run.observables)
        for mesh in ("sp", "rp"):
            want = np.asarray(swept[f"force_peak_{mesh}"])
            assert want.shape == (5,) and np.all(want > 0)
            np.testing.assert_allclose(branch[f"force_peak_{mesh}"].values[k], want, rtol=1e-6)
