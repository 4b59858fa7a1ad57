"""Mesh contact forces (issue 12): the closed-form linear response, exactly zero while the teeth
are apart, peaks tracked by the integrator independently of the sampling, one sampling default.

The closed forms are MODEL.md §10.5: without separation the backlash oscillator
x'' + 2ζx' + f(x; b) = F_m + F_a cos Ωτ is linear, x = b + F_m + F_a|H| cos(Ωτ − φ),
H = 1/(1 − Ω² + 2iζΩ), so its contact force Fᶜ = (x − b) + 2ζx' is
F_m + F_a|H| √(1 + 4ζ²Ω²) cos(Ωτ − φ + atan 2ζΩ): peak F_m + A and RMS √(F_m² + A²/2) with
A = F_a|H|√(1 + 4ζ²Ω²).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app
from gearchaos.dynamics.point import analyse_point
from gearchaos.integrate.settings import SolverSettings
from gearchaos.model.response import response_quantities

ZETA, FM, FA, B = 0.1, 1.0, 0.3, 1.0


def _linear_amplitude(omega: float, zeta: float, fa: float) -> float:
    h = 1.0 / complex(1.0 - omega**2, 2.0 * zeta * omega)
    return fa * abs(h) * math.sqrt(1.0 + 4.0 * zeta**2 * omega**2)


@pytest.mark.parametrize("omega", [0.5, 1.6])
def test_contact_force_without_separation_is_the_closed_form_linear_response(
    omega: float,
) -> None:
    # force amplitude (omega_power=0); F_a|H| < F_m: the teeth never separate
    sys_ = gc.backlash_oscillator(omega, zeta=ZETA, b=B, f_mean=FM, f_alt=FA, omega_power=0)
    assert FA / abs(complex(1 - omega**2, 2 * ZETA * omega)) < FM
    res = gc.simulate(
        sys_, transient_periods=80, periods=10, samples_per_period=16, rtol=1e-11, atol=1e-13
    )
    amp = _linear_amplitude(omega, ZETA, FA)
    rq = response_quantities(res.system, res.obs_min, res.obs_max, res.observables)
    assert float(rq["force_peak_mesh"]) == pytest.approx(FM + amp, abs=1e-6)
    assert float(rq["force_rms_mesh"]) == pytest.approx(math.sqrt(FM**2 + amp**2 / 2), abs=1e-6)
    lo, hi = res.extrema("contact_force")
    assert lo == pytest.approx(FM - amp, abs=1e-6)
    assert hi == pytest.approx(FM + amp, abs=1e-6)
    assert float(rq["load_factor_mesh"]) == pytest.approx((FM + amp) / FM, abs=1e-6)
    # DTE: the deflection's fluctuating part, F_a|H| cos(…), RMS F_a|H|/√2
    fah = FA / abs(complex(1 - omega**2, 2 * ZETA * omega))
    assert float(rq["dte_rms_mesh"]) == pytest.approx(fah / math.sqrt(2), abs=1e-6)


def _impacting() -> gc.System:
    """Transmission-error forcing strong enough to open the backlash every period."""
    return gc.backlash_oscillator(1.0, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.2)


def test_contact_force_is_exactly_zero_while_the_teeth_are_apart() -> None:
    res = gc.simulate(_impacting(), transient_periods=60, periods=8, samples_per_period=512)
    x = res.series("x")
    v = res.series("x_dot")
    fc = res.series("contact_force")
    apart = np.abs(x) <= 1.0
    assert 0.05 < apart.mean() < 0.95  # the run does separate
    assert np.all(fc[apart] == 0.0)
    # in contact: κ f(x; b) + 2ζx' with ε = 0, recomputed here
    touch = ~apart
    expected = (x - np.sign(x) * 1.0) + 2 * 0.05 * v
    np.testing.assert_allclose(fc[touch], expected[touch], rtol=1e-13, atol=1e-15)
    # the tracked extrema bound the samples and are reached by them to the sampling
    # resolution (512 samples per period)
    lo, hi = res.extrema("contact_force")
    assert lo <= fc.min() + 1e-12 and hi >= fc.max() - 1e-12
    assert hi - fc.max() < 1e-4 * hi
    assert fc.min() - lo < 1e-2 * hi


@pytest.mark.parametrize("target", ["oscillator", "planetary"])
def test_load_factors_do_not_depend_on_samples_per_period(target: str) -> None:
    if target == "oscillator":
        sys_ = _impacting()
        kw = {"transient_periods": 60, "periods": 6}
    else:
        sys_ = gc.model.target.resolve(gc.preset("hindawi2021"), {"omega": 0.8})
        kw = {"transient_periods": 40, "periods": 4}
    factors = []
    for spp in (1, 5, 64):
        res = gc.simulate(sys_, samples_per_period=spp, rtol=1e-10, atol=1e-12, **kw)
        rq = response_quantities(res.system, res.obs_min, res.obs_max, res.observables)
        factors.append({k: float(v) for k, v in rq.items() if k.startswith("load_factor")})
    for k in factors[0]:
        vals = [f[k] for f in factors]
        assert max(vals) - min(vals) <= 1e-6 * max(vals), (k, vals)
        assert vals[0] > 1.0  # a dynamic load factor exceeds the static one


def test_python_and_cli_give_identical_summaries() -> None:
    args = ["--preset", "hindawi2021", "--set", "omega=1.2", "--transient", "10"]
    out = CliRunner().invoke(app, ["simulate", *args, "--periods", "12", "--json"])
    assert out.exit_code == 0, out.output
    cli = json.loads(out.stdout)
    # the CLI's Python twin: the simulation and its verdict
    cfg = SolverSettings(transient_periods=10, periods=12, samples_per_period=64)
    py = json.loads(
        json.dumps(analyse_point(gc.preset("hindawi2021"), {"omega": 1.2}, cfg).summary)
    )
    assert cli == py
    assert cli["samples_per_period"] == 64
    assert cli["load_factor_sp_max"] is not None and cli["load_factor_sp_max"] > 0
