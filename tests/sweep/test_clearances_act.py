"""When the seed's clearances act, and when they do not (issue 34).

The seed sweeps the backlashes b̄_sp and b̄_rp (Figs. 6–11) because they shape the motion:
"tooth separation, single-sided and double-sided impact occur in the most area of chaotic and
multiple periodic motion state". In ``sheng2016-v1`` (today's default values) no mesh reaches
its back flank, so a backlash only shifts the coordinates and its sweeps are constants — the
report's "holds (constant)". In the variant issue 34 tried (A = 20 µm, b_c = 5 µm) and in the
recalibrated default ``sheng2016`` (paper/confirmation.json's winner):

* along b̄_sp ∈ [1, 10] at ξ = 0.11, Ω = 1 and 1.5 (Fig. 8's recipe), the continued period-1
  branch changes its largest Floquet multiplier by more than 10⁻³, or has an event;
* a sweep of Fig. 8's recipe holds double-sided contact somewhere, and the stored contact
  regime agrees with the mesh deflection recomputed from the state history by MODEL.md §3/§6
  (δ_spi = p_i + s_i − e_spi below −b̄_sp is the back flank), not with the code's own δ.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.dynamics.continuation.arclength import continuation

FIG8 = {"xi": 0.11, "backlash.planet_ring": 3.5, "clearance.sun_bearing": 2.0}
AXIS = "backlash.sun_planet"


def _variant() -> gc.GearSet:
    """sheng2016-v1 with issue 34's A = 20 µm and b_c = 5 µm (b̄ unchanged)."""
    return gc.preset("sheng2016-v1").evolve(
        {
            "transmission_error.sun_planet": 20e-6,
            "transmission_error.planet_ring": 20e-6,
            "clearance.characteristic_length": 5e-6,
        }
    )


def _branch_change(gs: gc.GearSet, omega: float) -> tuple[float, int]:
    br = continuation(
        gs, (AXIS, 1.0, 10.0), params={**FIG8, "omega": omega}, period=1,
        max_step=0.45, step=0.225, max_points=60,
    )  # fmt: skip
    mu = np.asarray(br["max_multiplier"].values, dtype=float)
    mu = mu[np.isfinite(mu)]
    lam = np.asarray(br[AXIS].values, dtype=float)
    events = int(br.sizes["event"]) if "event" in br.dims else 0
    assert mu.size >= 3, "the branch has too few points to judge"
    # the branch covers the axis (or stops at an event: a fold or a doubling ends a period-1 run)
    assert events or (lam.min() <= 1.0 + 1e-9 and lam.max() >= 10.0 - 1e-9), (lam.min(), lam.max())
    return float(mu.max() - mu.min()), events


def _gearset(which: str) -> gc.GearSet:
    return _variant() if which == "variant" else gc.preset("sheng2016")


@pytest.mark.parametrize("which", ["variant", "default"])
@pytest.mark.parametrize("omega", [1.0, 1.5])
def test_backlash_changes_the_period_one_branch(which: str, omega: float) -> None:
    change, events = _branch_change(_gearset(which), omega)
    assert change > 1e-3 or events > 0, (change, events)


def test_in_sheng2016_v1_the_branch_is_constant_along_the_backlash() -> None:
    """What the issue found: in sheng2016-v1 the same branch keeps max|μ| to 1e-6 and has no
    event (a backlash that no flank reaches only shifts the coordinates)."""
    change, events = _branch_change(gc.preset("sheng2016-v1"), 1.0)
    assert change < 1e-6 and events == 0, (change, events)


def _delta_sp(gs: gc.GearSet, omega: float, b_sp: float) -> tuple[np.ndarray, dict]:
    """δ_spi(τ) over a recorded window, from the state history by MODEL.md §3/§6."""
    res = gc.simulate(
        gs, omega=omega, **{**FIG8, AXIS: b_sp}, transient_periods=100, periods=100,
        samples_per_period=128,
    )  # fmt: skip
    ds = res.to_dataset()
    tau = ds["tau_sample"].values
    x, y = ds["x_s_history"].values, ds["y_s_history"].values
    p = ds["p_history"].values
    n = gs.n_planets
    alpha = math.radians(gs.geometry.pressure_angle_sun)
    psi = 2.0 * math.pi * np.arange(n) / n
    s = -x[:, None] * np.sin(psi - alpha) + y[:, None] * np.cos(psi - alpha)
    assert gs.mesh_phasing.model == "in_phase" and gs.eccentricity.sun == 0.0
    assert gs.eccentricity.planet == 0.0 and gs.eccentricity.ring == 0.0
    amp = gs.transmission_error.sun_planet / gs.clearance.characteristic_length
    e = amp * np.sin(omega * tau)[:, None]
    return p + s - e, dict(ds.attrs)


@pytest.mark.parametrize("which", ["variant", "default"])
def test_fig8_sweep_has_double_sided_contact_where_the_flank_is_reached(which: str) -> None:
    gs = _gearset(which)
    b = np.linspace(1.0, 10.0, 10)
    ds = gc.bifurcation(
        gs, {AXIS: b}, family={"omega": [1.0, 1.5, 2.0, 2.5]}, params=FIG8, progress=False
    )
    code = ds["contact_sp"].max("planet_all").values  # 0 none, 1 single-, 2 double-sided
    double = np.argwhere(code == 2)
    assert double.size, f"no double-sided contact on Fig. 8's sweep: {code}"
    single = np.argwhere(code == 1)
    omegas = ds["omega"].values
    # the stored regime agrees with the deflection the states give, at one point of each kind
    i, j = double[0]
    d, _ = _delta_sp(gs, float(omegas[i]), float(b[j]))
    assert d.min() < -b[j], (omegas[i], b[j], d.min())
    if single.size:
        i, j = single[-1]
        d, _ = _delta_sp(gs, float(omegas[i]), float(b[j]))
        # sampled points lie on the trajectory: their minimum is at or above the true minimum
        assert d.min() >= -b[j], (omegas[i], b[j], d.min())
