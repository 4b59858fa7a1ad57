"""The steps do not depend on the number of samples per period (issue 32), and the samples
between the sections come from the continuous extension, as accurate as its order promises.

1. A run recording 64 (or 3) samples per period takes the same steps as the run recording only
   the sections: section states, final state, step counts and tracked extrema are bitwise
   equal. On a chaotic transient (sheng2016 at Ω = 1.2: a long chaotic transient before a
   stable 1T) any difference in the steps is amplified until the runs end on different
   attractors, which is how ``simulate`` (64 samples per period) and a sweep (one) used to
   disagree. Before the change, every sample ended a step, so the two runs took different
   steps and none of these equalities held.
2. An interpolated sample agrees with scipy's DOP853 at tolerance 1e-13 to within the bound
   that the order-4 dense output allows at the run's tolerances (derived in
   :func:`_dense_to_embedded_ratio` and :func:`test_interpolated_samples_agree_with_dop853`);
   the cubic Hermite interpolant of the same steps, one order less, does not meet it.
"""

from __future__ import annotations

import dataclasses
import math
from fractions import Fraction as Fr
from typing import Any

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import gearchaos as gc
from gearchaos.integrate import integrate
from gearchaos.integrate.methods import use_tableau
from gearchaos.integrate.tableau import DOPRI5
from gearchaos.model import System


def _backlash() -> System:
    """The reference system with a clearance: impacts at Ω = 1.2 (contact switches)."""
    return gc.backlash_oscillator(1.2, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.2)


def _assert_same_steps(dense: Any, sections: Any) -> None:
    idx = dense.section_index
    assert sections.samples_per_period == 1 and idx.size == sections.tau.size
    for name in ("steps_accepted", "steps_rejected", "steps_switch", "next_step", "tau_reached"):
        assert getattr(dense, name) == getattr(sections, name), name
    assert np.array_equal(dense.tau[idx], sections.tau)
    for name in ("final_state", "obs_min", "obs_max"):
        a, b = getattr(dense, name), getattr(sections, name)
        assert a.tobytes() == b.tobytes(), name
    assert dense.states[idx].tobytes() == sections.states.tobytes()
    assert dense.observables[idx].tobytes() == sections.observables.tobytes()


@pytest.mark.parametrize("spp", [64, 3])
def test_sheng2016_chaotic_transient_takes_the_same_steps_whatever_the_samples(spp: int) -> None:
    """The default protocol (100 + 200 periods from rest) at Ω = 1.2."""
    gs = gc.preset("sheng2016-v1")
    dense = gc.simulate(gs, omega=1.2, samples_per_period=spp)
    sections = gc.simulate(gs, omega=1.2, samples_per_period=1)
    assert dense.steps_switch > 0  # the meshes open and close: switches are landed on
    _assert_same_steps(dense, sections)


@pytest.mark.parametrize("settle", ["off", "auto"])
def test_backlash_oscillator_takes_the_same_steps_whatever_the_samples(settle: str) -> None:
    kw = dict(transient_periods=60, periods=40, settle=settle)
    dense = gc.simulate(_backlash(), samples_per_period=64, **kw)
    sections = gc.simulate(_backlash(), samples_per_period=1, **kw)
    assert dense.steps_switch > 0
    _assert_same_steps(dense, sections)


def test_sections_land_and_samples_between_follow_the_grid() -> None:
    """Sections at τ_rec + kT exactly (the sum a sections-only run makes), the others at
    τ_rec + jT/s; a run with tangent vectors still renormalises them at every sample: the
    stretches recorded there add up to its log sum."""
    system = _backlash()
    T = system.period
    res = integrate(system, transient_periods=3, periods=4, samples_per_period=5)
    t_rec = 3 * T
    j = np.arange(20)
    expect = np.where(j % 5 == 0, t_rec + (j // 5) * T, t_rec + j * (T / 5))
    assert np.array_equal(res.tau, expect)
    tangent = integrate(system, transient_periods=3, periods=4, samples_per_period=5, n_tangent=1)
    assert np.array_equal(tangent.tau, expect)
    stretch = tangent.tangent_log_stretch[1:]
    assert np.all(np.isfinite(stretch))
    assert np.sum(stretch) == pytest.approx(tangent.tangent_log_sums[0], rel=1e-12)


# ------------------------------------------------------------------ accuracy of the samples
def _dense_to_embedded_ratio() -> float:
    """max over θ of ‖τ⁽⁵⁾(θ)‖ / ‖τ̂⁽⁵⁾‖: the leading (h⁵) error coefficients of the dense
    output, Σ_i b_i(θ) Φ_i(t) − θ⁵/γ(t) over the nine trees t of order 5, against those of
    the embedded error estimate Σ_i (b_i − b̂_i) Φ_i(t), in exact arithmetic from the tableau.
    The controller holds the estimate below the tolerance on every accepted step, so the
    interpolation error inside a step is at most about this ratio times the tolerance."""
    D = DOPRI5.dense_matrix()
    s = DOPRI5.stages
    trees = [(v, g) for v, g, r in DOPRI5._trees().values() if r == 5]
    e = DOPRI5.error_weights
    emb = math.sqrt(sum(float(sum(e[i] * v[i] for i in range(s))) ** 2 for v, _ in trees))
    worst = 0.0
    for k in range(1, 100):
        th = Fr(k, 100)
        b = [sum(D[i][m] * th ** (m + 1) for m in range(len(D[i]))) for i in range(s)]
        tau = [float(sum(b[i] * v[i] for i in range(s)) - th**5 * g) for v, g in trees]
        worst = max(worst, math.sqrt(sum(x * x for x in tau)))
    return worst / emb


def _errors(system: System, *, hermite: bool = False) -> tuple[np.ndarray, np.ndarray, Any]:
    rtol, atol, spp = 1e-8, 1e-10, 64
    y0 = np.full(system.n_state, 0.1)
    kw = dict(transient_periods=2, periods=6, samples_per_period=spp, rtol=rtol, atol=atol)
    if hermite:  # the same steps, the cubic Hermite interpolant of their ends between them
        with use_tableau(dataclasses.replace(DOPRI5, dense=None, dense_order=3)):
            run = integrate(system, y0=y0, **kw)
    else:
        run = integrate(system, y0=y0, **kw)
    ref = solve_ivp(
        system.derivative, (0.0, float(run.tau[-1])), y0, method="DOP853",
        rtol=1e-13, atol=1e-13, t_eval=run.tau,
    )  # fmt: skip
    assert ref.success
    err = np.max(np.abs(run.states - ref.y.T), axis=1)
    # the bound at every sample between two sections k and k + 1
    k = np.arange(run.tau.size) // spp
    sec = err[run.section_index]
    inner = (np.arange(run.tau.size) % spp != 0) & (k + 1 < sec.size)
    carried = np.maximum(sec[k[inner]], sec[k[inner] + 1])
    n = system.n_state
    tol = atol + rtol * np.max(np.abs(ref.y.T[inner]), axis=1)
    bound = carried + 2.0 * _dense_to_embedded_ratio() * math.sqrt(n) * tol
    return err[inner], bound, run


@pytest.mark.parametrize(
    "system", [gc.duffing(1.2, gamma=2.5), _backlash()], ids=["duffing", "backlash"]
)
def test_interpolated_samples_agree_with_dop853(system: System) -> None:
    """The error of an interpolated sample is the global error the integration carries at
    that time plus the interpolation error inside its step.

    * The global error is measured at the landed sections on either side (the larger of the
      two; on these non-expanding runs it changes little over a period).
    * The interpolation error is O(h⁵) (order 4): its leading coefficients are at most
      R = :func:`_dense_to_embedded_ratio` (≈ 1.9) times those of the embedded error
      estimate, which the controller keeps ≤ 1 in the RMS norm scaled by atol + rtol·|y|; an
      RMS bound of 1 allows √n in one component, and a factor 2 covers the higher-order terms
      and the spread of the elementary differentials: ≤ 2 R √n (atol + rtol·max|y|).
    """
    err, bound, run = _errors(system)
    assert run.ok and err.size > 300
    assert np.all(err <= bound), float(np.max(err / bound))


def test_cubic_hermite_of_the_same_steps_misses_that_bound() -> None:
    """One order less (the cubic Hermite interpolant of the steps' ends, which a pair without
    a dense output of its own gets) errs by O(h⁴): the bound is no formality."""
    system = gc.duffing(1.2, gamma=2.5)
    _, _, run = _errors(system)
    err, bound, h_run = _errors(system, hermite=True)
    assert h_run.final_state.tobytes() == run.final_state.tobytes()  # the same steps
    assert np.max(err / bound) > 2.0
