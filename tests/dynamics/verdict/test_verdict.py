"""The motion verdict against the project's rigorous tools and independent truth.

Ground truth here never comes from the verdict itself: orbits and multipliers come from the
single-point shooting (:func:`gearchaos.periodic_orbit`, an independent Newton iteration from
its own start), exponents from the variational equations run long, Lorenz's λ₁ from the
literature (0.9056, Sprott 2003).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.dynamics import (
    EVIDENCE,
    VerdictSettings,
    decide_motion,
    periodic_orbit,
    periodic_orbits,
)
from gearchaos.dynamics.lyapunov import exponent_estimate, lyapunov_spectrum
from gearchaos.dynamics.verdict.point import analyse_point, point_verdict
from gearchaos.integrate.settings import SolverSettings
from gearchaos.integrate.simulate import integrate
from gearchaos.model.target import resolve

GS = gc.preset("sheng2016-v1")
#: the seed's 100 + 100 periods from rest perturbed by 1e-6 (the verdict's protocol)
SEED = SolverSettings(transient_periods=100, periods=100, perturbation=1e-6)


def _verdict(omega: float, settings: SolverSettings = SEED):
    system = resolve(GS, {"omega": omega})
    tr = integrate(system, settings)
    return (
        decide_motion(
            GS,
            [{"omega": omega}],
            [system],
            tr.states[None],
            tr.final_state[None],
            [tr.ok],
            settings,
        )[0],
        tr,
    )


def test_lorenz_exponent_from_the_default_start() -> None:
    # the origin is an equilibrium: the perturbed default start leaves it
    r = lyapunov_spectrum(gc.lorenz(), n_exponents=1, perturbation=1e-6)
    assert abs(r.largest - 0.9056) <= 0.01 * 0.9056
    assert 0 < r.largest_error < 0.05


def test_exponent_estimate_of_independent_blocks() -> None:
    rng = np.random.default_rng(3)
    x = 0.5 + rng.standard_normal(100_000)  # i.i.d. log stretches, mean 0.5, sd 1
    lam, err = exponent_estimate(x, 2.0, blocks=10)
    assert abs(lam - 0.25) < 4 * err
    assert err == pytest.approx(1.0 / math.sqrt(100_000) / 2.0, rel=0.6)


def test_random_tangent_gives_the_exact_exponent_on_the_symmetric_manifold() -> None:
    # exact symmetric start: the motion is the stable 1T orbit; λ₁ must be ln|μ|max/T, not
    # the exponent of the symmetry-breaking subspace a basis vector would stay in
    omega = 1.2
    orb = periodic_orbit(GS, omega=omega, perturbation=0.0)  # its guess from the exact rest
    assert orb.converged and orb.max_multiplier < 1
    exact = math.log(orb.max_multiplier) / resolve(GS, {"omega": omega}).period
    r = lyapunov_spectrum(
        resolve(GS, {"omega": omega}), n_exponents=1, periods=1000, perturbation=0.0
    )
    assert abs(r.largest - exact) <= 3 * r.largest_error + 2e-4


def test_stable_orbit_with_slow_transient_is_labelled_with_it() -> None:
    # Ω = 3.5: the record still converges onto a stable 2T (the old labels said QP)
    v, _ = _verdict(3.5)
    ref = periodic_orbit(GS, omega=3.5, period=2, transient_periods=600)
    assert ref.converged and ref.minimal_period == 2 and ref.max_multiplier < 1
    assert v.label == "2T" and v.evidence == "floquet"
    assert v.max_multiplier == pytest.approx(ref.max_multiplier, abs=1e-5)
    T = 2 * math.pi / 3.5
    assert v.lle == pytest.approx(math.log(ref.max_multiplier) / (2 * T), abs=1e-6)


def test_slowly_spiralling_transient_onto_a_stable_orbit() -> None:
    # Ω = 1.5: fourfold |μ| = 0.997 — the record is far from repeating after 100 periods
    v, _ = _verdict(1.5)
    ref = periodic_orbit(GS, omega=1.5)
    assert v.label == "1T" and v.evidence == "floquet"
    assert v.max_multiplier == pytest.approx(ref.max_multiplier, abs=1e-5)


def test_unstable_orbit_on_the_symmetric_manifold_is_not_an_attractor() -> None:
    # Ω = 3.45 from the exact symmetric start: the record is a 2T on the symmetric manifold,
    # unstable to symmetry breaking; it must not be labelled 2T
    exact = SEED.replace(perturbation=0.0)
    system = resolve(GS, {"omega": 3.45})
    tr = integrate(system, exact)
    assert np.max(np.abs(tr.states[:, 0])) < 1e-10  # sun centred: on the manifold
    ref = periodic_orbits(
        GS, [{"omega": 3.45}], period=2, guesses=tr.final_state[None], settings=exact
    )[0]
    assert ref.converged and ref.max_multiplier > 1
    v = decide_motion(
        GS, [{"omega": 3.45}], [system], tr.states[None], tr.final_state[None], [True], exact
    )[0]
    assert v.label != "2T" and v.period == 0
    # the default protocol leaves the manifold
    tr2 = integrate(system, SEED)
    assert np.max(np.abs(tr2.states[:, 0])) > 1e-7


def test_no_unstable_orbit_is_labelled_periodic_over_a_range() -> None:
    # Ω 1.3–1.7 (the 8 unstable "1T" points): every nT label is a stable orbit
    for omega in np.linspace(1.3, 1.7, 6):
        v, _ = _verdict(float(omega))
        if v.period:
            assert v.max_multiplier < 1
        else:
            assert v.label in ("QP", "chaos", "unresolved")
            assert v.reason


def test_point_and_sweep_agree_and_invariants_hold() -> None:
    from gearchaos import sweep
    from gearchaos.analysis.periodicity import periods_of

    ds = sweep.bifurcation(GS, "omega=0.05:4:101", progress=False)  # the defaults: verdicts
    labels = ds.motion.values
    codes = ds.verdict.values
    n_per = 0
    for i, lab in enumerate(labels):
        lab = str(lab)
        omega = float(ds.omega.values[i])
        assert lab in ("QP", "chaos", "unresolved", "failed") or lab.endswith("T")
        mu = float(ds.max_multiplier.values[i])
        lam, err = float(ds.lle.values[i]), float(ds.lle_error.values[i])
        if lab.endswith("T"):
            n = int(lab[:-1])
            n_per += 1
            if codes[i] == EVIDENCE["floquet"]:
                # a stable orbit, and λ₁ exactly its exponent
                assert mu < 1
                T = 2 * math.pi / omega
                assert lam == pytest.approx(math.log(mu) / (n * T), abs=1e-6)
                assert err == 0
            else:  # too long to shoot: the record repeats and contracts
                assert codes[i] == EVIDENCE["record_contracting"] and lam + 2 * err < 0
            # the shown record holds n distinct points at the documented tolerance (10⁻³ of
            # the attractor's size above the integration's noise floor)
            pts = np.stack([ds.delta_sp.values[i, :, 0], ds.delta_sp_dot.values[i, :, 0]], axis=-1)
            floor = 1e3 * (1e-10 + 1e-8 * float(np.max(np.abs(pts))))
            found = int(periods_of(pts[None], rtol=1e-3, atol=floor, floor=floor)[0])
            assert found == n, (omega, lab, found)
        elif lab in ("QP", "chaos"):
            assert codes[i] == EVIDENCE["lyapunov"] and math.isfinite(lam) and err > 0
            # the rules of the verdict hold for the stored numbers
            assert (lam - 2 * err > 0) if lab == "chaos" else (lam + 2 * err >= 0)
        else:
            assert lab == "failed" or codes[i] in (
                EVIDENCE["contracting"],
                EVIDENCE["ambiguous"],
                EVIDENCE["unstable_orbit"],
            )
    assert n_per > 20
    unresolved = float(np.mean(labels == "unresolved"))
    assert unresolved <= 0.05
    # the same points through the single-point door
    for i in (10, 40, 70, 95):
        omega = float(ds.omega.values[i])
        pa = analyse_point(GS, {"omega": omega}, SEED, verdict=VerdictSettings())
        assert pa.summary["motion"] == str(labels[i]), omega


def test_verdict_settings_are_checked() -> None:
    with pytest.raises(gc.ParameterError, match="margin"):
        VerdictSettings(margin=-1)
    with pytest.raises(gc.ParameterError, match="verdict must be a VerdictSettings"):
        decide_motion(GS, [], [], np.zeros((0, 1, 1)), np.zeros((0, 1)), [], SEED, "x")  # type: ignore[arg-type]


def test_point_verdict_of_a_result() -> None:
    res = gc.simulate(GS, omega=3.5, transient_periods=100, periods=100, perturbation=1e-6)
    v = point_verdict(GS, {"omega": 3.5}, res)
    assert v.label == "2T"


def test_chaos_holds_in_two_windows() -> None:
    # the first window is as long as the record (500 periods), the next as long; chaos is
    # decided only when both say so (a chaotic transient ending between them is not chaos)
    cfg = SolverSettings(transient_periods=50, periods=500, perturbation=1e-6)
    v, _ = _verdict(2.0, cfg)
    assert v.label == "chaos" and v.lle - 2 * v.lle_error > 0
    assert (v.window_start, v.window_periods, v.extra_periods) == (500, 500, 1000)


def test_the_explorer_computes_the_label_the_sweep_stored(tmp_path) -> None:
    # the explorer's panel shows the stored verdict and, on demand, recomputes the point
    # through analyse_point with the store's protocol: the two must agree
    from gearchaos import sweep
    from gearchaos.explore.compute import compute_point

    path = tmp_path / "w.zarr"
    omegas = (1.5, 2.0, 3.5)
    ds = sweep.bifurcation(
        GS, {"omega": list(omegas)}, store=path, progress=False, transient_periods=100, periods=100
    )
    for i, omega in enumerate(omegas):
        out = compute_point(str(path), {"omega": omega})
        assert out["motion"] == str(ds.motion.values[i]), omega
        assert out["summary"]["evidence"] == (
            "floquet" if out["motion"].endswith("T") else "lyapunov"
        )


def test_every_settled_orbit_of_a_batch_is_confirmed_from_its_record() -> None:
    # at Ω ≤ 0.1 the damping contracts the state by e^(λ₁T) ≈ e^-1 a period (T = 2π/Ω ≥ 63):
    # after 100 transient periods every record sits on its stable 1T orbit, so the verdict
    # confirms each point of a batch from its record, with no extension (a confirmed point
    # must not change how the next point of the same batch is judged)
    from gearchaos import sweep

    ds = sweep.bifurcation(GS, "omega=0.05:0.1:6", params={"xi": 0.03}, progress=False)
    assert [str(m) for m in ds.motion.values] == ["1T"] * 6
    assert np.all(ds.extra_periods.values == 0)
    assert np.all(ds.max_multiplier.values < 1)


def test_a_lyapunov_vector_on_the_state_steps() -> None:
    # lyapunov_tol = inf: the vector is left out of the error control, so the state is
    # bitwise the plain run's; λ₁ of a stable orbit is then its exact ln|μ|max/T within the
    # error, and that of a chaotic point agrees with a fully controlled vector (factor 1)
    from gearchaos.dynamics.verdict.extension import extend

    omegas = [1.5, 2.05, 2.9]
    systems = [resolve(GS, {"omega": w}) for w in omegas]
    starts = np.array([integrate(s, SEED).final_state for s in systems])
    plain = extend(systems, starts, SEED, 200, None)
    riding = extend(systems, starts, SEED, 200, 0, tangent_tol=math.inf)
    full = extend(systems, starts, SEED, 200, 0, tangent_tol=1.0)
    n = systems[0].n_state
    assert np.array_equal(riding.states[..., :n], plain.states[..., :n])
    lam = [exponent_estimate(riding.stretch(n)[i, 0], s.period) for i, s in enumerate(systems)]
    ref = [exponent_estimate(full.stretch(n)[i, 0], s.period) for i, s in enumerate(systems)]
    for w, s, (l1, e1), (l0, e0) in zip(omegas, systems, lam, ref, strict=True):
        assert abs(l1 - l0) <= 3 * math.hypot(e0, e1), w
        orb = periodic_orbit(GS, omega=w, guess=starts[omegas.index(w)])
        if orb.converged and orb.max_multiplier < 1:  # a stable orbit: λ₁ is exact
            assert abs(l1 - math.log(orb.max_multiplier) / s.period) <= 3 * e1 + 2e-4, w
    assert lam[1][0] - 2 * lam[1][1] > 0  # Ω = 2.05 is chaotic
