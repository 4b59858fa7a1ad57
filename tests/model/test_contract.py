"""The model contract (issue 25), checked on every model: the built-in ones, a model written
outside the package as a :class:`~gearchaos.model.contract.UserModel` (here and in
``examples/``), each against properties that follow from the contract's definitions:

* the observables come as documented — the tracked ones first, then their τ-derivatives: the
  derivative columns equal the total derivative of the tracked columns along the flow,
  computed here by central differences of the compiled right-hand side along the trajectory;
* switch widths and contacts agree (a contact is judged on a tracked observable whose switch
  is its half clearance);
* the tangent (the model's own, or the finite-difference one for a model without) gives the
  monodromy matrix that finite differences of the flow map give;
* the default section variables exist.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numba
import numpy as np
import pytest

import gearchaos as gc
from gearchaos.dynamics.orbits.shooting import shoot
from gearchaos.integrate.settings import SolverSettings
from gearchaos.integrate.simulate import integrate
from gearchaos.model import System
from gearchaos.model.contract import UserModel, check_model
from gearchaos.model.loading import build_model, load_model_class

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "kahraman_singh_1991.py"


@numba.njit(cache=True)
def _pendulum_rhs(t, y, p, dydt, obs, level):  # pragma: no cover - compiled
    """A forced, damped pendulum with a dead-zone spring on its angle (no tangent given)."""
    x, v = y[0], y[1]
    b = p[2]
    fz = x - b if x > b else (x + b if x < -b else 0.0)
    dydt[0] = v
    dydt[1] = p[3] * math.cos(p[0] * t) - p[1] * v - math.sin(x) - fz
    obs[0] = x
    obs[1] = v
    obs[2] = math.sin(x)


@dataclass(frozen=True)
class Pendulum(UserModel):
    """A user model without a tangent (the finite-difference one is used)."""

    zeta: float = 0.1
    b: float = 0.5
    force: float = 0.8
    name = "pendulum"
    state_names = ("x", "x_dot")
    obs_names = ("x", "x_dot", "sine")
    n_track = 1
    rhs = _pendulum_rhs

    @property
    def switch_widths(self) -> np.ndarray:
        return np.array([self.b])

    @property
    def contacts(self) -> tuple[gc.model.contract.Contact, ...]:
        return (gc.model.contract.Contact("stop", 0, self.b),)

    def pack(self, omega: float) -> np.ndarray:
        return np.array([omega, self.zeta, self.b, self.force])


def _seven_planets() -> gc.GearSet:
    """sheng2016 with 7 planets (no compiled kernel of its own): 50 + 2·13 = 76 teeth on the
    ring, (z_s + z_r)/7 = 18 for equal spacing, planets small enough to fit."""
    changes = {"geometry.planets": 7, "teeth.sun": 50, "teeth.planet": 13, "teeth.ring": 76}
    return gc.preset("sheng2016-v1").evolve(changes)


def _systems() -> dict[str, System]:
    out = {
        "planetary sheng2016 (N = 5)": gc.planetary_system(gc.preset("sheng2016-v1"), 1.5),
        "planetary hindawi2021": gc.planetary_system(gc.preset("hindawi2021"), 0.8),
        "planetary N = 7 (general kernel)": gc.planetary_system(_seven_planets(), 1.2),
        "backlash oscillator": gc.backlash_oscillator(1.3, eps=0.2, f_alt=0.2),
        "linear oscillator": gc.linear_oscillator(1.1, force=0.5),
        "linear system": gc.linear_system([[0.0, 1.0], [-2.0, -0.3]], 0.9, cos_forcing=[0, 1]),
        "duffing": gc.duffing(1.2),
        "lorenz": gc.lorenz(),
        "user model without tangent": System(Pendulum(), 1.1),
    }
    if EXAMPLE.exists():
        cls = load_model_class(f"{EXAMPLE}:KahramanSingh1991")
        out["example: Kahraman & Singh 1991"] = System(build_model(cls), 0.9)
    return out


SYSTEMS = _systems()


def _state_on_the_attractor(system: System) -> tuple[float, np.ndarray]:
    traj = integrate(system, SolverSettings(transient_periods=7.3, periods=1, samples_per_period=1))
    assert traj.ok
    return float(traj.tau[0]), np.array(traj.states[0])


@pytest.mark.parametrize("name", list(SYSTEMS))
def test_the_model_meets_the_contract(name: str) -> None:
    system = SYSTEMS[name]
    model = system.model
    check_model(model)
    assert len(system.state_names) == system.n_state == len(set(system.state_names))
    assert len(system.obs_names) == system.n_obs == len(set(system.obs_names))
    widths = system.switch_widths
    assert widths.shape == (system.n_track,) and np.all(widths >= 0)
    for c in system.contacts:
        assert 0 <= c.column < system.n_track
        assert widths[c.column] == c.clearance
        assert c.kind in ("mesh", "bearing")
    var, dot = system.default_observables
    system.observable(var)
    system.observable(dot)
    if system.group_size:
        assert system.observable(var).columns.size in (1, system.group_size)
    for _label, force, deflection in system.force_groups:
        f, d = system.observable(force), system.observable(deflection)
        assert f.columns.size == d.columns.size


@pytest.mark.parametrize("name", list(SYSTEMS))
def test_tracked_observables_are_followed_by_their_derivatives(name: str) -> None:
    """obs[n_track + k] = d obs[k]/dτ along the flow: the total derivative, by a central
    difference over ±h along the trajectory through (τ, y) (y ± h f, τ ± h)."""
    system = SYSTEMS[name]
    nt = system.n_track
    if nt == 0:
        pytest.skip("no tracked observables")
    t, y = _state_on_the_attractor(system)
    obs, f = system.evaluate([t], y)
    h = 1e-6
    plus = system.observe(np.array([t + h]), (y + h * f[0])[None])[0]
    minus = system.observe(np.array([t - h]), (y - h * f[0])[None])[0]
    numeric = (plus[:nt] - minus[:nt]) / (2 * h)
    scale = 1.0 + np.abs(obs[0, nt : 2 * nt])
    # a dead-zone argument's derivative is continuous; a contact force's jumps at release,
    # so compare where the trajectory is not within h of a switch
    near = np.abs(np.abs(obs[0, :nt]) - system.switch_widths) < 1e-3
    ok = np.abs(obs[0, nt : 2 * nt] - numeric) <= 1e-5 * scale
    assert np.all(ok | near), (obs[0, nt : 2 * nt], numeric)


@pytest.mark.parametrize("name", list(SYSTEMS))
def test_the_tangent_gives_the_flow_maps_jacobian(name: str) -> None:
    """The monodromy matrix over one forcing period (integrated with the model's tangent, or
    with the finite-difference tangent of a model without one) equals the Jacobian of the
    flow map by central differences of the state alone."""
    system = SYSTEMS[name]
    _, y = _state_on_the_attractor(system)
    cfg = SolverSettings(rtol=1e-11, atol=1e-13)
    shot = shoot([system], y[None], 1, cfg)
    assert shot.ok(0)
    m = shot.monodromy[0]
    n = system.n_state
    fd = np.empty((n, n))
    for j in range(n):
        h = 1e-6 * max(1.0, abs(y[j]))
        e = np.zeros(n)
        e[j] = h
        ends = shoot([system, system], np.stack([y + e, y - e]), 1, cfg, tangents=False).end
        fd[:, j] = (ends[0] - ends[1]) / (2 * h)
    scale = max(1.0, float(np.max(np.abs(fd))))
    np.testing.assert_allclose(m, fd, atol=2e-5 * scale, rtol=0)


def test_a_broken_model_is_refused_naming_the_member() -> None:
    @dataclass(frozen=True)
    class Broken(Pendulum):
        @property
        def switch_widths(self) -> np.ndarray:
            return np.array([0.5, 0.5])  # two widths for one tracked observable

    with pytest.raises(gc.ParameterError, match="switch_widths"):
        check_model(Broken())
    with pytest.raises(gc.ParameterError, match=r"unknown parameter 'zta'.*'zeta'"):
        build_model(Pendulum, {"zta": "0.2"})
    model = build_model(Pendulum, {"zeta": "0.2"})  # text from --set, converted
    assert model.zeta == 0.2


def test_parameter_symbols_must_name_fields_with_strings() -> None:
    """``parameter_symbols`` (field → mathtext) is refused, naming the member, the key and
    the rule, where a key is no field of the model or a value no string; the example's pass."""

    @dataclass(frozen=True)
    class Named(Pendulum):
        parameter_symbols: ClassVar[dict[str, Any]] = {"zeta": r"\zeta", "b": r"\bar{b}"}

    check_model(Named())

    @dataclass(frozen=True)
    class NoField(Pendulum):
        parameter_symbols: ClassVar[dict[str, Any]] = {"zeta": r"\zeta", "omega": r"\Omega"}

    with pytest.raises(gc.ParameterError, match=r"parameter_symbols: key 'omega'.*field"):
        check_model(NoField())

    @dataclass(frozen=True)
    class NoString(Pendulum):
        parameter_symbols: ClassVar[dict[str, Any]] = {"force": 1.0}

    with pytest.raises(gc.ParameterError, match=r"parameter_symbols\['force'\].*string"):
        check_model(NoString())

    @dataclass(frozen=True)
    class NoMapping(Pendulum):
        parameter_symbols: ClassVar[Any] = ("zeta",)

    with pytest.raises(gc.ParameterError, match="parameter_symbols must map field names"):
        check_model(NoMapping())
    example = load_model_class(f"{EXAMPLE}:KahramanSingh1991")
    check_model(example())
    assert set(example.parameter_symbols) == {f.name for f in dataclasses.fields(example)}


def test_a_user_models_kind_follows_its_source() -> None:
    """The kernel kind is derived from the model's source file (this test file), outside the
    built-in kinds, and stable for the class."""
    kind = Pendulum().kind
    assert kind >= gc.model.contract.EXTERNAL_KIND_BASE
    assert Pendulum(zeta=0.3).kind == kind


@pytest.mark.parametrize("name", [n for n in SYSTEMS if n.startswith(("planetary", "backlash"))])
def test_switch_widths_are_the_clearances_the_kernel_reads(name: str) -> None:
    """The integrator lands steps at ±switch_widths while the compiled right-hand side bends
    at the clearances it reads from the packed parameters (MODEL.md's b̄_sp, b̄_rp, b̄_s; the
    oscillator's b): the two must be the same numbers, for every model that has clearances."""
    from gearchaos.model import layout as L

    system = SYSTEMS[name]
    p = system.params
    if name.startswith("planetary"):
        n = system.group_size
        packed = [p[L.P_BSP]] * n + [p[L.P_BRP]] * n + [p[L.P_BS]] * 2
    else:
        packed = [p[L.BO_B]]
    widths = system.switch_widths[: len(packed)]
    assert widths.tolist() == packed
