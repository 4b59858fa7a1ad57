"""The Kahraman–Singh (1991) example, a model written outside the package
(``examples/kahraman_singh_1991.py``), against an independent solution of the same equations.

The equations are written again here in plain numpy from the paper's model (the example's
docstring) and integrated with scipy's DOP853; gearchaos's simulation, periodic orbit and
Floquet multipliers must agree with it. The example also passes the model contract, its
analytic tangent is the Jacobian of its right-hand side, and a second process runs it from
numba's disk cache without compiling.
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import gearchaos as gc
from gearchaos.model import System
from gearchaos.model.contract import check_model
from gearchaos.model.loading import build_model, load_model_class

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "kahraman_singh_1991.py"
KahramanSingh1991 = load_model_class(f"{EXAMPLE}:KahramanSingh1991")

#: A periodic operating point with tooth separation (min δ̄ < b̄_h): a stable 1T orbit.
OMEGA = 2.5


# ------------------------------------------------------------------ the independent solution
def dead_zone(x: float, b: float) -> float:
    """f(x; b): x − b above the clearance, x + b below it, 0 inside."""
    if x > b:
        return x - b
    if x < -b:
        return x + b
    return 0.0


def reference_rhs(m: object, omega: float):  # type: ignore[no-untyped-def]
    """Kahraman & Singh's three equations, solved for the accelerations:

    q1'' + 2ζp q1' + μp κp f(q1; bp) + μp w = 0
    q2'' + 2ζg q2' + μg κg f(q2; bg) − μg w = 0
    q3'' − q1'' + q2'' + w = Fm + Fa Ω² cos Ωτ,   w = 2ζh q3' + (1 + ε cos Ωτ) f(q3; bh)
    """

    def f(t: float, y: np.ndarray) -> np.ndarray:
        c = math.cos(omega * t)
        w = 2 * m.zeta_h * y[5] + (1 + m.eps * c) * dead_zone(y[2], m.b_h)
        acc1 = -2 * m.zeta_p * y[3] - m.mu_p * m.kappa_p * dead_zone(y[0], m.b_p) - m.mu_p * w
        acc2 = -2 * m.zeta_g * y[4] - m.mu_g * m.kappa_g * dead_zone(y[1], m.b_g) + m.mu_g * w
        acc3 = acc1 - acc2 - w + m.f_mean + m.f_alt * omega**2 * c
        return np.array([y[3], y[4], y[5], acc1, acc2, acc3])

    return f


def scipy_flow(m: object, omega: float, y0: np.ndarray, periods: int) -> np.ndarray:
    """The states at τ = kT, k = 0 … periods (DOP853, rtol 1e-11)."""
    period = 2 * math.pi / omega
    times = period * np.arange(periods + 1)
    sol = solve_ivp(
        reference_rhs(m, omega),
        (0.0, times[-1]),
        np.asarray(y0, dtype=float),
        method="DOP853",
        rtol=1e-11,
        atol=1e-13,
        t_eval=times,
    )
    assert sol.success, sol.message
    return sol.y.T


def scipy_monodromy(m: object, omega: float, y: np.ndarray, h: float = 1e-4) -> np.ndarray:
    """DP(y) by central differences of the scipy period map. The vector field is continuous
    (the dead zone is), so the flow is differentiable across transversal contact switches.
    The step h = 1e-4 balances the truncation error (~h²) against the integration error
    divided by h (a smaller h is worse: 2e-6 off at 1e-5, 5e-5 at 1e-6)."""
    n = y.size
    mono = np.empty((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        mono[:, j] = (scipy_flow(m, omega, y + e, 1)[-1] - scipy_flow(m, omega, y - e, 1)[-1]) / (
            2 * h
        )
    return mono


def scipy_periodic_orbit(m: object, omega: float) -> tuple[np.ndarray, np.ndarray]:
    """The 1T orbit's state at τ = 0 and its monodromy matrix: 60 periods from static
    equilibrium, then Newton on P(y) − y with the finite-difference monodromy."""
    y = scipy_flow(m, omega, m.static_equilibrium(), 60)[-1]
    for _ in range(3):
        mono = scipy_monodromy(m, omega, y)
        y = y - np.linalg.solve(mono - np.eye(y.size), scipy_flow(m, omega, y, 1)[-1] - y)
    residual = np.abs(scipy_flow(m, omega, y, 1)[-1] - y).max()
    assert residual < 1e-10, residual
    return y, scipy_monodromy(m, omega, y)


# ------------------------------------------------------------------ the tests
def test_example_passes_the_model_contract() -> None:
    m = KahramanSingh1991()
    check_model(m)
    assert m.n_state == 6 and m.n_track == 3
    assert list(m.switch_widths) == [m.b_p, m.b_g, m.b_h]
    assert {(c.name, c.column, c.clearance, c.kind) for c in m.contacts} == {
        ("mesh", 2, m.b_h, "mesh"),
        ("bearing_p", 0, m.b_p, "bearing"),
        ("bearing_g", 1, m.b_g, "bearing"),
    }
    # the tracked observables are the dead-zone arguments, in switch_widths' order
    assert m.obs_names[: 2 * m.n_track] == (
        "y_p",
        "y_g",
        "delta",
        "y_p_dot",
        "y_g_dot",
        "delta_dot",
    )
    assert System(m, 1.0).params.size == 14
    # changed by field name, as --set does; a bad value is refused naming the parameter
    assert build_model(KahramanSingh1991, {"b_p": "0.25"}).b_p == 0.25
    with pytest.raises(gc.ParameterError, match="eps must be in"):
        KahramanSingh1991(eps=1.2)
    with pytest.raises(gc.ParameterError, match="kappa_g must be"):
        KahramanSingh1991(kappa_g=0.0)


def test_rhs_matches_the_reference_equations_and_rests_at_static_equilibrium() -> None:
    m = KahramanSingh1991()
    p = m.pack(OMEGA)
    f = reference_rhs(m, OMEGA)
    rng = np.random.default_rng(3)
    dydt, obs = np.empty(6), np.empty(len(m.obs_names))
    for _ in range(50):
        t, y = rng.uniform(0, 10), rng.normal(0, 1.2, 6)
        KahramanSingh1991.rhs(t, y, p, dydt, obs, 2)
        np.testing.assert_allclose(dydt, f(t, y), rtol=1e-14, atol=1e-14)
        np.testing.assert_array_equal(obs[:6], y)
        assert obs[9] == pytest.approx(1 + m.eps * math.cos(OMEGA * t), rel=1e-15)
    # at rest under the mean load (no stiffness variation, no transmission error) the
    # accelerations vanish: the mesh carries F_m, the bearings ∓F_m
    rest = KahramanSingh1991(eps=0.0, f_alt=0.0)
    y = rest.static_equilibrium()
    KahramanSingh1991.rhs(0.3, y, rest.pack(OMEGA), dydt, obs, 2)
    np.testing.assert_allclose(dydt, 0.0, atol=1e-15)
    assert obs[6] == pytest.approx(rest.f_mean)
    assert obs[7] == pytest.approx(-rest.f_mean) and obs[8] == pytest.approx(rest.f_mean)


def test_analytic_tangent_is_the_jacobian_of_the_rhs() -> None:
    """J v from the compiled tangent against central differences of the compiled rhs, at
    states away from the switches (where J jumps), in every contact combination."""
    m = KahramanSingh1991()
    p = m.pack(OMEGA)
    n = 6
    rng = np.random.default_rng(7)
    widths = np.array([m.b_p, m.b_g, m.b_h])
    seen = set()
    for _ in range(200):
        t, y = rng.uniform(0, 10), rng.normal(0, 1.5, n)
        if np.any(np.abs(np.abs(y[:3]) - widths) < 1e-3):
            continue
        seen.add(tuple(np.abs(y[:3]) > widths))
        ext = np.concatenate([y, np.eye(n).ravel()])  # k = n tangent vectors: the columns of J
        out = np.zeros(n + n * n)
        KahramanSingh1991.tangent(t, ext, p, np.empty(len(m.obs_names)), out, n, n)
        jac = out[n:].reshape(n, n).T
        fd = np.empty((n, n))
        for j in range(n):
            yp, ym = y.copy(), y.copy()
            yp[j] += 1e-6
            ym[j] -= 1e-6
            dp, dm = np.empty(n), np.empty(n)
            KahramanSingh1991.rhs(t, yp, p, dp, np.empty(10), 0)
            KahramanSingh1991.rhs(t, ym, p, dm, np.empty(10), 0)
            fd[:, j] = (dp - dm) / 2e-6
        np.testing.assert_allclose(jac, fd, atol=1e-8)
    assert len(seen) == 8  # all contact states of the three clearances were checked


def test_simulation_agrees_with_scipy() -> None:
    """30 forcing periods from static equilibrium at a periodic operating point with tooth
    separation: every section point and the final state agree with DOP853 at rtol 1e-11."""
    m = KahramanSingh1991()
    y0 = m.static_equilibrium()
    periods = 30
    ref = scipy_flow(m, OMEGA, y0, periods)
    res = gc.simulate(
        System(m, OMEGA), y0=y0, transient_periods=0, periods=periods, rtol=1e-10, atol=1e-12
    )
    assert res.ok
    # the teeth do separate on this orbit, so the comparison crosses the backlash switches
    assert res.obs_min[2] < m.b_h
    sections = np.stack([np.asarray(res.section(name)) for name in m.state_names[:3]], axis=1)
    np.testing.assert_allclose(res.section_tau, 2 * math.pi / OMEGA * np.arange(periods))
    err_sections = np.abs(sections - ref[:periods, :3]).max()
    err_final = np.abs(np.asarray(res.final_state)[:6] - ref[-1]).max()
    assert err_sections < 1e-7, err_sections
    assert err_final < 1e-7, err_final


def test_periodic_orbit_and_floquet_multipliers_agree_with_scipy() -> None:
    m = KahramanSingh1991()
    orbit = gc.periodic_orbit(System(m, OMEGA), tol=1e-11, rtol=1e-11, atol=1e-13)
    assert orbit.converged and orbit.period == 1
    y_ref, mono_ref = scipy_periodic_orbit(m, OMEGA)
    np.testing.assert_allclose(orbit.state, y_ref, atol=1e-8)
    np.testing.assert_allclose(orbit.monodromy, mono_ref, atol=1e-6)
    mults_ref = np.linalg.eigvals(mono_ref)
    mults_ref = mults_ref[np.argsort(-np.abs(mults_ref), kind="stable")]
    np.testing.assert_allclose(np.abs(orbit.multipliers), np.abs(mults_ref), atol=1e-6)
    assert np.abs(orbit.multipliers).max() < 1  # a stable orbit, as the simulation settles on
    # the contact switches lie on the orbit: the linearisation changes along it
    assert orbit.obs_min[2] < m.b_h < orbit.obs_max[2]


def test_a_second_process_does_not_compile(tmp_path: Path) -> None:
    """Run a fresh copy of the model from the command line twice, in two processes with one
    numba cache of their own: the first compiles (numba saves the model's rhs and the
    integrator specialised to it), the second only loads (no "data saved", and the
    command-line notice of a first compilation is not printed)."""
    shutil.copy(EXAMPLE, tmp_path / "ks_copy.py")
    env = {
        **os.environ,
        "NUMBA_CACHE_DIR": str(tmp_path / "numba_cache"),
        "NUMBA_DEBUG_CACHE": "1",
        "COLUMNS": "200",
        "NO_COLOR": "1",
    }
    command = [
        sys.executable,
        "-m",
        "gearchaos",
        "simulate",
        "--model",
        "ks_copy.py:KahramanSingh1991",
        "--set",
        f"omega={OMEGA}",
        "--transient",
        "2",
        "--periods",
        "2",
    ]
    runs = []
    for _ in range(2):
        proc = subprocess.run(command, cwd=tmp_path, env=env, capture_output=True, text=True)
        assert proc.returncode == 0, proc.stderr[-3000:]
        runs.append(proc.stdout + proc.stderr)
    first, second = runs
    saved = [line for line in first.splitlines() if "data saved to" in line]
    assert any("ks_copy.rhs" in line for line in saved), first[-3000:]
    assert any("dopri_chains" in line for line in saved), first[-3000:]
    assert "compiling numerical kernels" in first
    assert "data saved to" not in second, second[-3000:]
    assert any("data loaded from" in s and "dopri_chains" in s for s in second.splitlines())
    assert "compiling numerical kernels" not in second
