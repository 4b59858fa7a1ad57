"""Fuzzing the readers of sweep stores with damaged stores (issue 10).

Two small complete stores are built once per module (a 1-D Ω sweep, and a family × backlash
sweep at fixed Ω with Lyapunov exponents; 10 transient and 8 recorded periods) and one
interrupted store; copies are damaged in generated ways:

- chunks: a random chunk of a random array deleted, truncated, emptied, overwritten with
  other bytes of the same size, or lengthened;
- metadata: ``.zgroup``, ``.zattrs``, ``.zmetadata`` or an array's ``.zarray``/``.zattrs``
  deleted, replaced by junk bytes, by invalid JSON or by other JSON; an array that the
  consolidated metadata does not list;
- attributes (written consistently into ``.zattrs`` and ``.zmetadata``, as a careless script
  would): ``sweep_toml`` missing, an int, junk TOML or another sweep; ``gearset_toml`` a list,
  junk or empty; its model reference (``model_fields`` forged, junk or missing, ``model_class``
  junk, missing or another model's); ``omega_fixed`` 0, negative, a string or missing;
  ``periods`` missing, a string or another number; the ``status`` array missing; ``model``,
  ``dims``, ``complete``, ``rtol``, ``regime_table`` junk;
- the chunk manifest ``_manifest.json``: junk bytes, other JSON, a manifest of nothing, an
  entry of the wrong shape;
- an interrupted store: a chunk of a finished task damaged.

Every reader — :func:`gearchaos.open_sweep`, :meth:`SweepResult.open`,
:func:`gearchaos.sweep.classify_store`, ``gearchaos plot`` and ``gearchaos classify`` — must
report a :class:`StoreError` (exit 2) naming the store, and the chunk where a chunk is damaged,
within the time bound; none may change the store (no silent re-labelling) or write a figure.
"""

from __future__ import annotations

import itertools
import json
import os
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fuzz_helpers import (
    HOSTILE_FILES,
    cli_refused,
    hostile_file,
    hsettings,
    inside,
    profiles,
    refused,
)
from hypothesis import given, strategies as st

import gearchaos as gc
from gearchaos.errors import StoreError
from gearchaos.sweep import SweepResult, SweepSpec, classify_store
from gearchaos.sweep.integrity import MANIFEST, all_chunks

PROFILES = profiles({"damage": 6})
GROUPS = ["chunk", "metadata", "attribute", "manifest"]
SHORT = {"transient_periods": 10, "periods": 8, "progress": False}


# ----------------------------------------------------------------------------- base stores
@pytest.fixture(scope="module")
def bases(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("bases")
    gs = gc.preset("hindawi2021")
    omega = root / "omega.zarr"
    gc.bifurcation(gs, "omega=0.8:2.4:7", store=omega, **SHORT)
    family = root / "family.zarr"
    gc.bifurcation(
        gs,
        "backlash.sun_planet=1:3:3",
        family="xi=0.05,0.07",
        params={"omega": 1.5},
        store=family,
        lyapunov=True,
        **SHORT,
    )
    return {"omega": omega, "family": family}


@pytest.fixture(scope="module")
def interrupted(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A store of 3 tasks of which 2 finished (as a kill after the second would leave it)."""
    from gearchaos.integrate import run_chains
    from gearchaos.sweep.grid import Grid
    from gearchaos.sweep.run import _attrs, _coords, _Layout
    from gearchaos.sweep.store import SweepStore

    gs = gc.preset("hindawi2021")
    spec = SweepSpec.build("omega=0.8:2.4:9", transient_periods=10, periods=8)
    grid = Grid(gs, spec, chunk_points=3)
    layout = _Layout(grid)
    path = tmp_path_factory.mktemp("interrupted") / "partial.zarr"
    st_ = SweepStore(str(path))
    variables, chunks = layout.variables()
    st_.create(_coords(grid, layout), variables, chunks, _attrs(gs, grid))
    for t in list(grid.tasks())[:2]:
        run = grid.task_run(t)
        st_.write(t.index, t.block, layout.extract(t, run, run_chains(run)))
    return path


# ----------------------------------------------------------------------------- damage
def _chunks(store: Path) -> list[str]:
    return all_chunks(str(store))


def _set_attr(store: Path, name: str, value: Any, delete: bool = False) -> None:
    """Change an attribute consistently in .zattrs and in the consolidated .zmetadata."""
    attrs = json.loads((store / ".zattrs").read_text())
    zmeta = json.loads((store / ".zmetadata").read_text())
    if delete:
        attrs.pop(name, None)
    else:
        attrs[name] = value
    zmeta["metadata"][".zattrs"] = attrs
    (store / ".zattrs").write_text(json.dumps(attrs))
    (store / ".zmetadata").write_text(json.dumps(zmeta))


def _drop_array(store: Path, name: str) -> None:
    shutil.rmtree(store / name)
    zmeta = json.loads((store / ".zmetadata").read_text())
    for key in (f"{name}/.zarray", f"{name}/.zattrs"):
        zmeta["metadata"].pop(key, None)
    (store / ".zmetadata").write_text(json.dumps(zmeta))


def damage_chunk(draw: st.DrawFn, store: Path) -> str:
    """Damage one chunk; return its key (what the message must name)."""
    key = draw(st.sampled_from(_chunks(store)))
    path = store / key
    data = path.read_bytes()
    how = draw(st.sampled_from(["delete", "truncate", "empty", "flip", "append", "swap"]))
    if how == "delete":
        path.unlink()
    elif how == "truncate":
        path.write_bytes(data[: draw(st.integers(0, max(len(data) - 1, 0)))])
    elif how == "empty":
        path.write_bytes(b"")
    elif how == "flip":  # same size, other bytes: a silent wrong value without checksums
        path.write_bytes(bytes((b + 1) % 256 for b in data))
    elif how == "append":
        path.write_bytes(data + draw(st.binary(min_size=1, max_size=64)))
    else:  # another chunk's bytes (a plausible blosc stream with other numbers)
        others = [k for k in _chunks(store) if (store / k).read_bytes() != data]
        if not others:
            path.unlink()
        else:
            path.write_bytes((store / draw(st.sampled_from(others))).read_bytes())
    return key


def damage_metadata(draw: st.DrawFn, store: Path) -> str:
    arrays = sorted(p.name for p in store.iterdir() if (p / ".zarray").exists())
    files = [".zgroup", ".zattrs", ".zmetadata"]
    files += [f"{a}/{f}" for a in arrays for f in (".zarray", ".zattrs")]
    how = draw(st.sampled_from(["delete", "junk", "bad_json", "other_json", "extra_array"]))
    if how == "extra_array":
        src = draw(st.sampled_from(arrays))
        shutil.copytree(store / src, store / f"{src}_copy")
        return f"{src}_copy"
    rel = draw(st.sampled_from(files))
    path = store / rel
    if how == "delete":
        path.unlink()
    elif how == "junk":
        path.write_bytes(draw(st.binary(min_size=1, max_size=64)))
    elif how == "bad_json":
        path.write_text(draw(st.sampled_from(["{", "{junk", "[1,", "NaN NaN", ""])))
    else:
        old = json.loads(path.read_text())
        new = draw(st.sampled_from([{}, [], 5, "x", None, {"zarr_format": 3}]))
        if new == old:
            new = {"junk": 1}
        path.write_text(json.dumps(new))
    return rel


_OTHER_SPEC = SweepSpec.build("omega=1:2:3", transient_periods=10, periods=8).to_toml()
ATTRIBUTES: dict[str, list[Any]] = {
    "sweep_toml": ["<delete>", 5, "x = [1", "", _OTHER_SPEC, ["a"]],
    "gearset_toml": [[1, 2], "junk =", "", 5, "[teeth]\nsun = -1\n"],
    # the gear set's model reference (issue 36): forged fields, another class, half of it
    "model_fields": ["{}", '{"gearset": 5}', 5, "<delete>", '{"gearset": "x = 1"}', "{junk"],
    "model_class": [5, "", "<delete>", "gearchaos.model.library:Duffing"],
    "omega_fixed": [0, -1.5, "1.5", "<delete>", True, None, [1.5]],
    "periods": ["<delete>", "8", 9, 8.5, True, None],
    "transient_periods": ["<delete>", 11.0, "10"],
    "rtol": [2e-8, "1e-8", "<delete>"],
    "model": [5, "", None, "duffing"],
    "dims": [5, "omega", ["nope"], []],
    "complete": ["yes", 1, None],
    "regime_table": ["{junk", 5, "[]"],
    "<status array>": [None],
}


def damage_attribute(draw: st.DrawFn, store: Path) -> str:
    name = draw(st.sampled_from(sorted(ATTRIBUTES)))
    value = draw(st.sampled_from(ATTRIBUTES[name]))
    if name == "<status array>":
        _drop_array(store, "status")
        return "status"
    attrs = json.loads((store / ".zattrs").read_text())
    if value == "<delete>" and name not in attrs:  # omega_fixed of an Ω sweep: absent anyway
        value = 0
    _set_attr(store, name, value, delete=value == "<delete>")
    return ""


def damage_manifest(draw: st.DrawFn, store: Path) -> str:
    path = store / MANIFEST
    manifest = json.loads(path.read_text())
    key = draw(st.sampled_from(sorted(manifest["chunks"])))
    how = draw(st.sampled_from(["junk", "json", "empty", "entry", "dropped"]))
    if how == "junk":
        path.write_bytes(draw(st.binary(min_size=1, max_size=64)))
        return MANIFEST
    if how == "json":
        path.write_text(json.dumps(draw(st.sampled_from([[], 5, "x", {"chunks": 5}, {}]))))
        return MANIFEST
    if how == "empty":  # a manifest of nothing: every chunk on disk is unknown
        path.write_text(json.dumps({"chunks": {}}))
        return ""
    if how == "entry":
        manifest["chunks"][key] = draw(st.sampled_from(["x", 5, [1], [1, 2, 3], {"a": 1}]))
    else:  # one chunk no longer listed
        del manifest["chunks"][key]
    path.write_text(json.dumps(manifest))
    return key


DAMAGE: dict[str, Callable[[st.DrawFn, Path], str]] = {
    "chunk": damage_chunk,
    "metadata": damage_metadata,
    "attribute": damage_attribute,
    "manifest": damage_manifest,
}


# ----------------------------------------------------------------------------- readers
def _snapshot(store: Path) -> dict[str, bytes]:
    out = {}
    for d, _, files in os.walk(store):
        for f in files:
            p = Path(d) / f
            out[str(p.relative_to(store))] = p.read_bytes()
    return out


def every_reader_reports(store: Path, names: tuple[str, ...], work: Path) -> None:
    """All five readers refuse ``store`` naming it (and ``names``), changing nothing."""
    before = _snapshot(store)
    culprits = (str(store),)
    for entry, call in (
        ("open_sweep (damaged)", lambda: gc.open_sweep(store)),
        ("SweepResult.open (damaged)", lambda: SweepResult.open(store)),
        ("classify_store (damaged)", lambda: classify_store(store)),
    ):
        exc = refused(entry, call, *culprits, errors=(StoreError,))
        for name in names:
            assert name in str(exc), f"{entry}: {name!r} not named in {exc}"
    with inside(work):
        for args in (["plot", str(store), "-o", "f.png"], ["classify", str(store)]):
            text = cli_refused(f"CLI {args[0]} (damaged)", args, *culprits)
            for name in names:
                assert name in text, f"{args[0]}: {name!r} not named in {text}"
    assert _snapshot(store) == before, "a reader changed a damaged store"


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("base", ["omega", "family"])
@pytest.mark.parametrize("group", GROUPS)
def test_every_reader_reports_a_damaged_store(
    profile: dict[str, int], base: str, group: str, bases: dict[str, Path], tmp_path: Path
) -> None:
    serial = itertools.count()

    @hsettings(profile["damage"])
    @given(st.data())
    def check(data: st.DataObject) -> None:
        n = next(serial)
        store = tmp_path / f"d{n}.zarr"
        shutil.copytree(bases[base], store)
        culprit = DAMAGE[group](data.draw, store)
        names = (culprit,) if group == "chunk" or (group == "manifest" and "/" in culprit) else ()
        every_reader_reports(store, names, tmp_path / f"w{n}")

    check()


def test_the_base_stores_are_read_by_every_reader(bases: dict[str, Path], tmp_path: Path) -> None:
    """The undamaged copies pass every reader (the damage, not the store, is refused)."""
    from typer.testing import CliRunner

    from gearchaos.cli import app

    for name, base in bases.items():
        store = tmp_path / f"{name}.zarr"
        shutil.copytree(base, store)
        assert gc.open_sweep(store).status.size > 0
        classify_store(store)
        result = CliRunner().invoke(app, ["plot", str(store), "-o", str(tmp_path / "f.png")])
        assert result.exit_code == 0, result.output
        assert CliRunner().invoke(app, ["classify", str(store)]).exit_code == 0
        gc.open_sweep(store)  # still intact after re-labelling


@pytest.mark.parametrize("profile", PROFILES)
def test_a_damaged_finished_task_of_an_interrupted_store_is_reported(
    profile: dict[str, int], interrupted: Path, tmp_path: Path
) -> None:
    marker_chunks: list[str] = []
    for marker in sorted((interrupted / "_progress").glob("*.done")):
        chunks = json.loads(marker.read_text())["chunks"]
        marker_chunks += [k for k, v in chunks.items() if v is not None]
    serial = itertools.count()

    @hsettings(profile["damage"])
    @given(st.sampled_from(sorted(marker_chunks)), st.sampled_from(["delete", "flip", "empty"]))
    def check(key: str, how: str) -> None:
        n = next(serial)
        store = tmp_path / f"i{n}.zarr"
        shutil.copytree(interrupted, store)
        chunk = store / key
        if how == "delete":
            chunk.unlink()
        elif how == "flip":
            chunk.write_bytes(bytes((b + 1) % 256 for b in chunk.read_bytes()))
        else:
            chunk.write_bytes(b"")
        every_reader_reports(store, (key,), tmp_path / f"w{n}")

    check()
    # undamaged, the interrupted store is read (plotted with its missing points noted)
    ds = gc.open_sweep(interrupted)
    assert int(np.sum(ds.status.values == 4)) == 3


# ----------------------------------------------------------------------------- hostile paths
PATH_READERS: dict[str, Callable[[Path], object]] = {
    "open_sweep": lambda p: gc.open_sweep(p),
    "SweepResult.open": lambda p: SweepResult.open(p),
    "classify_store": lambda p: classify_store(p),
    "open_simulation": lambda p: gc.open_simulation(p),
}


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("kind", HOSTILE_FILES)
def test_hostile_paths_are_refused_by_every_python_reader(
    profile: dict[str, int], kind: str, tmp_path: Path
) -> None:
    """Missing paths, directories that are no store, FIFOs (never opened blocking), devices,
    binary, huge and junk files, link loops: a StoreError (or ParameterError) naming the path."""
    if kind.startswith("/dev/") and not os.path.exists(kind):
        pytest.skip(f"no {kind}")
    serial = itertools.count()

    @hsettings(profile["damage"])
    @given(st.data(), st.sampled_from(sorted(PATH_READERS)))
    def check(data: st.DataObject, reader: str) -> None:
        here = tmp_path / f"e{next(serial)}"
        here.mkdir()
        path = hostile_file(kind, here / "input.zarr", data.draw, huge_bytes=1 << 16)
        refused(f"{reader} (hostile path)", lambda: PATH_READERS[reader](path), str(path))

    check()
