"""The five holes of the verdict (issue 32), each against evidence the verdict does not make.

Independent truths here: λ₁ of a long run of the variational equations
(:func:`gearchaos.lyapunov_spectrum`, its own estimator and start), orbits and multipliers of
the single-point shooting (:func:`gearchaos.periodic_orbit`, its own Newton from its own
start, at 100 times tighter tolerances), a long plain run's distance from an orbit, the
analytic free direction of a two-planet sun inside its clearance, and the command line's
printed summary.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.dynamics import decide_motion, periodic_orbit
from gearchaos.dynamics.lyapunov import lyapunov_spectrum
from gearchaos.dynamics.orbits.stability import STABILITY_MARGIN, structural_multipliers
from gearchaos.integrate.settings import SolverSettings
from gearchaos.integrate.simulate import integrate
from gearchaos.model.target import resolve

SHENG = gc.preset("sheng2016-v1")
#: the sweeps' protocol: 100 + 100 periods from rest perturbed by 1e-6
SEED = SolverSettings(transient_periods=100, periods=100, perturbation=1e-6)


def _verdict(gs, values, settings=SEED):
    system = resolve(gs, values)
    tr = integrate(system, settings)
    v = decide_motion(
        gs, [values], [system], tr.states[None], tr.final_state[None], [tr.ok], settings
    )[0]
    return v, system


@pytest.mark.parametrize(
    ("preset", "values"),
    [("hindawi2021", {"omega": 2.5}), ("sheng2016", {"omega": 1.1, "xi": 0.02})],
)
def test_weak_chaos_on_two_bands_is_not_qp(preset, values) -> None:
    # the 0–1 test over the alternating bands gives K ≈ 0; λ₁ of a long independent run is
    # clear of zero: the verdict must say chaos with an interval that excludes zero
    gs = gc.preset(preset)
    v, system = _verdict(gs, values)
    ref = lyapunov_spectrum(
        system, n_exponents=1, transient_periods=300, periods=3000, perturbation=1e-6
    )
    assert ref.largest - 3 * ref.largest_error > 0  # the truth: weak chaos
    assert v.label == "chaos", v.reason
    assert v.lle - 2 * v.lle_error > 0
    assert v.window_periods > 0 and v.window_start >= 0


def test_a_coexisting_orbit_is_not_the_label_of_the_record() -> None:
    # Ω = 3.3325: a stable 1T exists, but the motion from rest does not approach it (after
    # 3000 periods it still spreads over a closed curve)
    v, system = _verdict(SHENG, {"omega": 3.3325})
    orb = periodic_orbit(SHENG, omega=3.3325, rtol=1e-10, atol=1e-12)
    assert orb.converged and orb.max_multiplier < 1
    long = integrate(system, SEED.replace(transient_periods=3000, periods=100))
    gap = np.max(np.abs(long.states[:, None, :] - orb.sections[None]), axis=-1).min(axis=1)
    assert np.min(gap) > 1e-2  # the truth: the record never comes near the 1T
    assert v.label != "1T", v.reason
    assert any(d == 1 and abs(mu - orb.max_multiplier) < 1e-5 for d, mu in v.coexisting)
    # the record shown is the trajectory's own: its spread is that of the long run's order
    assert v.record is None or np.ptp(v.record.states[:, 2]) > 1e-2


def test_an_alternating_approach_is_its_orbit() -> None:
    # Ω = 1.1426: the record repeats every 2 periods while it approaches a 1T along a
    # multiplier near −1; the period-2 candidate gives the 1T
    v, _ = _verdict(SHENG, {"omega": 1.1426})
    ref = periodic_orbit(SHENG, omega=1.1426, rtol=1e-10, atol=1e-12)
    assert ref.converged and ref.minimal_period == 1
    assert np.min(np.real(ref.multipliers)) < -0.9  # the alternation
    assert v.label == "1T", v.reason
    assert abs(v.max_multiplier - ref.max_multiplier) <= 1e-6


@pytest.mark.parametrize("omega", [1.5, 3.5])
def test_verdict_multipliers_as_accurate_as_stated(omega) -> None:
    # the stated max |μ| agrees with an independent shooting at 100 times tighter
    # tolerances to 1e-6, far inside the stability margin
    v, _ = _verdict(SHENG, {"omega": omega})
    n = v.period
    assert n > 0, v.reason
    ref = periodic_orbit(
        SHENG, omega=omega, period=n, rtol=1e-10, atol=1e-12, transient_periods=600
    )
    assert ref.converged and ref.minimal_period == n
    assert abs(v.max_multiplier - ref.max_multiplier) <= 1e-6 < STABILITY_MARGIN


def test_a_free_direction_is_structural_and_the_orbit_stable() -> None:
    # two planets at 180°: the sun's translation perpendicular to both lines of action,
    # (x, y) ∝ (cos α, −sin α), meets no force inside its bearing clearance, so Pⁿ has the
    # eigenvalue 1 exactly; the orbit is stable by every other multiplier
    gs = SHENG.evolve({"geometry.planets": 2})
    values = {"omega": 1.9}
    v, system = _verdict(gs, values)
    assert v.period > 0 and v.evidence == "floquet", v.reason
    orb = periodic_orbit(gs, omega=1.9, period=v.period, guess=v.orbit_state)
    assert orb.converged
    mask = structural_multipliers(system, orb.state, orb.period, orb.monodromy, orb.settings)
    assert int(mask.sum()) == 1
    assert abs(orb.multipliers[mask][0] - 1.0) < 1e-6
    # its eigenvector is the analytic free direction (positions only)
    w, vec = np.linalg.eig(orb.monodromy)
    u = np.real(vec[:, int(np.argmin(np.abs(w - 1.0)))])
    alpha = math.radians(gs.geometry.pressure_angle_sun)
    names = system.state_names
    ux, uy = u[names.index("x_s")], u[names.index("y_s")]
    others = np.delete(u, [names.index("x_s"), names.index("y_s")])
    assert np.max(np.abs(others)) < 1e-6 * max(abs(ux), abs(uy))
    assert ux * math.sin(alpha) + uy * math.cos(alpha) == pytest.approx(0.0, abs=1e-6 * abs(ux))
    # one criterion: the orbit tool calls it stable, with the same max |μ|
    assert orb.stable
    assert abs(orb.max_multiplier - v.max_multiplier) < 1e-6
    # and with five planets no multiplier is structural
    o5 = periodic_orbit(SHENG, omega=1.5)
    m5 = structural_multipliers(
        resolve(SHENG, {"omega": 1.5}), o5.state, 1, o5.monodromy, o5.settings
    )
    assert not m5.any()


def test_python_summary_is_the_command_line_summary(tmp_path) -> None:
    # one verdict: gc.summarize of gc.simulate and `gearchaos simulate --json` agree
    from typer.testing import CliRunner

    from gearchaos.analysis.summary import summarize as record_summary
    from gearchaos.cli import app

    for omega in (1.5, 3.5):
        res = gc.simulate(SHENG, omega=omega)
        py = gc.summarize(res)
        args = ["simulate", "--preset", SHENG.name, "--set", f"omega={omega}", "--json"]
        cli = CliRunner().invoke(app, args)
        assert cli.exit_code == 0, cli.output
        out = json.loads(cli.stdout)
        assert py["motion"] == out["motion"] and py["evidence"] == out["evidence"] == "floquet"
        assert py["load_factor_sp_max"] == pytest.approx(out["load_factor_sp_max"], rel=1e-9)
        assert py["max_multiplier"] == pytest.approx(out["max_multiplier"], rel=1e-9)
        # the record-only summary never calls its label the motion
        rec = record_summary(res)
        assert rec["motion"] is None and rec["record_label"] and rec["evidence"] == "record"


def test_transient_chaos_is_not_an_attractor() -> None:
    # Ω = 1.2: the run from rest is chaotic for hundreds of periods and then lands on a
    # stable 1T (|μ| 0.98965); a chaotic entry must survive a long continuation to be listed
    ref = periodic_orbit(SHENG, omega=1.2, rtol=1e-10, atol=1e-12)
    assert ref.converged and ref.stable
    found = gc.attractors(SHENG, omega=1.2, starts=4)
    labels = [a.label for a in found]
    assert "1T" in labels
    for a in found:
        if a.label == "chaos":  # listed chaos must be chaos over its last 2000 periods
            assert a.verdict.window_periods >= 2000 and a.verdict.lle - 2 * a.verdict.lle_error > 0


@pytest.mark.slow
def test_invariants_over_a_real_sweep() -> None:
    # Ω 0.05–4, 200 points: no QP whose λ₁ interval lies above the bound; no nT whose
    # stored sections lie farther from its orbit than the documented reach
    from gearchaos import sweep
    from gearchaos.analysis.classify import LLE_C

    ds = sweep.bifurcation(SHENG, "omega=0.05:4:200", progress=False)
    n_state = resolve(SHENG, {"omega": 1.0}).n_state
    for i, lab in enumerate(ds.motion.values.astype(str)):
        omega = float(ds.omega.values[i])
        if lab == "QP":
            lam, err = float(ds.lle.values[i]), float(ds.lle_error.values[i])
            t = (int(ds.window_periods.values[i]) - 1) * 2 * math.pi / omega
            assert lam - 2 * err <= LLE_C / t, omega
        if lab.endswith("T") and lab[:-1].isdigit():
            n = int(lab[:-1])
            fin = np.asarray(ds.final_state.values[i][:n_state])
            orb = periodic_orbit(SHENG, omega=omega, period=n, guess=fin)
            assert orb.converged, omega
            scale = max(1.0, float(np.max(np.abs(orb.state))))
            gap = np.min(np.max(np.abs(fin[None] - orb.sections), axis=-1))
            assert gap <= 1e-3 * scale, omega


@pytest.mark.slow
def test_a_long_period_is_seen_before_qp() -> None:
    # ξ = 0.05, Ω = 1.25: a stable period-55 orbit; a 100-period record is shorter than two
    # of its periods, so QP must wait for a record long enough to show the period
    found = gc.attractors(SHENG, omega=1.25, xi=0.05)
    assert "QP" not in [a.label for a in found]
    long = [a for a in found if a.period > 8]
    assert long and all(a.period == 55 for a in long)
    for a in long:  # the record repeats with its period, independently checked
        x = a.section_states
        assert np.max(np.abs(x[55:] - x[:-55])) < 1e-3 * max(1.0, float(np.max(np.abs(x))))


def test_simulate_and_a_sweep_end_in_one_verdict() -> None:
    # one protocol (100 + 100 periods from rest, perturbed by 1e-6), one point: the single
    # point door records 64 samples a period, the sweep one; their steps and so their
    # verdicts must not differ (Ω = 1.2 has a long chaotic transient that amplifies any)
    from gearchaos import sweep
    from gearchaos.dynamics.verdict.point import analyse_point
    from gearchaos.integrate.settings import SIMULATION

    cfg = SIMULATION.replace(periods=100)
    ds = sweep.bifurcation(SHENG, "omega=1.2,1.1426", progress=False)
    for i, omega in enumerate((1.2, 1.1426)):
        pa = analyse_point(SHENG, {"omega": omega}, cfg)
        assert pa.verdict is not None
        assert pa.verdict.label == str(ds.motion.values[i]), omega
        lam = float(ds.lle.values[i])
        assert pa.verdict.lle == lam or (math.isnan(lam) and math.isnan(pa.verdict.lle))


def test_a_points_exponent_does_not_depend_on_its_batch() -> None:
    # the same chaotic point (Ω = 2.05) alone and third in a batch of three: bitwise the
    # same windows and λ₁
    omegas = [1.5, 2.9, 2.05]
    systems = [resolve(SHENG, {"omega": w}) for w in omegas]
    runs = [integrate(s, SEED) for s in systems]
    batch = decide_motion(
        SHENG,
        [{"omega": w} for w in omegas],
        systems,
        np.stack([r.states for r in runs]),
        np.stack([r.final_state for r in runs]),
        [True] * 3,
        SEED,
    )
    alone = decide_motion(
        SHENG, [{"omega": 2.05}], systems[2:], runs[2].states[None], runs[2].final_state[None],
        [True], SEED,
    )[0]  # fmt: skip
    assert (batch[2].label, batch[2].window_periods) == (alone.label, alone.window_periods)
    assert alone.label == "chaos" and math.isfinite(alone.lle)
    assert batch[2].lle == alone.lle
