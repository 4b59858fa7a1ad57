"""Solver settings serialise themselves (issue 25): one record from the dataclass fields for
TOML, store attributes and result files; the round trip is exact for every field; the resume
check sees every setting; a refused setting carries its name, which the CLI maps to its option."""

from __future__ import annotations

import pickle
from pathlib import Path

import pytest

import gearchaos as gc
from gearchaos._checks import check_bool, check_choice, check_int, check_real
from gearchaos.cli._common import setting_option, solver_settings
from gearchaos.errors import ParameterError, StoreError
from gearchaos.integrate.settings import UNRECORDED, SolverSettings
from gearchaos.sweep import SweepSpec
from gearchaos.sweep.store import _spec_text

#: A value other than the default for every setting (and other than what its absence means).
CHANGED = {
    "transient_periods": 12.5,
    "periods": 7,
    "samples_per_period": 3,
    "section_phase": 0.7,
    "rtol": 3e-7,
    "atol": 2e-9,
    "max_steps": 123_457,
    "settle": "auto",
    "perturbation": 3e-5,
}
DEFAULT = SolverSettings()


def test_the_changed_values_cover_every_field_with_a_value_other_than_the_default() -> None:
    """A new setting must join CHANGED, so that the round trips below cover it."""
    assert set(CHANGED) == set(SolverSettings.field_names())
    for name, value in CHANGED.items():
        assert value != getattr(DEFAULT, name), name
        assert value != UNRECORDED.get(name, object()), name


@pytest.mark.parametrize("name", sorted(CHANGED))
def test_record_round_trip_is_exact_for_every_field(name: str) -> None:
    one = SolverSettings(**{name: CHANGED[name]})
    back = SolverSettings.from_record(one.to_record())
    assert back == one
    assert getattr(back, name) == CHANGED[name]
    assert type(getattr(back, name)) is type(CHANGED[name])
    everything = SolverSettings(**CHANGED)
    assert SolverSettings.from_record(everything.to_record()) == everything


def test_record_is_generated_from_the_fields_in_their_order() -> None:
    record = SolverSettings(**CHANGED).to_record()
    assert list(record) == list(SolverSettings.field_names())
    # what a record without a setting means is left out; nothing else is
    assert set(DEFAULT.to_record()) == {
        n for n in SolverSettings.field_names() if getattr(DEFAULT, n) != UNRECORDED.get(n, ...)
    }
    assert SolverSettings.from_record(DEFAULT.to_record()) == DEFAULT


def test_a_record_without_a_setting_means_what_older_results_used() -> None:
    old = {"transient_periods": 100.0, "periods": 100, "rtol": 1e-8, "atol": 1e-10}
    assert SolverSettings.from_record(old) == SolverSettings(
        transient_periods=100, periods=100, perturbation=0.0
    )
    with pytest.raises(ParameterError, match="periods") as info:
        SolverSettings.from_record({"transient_periods": 1.0, "rtol": 1e-8, "atol": 1e-10})
    assert info.value.name == "periods"


@pytest.mark.parametrize("name", sorted(CHANGED))
def test_sweep_toml_round_trip_is_exact_for_every_setting(name: str) -> None:
    # a response sweep may record more than one sample per period
    spec = SweepSpec.build("omega=1:2:3", response=True, **{name: CHANGED[name]})
    back = SweepSpec.from_toml(spec.to_toml())
    assert back == spec
    assert getattr(back.solver, name) == CHANGED[name]
    every = SweepSpec.build("omega=1:2:3", response=True, orbits=True, lyapunov=True, **CHANGED)
    assert SweepSpec.from_toml(every.to_toml()) == every
    assert every.to_toml() == SweepSpec.from_toml(every.to_toml()).to_toml()


def test_sweep_toml_written_before_issue_25_reads_and_compares_the_same() -> None:
    """A response store's text had its samples per period last; the resume check compares
    the specifications, not their layout."""
    spec = SweepSpec.build("omega=1:2:3", response=True)
    old = "\n".join(
        [
            'initial_conditions = "fresh"',
            'direction = "up"',
            "transient_periods = 100.0",
            "periods = 50",
            "rtol = 1e-08",
            "atol = 1e-10",
            "perturbation = 1e-06",
            "lyapunov = false",
            'observe = ["delta_sp", "delta_sp_dot"]',
            "planets = [1]",
            "verdicts = true",
            "response = true",
            "samples_per_period = 32",
            "",
            "[[vary]]",
            'name = "omega"',
            "values = [1.0, 1.5, 2.0]",
            "",
        ]
    )
    assert spec.solver.samples_per_period == 32
    assert SweepSpec.from_toml(old) == spec
    assert old != spec.to_toml()
    assert _spec_text(old) == spec.to_toml()


TINY = {"transient_periods": 2, "periods": 3}


def _sweep(path: Path, **kw: object) -> object:
    return gc.bifurcation(
        gc.duffing(1.2), "omega=1.0:1.2:2", store=path, progress=False, **{**TINY, **kw}
    )


def test_store_attributes_round_trip_every_setting(tmp_path: Path) -> None:
    changed = {k: v for k, v in CHANGED.items() if k not in ("samples_per_period", "periods")}
    ds = _sweep(tmp_path / "s.zarr", **changed)
    attrs = dict(gc.open_sweep(tmp_path / "s.zarr").attrs)
    spec = SweepSpec.from_toml(attrs["sweep_toml"])
    assert SolverSettings.from_record(attrs) == spec.solver
    for name, value in changed.items():
        assert attrs[name] == value, name
        assert getattr(spec.solver, name) == value, name
    assert ds is not None


@pytest.mark.parametrize(
    ("name", "first", "second"),
    [("max_steps", 200_000, 200_001), ("section_phase", 0.0, 0.5), ("settle", "off", "auto")],
)
def test_the_resume_check_sees_every_setting(
    tmp_path: Path, name: str, first: object, second: object
) -> None:
    path = tmp_path / "s.zarr"
    _sweep(path, **{name: first})
    _sweep(path, **{name: first})  # the same settings resume (here: it is complete)
    with pytest.raises(StoreError, match=f"other settings.*{name}"):
        _sweep(path, **{name: second})


# ----------------------------------------------------------------------------- names
def test_parameter_errors_carry_the_name_of_what_was_refused() -> None:
    for call, name in [
        (lambda: check_real("rtol", -1.0, lo=0.0), "rtol"),
        (lambda: check_real("backlash.sun_planet", "3"), "backlash.sun_planet"),
        (lambda: check_int("periods", 1.5), "periods"),
        (lambda: check_int("periods", 0, lo=1), "periods"),
        (lambda: check_bool("check", "yes"), "check"),
        (lambda: check_choice("settle", "sometimes", ("off", "auto")), "settle"),
        (lambda: SolverSettings(transient_periods=1e-9), "transient_periods"),
        (lambda: SolverSettings(samples_per_period=0), "samples_per_period"),
        (lambda: SolverSettings.build(None, rtoll=1e-8), "rtoll"),
    ]:
        with pytest.raises(ParameterError) as info:
            call()
        assert info.value.name == name
        assert name in str(info.value)
    assert ParameterError("no name").name is None


def test_the_name_survives_a_process_boundary() -> None:
    err = pickle.loads(pickle.dumps(ParameterError("rtol must be ...", name="rtol")))
    assert isinstance(err, ParameterError)
    assert (str(err), err.name) == ("rtol must be ...", "rtol")


def test_the_command_line_names_its_option_from_the_error_name() -> None:
    assert setting_option("transient_periods") == "--transient"
    assert setting_option("samples_per_period") == "--samples-per-period"
    assert setting_option("rtol") == "--rtol"
    assert setting_option("backlash.sun_planet") is None
    assert setting_option(None) is None
    for args, option in [
        ((100.0, 10, 1e-8, 1e-10, 0), "--samples-per-period"),
        ((100.0, 0, 1e-8, 1e-10), "--periods"),
        ((-1.0, 10, 1e-8, 1e-10), "--transient"),
        ((100.0, 10, 1.0, 1e-10), "--rtol"),
    ]:
        with pytest.raises(ParameterError) as info:
            solver_settings(*args)  # type: ignore[arg-type]
        assert str(info.value).startswith(f"{option}: ")
    with pytest.raises(ParameterError, match=r"^--settle: settle must be one of"):
        solver_settings(100.0, 10, 1e-8, 1e-10, settle="sometimes")
    with pytest.raises(ParameterError, match=r"^--perturbation: "):
        solver_settings(100.0, 10, 1e-8, 1e-10, perturbation=1.0)
