"""Stores and files record the model reference of their gear set (issue 36): a sweep store or
orbit file written now names the planetary model, whose fields are the gear set, and opens in
every reader (``SweepResult``, ``gearchaos plot``, the explorer, ``--from``) as the gear set; a
file of the previous release (no model reference) opens exactly as before; a file whose two
copies of the gear set differ is refused as damaged, in one line.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

import gearchaos as gc
from forged_files import forge_nc
from gearchaos.cli import app
from gearchaos.dynamics.orbits.file import save_orbit
from gearchaos.errors import StoreError
from gearchaos.gearset import GearSet
from gearchaos.model.planetary import PlanetaryModel
from gearchaos.sweep.result import SweepResult

#: The class a gear set's file names (spelled out, not read from the code).
PLANETARY = "gearchaos.model.planetary:PlanetaryModel"
REFERENCE = ("model_class", "model_fields")


@pytest.fixture(scope="module")
def gearset() -> GearSet:
    return gc.preset("hindawi2021").evolve({"backlash.sun_planet": 3.0})


@pytest.fixture(scope="module")
def store(gearset: GearSet, tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("reference") / "s.zarr"
    gc.bifurcation(
        gearset, "omega=1.0:1.2:2", store=path, progress=False, verdicts=False,
        transient_periods=2, periods=4,
    )  # fmt: skip
    return path


def _forge_store(src: Path, dst: Path, **attrs: Any) -> Path:
    """A copy of the store ``src`` with root attributes changed (``None``: removed) in both
    metadata files (``.zattrs`` and the consolidated ``.zmetadata``), as an older writer or a
    forger would leave them."""
    shutil.copytree(src, dst)
    zattrs = json.loads((dst / ".zattrs").read_text())
    meta = json.loads((dst / ".zmetadata").read_text())
    for table in (zattrs, meta["metadata"][".zattrs"]):
        for key, value in attrs.items():
            if value is None:
                table.pop(key, None)
            else:
                table[key] = value
    (dst / ".zattrs").write_text(json.dumps(zattrs, indent=4))
    (dst / ".zmetadata").write_text(json.dumps(meta, indent=4))
    return dst


def _plot(path: Path, out: Path) -> Any:
    return CliRunner().invoke(app, ["plot", str(path), "-o", str(out)])


def test_a_store_written_now_records_the_planetary_model_of_its_gear_set(
    store: Path, gearset: GearSet
) -> None:
    res = SweepResult.open(store)
    attrs = res.ds.attrs
    assert attrs["model_class"] == PLANETARY
    assert GearSet.from_toml_string(json.loads(attrs["model_fields"])["gearset"]) == gearset
    assert GearSet.from_toml_string(attrs["gearset_toml"]) == gearset  # the previous release's
    assert res.base_gearset == gearset and res.base_target == gearset
    assert isinstance(res.base_model, PlanetaryModel) and res.base_model.gearset == gearset


def test_a_store_written_now_opens_in_the_plot_and_the_explorer(
    store: Path, gearset: GearSet, tmp_path: Path
) -> None:
    from gearchaos.explore.compute import point_target

    result = _plot(store, tmp_path / "f.png")
    assert result.exit_code == 0, result.output
    assert (tmp_path / "f.png").stat().st_size > 0
    target, values = point_target(SweepResult.open(store), {"omega": 1.2})
    assert target == gearset and values == {"omega": 1.2}


def test_a_store_of_the_previous_release_opens_as_before(
    store: Path, gearset: GearSet, tmp_path: Path
) -> None:
    old = _forge_store(store, tmp_path / "old.zarr", model_class=None, model_fields=None)
    res = SweepResult.open(old)
    assert not set(REFERENCE) & set(res.ds.attrs)
    assert res.base_gearset == gearset and res.base_target == gearset
    result = _plot(old, tmp_path / "f.png")
    assert result.exit_code == 0, result.output


def test_a_store_whose_two_gear_sets_differ_is_refused(store: Path, tmp_path: Path) -> None:
    other = json.dumps({"gearset": gc.preset("sheng2016-v1").to_toml()})
    damaged = _forge_store(store, tmp_path / "damaged.zarr", model_fields=other)
    with pytest.raises(StoreError, match=r"damaged\.zarr is damaged: .*gearset_toml.*model_fields"):
        SweepResult.open(damaged)
    result = _plot(damaged, tmp_path / "f.png")
    assert result.exit_code == 2 and "Traceback" not in result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and "gearset_toml" in lines[0]
    assert not (tmp_path / "f.png").exists()


def test_a_forged_planetary_record_in_a_store_is_refused(store: Path, tmp_path: Path) -> None:
    forged = _forge_store(store, tmp_path / "forged.zarr", model_fields='{"gearset": 5}')
    with pytest.raises(StoreError, match=r"forged\.zarr is damaged: .*model_fields"):
        SweepResult.open(forged)


# ------------------------------------------------------------------ an orbit file (--from)
@pytest.fixture(scope="module")
def orbit_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("orbit") / "orb.nc"
    orbit = gc.periodic_orbit(gc.preset("sheng2016-v1"), omega=0.5, period=1, transient_periods=2)
    save_orbit(orbit, path)
    return path


def test_an_orbit_file_starts_from_its_recorded_gear_set_new_or_old(
    orbit_file: Path, tmp_path: Path
) -> None:
    from gearchaos.cli._start import load_start

    gs = gc.preset("sheng2016-v1")
    old = forge_nc(orbit_file, tmp_path / "old.nc", model_class=None, model_fields=None)
    for path in (orbit_file, old):
        assert load_start(str(path), None).gearset == gs
    other = json.dumps({"gearset": gc.preset("hindawi2021").to_toml()})
    damaged = forge_nc(orbit_file, tmp_path / "damaged.nc", model_fields=other)
    with pytest.raises(StoreError, match=r"--from .*damaged\.nc is damaged: .*gearset_toml"):
        load_start(str(damaged), None)
