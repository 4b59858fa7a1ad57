"""What a file records about its model (issue 36): a gear set is an input that builds the
planetary model, and every file records that model's reference as it records any other model
(``model_class``, ``model_fields``: the gear set's TOML), beside the ``gearset_toml`` that the
previous release reads. One reader (:func:`~gearchaos.model.record.recorded_target`) turns every
record, new or old, back into its target; a damaged or forged one is refused in one line naming
the file, the attribute and the rule.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

import gearchaos as gc
from gearchaos.errors import ParameterError
from gearchaos.gearset import GearSet, list_presets
from gearchaos.model import System
from gearchaos.model.loading import ModelConsentError, load_model_class, rebuild_model
from gearchaos.model.planetary import PlanetaryModel
from gearchaos.model.record import (
    model_record,
    record_problem,
    recorded_parameters,
    recorded_target,
    target_record,
)

#: The class a gear set's file names, spelled out here (not read from the code): gearchaos's
#: own planetary model.
PLANETARY = "gearchaos.model.planetary:PlanetaryModel"
EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "kahraman_singh_1991.py"
#: Gear sets whose record must round-trip: every preset, and one with changed values (a
#: store's gear set is often evolved).
GEARSETS = [name for name, _ in list_presets()]


def _gearset(name: str) -> GearSet:
    return gc.preset(name)


def _old(record: dict[str, Any]) -> dict[str, Any]:
    """The record as the previous release wrote it: no model reference."""
    return {k: v for k, v in record.items() if k not in ("model_class", "model_fields")}


# ------------------------------------------------------------------ round trips
@pytest.mark.parametrize("name", GEARSETS)
def test_a_gear_set_records_the_planetary_model_whose_fields_are_the_gear_set(name: str) -> None:
    gs = _gearset(name).evolve({"backlash.sun_planet": 7.5, "damping.sun_planet": 0.04})
    record = target_record(gs)
    assert record["model_class"] == PLANETARY
    fields = json.loads(record["model_fields"])
    assert set(fields) == {"gearset"}
    assert GearSet.from_toml_string(fields["gearset"]) == gs  # the gear set, every value
    # the previous release reads gearset_toml only: it is kept, the same gear set
    assert GearSet.from_toml_string(record["gearset_toml"]) == gs
    assert record_problem(record) is None
    assert recorded_target(record) == gs
    model = rebuild_model(record, where="f.nc")
    assert isinstance(model, PlanetaryModel) and model.gearset == gs
    assert model.parameters == PlanetaryModel.from_gearset(gs).parameters


def test_a_model_built_from_a_gear_set_records_the_same_reference() -> None:
    """A simulation, orbit or branch file records the model its System runs: built from a
    gear set, that is the gear set's record (also for a System the user built by hand)."""
    gs = gc.preset("hindawi2021")
    for system in (gc.planetary_system(gs, 1.3), System(PlanetaryModel.from_gearset(gs), 0.7)):
        assert model_record(system) == target_record(gs)
        assert target_record(system) == target_record(gs)


def test_a_user_model_round_trips_through_its_fields() -> None:
    cls = load_model_class(f"{EXAMPLE}:KahramanSingh1991")
    model = cls(zeta_h=0.07, b_p=0.25)
    record = target_record(System(model, 2.5))
    assert record["gearset_toml"] == "" and record["model_class"].endswith(":KahramanSingh1991")
    assert record_problem(record) is None
    back = recorded_target(record, where="f.nc")
    assert isinstance(back, System) and back.model == model and back.omega == 1.0
    params = recorded_parameters(record)
    assert params["zeta_h"] == 0.07 and params["b_p"] == 0.25 and "n_state" not in params
    assert recorded_parameters(target_record(gc.preset("hindawi2021"))) == {}


def test_a_reference_system_round_trips() -> None:
    system = gc.duffing(1.2)
    record = target_record(system)
    back = recorded_target(record)
    assert back.model == system.model and record_problem(record) is None


# ------------------------------------------------------------------ old records
@pytest.mark.parametrize("name", GEARSETS)
def test_an_old_record_without_the_model_reference_opens_as_before(name: str) -> None:
    gs = _gearset(name)
    old = _old(target_record(gs))
    assert "model_class" not in old and old["gearset_toml"]
    assert record_problem(old) is None
    assert recorded_target(old) == gs
    model = rebuild_model(old)
    assert isinstance(model, PlanetaryModel) and model.gearset == gs
    # and an invalid one is refused as it always was, naming the attribute
    with pytest.raises(ParameterError, match=r"old\.nc is damaged: .*gearset_toml"):
        recorded_target({**old, "gearset_toml": "[teeth]\nsun = -1\n"}, where="old.nc")


def test_the_stores_an_older_release_wrote_open() -> None:
    """The regression references were written before gear sets recorded their model."""
    from gearchaos.sweep.result import SweepResult

    root = Path(__file__).resolve().parents[1] / "regression" / "reference"
    res = SweepResult.open(root / "sweep_fresh.zarr")
    assert "model_class" not in res.ds.attrs
    assert res.base_gearset == GearSet.from_toml_string(res.ds.attrs["gearset_toml"])
    assert res.base_target == res.base_gearset


# ------------------------------------------------------------------ forged and damaged
def _fields(value: Any) -> str:
    return value if isinstance(value, str) else json.dumps(value)


@pytest.mark.parametrize(
    ("fields", "rule"),
    [
        ("{not json", r'must be the JSON object \{"gearset"'),
        ([1, 2], r'must be the JSON object \{"gearset"'),
        ({}, r"got the keys none"),
        ({"gearset": "<TOML>", "evil": 1}, r"got the keys evil, gearset"),
        ({"gearset": 5}, r"its gearset is 5"),
        ({"gearset": ""}, r"its gearset is ''"),
        ({"gearset": "[teeth]\nsun = -1\n"}, r"gear set of the attribute model_fields is invalid"),
    ],
)
def test_a_forged_planetary_record_is_refused_naming_the_rule(fields: Any, rule: str) -> None:
    """Before, a planetary reference was no trusted class: the file was refused for want of
    the user's consent, whatever its fields (or its fields were never read)."""
    gs = gc.preset("hindawi2021")
    if isinstance(fields, dict) and fields.get("gearset") == "<TOML>":
        fields = {**fields, "gearset": gs.to_toml()}
    forged = {**target_record(gs), "model_fields": _fields(fields)}
    problem = record_problem(forged)
    assert problem is not None and "model_fields" in problem
    for read in (recorded_target, rebuild_model):
        with pytest.raises(ParameterError, match=rule) as info:
            read(forged, where="forged.nc")
        assert not isinstance(info.value, ModelConsentError)
        message = str(info.value)
        assert message.startswith("forged.nc is damaged: ") and "\n" not in message
        assert "model_fields" in message


@pytest.mark.parametrize(
    ("gearset_toml", "shown"),
    [
        ("OTHER", r"records another \(.*differ\)"),  # another gear set
        ("EVOLVED", r"records another \(backlash\.sun_planet differs\)"),  # one value apart
        ("", r"records none"),  # the gear set dropped from gearset_toml
    ],
)
def test_a_record_whose_two_gear_sets_differ_is_refused(gearset_toml: str, shown: str) -> None:
    gs = gc.preset("hindawi2021")
    text = {
        "OTHER": gc.preset("sheng2016-v1").to_toml(),
        "EVOLVED": gs.evolve({"backlash.sun_planet": 9.0}).to_toml(),
        "": "",
    }[gearset_toml]
    damaged = {**target_record(gs), "gearset_toml": text}
    problem = record_problem(damaged)
    assert problem is not None and "gearset_toml" in problem and "model_fields" in problem
    for read in (recorded_target, rebuild_model):
        with pytest.raises(ParameterError, match=f"damaged.nc is damaged: .*{shown}"):
            read(damaged, where="damaged.nc")


def test_another_models_record_with_a_gear_set_is_refused() -> None:
    record = {**target_record(gc.duffing(1.0)), "gearset_toml": gc.preset("hindawi2021").to_toml()}
    problem = record_problem(record)
    assert problem is not None and "gearchaos.model.library:Duffing" in problem
    with pytest.raises(ParameterError, match=r"f\.nc is damaged: .*Duffing.*gearset_toml"):
        recorded_target(record, where="f.nc")


@pytest.mark.parametrize(
    ("change", "named"),
    [
        ({"model_class": 5}, "model_class"),
        ({"model_class": ""}, "model_class"),
        ({"model_fields": None}, "model_fields"),
        ({"model_class": None}, "model_fields has no model_class"),
    ],
)
def test_record_problem_checks_the_model_reference(change: dict[str, Any], named: str) -> None:
    record = target_record(gc.duffing(1.0))
    for key, value in change.items():
        if value is None:
            del record[key]
        else:
            record[key] = value
    problem = record_problem(record)
    assert problem is not None and named in problem
