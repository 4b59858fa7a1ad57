"""One keyword vocabulary across the front doors (issue 25).

``settings=`` a :class:`SolverSettings` plus setting fields by name; ``params=`` a mapping of
dotted names to values plus parameters whose names are identifiers by name. Every door accepts
it and gives bitwise the same result whichever way a value is given; the spellings from before
(``fixed=``, ``solver=`` of the sweeps) still work for one release, with a DeprecationWarning
that names the new spelling.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
import pytest
import xarray as xr

import gearchaos as gc
from gearchaos.errors import ParameterError
from gearchaos.integrate.settings import SolverSettings
from gearchaos.sweep import SweepSpec

GS = gc.preset("hindawi2021")
OSC = gc.backlash_oscillator(1.0, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.2)
TINY = SolverSettings(transient_periods=2, periods=3)
VARY = "omega=1.2:1.4:2"


def _quiet(call: Any) -> Any:
    """``call()``, failing on any DeprecationWarning: the new spelling warns about nothing."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        return call()


def _same_dataset(a: xr.Dataset, b: xr.Dataset) -> None:
    assert sorted(a.variables) == sorted(b.variables)
    for name in a.variables:
        x, y = np.asarray(a[name].values), np.asarray(b[name].values)
        assert x.dtype == y.dtype and x.shape == y.shape, name
        assert x.tobytes() == y.tobytes(), name
    keep = {k for k in a.attrs if k not in ("version",)}
    assert {k: a.attrs[k] for k in keep} == {k: b.attrs[k] for k in keep}


# ----------------------------------------------------------------------------- simulate
def test_simulate_takes_settings_and_params() -> None:
    by_name = _quiet(lambda: gc.simulate(GS, omega=1.5, xi=0.05, transient_periods=2, periods=3))
    new = _quiet(
        lambda: gc.simulate(
            GS,
            settings=TINY.replace(samples_per_period=64),
            params={"omega": 1.5, "xi": 0.05},
        )
    )
    mixed = _quiet(
        lambda: gc.simulate(
            GS, settings=TINY, samples_per_period=64, omega=1.5, params={"xi": 0.05}
        )
    )
    for other in (new, mixed):
        _same_dataset(by_name.to_dataset(), other.to_dataset())
    assert by_name.system.model.gearset.damping.sun_planet == 0.05


def test_simulate_refuses_a_value_given_twice_and_settings_of_the_wrong_kind() -> None:
    with pytest.raises(ParameterError, match="given twice") as info:
        gc.simulate(GS, omega=1.5, params={"omega": 1.4}, settings=TINY)
    assert info.value.name == "omega"
    with pytest.raises(ParameterError, match="settings must be a SolverSettings"):
        gc.simulate(GS, omega=1.5, settings={"rtol": 1e-8})


# ----------------------------------------------------------------------------- sweeps
@pytest.mark.parametrize("door", ["bifurcation", "response"])
def test_sweeps_take_params_and_settings_and_the_old_spellings_warn(door: str) -> None:
    fn = getattr(gc, door)
    settings = TINY.replace(samples_per_period=4) if door == "response" else TINY
    new = _quiet(
        lambda: fn(GS, VARY, params={"backlash.sun_planet": 2.5}, settings=settings, progress=False)
    )
    by_name = _quiet(
        lambda: fn(
            GS, VARY, params={"backlash.sun_planet": 2.5}, progress=False, **settings.to_record()
        )
    )
    with pytest.warns(DeprecationWarning, match=rf"{door}\(fixed=\.\.\.\).*use params="):
        with pytest.warns(DeprecationWarning, match=rf"{door}\(solver=\.\.\.\).*use settings="):
            old = fn(GS, VARY, fixed={"backlash.sun_planet": 2.5}, solver=settings, progress=False)
    _same_dataset(new, old)
    _same_dataset(new, by_name)
    assert new.attrs["sweep_toml"] == old.attrs["sweep_toml"]


def test_a_sweep_takes_parameters_by_name() -> None:
    by_name = _quiet(lambda: gc.bifurcation(GS, VARY, xi=0.05, settings=TINY, progress=False))
    in_params = _quiet(
        lambda: gc.bifurcation(GS, VARY, params={"xi": 0.05}, settings=TINY, progress=False)
    )
    _same_dataset(by_name, in_params)
    assert dict(SweepSpec.from_toml(by_name.attrs["sweep_toml"]).fixed) == {"xi": 0.05}


def test_sweeps_refuse_both_spellings_at_once_and_unknown_names() -> None:
    with pytest.raises(ParameterError, match=r"give params= only \(fixed= is its deprecated"):
        gc.bifurcation(GS, VARY, params={"xi": 0.05}, fixed={"xi": 0.05}, progress=False)
    with pytest.raises(ParameterError, match=r"give settings= only"):
        gc.response(GS, VARY, settings=TINY, solver=TINY, progress=False)
    with pytest.raises(ParameterError, match="unknown sweep option 'rtoll'; did you mean 'rtol'"):
        gc.bifurcation(GS, VARY, rtoll=1e-6, progress=False)
    with pytest.raises(ParameterError, match="given twice") as info:
        gc.bifurcation(GS, VARY, xi=0.05, params={"xi": 0.07}, progress=False)
    assert info.value.name == "xi"


def test_sweep_spec_build_takes_the_vocabulary_too() -> None:
    new = _quiet(lambda: SweepSpec.build(VARY, params={"xi": 0.05}, settings=TINY))
    with pytest.warns(DeprecationWarning, match="use params="):
        with pytest.warns(DeprecationWarning, match="use settings="):
            old = SweepSpec.build(VARY, fixed={"xi": 0.05}, solver=TINY)
    assert new == old


# ----------------------------------------------------------------------------- galleries
def test_run_gallery_takes_params_and_settings_and_the_old_spelling_warns() -> None:
    import matplotlib.pyplot as plt

    from gearchaos.paper.galleries import run_gallery

    path: tuple[Any, ...] = (GS, "xi", [0.02, 0.05])
    fixed = {"omega": 1.5, "backlash.sun_planet": 2.5}

    def run(call: Any) -> tuple[list[dict[str, Any]], str]:
        fig, rows = call(progress=False)
        title = fig.get_suptitle()
        plt.close(fig)
        return rows, title

    new = _quiet(lambda: run(lambda **kw: run_gallery(*path, params=fixed, settings=TINY, **kw)))
    by_name = _quiet(
        lambda: run(
            lambda **kw: run_gallery(
                *path, omega=1.5, params={"backlash.sun_planet": 2.5}, **TINY.to_record(), **kw
            )
        )
    )
    mixed = _quiet(
        lambda: run(
            lambda **kw: run_gallery(
                *path,
                params={"backlash.sun_planet": 2.5},
                settings=TINY,
                omega=1.5,
                periods=3,
                **kw,
            )
        )
    )
    with pytest.warns(DeprecationWarning, match=r"run_gallery\(fixed=\.\.\.\).*use params="):
        old = run(lambda **kw: run_gallery(*path, fixed=fixed, settings=TINY, **kw))
    assert new == by_name == mixed == old
    assert [r["value"] for r in new[0]] == [0.02, 0.05]


# ----------------------------------------------------------------------------- orbits
def test_periodic_orbit_takes_settings_and_params() -> None:
    settings = SolverSettings(transient_periods=30, rtol=1e-9)
    by_name = _quiet(lambda: gc.periodic_orbit(OSC, omega=1.3, transient_periods=30, rtol=1e-9))
    new = _quiet(lambda: gc.periodic_orbit(OSC, settings=settings, params={"omega": 1.3}))
    assert by_name.state.tobytes() == new.state.tobytes()
    assert by_name.multipliers.tobytes() == new.multipliers.tobytes()


def test_continuation_takes_settings_and_params() -> None:
    kw: dict[str, Any] = {"max_points": 4}
    by_name = _quiet(
        lambda: gc.continuation(OSC, ("omega", 1.5, 1.6), transient_periods=30, zeta=0.06, **kw)
    )
    new = _quiet(
        lambda: gc.continuation(
            OSC,
            ("omega", 1.5, 1.6),
            settings=SolverSettings(transient_periods=30),
            params={"zeta": 0.06},
            **kw,
        )
    )
    _same_dataset(by_name, new)


def test_attractors_take_settings_and_params() -> None:
    settings = SolverSettings(transient_periods=20, periods=20)
    by_name = _quiet(
        lambda: gc.attractors(OSC, starts=2, omega=1.3, transient_periods=20, periods=20)
    )
    new = _quiet(lambda: gc.attractors(OSC, starts=2, settings=settings, params={"omega": 1.3}))
    assert len(by_name) == len(new)
    for a, b in zip(by_name, new, strict=True):
        assert a.sections.tobytes() == b.sections.tobytes()


UNKNOWN_NAMES = [
    ("simulate", lambda gs: gc.simulate(gs, omega=1.5, rtoll=1e-9), "rtoll", "rtol"),
    ("periodic_orbit", lambda gs: gc.periodic_orbit(gs, omega=1.5, perod=2), "perod", "period"),
    ("continuation", lambda gs: gc.continuation(gs, "omega=1:2", cascde=1), "cascde", "cascade"),
    ("attractors", lambda gs: gc.attractors(gs, omega=1.5, strats=4), "strats", "starts"),
    (
        "lyapunov_spectrum",
        lambda gs: gc.lyapunov_spectrum(gs, omega=1.5, n_exponent=2),
        "n_exponent",
        "n_exponents",
    ),
    ("simulate", lambda gs: gc.simulate(gs, omega=1.5, xii=0.05), "xii", "xi"),
    (
        "basins",
        lambda gs: gc.basins(gs, "x=-1:1:2", "x_dot=-1:1:2", omega=1.2, worker=2),
        "worker",
        "workers",
    ),
    (
        "basin_fractions",
        lambda gs: gc.basin_fractions(gs, "omega=1:1.2:2", strats=3),
        "strats",
        "starts",
    ),
]


@pytest.mark.parametrize(("door", "call", "wrong", "meant"), UNKNOWN_NAMES)
def test_a_misspelt_keyword_is_refused_naming_the_closest(door, call, wrong, meant) -> None:
    """A keyword that is neither a setting, a parameter nor one of the door's own keywords is
    refused before anything runs, naming the door and the closest of the three (the door's
    keywords read from its signature: `period` for periodic_orbit, not the setting `periods`)."""
    with pytest.raises(gc.ParameterError) as info:
        call(gc.preset("sheng2016-v1"))
    text = str(info.value)
    assert f"unknown {door} option {wrong!r}; did you mean {meant!r}?" in text
    assert info.value.name == wrong
