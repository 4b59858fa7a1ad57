"""Metadata edited consistently is damage, not data (issue 33).

A float array re-typed ``<i8`` with ``fill_value: null`` — edited in its ``.zarray`` and in
``.zmetadata`` alike, as a careful forger or a careless script would — passed every check of
the store, and ``export`` wrote ``delta_sp=4614090374971014112`` (a float's bits read as an
integer) as data. The chunk manifest now holds a digest of every array's metadata
(``.zarray`` and ``.zattrs``), so any such edit is reported by the array's name.

Stores written before the digests (a manifest of chunks only) still open; for them the element
types the sweep's layout fixes (the swept and observed values and final states as floats, the
status, step counts and verdict codes as their integers) are checked instead. A Zarr branch of
``gearchaos continue`` keeps the digests of its metadata files beside its chunks' in the same
way.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fuzz_helpers import cli_refused, inside, refused

import gearchaos as gc
from gearchaos.sweep.integrity import MANIFEST

SHORT = {"transient_periods": 5, "periods": 4, "progress": False}


@pytest.fixture(scope="module")
def base(tmp_path_factory: pytest.TempPathFactory) -> Path:
    store = tmp_path_factory.mktemp("retyped") / "base.zarr"
    gc.bifurcation(gc.preset("sheng2016-v1"), "omega=1.2:2.0:3", store=store, **SHORT)
    return store


def _copy(base: Path, where: Path, *, old: bool = False) -> Path:
    """A copy of the store; ``old``: its manifest as versions before the digests wrote it."""
    store = where / "run.zarr"
    shutil.copytree(base, store)
    if old:
        manifest = json.loads((store / MANIFEST).read_text())
        (store / MANIFEST).write_text(json.dumps({"chunks": manifest["chunks"]}))
    return store


def edit(store: Path, key: str, **changes: Any) -> None:
    """Edit the metadata file ``key`` (``delta_sp/.zarray``) in place and in .zmetadata."""
    meta = {**json.loads((store / key).read_text()), **changes}
    (store / key).write_text(json.dumps(meta, indent=4))
    consolidated = json.loads((store / ".zmetadata").read_text())
    consolidated["metadata"][key] = meta
    (store / ".zmetadata").write_text(json.dumps(consolidated, indent=4))


def _compressor(store: Path, array: str) -> dict[str, Any]:
    comp = dict(json.loads((store / array / ".zarray").read_text())["compressor"])
    comp["clevel"] = 9 if comp.get("clevel") != 9 else 1
    return comp


def _dims(store: Path, array: str) -> list[str]:
    return list(reversed(json.loads((store / array / ".zattrs").read_text())["_ARRAY_DIMENSIONS"]))


#: (array, metadata file, the change): each reads the stored bytes as other numbers, or
#: labels them with other dimensions.
EDITS = [
    ("delta_sp", ".zarray", lambda s: {"dtype": "<i8", "fill_value": None}),
    ("final_state", ".zarray", lambda s: {"dtype": "<i8", "fill_value": None}),
    ("omega", ".zarray", lambda s: {"dtype": "<i8", "fill_value": None}),
    ("status", ".zarray", lambda s: {"dtype": "<i8"}),
    ("steps_accepted", ".zarray", lambda s: {"dtype": "<i4"}),
    ("lle", ".zarray", lambda s: {"compressor": _compressor(s, "lle")}),
    ("final_state", ".zattrs", lambda s: {"_ARRAY_DIMENSIONS": _dims(s, "final_state")}),
]


def test_export_of_a_retyped_float_array_is_refused(base: Path, tmp_path: Path) -> None:
    # export wrote delta_sp=4614090374971014112 with exit 0
    store = _copy(base, tmp_path)
    edit(store, "delta_sp/.zarray", dtype="<i8", fill_value=None)
    with inside(tmp_path / "out"):
        cli_refused("export retyped", ["export", str(store), "-o", "run.csv"], "delta_sp")
        cli_refused("plot retyped", ["plot", str(store), "-o", "run.png"], "delta_sp")


@pytest.mark.parametrize(("array", "file", "change"), EDITS, ids=[f"{a}/{f}" for a, f, _ in EDITS])
def test_any_consistent_edit_of_an_arrays_metadata_is_damage(
    base: Path, tmp_path: Path, array: str, file: str, change: Any
) -> None:
    store = _copy(base, tmp_path)
    edit(store, f"{array}/{file}", **change(store))
    err = refused(f"open_sweep {array}/{file}", lambda: gc.open_sweep(store), array)
    assert f"{array}/{file}" in str(err) and "changed since it was written" in str(err)


def test_an_array_the_manifest_does_not_know_is_damage(base: Path, tmp_path: Path) -> None:
    store = _copy(base, tmp_path)
    shutil.copytree(store / "lle", store / "lle_copy")
    consolidated = json.loads((store / ".zmetadata").read_text())
    for name in (".zarray", ".zattrs"):
        consolidated["metadata"][f"lle_copy/{name}"] = consolidated["metadata"][f"lle/{name}"]
    (store / ".zmetadata").write_text(json.dumps(consolidated, indent=4))
    refused("open_sweep unknown array", lambda: gc.open_sweep(store), "lle_copy")


# ------------------------------------------------------------ stores written before digests
def test_a_store_without_digests_still_opens_and_exports(base: Path, tmp_path: Path) -> None:
    store = _copy(base, tmp_path, old=True)
    ds = gc.open_sweep(store)
    reference = gc.open_sweep(base)
    assert np.array_equal(ds["delta_sp"].values, reference["delta_sp"].values, equal_nan=True)
    out = tmp_path / "run.csv"
    gc.export(store, out)
    assert out.stat().st_size > 0


@pytest.mark.parametrize(
    ("array", "changes", "want"),
    [
        ("delta_sp", {"dtype": "<i8", "fill_value": None}, "float64"),
        ("final_state", {"dtype": "<i8", "fill_value": None}, "float64"),
        ("status", {"dtype": "<i8"}, "int8"),
        ("steps_rejected", {"dtype": "<i4"}, "int64"),
    ],
)
def test_a_store_without_digests_is_checked_against_its_layout(
    base: Path, tmp_path: Path, array: str, changes: dict[str, Any], want: str
) -> None:
    store = _copy(base, tmp_path, old=True)
    edit(store, f"{array}/.zarray", **changes)
    err = refused(f"open_sweep old {array}", lambda: gc.open_sweep(store), array)
    assert f"writes it as {want}" in str(err)
    with inside(tmp_path / "out"):
        cli_refused(f"export old {array}", ["export", str(store), "-o", "run.csv"], array)


# ---------------------------------------------------------------------------- Zarr branches
@pytest.fixture(scope="module")
def branch(tmp_path_factory: pytest.TempPathFactory) -> Path:
    osc = gc.backlash_oscillator(1.0, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.2)
    path = tmp_path_factory.mktemp("branch") / "b.zarr"
    gc.save_branch(gc.continuation(osc, ("omega", 1.5, 1.6), max_points=4), path)
    return path


def test_a_retyped_array_of_a_zarr_branch_is_damage(branch: Path, tmp_path: Path) -> None:
    copy = tmp_path / "b.zarr"
    shutil.copytree(branch, copy)
    gc.open_branch(copy)  # intact: opens
    edit(copy, "omega/.zarray", dtype="<i8", fill_value=None)
    err = refused("open_branch retyped", lambda: gc.open_branch(copy), "b.zarr")
    assert "metadata file" in str(err) and "altered" in str(err)
