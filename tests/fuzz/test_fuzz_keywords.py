"""Fuzzing the keywords of every public Python function (issue 10): wrong types and values.

One row per (entry point, keyword): the function of ``gearchaos.__all__`` (and the main ones
behind it: ``integrate``, ``integrate_batch``, ``lyapunov_spectrum``, ``max_lyapunov``,
``analysis.analyse_point``, ``sweep.classify_store``, ``SweepSpec.build``,
``paper.galleries.run_gallery``, ``plot.sweep_figure`` on a store, the reference systems), the
keyword, generated values that break its documented rule (wrong types — bools, text, None where
it has no meaning, containers, huge integers — and out-of-range values), and what the message
must name. Every call must be refused with :class:`ParameterError`/:class:`StoreError` naming
the keyword, at once. The other arguments are valid and tiny (1 transient, 2 recorded periods),
so an input that slipped through would finish at once and fail as "accepted".
"""

from __future__ import annotations

import dataclasses
import inspect
import math
from collections.abc import Callable
from pathlib import Path
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

import gearchaos as gc
from gearchaos.dynamics.lyapunov import lyapunov_spectrum, max_lyapunov
from gearchaos.dynamics.verdict.point import analyse_point
from gearchaos.integrate import integrate, integrate_batch
from gearchaos.integrate.settings import SolverSettings
from gearchaos.model.target import parameter_names
from gearchaos.paper.galleries import MAX_GALLERY_VALUES, run_gallery
from gearchaos.sweep import SweepResult, SweepSpec, classify_store

BASE = gc.preset("hindawi2021")
TINY = {"transient_periods": 1, "periods": 2}
TINY_SETTINGS = SolverSettings(**TINY)
SYSTEM = gc.planetary_system(BASE, 1.5)  # 5 planets
DUFFING = gc.duffing(1.2)
VARY = "omega=1:2:2"

PROFILES = profiles({"rows": 8})

# ----------------------------------------------------------------------------- value kinds
NOT_BOOL = st.one_of(
    st.integers(-2, 2),
    st.floats(),
    st.text(max_size=5),
    st.sampled_from(["yes", "true", "False", None, [], [True], {}, np.int64(1), b"1"]),
)
#: What a ``target`` (GearSet or System) is not.
NOT_TARGET = st.one_of(
    st.none(),
    NOT_NUMBERS,
    st.sampled_from([DUFFING.model, BASE.to_dict(), BASE.to_toml(), "hindawi2021", [BASE]]),
)
NOT_SYSTEM = st.one_of(NOT_TARGET, st.just(BASE))
NOT_MAPPING = st.one_of(
    st.text(max_size=8),
    st.sampled_from(["xi=0.1", [("xi", 0.1)], 5, 1.5, True, (("xi", 0.1),), b"x", object()]),
)
NOT_SETTINGS = st.one_of(
    NOT_NUMBERS.filter(lambda v: not isinstance(v, dict)),
    st.sampled_from([{"rtol": 1e-6}, TINY, "default", 0, False]),
)
NOT_PATH = st.one_of(
    st.integers(),
    st.floats(),
    st.booleans(),
    st.binary(max_size=8),
    st.sampled_from(["", " ", "a\0b", ["x.zarr"], {"path": "x"}, object()]),
)
#: Observed variable lists that break the rule: names of variables, each once, at least one.
BAD_OBSERVE = st.one_of(
    st.sampled_from([[], (), [5], [""], ["nope"], ["delta_sp", "delta_sp"], 5, [None], [b"x"]]),
    st.lists(st.text(alphabet="xyzq", min_size=1, max_size=5), min_size=1, max_size=3),
)
#: Planet lists: 1-based planet numbers (hindawi2021 has 5), each once, at least one.
BAD_PLANETS = st.one_of(
    st.sampled_from(["1", "1,2", [1.5], [0], [-1], [1, 1], [6], [True], 5, [], [None], 1.0]),
    st.lists(st.integers(6, 10**30), min_size=1, max_size=3),
    st.lists(st.integers(-(10**30), 0), min_size=1, max_size=3),
)
NOT_CHOICE = st.one_of(
    st.text(max_size=12),
    st.sampled_from([None, 5, True, ["fresh"], "FRESH", " fresh", "Up", "both"]),
)
BAD_WORKERS = st.one_of(not_integers(), ints_outside(1, 4096))
BAD_SCHEDULER = st.one_of(
    st.text(alphabet="abcdefgh:/.1", max_size=12).filter(lambda s: "://" not in s),
    st.sampled_from([5, True, ["tcp://x:1"], b"tcp://x:1", {}]),
)
BAD_Y0 = st.one_of(
    NOT_NUMBERS.filter(lambda v: not isinstance(v, list) or len(v) != 16),
    st.lists(st.floats(-1, 1), max_size=15).filter(lambda v: len(v) != 16),
    st.sampled_from([np.full(16, np.nan), np.full(16, np.inf), np.zeros((4, 4)), np.zeros(17)]),
)
POSITIVE_REAL_BAD = st.one_of(NOT_NUMBERS, NON_FINITE, reals_outside(0.0, None, lo_ok=False))
NOT_STRING = st.one_of(
    st.integers(), st.floats(), st.booleans(), st.sampled_from([[], {}, b"x", ["omega"]])
)
UNKNOWN_OPTION = st.text(alphabet="abcdefghijklmnopqrstuvwxyz_", min_size=1, max_size=12)


# ----------------------------------------------------------------------------- the rows
class Row:
    def __init__(
        self,
        entry: str,
        keyword: str,
        call: Callable[[Any], object],
        values: st.SearchStrategy[Any],
        *culprits: str,
    ):
        self.entry, self.keyword, self.call, self.values = entry, keyword, call, values
        self.culprits = culprits or (keyword,)

    @property
    def id(self) -> str:
        return f"{self.entry}-{self.keyword}"


def _sim(**kw: Any) -> Any:
    return gc.simulate(BASE, **{"omega": 1.5, **TINY, **kw})


def _bif(**kw: Any) -> Any:
    return gc.bifurcation(BASE, VARY, **{"progress": False, **TINY, **kw})


def _resp(**kw: Any) -> Any:
    return gc.response(BASE, VARY, **{"progress": False, **TINY, **kw})


def _explore(**kw: Any) -> Any:
    from gearchaos.explore import explore

    return explore(**kw)


def _build(**kw: Any) -> Any:
    return SweepSpec.build(VARY, **kw)


#: The arguments of run_gallery that _gallery passes by name.
#: every keyword run_gallery names in its signature
_GALLERY_KEYWORDS = tuple(inspect.signature(run_gallery).parameters)


def _gallery(**kw: Any) -> Any:
    args = {"param": "omega", "values": [1.5], "progress": False, **TINY, **kw}
    gs = args.pop("gs", BASE)
    return run_gallery(gs, args.pop("param"), args.pop("values"), **args)


ROWS = [
    # simulate
    Row(
        "simulate",
        "system_or_gearset",
        lambda v: gc.simulate(v, omega=1.5, **TINY),
        NOT_TARGET,
        "target",
    ),
    Row("simulate", "y0", lambda v: _sim(y0=v), BAD_Y0),
    Row("simulate", "check", lambda v: _sim(check=v), NOT_BOOL),
    Row("simulate", "params", lambda v: _sim(params=v), NOT_MAPPING),
    Row("simulate", "settings", lambda v: _sim(settings=v), NOT_SETTINGS),
    # bifurcation and SweepSpec.build
    Row(
        "bifurcation",
        "target",
        lambda v: gc.bifurcation(v, VARY, progress=False, **TINY),
        NOT_TARGET.filter(lambda v: not isinstance(v, str) or v != ""),
        "target",
    ),
    Row("bifurcation", "params", lambda v: _bif(params=v), NOT_MAPPING),
    Row("bifurcation", "fixed", lambda v: _bif(fixed=v), NOT_MAPPING),  # deprecated: params
    Row("bifurcation", "store", lambda v: _bif(store=v), NOT_PATH, "store", "path"),
    Row("bifurcation", "overwrite", lambda v: _bif(overwrite=v), NOT_BOOL),
    Row("bifurcation", "progress", lambda v: _bif(progress=v), NOT_BOOL),
    Row("bifurcation", "observe", lambda v: _bif(observe=v), BAD_OBSERVE, "observe"),
    Row("bifurcation", "planets", lambda v: _bif(planets=v), BAD_PLANETS, "planet"),
    Row(
        "bifurcation",
        "initial_conditions",
        lambda v: _bif(initial_conditions=v),
        NOT_CHOICE.filter(lambda v: v not in ("fresh", "continuation")),
    ),
    Row(
        "bifurcation",
        "direction",
        lambda v: _bif(direction=v),
        NOT_CHOICE.filter(lambda v: v != "up"),
    ),
    Row("bifurcation", "lyapunov", lambda v: _bif(lyapunov=v), NOT_BOOL),
    Row("bifurcation", "workers", lambda v: _bif(workers=v), BAD_WORKERS),
    Row("bifurcation", "dask_local", lambda v: _bif(dask_local=v), BAD_WORKERS),
    Row("bifurcation", "scheduler", lambda v: _bif(scheduler=v), BAD_SCHEDULER),
    Row("bifurcation", "settings", lambda v: _bif(settings=v), NOT_SETTINGS),
    # deprecated spelling of settings
    Row("bifurcation", "solver", lambda v: _bif(solver=v), NOT_SETTINGS, "solver", "settings"),
    Row(
        "bifurcation",
        "<unknown option>",
        lambda v: _bif(**{v: 1}),
        UNKNOWN_OPTION.filter(lambda v: v not in _OPTIONS),
        "unknown",
    ),
    # response: a continuation sweep with the response quantities (the sweep's doors)
    Row(
        "response",
        "target",
        lambda v: gc.response(v, VARY, progress=False, **TINY),
        NOT_TARGET.filter(lambda v: not isinstance(v, str) or v != ""),
        "target",
    ),
    Row("response", "params", lambda v: _resp(params=v), NOT_MAPPING),
    Row("response", "fixed", lambda v: _resp(fixed=v), NOT_MAPPING),  # deprecated: params
    Row("response", "store", lambda v: _resp(store=v), NOT_PATH, "store", "path"),
    Row("response", "overwrite", lambda v: _resp(overwrite=v), NOT_BOOL),
    Row("response", "progress", lambda v: _resp(progress=v), NOT_BOOL),
    Row(
        "response",
        "direction",
        lambda v: _resp(direction=v),
        NOT_CHOICE.filter(lambda v: v not in ("up", "down", "both")),
    ),
    Row("response", "settings", lambda v: _resp(settings=v), NOT_SETTINGS),
    Row("response", "solver", lambda v: _resp(solver=v), NOT_SETTINGS, "solver", "settings"),
    Row(
        "response",
        "<unknown option>",
        lambda v: _resp(**{v: 1}),
        UNKNOWN_OPTION.filter(lambda v: v not in _OPTIONS),
        "unknown",
    ),
    # explore: the store is read (and refused) before any server starts
    Row("explore", "store", lambda v: _explore(store=v), NOT_PATH, "store", "path"),
    Row("SweepSpec.build", "params", lambda v: _build(params=v), NOT_MAPPING),
    Row("SweepSpec.build", "fixed", lambda v: _build(fixed=v), NOT_MAPPING),
    Row(
        "SweepSpec.build",
        "observe",
        lambda v: _build(observe=v),
        BAD_OBSERVE.filter(
            lambda v: (
                not (
                    isinstance(v, list)
                    and v
                    and all(isinstance(x, str) and x for x in v)
                    and len(set(v)) == len(v)
                )
            )
        ),
    ),
    Row(
        "SweepSpec.build",
        "planets",
        lambda v: _build(planets=v),
        BAD_PLANETS.filter(
            lambda v: (
                not (
                    isinstance(v, list)
                    and v
                    and all(isinstance(x, int) and not isinstance(x, bool) and x >= 1 for x in v)
                    and len(set(v)) == len(v)
                )
            )
        ),
        "planet",
    ),
    Row(
        "SweepSpec.build",
        "initial_conditions",
        lambda v: _build(initial_conditions=v),
        NOT_CHOICE.filter(lambda v: v not in ("fresh", "continuation")),
    ),
    Row("SweepSpec.build", "lyapunov", lambda v: _build(lyapunov=v), NOT_BOOL),
    Row("SweepSpec.build", "settings", lambda v: _build(settings=v), NOT_SETTINGS),
    Row(
        "SweepSpec.build", "solver", lambda v: _build(solver=v), NOT_SETTINGS, "solver", "settings"
    ),
    # integrate, integrate_batch
    Row("integrate", "system", lambda v: integrate(v, **TINY), NOT_SYSTEM),
    Row("integrate", "settings", lambda v: integrate(SYSTEM, v), NOT_SETTINGS),
    Row("integrate", "y0", lambda v: integrate(SYSTEM, TINY_SETTINGS, y0=v), BAD_Y0),
    Row(
        "integrate",
        "t0",
        lambda v: integrate(SYSTEM, TINY_SETTINGS, t0=v),
        st.one_of(NOT_NUMBERS, NON_FINITE),
    ),
    Row(
        "integrate",
        "max_step",
        lambda v: integrate(SYSTEM, TINY_SETTINGS, max_step=v),
        st.one_of(
            NOT_NUMBERS,
            NON_FINITE.filter(lambda v: v != math.inf),
            st.just(None),
            reals_outside(0.0, None, lo_ok=False),
        ),
    ),
    Row(
        "integrate",
        "first_step",
        lambda v: integrate(SYSTEM, TINY_SETTINGS, first_step=v),
        POSITIVE_REAL_BAD,
    ),
    Row(
        "integrate",
        "n_tangent",
        lambda v: integrate(SYSTEM, TINY_SETTINGS, n_tangent=v),
        st.one_of(not_integers(), ints_outside(0, SYSTEM.n_state)),
    ),
    Row(
        "integrate_batch",
        "systems",
        lambda v: integrate_batch(v, TINY_SETTINGS),
        st.one_of(NOT_SYSTEM, st.sampled_from([[], (), [SYSTEM, DUFFING], [SYSTEM, None]])),
    ),
    Row("integrate_batch", "settings", lambda v: integrate_batch([SYSTEM], v), NOT_SETTINGS),
    Row("integrate_batch", "y0", lambda v: integrate_batch([SYSTEM], TINY_SETTINGS, y0=v), BAD_Y0),
    Row(
        "integrate_batch",
        "max_step",
        lambda v: integrate_batch([SYSTEM], TINY_SETTINGS, max_step=v),
        st.one_of(NOT_NUMBERS, st.just(math.nan), reals_outside(0.0, None, lo_ok=False)),
    ),
    # Lyapunov exponents
    # a GearSet is a valid system here with omega= (without it: "omega is required", tested
    # in tests/cli/test_cli_start_24.py)
    Row("lyapunov_spectrum", "system", lambda v: lyapunov_spectrum(v, **TINY), NOT_TARGET),
    Row("lyapunov_spectrum", "settings", lambda v: lyapunov_spectrum(DUFFING, v), NOT_SETTINGS),
    Row(
        "lyapunov_spectrum",
        "n_exponents",
        lambda v: lyapunov_spectrum(DUFFING, TINY_SETTINGS, n_exponents=v),
        st.one_of(not_integers().filter(lambda v: v is not None), ints_outside(1, 2)),
    ),
    Row(
        "lyapunov_spectrum",
        "renormalizations_per_period",
        lambda v: lyapunov_spectrum(DUFFING, TINY_SETTINGS, renormalizations_per_period=v),
        st.one_of(not_integers(), ints_outside(1, 10**6)),
    ),
    Row(
        "lyapunov_spectrum",
        "y0",
        lambda v: lyapunov_spectrum(DUFFING, TINY_SETTINGS, y0=v),
        BAD_Y0.filter(lambda v: np.shape(v) != (2,) if not isinstance(v, str | bytes) else True),
    ),
    Row("max_lyapunov", "system", lambda v: max_lyapunov(v, **TINY), NOT_TARGET),
    # analyse_point
    Row(
        "analyse_point",
        "target",
        lambda v: analyse_point(v, {"omega": 1.5}, TINY_SETTINGS),
        NOT_TARGET,
        "target",
    ),
    Row("analyse_point", "values", lambda v: analyse_point(BASE, v, TINY_SETTINGS), NOT_MAPPING),
    Row(
        "analyse_point", "settings", lambda v: analyse_point(BASE, {"omega": 1.5}, v), NOT_SETTINGS
    ),
    Row(
        "analyse_point",
        "lyapunov",
        lambda v: analyse_point(BASE, {"omega": 1.5}, TINY_SETTINGS, lyapunov=v),
        NOT_BOOL,
    ),
    Row(
        "analyse_point",
        "check",
        lambda v: analyse_point(BASE, {"omega": 1.5}, TINY_SETTINGS, check=v),
        NOT_BOOL,
    ),
    # galleries
    Row("run_gallery", "gs", lambda v: _gallery(gs=v), NOT_TARGET, "target"),
    Row("run_gallery", "param", lambda v: _gallery(param=v), NOT_STRING),
    Row(
        "run_gallery",
        "values",
        lambda v: _gallery(values=v),
        st.one_of(
            st.sampled_from(["1.5", b"1", None, 1.5, [], {}, [None], ["1.5"], [True], [[1.5]]]),
            st.lists(st.one_of(NOT_NUMBERS, NON_FINITE), min_size=1, max_size=3),
            st.integers(MAX_GALLERY_VALUES + 1, 10**5).map(lambda n: np.linspace(1, 2, n)),
        ),
        "values",
    ),
    Row(
        "run_gallery",
        "params",
        lambda v: _gallery(param="xi", values=[0.05], params=v),
        NOT_MAPPING,
    ),
    Row(  # deprecated spelling of params
        "run_gallery", "fixed", lambda v: _gallery(param="xi", values=[0.05], fixed=v), NOT_MAPPING
    ),
    Row(
        "run_gallery",
        "with_",
        lambda v: _gallery(with_=v),
        st.one_of(
            st.text(min_size=1, max_size=8).filter(
                lambda s: (
                    {p.strip().lower() for p in s.split(",") if p.strip()} - {"phase", "spectrum"}
                )
            ),
            st.sampled_from([5, 1.5, True, ["x"], [5]]),
        ),
    ),
    Row("run_gallery", "progress", lambda v: _gallery(progress=v), NOT_BOOL),
    Row(
        "run_gallery",
        "planet",
        lambda v: _gallery(planet=v),
        st.one_of(not_integers(), ints_outside(1, 5)),
    ),
    Row("run_gallery", "title", lambda v: _gallery(title=v), NOT_STRING),
    Row("run_gallery", "settings", lambda v: _gallery(settings=v), NOT_SETTINGS),
    Row(
        "run_gallery",
        "<unknown option>",
        lambda v: _gallery(**{v: 1}),
        UNKNOWN_OPTION.filter(lambda v: v not in {*_OPTIONS, *_GALLERY_KEYWORDS}),
        "unknown",
    ),
    # files and stores
    Row("open_sweep", "path", lambda v: gc.open_sweep(v), NOT_PATH, "path", "store"),
    Row(
        "open_simulation",
        "path",
        lambda v: gc.open_simulation(v),
        NOT_PATH,
        "path",
        "simulation file",
    ),
    Row("classify_store", "store", lambda v: classify_store(v), NOT_PATH, "store", "path"),
    Row(
        "classify_store",
        "period_rtol",
        lambda v: classify_store("x.zarr", period_rtol=v),
        st.one_of(NOT_NUMBERS, NON_FINITE, reals_outside(0.0, 1.0, lo_ok=False, hi_ok=False)),
    ),
    Row(
        "classify_store",
        "max_period",
        lambda v: classify_store("x.zarr", max_period=v),
        st.one_of(not_integers(), ints_outside(1, 10_000)),
    ),
    Row("SweepResult.open", "path", lambda v: SweepResult.open(v), NOT_PATH, "path", "store"),
    Row(
        "SweepSpec.from_toml",
        "text",
        lambda v: SweepSpec.from_toml(v),
        st.one_of(
            st.text(max_size=200),
            st.sampled_from(["", "vary = []", "[[vary]]\nname = 5", 5, None, b"x"]),
        ),
        "sweep specification",
    ),
    Row("SweepResult", "ds", lambda v: SweepResult(v), NOT_TARGET, "Dataset"),
    Row(
        "preset",
        "name",
        lambda v: gc.preset(v),
        st.one_of(NOT_STRING, st.text(max_size=12), st.sampled_from(["../x", "a\0b", "Sheng2016"])),
        "preset",
    ),
    # reference systems and model constructors
    Row("duffing", "delta", lambda v: gc.duffing(1.0, delta=v), st.one_of(NOT_NUMBERS, NON_FINITE)),
    Row("duffing", "beta", lambda v: gc.duffing(1.0, beta=v), st.one_of(NOT_NUMBERS, NON_FINITE)),
    Row("lorenz", "rho", lambda v: gc.lorenz(rho=v), st.one_of(NOT_NUMBERS, NON_FINITE)),
    Row("lorenz", "sample_interval", lambda v: gc.lorenz(sample_interval=v), POSITIVE_REAL_BAD),
    Row(
        "backlash_oscillator",
        "zeta",
        lambda v: gc.backlash_oscillator(1.0, zeta=v),
        st.one_of(NOT_NUMBERS, NON_FINITE, reals_outside(0.0, None)),
    ),
    Row(
        "backlash_oscillator",
        "eps",
        lambda v: gc.backlash_oscillator(1.0, eps=v),
        st.one_of(NOT_NUMBERS, NON_FINITE, reals_outside(0.0, 1.0, hi_ok=False)),
    ),
    Row(
        "backlash_oscillator",
        "omega_power",
        lambda v: gc.backlash_oscillator(1.0, omega_power=v),
        st.one_of(NOT_NUMBERS, st.integers().filter(lambda n: n not in (0, 2)), st.just(2.5)),
    ),
    Row(
        "linear_oscillator",
        "zeta",
        lambda v: gc.linear_oscillator(1.0, zeta=v),
        st.one_of(NOT_NUMBERS, NON_FINITE),
    ),
    Row(
        "linear_system",
        "matrix",
        lambda v: gc.linear_system(v, 1.0),
        st.one_of(
            NOT_NUMBERS.filter(lambda v: not isinstance(v, np.ndarray)),
            st.sampled_from(
                [
                    [[1.0, 2.0]],
                    [],
                    [[]],
                    np.full((2, 2), np.nan),
                    np.array([[1 + 1j]]),
                    [[1.0], [2.0]],
                    [["a"]],
                ]
            ),
        ),
    ),
    Row(
        "linear_system",
        "cos_forcing",
        lambda v: gc.linear_system([[0.0, 1.0], [-1.0, 0.0]], 1.0, cos_forcing=v),
        st.one_of(
            NOT_NUMBERS.filter(  # a list or array of 2 numbers is valid
                lambda v: not (isinstance(v, list | np.ndarray) and len(v) == 2)
            ),
            st.sampled_from([[1.0], [math.nan, 0.0], np.zeros((2, 2))]),
        ),
    ),
    Row("planetary_system", "gs", lambda v: gc.planetary_system(v, 1.5), NOT_TARGET, "gs"),
    Row("nondimensionalise", "gs", lambda v: gc.nondimensionalise(v), NOT_TARGET, "gs"),
    Row(
        "System",
        "model",
        lambda v: gc.System(v, 1.0),
        NOT_TARGET.filter(lambda v: not hasattr(v, "pack")),
        "model",
    ),
]
_OPTIONS = {*SolverSettings.field_names(), "observe", "planets", "initial_conditions"}
_OPTIONS |= {"direction", "lyapunov", "workers", "scheduler", "dask_local", "solver"}
_OPTIONS |= {"target", "vary", "family", "fixed", "store", "overwrite", "progress"}
# every SweepSpec field is a keyword of the sweep functions too ('response' and 'orbits' were
# missing: hypothesis drew 'response' as an "unknown" option, a flaky failure)
_OPTIONS |= {f.name for f in dataclasses.fields(SweepSpec)}
# the one vocabulary (issue 25): params and settings, and parameters by name (xi, omega)
_OPTIONS |= {"params", "settings", *(n for n in parameter_names(BASE) if n.isidentifier())}


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("row", ROWS, ids=[r.id for r in ROWS])
def test_invalid_keyword_values_are_refused(
    profile: dict[str, int], row: Row, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)  # paths such as "x.zarr" never exist

    @hsettings(profile["rows"])
    @given(row.values)
    def check(value: Any) -> None:
        refused(row.entry, lambda: row.call(value), *row.culprits)

    check()
    assert not any(tmp_path.iterdir()), "a refused call wrote a file"


# ----------------------------------------------------------------------------- sweep_figure
@pytest.fixture(scope="module")
def small_store(tmp_path_factory: pytest.TempPathFactory) -> Any:
    path = tmp_path_factory.mktemp("figure") / "s.zarr"
    gc.bifurcation(
        BASE, "omega=0.8:2.4:7", store=path, transient_periods=10, periods=8, progress=False
    )
    return gc.open_sweep(path)


FIGURE_KEYWORDS = {
    "var": st.one_of(NOT_STRING.filter(lambda v: v is not None), st.sampled_from(["nope", "xi"])),
    "planet": st.one_of(not_integers(), ints_outside(1, 1)),  # the store observes planet 1
    "clearance_lines": NOT_BOOL,
    "resonances": NOT_BOOL,
    "max_count": st.one_of(not_integers(), ints_outside(1, 10_000)),
    "regimes": NOT_BOOL.filter(lambda v: v is not None),
    "figsize": st.one_of(
        NOT_NUMBERS.filter(lambda v: not isinstance(v, list)),
        st.tuples(
            st.one_of(NOT_NUMBERS, NON_FINITE, reals_outside(0.0, 200.0, lo_ok=False)),
            st.floats(1, 10),
        ),
        st.sampled_from([(1.0,), (1.0, 2.0, 3.0), (0, 1), (1e9, 1e9)]),
    ),
}


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("keyword", sorted(FIGURE_KEYWORDS))
def test_sweep_figure_refuses_invalid_options(
    profile: dict[str, int], keyword: str, small_store: Any
) -> None:
    from gearchaos.plot import sweep_figure

    @hsettings(profile["rows"])
    @given(FIGURE_KEYWORDS[keyword])
    def check(value: Any) -> None:
        refused("sweep_figure", lambda: sweep_figure(small_store, **{keyword: value}), keyword)

    check()
    refused("sweep_figure", lambda: sweep_figure(None), "Dataset")
