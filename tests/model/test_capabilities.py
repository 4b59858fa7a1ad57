"""The model contract as one record (issue 36): :class:`Capabilities` read from a model.

A model written outside the package gets every member it does not give from the record's
defaults, and every member it gives as it gave it (its own quantities, scales, names of its
period and group members, hooks); the package's own models fill the record the same way; a
missing required member is refused naming the member; the record's members are what the
layers above read (store attributes, speeds, the parameters a target accepts).
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass
from typing import Any, ClassVar

import numba
import numpy as np
import pytest

import gearchaos as gc
from gearchaos.model import System
from gearchaos.model.contract import (
    EXTERNAL_KIND_BASE,
    QUANTITIES,
    Capabilities,
    Contact,
    Model,
    UserModel,
    check_model,
)
from gearchaos.model.target import parameter_names, scale_attrs, speeds_at
from stage_scales import StageScales


@numba.njit(cache=True)
def _two_stage_rhs(t, y, p, dydt, obs, level):  # pragma: no cover - compiled
    """Two gear stages in series, each a backlash oscillator; the second stage's mesh
    frequency is 3/5 of the first's (a train with mesh frequencies Ω and 3Ω/5)."""
    om = p[0]
    for s in range(2):
        x, v = y[s], y[2 + s]
        b = p[2 + s]
        f = x - b if x > b else (x + b if x < -b else 0.0)
        w = om if s == 0 else 0.6 * om
        dydt[s] = v
        dydt[2 + s] = -2.0 * p[1] * v - f + 0.1 + 0.1 * math.cos(w * t)
        obs[s] = x
        obs[2 + s] = v


@dataclass(frozen=True)
class Minimal(UserModel):
    """The required members only."""

    zeta: float = 0.05
    b_1: float = 1.0
    b_2: float = 0.5
    name = "minimal"
    state_names = ("x_1", "x_2", "x_1_dot", "x_2_dot")
    obs_names = ("x_1", "x_2", "x_1_dot", "x_2_dot")
    n_track = 2
    rhs = _two_stage_rhs

    def pack(self, omega: float) -> np.ndarray:
        return np.array([omega, self.zeta, self.b_1, self.b_2])


@dataclass(frozen=True)
class TwoStage(Minimal):
    """Every optional member given, in the model's own words."""

    name = "two_stage"
    quantities: ClassVar[dict[str, str]] = {
        "x": "length",
        "x_dot": "velocity",
    }
    symbols: ClassVar[dict[str, Any]] = {"x": (r"\bar{x}_{%d}", r"x_{%d}/b_c", None, None)}
    parameter_symbols: ClassVar[dict[str, str]] = {"zeta": r"\zeta"}
    period_name = "input mesh"
    member_name = "stage"
    default_observables = ("x_2", "x_2_dot")
    scales = StageScales()

    @property
    def contacts(self) -> tuple[Contact, ...]:
        return (Contact("stage_1", 0, self.b_1), Contact("stage_2", 1, self.b_2))

    @property
    def switch_widths(self) -> np.ndarray:
        return np.array([self.b_1, self.b_2])

    def static_mesh_force(self, omega: float) -> float:
        return 0.1

    def warn_for(self, analysis: str) -> None:
        warnings.warn(f"{analysis}: the two stages have no common period", stacklevel=2)


def test_a_user_model_gets_the_defaults_of_what_it_does_not_give() -> None:
    model = Minimal()
    caps = Capabilities.of(model)
    check_model(model)
    assert caps.name == "minimal" and caps.n_state == 4 and caps.n_track == 2
    assert caps.kind >= EXTERNAL_KIND_BASE and caps.rhs is Minimal.rhs
    assert caps.tangent is None  # finite differences
    assert caps.switch_widths.tolist() == [math.inf, math.inf]  # no switches
    assert caps.contacts == () and dict(caps.clearances) == {}
    assert caps.n_contact_forces == 0 and caps.force_groups == ()
    # the first tracked observable and its derivative (the observable after the tracked ones)
    assert caps.default_observables == ("x_1", "x_1_dot")
    assert caps.scales is None and not caps.has_scales
    assert dict(caps.quantities) == {} and dict(caps.symbols) == {}
    assert dict(caps.parameter_symbols) == {}
    assert (caps.period_name, caps.member_name) == ("forcing", "member")
    # contacts and groups are written by their names
    assert dict(caps.contact_words) == {} and caps.in_words("stage_1") == "stage_1"
    assert caps.gearset is None and caps.result_dataset is None
    assert caps.static_mesh_force is None and caps.warn_for is None
    # every optional member has its default, and only the required ones have none
    for f in dataclasses.fields(Capabilities):
        required = f.metadata["otherwise"] is None
        assert required == (f.name in Capabilities.REQUIRED), f.name
        no_default = f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
        assert required == no_default, f.name


def test_a_user_model_overrides_with_its_own_quantities_and_names() -> None:
    model = TwoStage(b_1=0.8, b_2=0.4)
    check_model(model)
    system = System(model, 1.2)
    caps = system.capabilities
    assert caps is Capabilities.of(model)  # read once per model
    assert dict(caps.quantities) == {"x": "length", "x_dot": "velocity"}
    assert set(caps.quantities.values()) <= set(QUANTITIES)
    assert caps.scales.velocity == pytest.approx(20e-6 * 5000.0)  # b_c ω_n = 0.1 m/s
    assert (caps.period_name, caps.member_name) == ("input mesh", "stage")
    assert caps.default_observables == ("x_2", "x_2_dot")
    # the clearances by name come from the contacts when the model does not give them
    assert dict(caps.clearances) == {"stage_1": 0.8, "stage_2": 0.4}
    assert caps.switch_widths.tolist() == [0.8, 0.4]
    assert caps.static_mesh_force(1.2) == 0.1
    with pytest.warns(UserWarning, match="Poincaré section: the two stages"):
        system.warn_for("Poincaré section")
    # the layers above read the record: store attributes, speeds, the parameters by name
    attrs = scale_attrs(model)
    assert attrs["omega_n_rad_s"] == 5000.0 and attrs["characteristic_length_m"] == 20e-6
    assert attrs["clearance_stage_1"] == 0.8 and attrs["clearance_stage_2"] == 0.4
    assert speeds_at(model, 1.2) == {}  # no gear set: no speeds in rpm or Hz
    names = parameter_names(system)
    assert {"zeta", "b_1", "b_2", "omega"} <= set(names)
    members = {f.name for f in dataclasses.fields(Capabilities)}
    assert not members & set(names)


def test_a_missing_required_member_is_refused_naming_it() -> None:
    @dataclass(frozen=True)
    class NoObservables(UserModel):
        name = "no_observables"
        state_names = ("x", "x_dot")
        n_track = 1
        rhs = _two_stage_rhs

        def pack(self, omega: float) -> np.ndarray:
            return np.array([omega])

    with pytest.raises(gc.ParameterError, match=r"NoObservables must define obs_names, the obs"):
        check_model(NoObservables())
    with pytest.raises(gc.ParameterError, match=r"must define obs_names"):
        Capabilities.of(NoObservables())

    @dataclass(frozen=True)
    class NoPack(UserModel):
        name = "no_pack"
        state_names = ("x", "x_dot")
        obs_names = ("x", "x_dot")
        n_track = 1
        rhs = _two_stage_rhs

    with pytest.raises(gc.ParameterError, match=r"NoPack must define pack, the float64"):
        check_model(NoPack())
    with pytest.raises(gc.ParameterError, match=r"object must define name"):
        Capabilities.of(object())

    @dataclass(frozen=True)
    class NoRhs(Minimal):
        rhs = None

    with pytest.raises(gc.ParameterError, match=r"NoRhs needs a compiled right-hand side"):
        check_model(NoRhs())


def test_members_of_the_wrong_kind_are_refused_naming_them() -> None:
    @dataclass(frozen=True)
    class WrongQuantity(Minimal):
        quantities: ClassVar[dict[str, str]] = {"x": "mass"}

    with pytest.raises(gc.ParameterError, match=r"quantities\['x'\] must be one of length"):
        check_model(WrongQuantity())

    @dataclass(frozen=True)
    class NoSuchVariable(Minimal):
        quantities: ClassVar[dict[str, str]] = {"y": "length"}

    with pytest.raises(gc.ParameterError, match=r"quantities: key 'y' must be a variable"):
        check_model(NoSuchVariable())

    @dataclass(frozen=True)
    class NoForceScale(TwoStage):
        quantities: ClassVar[dict[str, str]] = {"x_1": "length", "x_2": "force"}
        scales = dataclasses.make_dataclass("S", [("length", float), ("omega_n", float)])(1, 1)

    with pytest.raises(gc.ParameterError, match=r"scales must have a 'force' factor"):
        check_model(NoForceScale())

    @dataclass(frozen=True)
    class CountAsText(Minimal):
        n_track = "2"  # type: ignore[assignment]

    with pytest.raises(gc.ParameterError, match=r"CountAsText.n_track must be an integer"):
        check_model(CountAsText())

    @dataclass(frozen=True)
    class SymbolsAsList(Minimal):
        symbols: ClassVar[Any] = ["x"]

    with pytest.raises(gc.ParameterError, match=r"SymbolsAsList.symbols must map variable"):
        check_model(SymbolsAsList())


@pytest.mark.parametrize(
    "system",
    [
        gc.planetary_system(gc.preset("sheng2016"), 1.5),
        gc.backlash_oscillator(1.3),
        gc.duffing(1.2),
        gc.linear_oscillator(1.1),
        gc.lorenz(),
    ],
    ids=lambda s: s.name,
)
def test_the_packages_own_models_fill_the_same_record(system: System) -> None:
    """The built-in models meet the contract through the same record: the required members
    are those of the :class:`Model` protocol, and what each gives is what the record holds."""
    model = system.model
    check_model(model)
    assert isinstance(model, Model)
    caps = system.capabilities
    for name in Capabilities.REQUIRED:
        assert hasattr(model, name), name
    assert caps.state_names == tuple(model.state_names) and caps.kind == model.kind
    given = {f.name for f in dataclasses.fields(Capabilities) if hasattr(model, f.name)}
    for name in given - set(Capabilities.REQUIRED) - {"switch_widths"}:
        value = getattr(model, name)
        if isinstance(value, dict | type(caps.symbols)):
            assert dict(getattr(caps, name)) == dict(value), name
        elif not callable(value):
            assert getattr(caps, name) == value or getattr(caps, name) == tuple(value), name


def test_the_model_protocol_is_the_records_required_members() -> None:
    """The typing view of a model (:class:`Model`) names exactly the required members."""
    import typing

    assert set(typing._get_protocol_attrs(Model)) == set(Capabilities.REQUIRED)  # type: ignore[attr-defined]


def test_the_planetary_quantities_are_lengths_velocities_and_forces() -> None:
    """The planetary model's displacements and deflections are lengths (in units of b_c),
    their τ-derivatives velocities (b_c ω_n), the mesh forces forces (k_m,sp b_c); its scales
    convert each: velocity = length · ω_n, force = stiffness · length."""
    caps = gc.planetary_system(gc.preset("sheng2016"), 1.5).capabilities
    q = caps.quantities
    for name, quantity in q.items():
        if name.endswith("_dot"):
            assert quantity == "velocity" and q[name[:-4]] == "length", name
        elif quantity == "length":
            assert q[f"{name}_dot"] == "velocity", name
        else:
            assert quantity == "force" and "force" in name, name
    sc = caps.scales
    assert sc.velocity == pytest.approx(sc.length * sc.omega_n)
    assert sc.force == pytest.approx(sc.stiffness * sc.length)
    assert {"delta_sp", "delta_rp", "x_s", "y_s", "p", "sigma"} <= set(q)
    assert (caps.period_name, caps.member_name) == ("mesh", "planet")
    assert caps.gearset is not None and caps.result_dataset is not None
    # the meshes' contact groups in words, a member by its group's words and number; the
    # bearing's contacts (sun_bearing_x, _y) are written by their names
    assert [caps.in_words(n) for n in ("sun_planet", "planet_ring", "sun_planet_1")] == [
        "sun–planet", "planet–ring", "sun–planet_1",
    ]  # fmt: skip
    assert caps.in_words("sun_bearing_x") == "sun_bearing_x"


@numba.njit(cache=True)
def _half_forced_rhs(t, y, p, dydt, obs, level):  # pragma: no cover - compiled
    """x'' + 2ζx' + x = F cos(Ωτ/2): a forcing that repeats after 2·2π/Ω."""
    dydt[0] = y[1]
    dydt[1] = p[2] * math.cos(0.5 * p[0] * t) - 2.0 * p[1] * y[1] - y[0]
    obs[0] = y[0]
    obs[1] = y[1]


@dataclass(frozen=True)
class HalfForced(UserModel):
    """A linear oscillator forced at Ω/2, whose forcing period is T = ``factor``·2π/Ω."""

    zeta: float = 0.1
    force: float = 1.0
    factor: float = 2.0
    name = "half_forced"
    state_names = ("x", "x_dot")
    obs_names = ("x", "x_dot")
    n_track = 1
    rhs = _half_forced_rhs

    @property
    def period_factor(self) -> float:
        return self.factor

    def pack(self, omega: float) -> np.ndarray:
        return np.array([omega, self.zeta, self.force])


def test_a_declared_forcing_period_is_the_period_sections_count() -> None:
    """With T = 2·2π/Ω declared, the steady response x = A cos(Ωτ/2 − φ) (A = F/√((1 − w²)² +
    (2ζw)²), tan φ = 2ζw/(1 − w²), w = Ω/2) is one point on the section, x = A cos φ at
    τ = kT; counted in 2π/Ω instead (factor 1) the section alternates between ±A cos φ. Its
    spectrum's line, at ω = Ω/2 = 2π/T, lies at 1 in multiples of its period's frequency."""
    omega, zeta, force = 1.2, 0.1, 1.0
    w = omega / 2
    amp = force / math.hypot(1 - w * w, 2 * zeta * w)
    phi = math.atan2(2 * zeta * w, 1 - w * w)
    declared = System(HalfForced(zeta, force, 2.0), omega)
    assert declared.period == pytest.approx(4 * math.pi / omega, rel=1e-15)
    assert scale_attrs(declared.model)["period_factor"] == 2.0
    res = gc.simulate(declared, transient_periods=60, periods=8, samples_per_period=16)
    np.testing.assert_allclose(res.section("x"), amp * math.cos(phi), atol=1e-6)
    ratio, spec = gc.plot.timeseries.amplitude_spectrum(res, "x")
    assert ratio[int(np.argmax(spec))] == pytest.approx(1.0)
    assert np.max(spec) == pytest.approx(amp, rel=1e-4)
    # the same model counted in 2π/Ω: the section points alternate between ±A cos φ
    plain = System(HalfForced(zeta, force, 1.0), omega)
    assert "period_factor" not in scale_attrs(plain.model)
    x = gc.simulate(plain, transient_periods=120, periods=8).section("x")
    np.testing.assert_allclose(x, amp * math.cos(phi) * (-1.0) ** np.arange(8), atol=1e-6)


@pytest.mark.parametrize("factor", [0.0, -2.0, math.inf, "2", True])
def test_a_period_factor_must_be_a_positive_number(factor: Any) -> None:
    with pytest.raises(gc.ParameterError, match=r"HalfForced.period_factor must be a"):
        check_model(HalfForced(factor=factor))


def test_a_sweep_store_records_the_declared_period() -> None:
    """A store of a model with T = 2·2π/Ω records its period factor, and the store's forcing
    period (which the record's classification counts in) is 4π/Ω at every point."""
    from gearchaos.sweep.result import SweepResult

    ds = gc.bifurcation(
        System(HalfForced(), 1.0), "omega=1.0:1.2:3", transient_periods=30, periods=6,
        progress=False,
    )  # fmt: skip
    assert ds.attrs["period_factor"] == 2.0
    omega = np.array([1.0, 1.1, 1.2])
    np.testing.assert_allclose(SweepResult(ds).forcing_period(), 4 * math.pi / omega, rtol=1e-15)
