"""Coexisting attractors at one operating point (:func:`gearchaos.attractors`).

* At the README's quick-start point (default gear set, Ω = 1.5) the start at rest settles on
  a barely stable 1T orbit (the shot orbit converges with max |μ| ≈ 0.997 < 1) while random
  starts land on a chaotic attractor (λ₁ > 0). That they are two attractors, not a slow
  transient, is checked independently: the chaotic run continued 300 more periods with
  :func:`gearchaos.simulate` stays chaotic and never approaches the 1T orbit's section point.
* A damped linear oscillator has exactly one attractor: the steady state
  x(τ) = Re[F e^{iΩτ} / (1 − Ω² + 2iζΩ)], with multipliers of modulus e^{−ζT}.
"""

from __future__ import annotations

import cmath
import math

import numpy as np
import pytest
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app

#: the gear set whose Ω = 1.5 holds a stable 1T orbit beside a chaotic attractor (the
#: recalibrated default ends on one 2T orbit there)
V1 = ["--preset", "sheng2016-v1"]


@pytest.fixture(scope="module")
def quickstart() -> list:
    return gc.attractors(gc.preset("sheng2016-v1"), omega=1.5)


def test_quickstart_point_has_a_stable_1T_orbit_and_a_chaotic_attractor(quickstart) -> None:
    labels = [a.label for a in quickstart]
    assert labels == ["1T", "chaos"], labels
    one, chaos = quickstart
    assert one.starts[0] == 0  # the seed's start at rest
    assert one.orbit is not None and one.orbit.converged
    assert one.orbit.residual < 1e-8
    assert 0.99 < one.max_multiplier < 1.0 and one.stable
    assert chaos.lle > 0.02 and chaos.orbit is None and chaos.stable is None
    assert len(one.starts) + len(chaos.starts) == 8
    # independent check: the chaotic run, continued, stays chaotic and away from the orbit
    res = gc.simulate(
        gc.preset("sheng2016-v1"), omega=1.5, y0=chaos.final_state, transient_periods=0, periods=300
    )
    x = np.asarray(res.series("delta_sp_1"))[res.section_index]
    assert np.ptp(x[-100:]) > 0.3  # still spread over the chaotic band
    # never on the orbit: distance in all 2N mesh deflections at the section (one of them alone
    # may pass close to the orbit's value now and then: it lies inside the chaotic band)
    n = one.system.model.n_planets
    names = [f"delta_{m}_{i}" for m in ("sp", "rp") for i in range(1, n + 1)]
    run = np.stack([np.asarray(res.series(k))[res.section_index][-100:] for k in names], axis=1)
    orbit = np.concatenate([one.orbit.section("delta_sp")[0], one.orbit.section("delta_rp")[0]])
    assert np.min(np.linalg.norm(run - orbit, axis=1)) > 1e-3


def test_a_linear_oscillator_has_exactly_one_attractor() -> None:
    omega, zeta, force = 1.3, 0.1, 1.0
    found = gc.attractors(gc.linear_oscillator(omega, zeta=zeta, force=force), starts=12, seed=3)
    assert len(found) == 1
    (a,) = found
    assert a.label == "1T" and len(a.starts) == 12
    h = force / (1 - omega**2 + 2j * zeta * omega)
    # the section lies at whole forcing periods, where e^{iΩτ} = 1
    assert a.section("y_0")[-1] == pytest.approx(abs(h) * math.cos(cmath.phase(h)), abs=1e-7)
    assert a.section("y_1")[-1] == pytest.approx(
        -omega * abs(h) * math.sin(cmath.phase(h)), abs=1e-7
    )
    assert a.max_multiplier == pytest.approx(math.exp(-zeta * 2 * math.pi / omega), rel=1e-7)
    assert a.lle == pytest.approx(-zeta, abs=2e-3)


def test_arguments_are_checked() -> None:
    with pytest.raises(gc.ParameterError, match="starts"):
        gc.attractors(gc.duffing(1.0), starts=0)
    with pytest.raises(gc.ParameterError, match="spread_fraction"):
        gc.attractors(gc.duffing(1.0), spread_fraction=2.0)


def test_cli_attractors_json_lists_both(quickstart) -> None:
    import json

    result = CliRunner().invoke(app, ["attractors", *V1, "--set", "omega=1.5", "--json"])
    assert result.exit_code == 0, result.output
    items = json.loads(result.stdout)
    assert [i["label"] for i in items] == [a.label for a in quickstart]
    assert items[0]["orbit"]["stable"] is True
    assert items[0]["orbit"]["max_multiplier"] == pytest.approx(quickstart[0].max_multiplier)
    assert items[1]["lle"] > 0 and items[1]["orbit"] is None
    result = CliRunner().invoke(app, ["attractors", *V1, "--set", "omega=1.5", "--starts", "2"])
    assert result.exit_code == 0, result.output
    assert "coexist" in result.stdout
