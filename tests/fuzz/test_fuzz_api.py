"""Fuzzing the Python entry points (issue 10): settings, parameters, Ω and axis specifications.

Generated invalid values go through every front door that takes them — the solver settings
through ``SolverSettings``, ``simulate``, ``integrate``, ``integrate_batch``,
``lyapunov_spectrum``, ``max_lyapunov``, ``SweepSpec.build``, ``bifurcation`` and
``run_gallery``; every dotted gear-set parameter as a fixed value, a sweep axis, a gallery
path and an ``analyse_point`` value; Ω everywhere it is given; malformed ``vary``/``family``
specifications. "Invalid" is taken from the documented rules (``SolverSettings.check``, the
gear-set registry, Ω in its plausible range [1e-6, 1e6], the axis syntax
``start:stop:count | log:start:stop:count | a,b,c`` with 1 to 10⁶ values), so every generated
input must be refused: :class:`ParameterError` (or :class:`StoreError`) naming the culprit,
at once (see :mod:`fuzz_helpers`). Nothing here integrates: an input that slipped through would
run with 1 transient and 2 recorded periods and fail the test as "accepted".
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from fuzz_helpers import (
    NON_FINITE,
    NOT_NUMBERS,
    hsettings,
    ints_outside,
    not_integers,
    profiles,
    reals_outside,
    refused,
)
from hypothesis import given, strategies as st
from test_fuzz_gearset import BASE, culprits, invalid_values

import gearchaos as gc
from gearchaos.dynamics.lyapunov import lyapunov_spectrum, max_lyapunov
from gearchaos.dynamics.verdict.point import analyse_point
from gearchaos.gearset.schema import ALIASES, FIELDS
from gearchaos.integrate import integrate, integrate_batch
from gearchaos.integrate.settings import SolverSettings
from gearchaos.paper.galleries import run_gallery
from gearchaos.sweep import SweepSpec

#: The shortest protocol: anything that slipped through would finish at once.
TINY = {"transient_periods": 1, "periods": 2}
TINY_SETTINGS = SolverSettings(**TINY)
SYSTEM = gc.planetary_system(BASE, 1.5)
DUFFING = gc.duffing(1.2)

PROFILES = profiles({"settings": 25, "params": 8, "omega": 30, "specs": 60, "objects": 40})


# ----------------------------------------------------------------------------- solver settings
def invalid_setting(name: str) -> st.SearchStrategy[Any]:
    """Values that break the documented rule of a solver setting (``SolverSettings.check``):
    transient_periods a number in [0, 1e9]; periods an integer in [1, 1e9];
    samples_per_period an integer in [1, 1e6]; section_phase a finite number; rtol a number in
    [1e-14, 1]; atol a number in (0, 1]; max_steps an integer in [1, 2^62] (or None); settle
    "off" or "auto"; perturbation a number in [0, 1e-2]."""
    real = st.one_of(NOT_NUMBERS, NON_FINITE)
    if name == "transient_periods":
        return st.one_of(real, reals_outside(0.0, 1e9))
    if name == "periods":
        return st.one_of(not_integers(), ints_outside(1, 10**9))
    if name == "samples_per_period":
        return st.one_of(not_integers(), ints_outside(1, 10**6))
    if name == "section_phase":
        return real
    if name == "rtol":
        return st.one_of(real, reals_outside(1e-14, 1.0), st.just(0.0))
    if name == "atol":
        return st.one_of(real, reals_outside(0.0, 1.0, lo_ok=False))
    if name == "settle":
        return st.one_of(
            # NOT_NUMBERS holds arrays too, which `in` cannot compare: only strings can match
            NOT_NUMBERS.filter(lambda v: not isinstance(v, str) or v not in ("off", "auto")),
            st.text(max_size=6).filter(lambda v: v not in ("off", "auto")),
            st.sampled_from(["OFF", "Auto", " auto", True, 1]),
        )
    if name == "perturbation":
        return st.one_of(real, reals_outside(0.0, 1e-2))
    assert name == "max_steps"
    return st.one_of(not_integers(), ints_outside(1, 2**62))


def _with(name: str, value: Any) -> dict[str, Any]:
    return {**TINY, name: value}


#: Every front door that takes solver settings by name.
SETTING_DOORS = {
    "SolverSettings": lambda kw: SolverSettings(**kw),
    "SolverSettings.build": lambda kw: SolverSettings.build(None, **kw),
    "simulate": lambda kw: gc.simulate(BASE, omega=1.5, **kw),
    "integrate": lambda kw: integrate(SYSTEM, **kw),
    "integrate_batch": lambda kw: integrate_batch([SYSTEM, SYSTEM], **kw),
    "lyapunov_spectrum": lambda kw: lyapunov_spectrum(DUFFING, **kw),
    "max_lyapunov": lambda kw: max_lyapunov(DUFFING, **kw),
    "SweepSpec.build": lambda kw: SweepSpec.build("omega=1:2:2", **kw),
    "bifurcation": lambda kw: gc.bifurcation(BASE, "omega=1:2:2", progress=False, **kw),
    "run_gallery": lambda kw: run_gallery(BASE, "omega", [1.5], progress=False, **kw),
}
#: Doors where None means "the default" (``SolverSettings.build``); elsewhere it is refused.
NONE_IS_DEFAULT = {"SolverSettings.build", "integrate", "integrate_batch", "lyapunov_spectrum"}
NONE_IS_DEFAULT |= {"max_lyapunov", "SweepSpec.build", "bifurcation", "run_gallery", "simulate"}


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("name", SolverSettings.field_names())
def test_invalid_solver_settings_are_refused_everywhere(profile: dict[str, int], name: str) -> None:
    @hsettings(profile["settings"])
    @given(invalid_setting(name), st.sampled_from(sorted(SETTING_DOORS)))
    def check(value: Any, door: str) -> None:
        refused(door, lambda: SETTING_DOORS[door](_with(name, value)), name)

    check()
    if name != "max_steps":  # None: refused where it is not "the default"
        for door in sorted(set(SETTING_DOORS) - NONE_IS_DEFAULT):
            refused(door, lambda door=door: SETTING_DOORS[door](_with(name, None)), name)


def test_memory_is_checked_before_allocating() -> None:
    """Valid settings whose outputs would not fit: refused up front with the size."""
    huge = {"transient_periods": 0, "periods": 10**9, "samples_per_period": 10**6}
    for door in ("simulate", "integrate", "integrate_batch", "lyapunov_spectrum"):
        refused(door, lambda door=door: SETTING_DOORS[door](huge), "memory")
    for door in ("bifurcation",):
        refused(door, lambda: gc.bifurcation(BASE, "omega=1:2:2", periods=10**9), "memory")


# ----------------------------------------------------------------------------- parameters
PARAMETER_DOORS = ["fixed", "vary", "family", "gallery", "gallery(fixed)", "analyse_point"]


def _parameter_call(door: str, name: str, value: Any) -> Any:
    if door == "fixed":
        return lambda: gc.bifurcation(
            BASE, "omega=1:2:2", params={name: value}, progress=False, **TINY
        )
    if door == "vary":
        return lambda: gc.bifurcation(
            BASE, {name: [value]}, params={"omega": 1.5}, progress=False, **TINY
        )
    if door == "family":
        return lambda: gc.bifurcation(
            BASE, "omega=1:2:2", family={name: [value]}, progress=False, **TINY
        )
    if door == "gallery":
        return lambda: run_gallery(BASE, name, [value], omega=1.5, progress=False, **TINY)
    if door == "gallery(fixed)":  # the deprecated spelling of params: warns, then refuses

        def old_spelling() -> Any:
            with pytest.warns(DeprecationWarning, match=r"run_gallery\(fixed=\.\.\.\)"):
                return run_gallery(
                    BASE, name, [value], fixed={"omega": 1.5}, progress=False, **TINY
                )

        return old_spelling
    return lambda: analyse_point(BASE, {"omega": 1.5, name: value}, TINY_SETTINGS)


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("name", [*FIELDS, *ALIASES])
def test_invalid_parameter_values_are_refused_everywhere(
    profile: dict[str, int], name: str
) -> None:
    """Every dotted parameter, with values no gear set accepts, as a fixed value, a swept or
    family axis, a gallery path and a point of ``analyse_point``."""

    @hsettings(profile["params"])
    @given(invalid_values(name), st.sampled_from(PARAMETER_DOORS))
    def check(value: Any, door: str) -> None:
        refused(f"parameter as {door}", _parameter_call(door, name, value), *culprits(name))

    check()


def test_unknown_parameter_names_are_refused_with_a_suggestion() -> None:
    for name in ("backlash.sunplanet", "omgea", "teeth", "xi.sun", "", "geometry.planets.x"):
        for door in PARAMETER_DOORS:
            if door in ("vary", "family") and not name:
                continue  # an empty axis name is refused as such (below)
            refused(f"parameter as {door}", _parameter_call(door, name, 1.0), "parameter", name)


# ----------------------------------------------------------------------------- Ω
def invalid_omega() -> st.SearchStrategy[Any]:
    """Ω must be a finite number in the plausible range [1e-6, 1e6] (> 0)."""
    return st.one_of(NOT_NUMBERS, NON_FINITE, reals_outside(1e-6, 1e6), st.just(0.0))


OMEGA_DOORS = {
    "simulate": lambda v: gc.simulate(BASE, omega=v, **TINY),
    "simulate(System)": lambda v: gc.simulate(SYSTEM, omega=v, **TINY),
    "bifurcation": lambda v: gc.bifurcation(
        BASE, "xi=0.05,0.07", params={"omega": v}, progress=False, **TINY
    ),
    "bifurcation(vary)": lambda v: gc.bifurcation(
        BASE, {"omega": [1.0, v]}, progress=False, **TINY
    ),
    "analyse_point": lambda v: analyse_point(BASE, {"omega": v}, TINY_SETTINGS),
    "analyse_point(default_omega)": lambda v: analyse_point(
        BASE, None, TINY_SETTINGS, default_omega=v
    ),
    "run_gallery": lambda v: run_gallery(BASE, "omega", [1.5, v], progress=False, **TINY),
}
#: Systems built directly: Ω a finite number > 0 (the plausible range applies where a target
#: is resolved at Ω: simulate, sweeps, galleries).
REFERENCE_OMEGA_DOORS = {
    "planetary_system": lambda v: gc.planetary_system(BASE, v),
    "duffing": lambda v: gc.duffing(v),
    "backlash_oscillator": lambda v: gc.backlash_oscillator(v),
    "linear_oscillator": lambda v: gc.linear_oscillator(v),
    "linear_system": lambda v: gc.linear_system([[0.0, 1.0], [-1.0, -0.1]], v),
    "System": lambda v: gc.System(DUFFING.model, v),
}


@pytest.mark.parametrize("profile", PROFILES)
def test_invalid_omega_is_refused_everywhere(profile: dict[str, int]) -> None:
    @hsettings(profile["omega"])
    @given(invalid_omega(), st.sampled_from(sorted(OMEGA_DOORS)))
    def check(value: Any, door: str) -> None:
        refused(door, lambda: OMEGA_DOORS[door](value), "omega")

    check()

    @hsettings(profile["omega"])
    @given(
        st.one_of(NOT_NUMBERS, NON_FINITE, reals_outside(0.0, None), st.just(0.0)),
        st.sampled_from(sorted(REFERENCE_OMEGA_DOORS)),
    )
    def check_reference(value: Any, door: str) -> None:
        refused(door, lambda: REFERENCE_OMEGA_DOORS[door](value), "omega")

    check_reference()


# ----------------------------------------------------------------------------- axis specs
_NUM = st.one_of(
    st.integers(-5, 5).map(str),
    st.floats(-10, 10, allow_nan=False).map(lambda x: f"{x:.3g}"),
)


@st.composite
def malformed_body(draw: st.DrawFn) -> str:
    """VALUES text that breaks the syntax: start:stop:count (count an integer in [1, 10⁶]),
    log:start:stop:count (positive bounds), a,b,c (no empty item), finite numbers only."""
    a, b = draw(_NUM), draw(_NUM)
    pos = draw(st.floats(1e-3, 10).map(lambda x: f"{x:.3g}"))
    count = draw(st.integers(1, 9))
    junk = draw(st.text(alphabet="xyzq!@#$%^&*()[]{}<>|~`'\"", min_size=1, max_size=6))
    bad_count = draw(
        st.one_of(
            st.sampled_from(["0", "-3", "1.5", "abc", "", " ", "1e3", "nan", "inf"]),
            st.integers(10**6 + 1, 10**30).map(str),
            st.integers(-(10**9), 0).map(str),
        )
    )
    bad_number = draw(st.sampled_from(["nan", "inf", "-inf", "1e400", "-1e999", "", "x", junk]))
    return draw(
        st.sampled_from(
            [
                f"{a}:{b}",  # two parts
                f"{a}:{b}:{count}:{count}",  # four parts
                f"{a}:{b}:{bad_count}",
                f"{bad_number}:{b}:{count}",
                f"{a}:{bad_number}:{count}",
                f"log:{pos}:{pos}",
                f"log:{pos}:{pos}:{bad_count}",
                f"log:-{pos}:{pos}:{count}",
                f"log:0:{pos}:{count}",
                f"log:{pos}:{bad_number}:{count}",
                f"{a},,{b}",
                f"{a},{b},,",
                f",{a}",
                ",",
                f"{a},{bad_number}",
                f"{bad_number}",
                junk,
                "",
                " ",
                f"{a}:{b}:{count}:",
                ":::",
                "log:",
            ]
        )
    )


AXIS_NAMES = st.sampled_from(["omega", "xi", "backlash.sun_planet", "torque.input"])


@st.composite
def malformed_spec(draw: st.DrawFn) -> tuple[str, tuple[str, ...]]:
    """(NAME=VALUES text, what the message may name) — malformed by construction."""
    name = draw(AXIS_NAMES)
    how = draw(st.sampled_from(["body", "no_equals", "no_name", "unknown"]))
    if how == "body":
        return f"{name}={draw(malformed_body())}", (name,)
    if how == "no_equals":
        return draw(st.sampled_from([name, f"{name}:1:2:3", f"{name} 1:2:3"])), ("NAME=VALUES",)
    if how == "no_name":
        return f"={draw(st.sampled_from(['1:2:3', '1,2', '']))}", ("name",)
    unknown = draw(st.text(alphabet="abcdefghij_.", min_size=1, max_size=10))
    if unknown in ("omega", "xi") or unknown in FIELDS:
        unknown += "_x"
    return f"{unknown}=1:2:2", ("unknown parameter",)


@pytest.mark.parametrize("profile", PROFILES)
def test_malformed_vary_and_family_specs_are_refused(profile: dict[str, int]) -> None:
    @hsettings(profile["specs"])
    @given(malformed_spec(), st.sampled_from(["vary", "family", "build vary", "build family"]))
    def check(spec: tuple[str, tuple[str, ...]], where: str) -> None:
        text, names = spec
        fixed = {"omega": 1.5} if not text.startswith("omega=") else {}
        if where == "vary":
            call = lambda: gc.bifurcation(BASE, text, params=fixed, progress=False, **TINY)  # noqa: E731
        elif where == "family":
            other = "xi=0.05,0.07" if not text.startswith("xi") else "backlash.sun_planet=1,2"
            call = lambda: gc.bifurcation(  # noqa: E731
                BASE, other, family=text, params=fixed, progress=False, **TINY
            )
        elif where == "build vary":
            call = lambda: SweepSpec.build(text)  # noqa: E731
            if "unknown parameter" in names:
                return  # SweepSpec knows no target: unknown names are the sweep's to refuse
        else:
            call = lambda: SweepSpec.build("omega=1:2:2", family=text)  # noqa: E731
            if "unknown parameter" in names:
                return
        refused(f"{where.split()[0]} spec", call, *names, "vary", "family", "axis")

    check()


def _huge_array() -> np.ndarray:
    return np.linspace(1.0, 2.0, 10**6 + 1)


#: vary/family values that are not a valid axis: wrong types, shapes, sizes and values.
def _number_vector(v: Any) -> bool:
    """A 1-D array or list of finite real numbers: valid axis values, not a bad object."""
    if isinstance(v, list) and v and not any(isinstance(x, bool) for x in v):
        v = np.asarray(v) if all(isinstance(x, int | float) for x in v) else None
    return (
        isinstance(v, np.ndarray)
        and v.ndim == 1
        and v.size > 0
        and v.dtype.kind in "fiu"
        and bool(np.all(np.isfinite(v)))
    )


BAD_AXIS_OBJECTS = st.one_of(
    st.sampled_from(
        [
            5,
            None,
            True,
            3.5,
            b"omega=1:2:3",
            object(),
            BASE,
            SYSTEM,
            [],
            ["omega=1:2:2", "xi=0.05,0.07", "backlash.sun_planet=1,2"],  # three axes
            ["omega=1:2:2", "omega=1:3:2"],  # one axis twice
            {"omega": np.ones((2, 2))},
            {"omega": []},
            {"omega": None},
            {"omega": "x"},
            {"omega": {1: 2}},
            {"omega": [True, False]},
            {"omega": np.array([1 + 1j])},
            {"omega": np.array(["1", "2"])},
            {"omega": [1.0, math.nan]},
            {"omega": [1.0, math.inf]},
            {"omega": [[1.0], [2.0]]},
            {"omega": 10**400},
            {5: [1.0, 2.0]},
            {None: [1.0]},
            ("omega", "1:2:2", "x"),
            [("omega",)],
            [(5, [1.0])],
            {"omega": (1.0, "x")},
        ]
    ),
    st.just("huge").map(lambda _: {"omega": _huge_array()}),
    st.dictionaries(  # text values are VALUES specifications (malformed ones: above)
        st.sampled_from(["omega", "xi"]),
        # not text (VALUES specifications, above) and not a vector of numbers (a valid axis)
        NOT_NUMBERS.filter(lambda v: not isinstance(v, str) and not _number_vector(v)),
        min_size=1,
        max_size=2,
    ),
)


@pytest.mark.parametrize("profile", PROFILES)
def test_vary_and_family_objects_of_the_wrong_kind_are_refused(profile: dict[str, int]) -> None:
    @hsettings(profile["objects"])
    @given(BAD_AXIS_OBJECTS, st.booleans())
    def check(obj: Any, as_family: bool) -> None:
        if as_family and (obj is None or (isinstance(obj, list) and not obj)):
            return  # family=None or []: no family
        if as_family:
            refused(
                "family spec",
                lambda: SweepSpec.build("backlash.sun_planet=1,2", family=obj),
                "family",
                "omega",
                "xi",
                "axis",
                "5",
                "None",
            )
        else:
            refused(
                "vary spec",
                lambda: gc.bifurcation(BASE, obj, progress=False, **TINY),
                "vary",
                "omega",
                "xi",
                "axis",
                "parameter",
            )

    check()


def test_an_axis_both_swept_and_fixed_or_family_is_refused() -> None:
    refused(
        "vary spec",
        lambda: gc.bifurcation(BASE, "omega=1:2:2", params={"omega": 1.5}, progress=False),
        "omega",
    )
    refused(
        "family spec",
        lambda: gc.bifurcation(BASE, "omega=1:2:2", family="omega=1,2", progress=False),
        "omega",
    )


@pytest.mark.parametrize(
    "text", ["log:1:inf:1", "log:inf:2:3", "0:inf:1", "-inf:1:5", "nan:1:2", "log:1:nan:4"]
)
def test_ranges_with_a_non_finite_bound_are_refused(text: str) -> None:
    """Found by the fuzz suite: ``log:1:inf:1`` was accepted (one value, 1.0), and linspace
    was asked for infinite ranges (numpy's RuntimeWarnings) before the values were refused."""
    from gearchaos.sweep.spec import parse_values

    with pytest.raises(gc.ParameterError, match="omega: the start and stop of a range must be"):
        parse_values("omega", text)
