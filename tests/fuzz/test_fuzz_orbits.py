"""Fuzzing the orbit entry points and the newer commands (issue 10).

``gearchaos.periodic_orbit``, ``gearchaos.continuation``, ``gearchaos.export`` and
``analysis.branch.open_branch``; the commands ``orbit``, ``continue``, ``export`` and
``plot --branch``: generated invalid keyword and option values, malformed ``--vary`` ranges,
hostile files where a branch or a result is read, and damaged branch files (a deleted,
emptied, overwritten or added Zarr chunk, junk metadata, a damaged netCDF data chunk, a
truncated file). Every input must be refused at once — :class:`ParameterError` or
:class:`StoreError` naming the keyword, option or file (a damaged Zarr chunk by its name), or
exit code 2 with one ``error:`` line — never a traceback, never accepted, never a hang (see
:mod:`fuzz_helpers`). Invalid values are refused before any orbit is computed, so the valid
rest of each call is tiny (a Duffing oscillator, 2 transient periods, 3 branch points).
"""

from __future__ import annotations

import itertools
import math
import os
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fuzz_helpers import (
    HOSTILE_FILES,
    NON_FINITE,
    NOT_NUMBERS,
    cli_refused,
    hostile_file,
    hsettings,
    inside,
    ints_outside,
    not_integers,
    profiles,
    reals_outside,
    refused,
)
from hypothesis import given, strategies as st
from test_fuzz_api import invalid_setting
from test_fuzz_cli import SETTINGS_TEXT, int_text, invalid_set
from test_fuzz_keywords import (
    BAD_OBSERVE,
    BAD_Y0,
    NOT_BOOL,
    NOT_MAPPING,
    NOT_PATH,
    NOT_SETTINGS,
    NOT_TARGET,
    POSITIVE_REAL_BAD,
    Row,
)

import gearchaos as gc
from gearchaos.dynamics.continuation.branch import MANIFEST, open_branch, save_branch

PROFILES = profiles({"rows": 6, "options": 5, "files": 1, "damage": 3})
DUFFING = gc.duffing(1.0)
TINY = {"transient_periods": 2}
RANGE = "omega=1.0:1.2"


def _po(**kw: Any) -> Any:
    return gc.periodic_orbit(DUFFING, **{**TINY, **kw})


def _co(**kw: Any) -> Any:
    args = {"max_points": 3, **TINY, **kw}
    return gc.continuation(args.pop("target", DUFFING), args.pop("vary", RANGE), **args)


def _not_state(v: Any) -> bool:
    """Not a state of the Duffing oscillator (2 finite real numbers)."""
    if isinstance(v, str | bytes):
        return True
    try:
        a = np.asarray(v)
        return not (a.shape == (2,) and a.dtype.kind in "fiu" and np.all(np.isfinite(a)))
    except (ValueError, TypeError):
        return True


def _not_duffing_observe(v: Any) -> bool:
    names = (v,) if isinstance(v, str) else v
    if not isinstance(names, list | tuple) or not names or len(set(map(str, names))) < len(names):
        return True
    return not all(isinstance(n, str) and n in ("x", "x_dot") for n in names)


#: Ranges ``vary`` must refuse: malformed text, wrong shapes and types, an empty range, ends
#: that are no numbers or no valid values of the parameter, an unknown parameter.
BAD_VARY = st.one_of(
    st.sampled_from(
        [
            "",
            "omega",
            "omega=",
            "omega=1",
            "omega=1:1",
            "omega=a:b",
            "omega=1:2:3",
            "=1:2",
            "omega=nan:2",
            "omega=1:inf",
            "omega=-1:2",
            "omega=1:1e308",
            "nope=1:2",
            5,
            None,
            b"omega=1:2",
            ("omega",),
            ("omega", 1.0),
            ("omega", "a", 2.0),
            ("omega", True, 2.0),
            (5, 1.0, 2.0),
            {"omega": 5},
            {"omega": (1.0,)},
            {"omega": (1.0, 2.0), "delta": (0.1, 0.2)},
            {},
        ]
    ),
    st.text(alphabet="abcmoeg=:;,. xyz", max_size=12),
)
VARY_CULPRITS = ("vary", "omega", "nope", "parameter")

ROWS = [
    Row("periodic_orbit", "target", lambda v: gc.periodic_orbit(v, **TINY), NOT_TARGET, "target"),
    Row(
        "periodic_orbit",
        "period",
        lambda v: _po(period=v),
        st.one_of(not_integers(), ints_outside(1, 10_000)),
    ),
    Row("periodic_orbit", "guess", lambda v: _po(guess=v), BAD_Y0.filter(_not_state)),
    Row(
        "periodic_orbit",
        "tol",
        lambda v: _po(tol=v),
        st.one_of(NOT_NUMBERS, NON_FINITE, reals_outside(0.0, 0.1, lo_ok=False)),
    ),
    Row(
        "periodic_orbit",
        "max_iterations",
        lambda v: _po(max_iterations=v),
        st.one_of(not_integers(), ints_outside(1, 10_000)),
    ),
    Row("periodic_orbit", "params", lambda v: _po(params=v), NOT_MAPPING),
    Row(
        "periodic_orbit", "settings", lambda v: _po(settings=v), NOT_SETTINGS, "settings", "solver"
    ),
    *(
        Row("periodic_orbit", name, lambda v, name=name: _po(**{name: v}), invalid_setting(name))
        for name in ("transient_periods", "rtol", "atol", "section_phase", "max_steps")
    ),
    Row("periodic_orbit", "omega", lambda v: _po(omega=v), st.one_of(NOT_NUMBERS, NON_FINITE)),
    Row("continuation", "target", lambda v: _co(target=v), NOT_TARGET, "target"),
    Row("continuation", "vary", lambda v: _co(vary=v), BAD_VARY, *VARY_CULPRITS),
    Row(
        "continuation",
        "period",
        lambda v: _co(period=v),
        st.one_of(not_integers(), ints_outside(1, 10_000)),
    ),
    *(
        Row("continuation", name, lambda v, name=name: _co(**{name: v}), POSITIVE_REAL_BAD)
        for name in ("step", "min_step", "max_step", "event_tol")
    ),
    Row(
        "continuation",
        "max_points",
        lambda v: _co(max_points=v),
        st.one_of(not_integers(), ints_outside(2, 10**6)),
    ),
    Row(
        "continuation",
        "max_corrector",
        lambda v: _co(max_corrector=v),
        st.one_of(not_integers(), ints_outside(2, 1000)),
    ),
    Row(
        "continuation",
        "tol",
        lambda v: _co(tol=v),
        st.one_of(NOT_NUMBERS, NON_FINITE, reals_outside(0.0, 0.1, lo_ok=False)),
    ),
    Row(
        "continuation",
        "grid",
        lambda v: _co(grid=v),
        st.one_of(
            st.sampled_from(["x", "1.1", [math.nan], [1.0, math.inf], [[1.0], [2.0, 3.0]]]),
            st.sampled_from([{"a": 1}, [None], [True], [1 + 1j], b"1", object()]),
        ),
    ),
    Row(
        "continuation",
        "observe",
        lambda v: _co(observe=v),
        BAD_OBSERVE.filter(_not_duffing_observe),
    ),
    Row(
        "continuation",
        "store",
        lambda v: _co(store=v),
        st.one_of(NOT_PATH, st.sampled_from(["b.txt", "b", "b.zarr/", "a\0b.nc"])),
        "store",
    ),
    Row("continuation", "overwrite", lambda v: _co(overwrite=v), NOT_BOOL),
    Row(
        "continuation",
        "start",
        lambda v: _co(start=v),
        st.one_of(
            NOT_NUMBERS.filter(_not_state), st.sampled_from([[1.0], [math.nan, 0.0], "x", 5])
        ),
    ),
    Row("continuation", "params", lambda v: _co(params=v), NOT_MAPPING),
    Row("continuation", "settings", lambda v: _co(settings=v), NOT_SETTINGS, "settings", "solver"),
    Row(
        "export",
        "source",
        lambda v: gc.export(v, "o.csv"),
        st.one_of(NOT_PATH, st.sampled_from(["missing.zarr", "missing.nc", None, 5])),
        "source",
        "result",
    ),
    Row(
        "export",
        "path",
        lambda v: gc.export("missing.zarr", v),
        st.one_of(NOT_PATH, st.sampled_from(["o.txt", "o", "o.csv.gz", "a\0b.csv", None])),
        "output",
        "format",
    ),
    Row(
        "export",
        "to",
        lambda v: gc.export("missing.zarr", "o.csv", to=v),
        st.one_of(
            st.text(max_size=6).filter(lambda s: s not in ("csv", "mat")),
            st.sampled_from([5, True, ["csv"], b"csv", "CSV", " csv"]),
        ),
        "format",
    ),
    Row("open_branch", "path", lambda v: open_branch(v), NOT_PATH, "branch"),
]


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("row", ROWS, ids=[r.id for r in ROWS])
def test_invalid_orbit_and_export_keywords_are_refused(
    profile: dict[str, int], row: Row, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Refused before any orbit is computed, by name; nothing written."""
    monkeypatch.chdir(tmp_path)

    @hsettings(profile["rows"])
    @given(row.values)
    def check(value: Any) -> None:
        refused(row.entry, lambda: row.call(value), *row.culprits)

    check()
    assert not any(tmp_path.iterdir()), "a refused call wrote a file"


def test_unknown_names_and_conflicts_are_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    base = gc.preset("hindawi2021")
    refused("periodic_orbit", lambda: _po(nope=1.0), "nope")
    refused("periodic_orbit", lambda: _po(params={"nope": 1.0}), "nope")
    refused("periodic_orbit", lambda: _po(params={"delta": 0.1}, delta=0.2), "delta")
    refused(
        "periodic_orbit",
        lambda: gc.periodic_orbit(base, omega=1.5, xi="0.1", **TINY),
        "xi",
        "damping",
    )
    refused("continuation", lambda: _co(omega=1.1), "omega")
    refused("continuation", lambda: _co(start=[0.0, 0.0], vary="omega=1.0:1.2", period=0), "period")
    (tmp_path / "b.nc").write_text("x")
    refused("continuation", lambda: _co(store="b.nc"), "b.nc")


# ----------------------------------------------------------------------------- the commands
TINY_CLI = ["--transient", "2"]
BASE = {
    "orbit": ["orbit", *TINY_CLI],
    "continue": [
        "continue",
        *("-o", "b.nc", "--vary", "omega=1.4:1.5", "--max-points", "3", *TINY_CLI, "-q"),
    ],
    "export": ["export", "missing.zarr", "-o", "o.csv"],
}
OPTION_ROWS: list[tuple[str, str, Any, tuple[str, ...]]] = [
    *(
        (cmd, opt, text, (opt,))
        for cmd in ("orbit", "continue")
        for opt, text in SETTINGS_TEXT.items()
        if opt != "--periods"
    ),
    ("orbit", "--period", int_text(1, 64), ("--period",)),
    ("continue", "--period", int_text(1, 10_000), ("--period", "period")),
    ("continue", "--max-points", int_text(2, 10**6), ("--max-points", "max_points")),
    (
        "continue",
        "--vary",
        BAD_VARY.filter(lambda v: isinstance(v, str)),
        ("--vary", *VARY_CULPRITS),
    ),
    (
        "continue",
        "-o",
        st.sampled_from(["", " ", "b.txt", "b", ".", "b.nc/x.txt"]),
        ("--output", "store"),
    ),
    (
        "export",
        "--to",
        st.text(max_size=6).filter(lambda s: s not in ("csv", "mat")),
        ("format", "--to"),
    ),
    (
        "export",
        "-o",
        st.sampled_from(["", " ", "o.txt", "o", "."]),
        ("--output", "output", "format"),
    ),
]


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize(
    ("command", "option", "values", "names"),
    OPTION_ROWS,
    ids=[f"{c}{o}" for c, o, *_ in OPTION_ROWS],
)
def test_invalid_options_of_orbit_continue_export_exit_2(
    profile: dict[str, int],
    command: str,
    option: str,
    values: Any,
    names: tuple[str, ...],
    tmp_path: Path,
) -> None:
    serial = itertools.count()

    @hsettings(profile["options"])
    @given(values)
    def check(text: str) -> None:
        args = [a for a in BASE[command]]
        if option in args:  # replace the valid value
            i = args.index(option)
            args[i + 1] = text
        else:
            args += [option, text]
        with inside(tmp_path / f"e{next(serial)}"):
            cli_refused(f"CLI {command}", args, *names)

    check()


@pytest.mark.parametrize("profile", PROFILES)
def test_invalid_set_of_orbit_and_continue_exits_2(profile: dict[str, int], tmp_path: Path) -> None:
    serial = itertools.count()

    @hsettings(profile["options"] * 5)
    @given(invalid_set(), st.sampled_from(["orbit", "continue"]))
    def check(item: tuple[str, tuple[str, ...]], command: str) -> None:
        text, names = item
        args = [*BASE[command], "--set", text]
        with inside(tmp_path / f"e{next(serial)}"):
            cli_refused(f"CLI {command}", args, *names, "omega", "continued")

    check()


# ----------------------------------------------------------------------------- files
@pytest.fixture(scope="module")
def branch_files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A small sweep store and a Duffing branch as .zarr and .nc (undamaged)."""
    root = tmp_path_factory.mktemp("branches")
    sweep = root / "s.zarr"
    gc.bifurcation(
        gc.preset("hindawi2021"),
        "omega=1:2:2",
        store=sweep,
        transient_periods=1,
        periods=2,
        progress=False,
    )
    ds = gc.continuation(DUFFING, RANGE, max_points=4, transient_periods=20)
    files = {"sweep": sweep}
    for kind in ("zarr", "nc"):
        files[kind] = Path(save_branch(ds, root / f"b.{kind}"))
    return files


def test_undamaged_branches_are_read(branch_files: dict[str, Path]) -> None:
    """The damage tests below must fail only for the damage: the files as written are read."""
    for kind in ("zarr", "nc"):
        ds = open_branch(branch_files[kind])
        assert ds.attrs["parameter"] == "omega" and ds.sizes["point"] >= 2


BRANCH_DOORS = {
    "open_branch": lambda p, files: refused("open_branch", lambda: open_branch(p), str(p)),
    "export (Python)": lambda p, files: refused(
        "export", lambda: gc.export(p, Path(p).parent / "o.csv"), str(p)
    ),
    "CLI plot --branch": lambda p, files: cli_refused(
        "CLI plot", ["plot", str(files["sweep"]), "-o", "f.png", "--branch", str(p)], str(p)
    ),
    "CLI export": lambda p, files: cli_refused(
        "CLI export", ["export", str(p), "-o", "o.csv"], str(p)
    ),
}


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("kind", HOSTILE_FILES)
def test_hostile_files_where_a_branch_or_result_is_read(
    profile: dict[str, int], kind: str, tmp_path: Path, branch_files: dict[str, Path]
) -> None:
    """Missing, directories, FIFOs (never opened blocking), devices, binary, huge, empty,
    link loops: refused naming the file."""
    if kind.startswith("/dev/") and not os.path.exists(kind):
        pytest.skip(f"no {kind}")
    serial = itertools.count()

    @hsettings(profile["files"])
    @given(st.data(), st.sampled_from(sorted(BRANCH_DOORS)))
    def check(data: st.DataObject, door: str) -> None:
        with inside(tmp_path / f"e{next(serial)}") as here:
            suffix = data.draw(st.sampled_from([".nc", ".zarr"]))
            path = hostile_file(kind, here / f"input{suffix}", data.draw, huge_bytes=1 << 16)
            BRANCH_DOORS[door](path, branch_files)

    check()


def _damage_zarr(path: Path, how: str, draw: Any) -> str:
    """Damage a Zarr branch; returns what the message must name."""
    import json

    chunks = sorted(json.loads((path / MANIFEST).read_text()))
    chunk = draw(st.sampled_from(chunks))
    if how == "deleted chunk":
        (path / chunk).unlink()
    elif how == "emptied chunk":
        (path / chunk).write_bytes(b"")
    elif how == "junk chunk":
        (path / chunk).write_bytes(draw(st.binary(min_size=1, max_size=200)))
    elif how == "flipped byte":
        data = bytearray((path / chunk).read_bytes())
        i = draw(st.integers(0, len(data) - 1))
        data[i] ^= draw(st.integers(1, 255))
        (path / chunk).write_bytes(bytes(data))
    elif how == "added chunk":
        # beside a data chunk (the manifest also lists the arrays' metadata files, whose
        # names start with a dot, since it digests them)
        data_chunks = [c for c in chunks if "/" in c and not c.rsplit("/", 1)[1].startswith(".")]
        chunk = draw(st.sampled_from(data_chunks))
        name = chunk.rsplit("/", 1)[0] + "/7"
        (path / name).write_bytes(b"\0" * 8)
        return name
    elif how == "junk manifest":
        (path / MANIFEST).write_text(draw(st.sampled_from(["", "[1]", '{"a": 5}', "{"])))
        return "manifest"
    elif how == "deleted manifest":
        (path / MANIFEST).unlink()
        return "manifest"
    elif how == "junk metadata":
        (path / ".zmetadata").write_bytes(draw(st.sampled_from([b"", b"{", b"[]", b"\xff"])))
        return str(path)
    elif how == "deleted metadata":
        (path / ".zmetadata").unlink()
        return str(path)
    return chunk


ZARR_DAMAGE = [
    "deleted chunk",
    "emptied chunk",
    "junk chunk",
    "flipped byte",
    "added chunk",
    "junk manifest",
    "deleted manifest",
    "junk metadata",
    "deleted metadata",
]
NC_DAMAGE = ["data chunk", "truncated", "junk", "empty"]


def _damage_nc(path: Path, how: str, draw: Any) -> None:
    import h5py

    data = bytearray(path.read_bytes())
    if how == "data chunk":  # a byte of a data chunk: the Fletcher-32 checksum must catch it
        with h5py.File(path, "r") as f:
            names = sorted(n for n in f if f[n].chunks is not None and f[n].fletcher32)
            info = f[draw(st.sampled_from(names))].id.get_chunk_info(0)
        i = info.byte_offset + draw(st.integers(0, info.size - 1))
        data[i] ^= draw(st.integers(1, 255))
    elif how == "truncated":
        data = data[: draw(st.integers(0, len(data) - 1))]
    elif how == "junk":
        data = bytearray(draw(st.binary(min_size=1, max_size=4000)))
    else:
        data = bytearray()
    path.write_bytes(bytes(data))


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize(
    "how", [*(f"zarr: {h}" for h in ZARR_DAMAGE), *(f"nc: {h}" for h in NC_DAMAGE)]
)
def test_a_damaged_branch_is_reported_never_read(
    profile: dict[str, int], how: str, tmp_path: Path, branch_files: dict[str, Path]
) -> None:
    """Every reader of a branch (open_branch, plot --branch) reports the damage, a damaged
    Zarr chunk by its name; never draws fill values or junk as a branch."""
    kind, what = how.split(": ")
    serial = itertools.count()

    @hsettings(profile["damage"])
    @given(st.data(), st.booleans())
    def check(data: st.DataObject, cli: bool) -> None:
        path = tmp_path / f"e{next(serial)}" / f"b.{kind}"
        path.parent.mkdir()
        if kind == "zarr":
            shutil.copytree(branch_files["zarr"], path)
            names = _damage_zarr(path, what, data.draw)
        else:
            shutil.copy(branch_files["nc"], path)
            _damage_nc(path, what, data.draw)
            names = str(path)
        if cli:
            args = ["plot", str(branch_files["sweep"]), "-o", str(path.parent / "f.png")]
            cli_refused("CLI plot", [*args, "--branch", str(path)], names, watch=path.parent)
        else:
            refused("open_branch", lambda: open_branch(path), names)

    check()


# ----------------------------------------------------------------------------- outputs
@pytest.fixture(scope="module")
def results(branch_files: dict[str, Path]) -> dict[str, Any]:
    sim = gc.simulate(gc.preset("hindawi2021"), omega=1.5, transient_periods=1, periods=2)
    return {"sim": sim, "branch": open_branch(branch_files["nc"])}


OUTPUT_WRITERS = {
    "SimulationResult.save": (".nc", lambda p, r: r["sim"].save(p)),
    "export": (".csv", lambda p, r: gc.export(r["sim"].to_dataset(), p, to="csv")),
    "save_branch": (".nc", lambda p, r: save_branch(r["branch"], p, overwrite=True)),
    "save_branch (zarr)": (".zarr", lambda p, r: save_branch(r["branch"], p, overwrite=True)),
    "savefig": (".png", lambda p, r: __import__("gearchaos.plot").plot.savefig(_figure(), p)),
}


def _figure() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt.figure()


@pytest.mark.parametrize("writer", sorted(OUTPUT_WRITERS))
@pytest.mark.parametrize("kind", ["fifo", "directory", "under_file", "not a path"])
def test_writers_never_replace_what_is_no_regular_file(
    writer: str, kind: str, tmp_path: Path, results: dict[str, Any]
) -> None:
    """A FIFO or a directory (or a device such as /dev/null, never touched here) at the output
    path is refused, never replaced by the rename that ends a write; nothing is left behind."""
    suffix, write = OUTPUT_WRITERS[writer]
    if writer == "save_branch (zarr)" and kind == "directory":
        pytest.skip("a Zarr branch is a directory: overwrite=True replaces it (documented)")
    path: Any = tmp_path / f"out{suffix}"
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "directory":
        path.mkdir()
    elif kind == "under_file":
        (tmp_path / "file").write_text("x")
        path = tmp_path / "file" / f"out{suffix}"
    before = sorted(os.listdir(tmp_path))
    if kind == "not a path":
        for value in ("", " ", "a\0b" + suffix, 5, None, b"x" + suffix.encode(), [str(path)]):
            refused(writer, lambda v=value: write(v, results))
    else:
        refused(writer, lambda: write(path, results), str(path))
    assert sorted(os.listdir(tmp_path)) == before, "a refused write left a file"
    if kind == "fifo":
        import stat

        assert stat.S_ISFIFO(os.stat(path).st_mode), "the FIFO was replaced"
