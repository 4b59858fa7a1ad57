"""Fuzzing the command line (issue 10): every command refuses bad input cleanly, by name.

Every command (``simulate``, ``info``, ``presets``, ``init-gearset``, ``bifurcation``,
``plot``, ``classify``, ``poincare``, ``reproduce``, ``calibrate``, ``--version``) gets
generated invalid option values — numbers outside their documented rule or not numbers at all,
malformed ``--set``/``--vary``/``--family``/``--planets``/``--observe``/``--scheduler``/``-o``
values — and hostile files (``--gearset``, ``--landmarks``, ``--out``, sweep stores). Each
invocation runs in-process (``CliRunner``) in an empty working directory and must exit 2 (or 1
where the CLI documents it) with one ``error:`` line naming the culprit — or click's own usage
error naming the option, for values click parses itself — never a traceback, never exit 0,
within the time bound, and leave the directory as it was (see :func:`fuzz_helpers.cli_refused`).
A few real subprocesses check what only a real process shows: exit codes, one line on stderr,
a FIFO that would block, and SIGTERM during a sweep.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest
from fuzz_helpers import (
    HOSTILE_FILES,
    NOT_NUMBER_TEXT,
    cli_refused,
    hostile_file,
    hsettings,
    inside,
    ints_outside,
    option_number_text,
    profiles,
    reals_outside,
)
from hypothesis import given, strategies as st
from test_fuzz_api import malformed_spec
from test_fuzz_gearset import invalid_values

import gearchaos as gc
from gearchaos.gearset.schema import ALIASES, FIELDS

PROFILES = profiles({"options": 5, "specs": 25, "sets": 25, "files": 1})

TINY = ["--transient", "1", "--periods", "2"]
#: Valid, tiny invocations of the commands that run something; a row adds one bad option.
BASE = {
    "simulate": ["simulate", *TINY, "--samples-per-period", "1"],
    "info": ["info"],
    "bifurcation": ["bifurcation", "-o", "out.zarr", "--vary", "omega=1:2:2", *TINY, "-q"],
    "poincare": ["poincare", "--vary", "omega=1.5", "-o", "g.png", *TINY, "-q"],
    "reproduce": ["reproduce", "fig4", "--quick", "-o", "rep", "-q"],
    "calibrate": ["calibrate", "--quick", "--out", "cal.jsonl", "--max-candidates", "1", "-q"],
}


# ----------------------------------------------------------------------------- value text
def real_text(lo: float | None, hi: float | None, *, lo_ok: bool = True, hi_ok: bool = True):
    """Option text that is not a number in [lo, hi] (click's own refusals included)."""
    return st.one_of(
        NOT_NUMBER_TEXT,
        st.sampled_from(["nan", "inf", "-inf", "1e400"]),
        reals_outside(lo, hi, lo_ok=lo_ok, hi_ok=hi_ok).map(option_number_text),
    )


def int_text(lo: int | None, hi: int | None):
    """Option text that is not an integer in [lo, hi]."""
    return st.one_of(
        NOT_NUMBER_TEXT,
        st.sampled_from(["1.5", "1e3", "nan", "0x10"]),
        ints_outside(lo, hi).map(str),
    )


SETTINGS_TEXT = {
    "--transient": real_text(0.0, 1e9),
    "--periods": int_text(1, 10**9),
    "--rtol": st.one_of(real_text(1e-14, 1.0), st.just("0")),
    "--atol": real_text(0.0, 1.0, lo_ok=False),
}

# (command, option, values, culprits, exit codes)
OPTION_ROWS: list[tuple[str, str, Any, tuple[str, ...]]] = [
    *(
        (cmd, opt, text, (opt,))
        for cmd in ("simulate", "bifurcation", "poincare")
        for opt, text in SETTINGS_TEXT.items()
    ),
    ("simulate", "--samples-per-period", int_text(1, 10**6), ("--samples-per-period",)),
    ("bifurcation", "--workers", int_text(1, 4096), ("--workers", "workers")),
    ("bifurcation", "--dask-local", int_text(1, 4096), ("--dask-local", "dask_local")),
    (
        "bifurcation",
        "--planets",
        st.one_of(
            st.sampled_from(
                ["", ",", "0", "-1", "1.5", "x", "1,1", "9", "1,,2", "1;2", "99999999999999999999"]
            ),
            st.text(alphabet="xyz-;. ", min_size=1, max_size=6),
        ),
        ("--planets", "planet"),
    ),
    (
        "bifurcation",
        "--observe",
        st.one_of(
            st.sampled_from(["", "nope", "delta", "DELTA_SP", "delta_sp "]),
            st.text(alphabet="xyzq_", min_size=1, max_size=8),
        ),
        ("--observe", "observe"),
    ),
    (
        "bifurcation",
        "--scheduler",
        st.one_of(
            st.sampled_from(["", "garbage", "localhost:8786", "tcp:/x", "8786"]),
            st.text(alphabet="abcxyz:/.1", max_size=10).filter(lambda s: "://" not in s),
        ),
        ("--scheduler", "scheduler"),
    ),
    (
        "bifurcation",
        "--initial-conditions",
        st.text(max_size=10).filter(lambda s: s not in ("fresh", "continuation")),
        ("--initial-conditions",),
    ),
    (
        "bifurcation",
        "--direction",
        st.text(max_size=10).filter(lambda s: s != "up"),
        ("--direction",),
    ),
    ("bifurcation", "-o", st.sampled_from(["", " ", ".", "..", "/"]), ("--output", "store", "-o")),
    ("poincare", "--planet", int_text(1, 5), ("--planet", "planet")),
    (
        "poincare",
        "--with",
        st.text(max_size=10).filter(
            lambda s: {p.strip().lower() for p in s.split(",") if p.strip()} - {"phase", "spectrum"}
        ),
        ("--with",),
    ),
    (
        "poincare",
        "-o",
        st.sampled_from(["", "g", "g.xyz", "g.png.txt", ".png", "dir/"]),
        ("--output", "-o"),
    ),
    ("reproduce", "--workers", int_text(1, 4096), ("--workers", "workers")),
    ("calibrate", "--budget-minutes", real_text(0.0, None, lo_ok=False), ("--budget-minutes",)),
    ("calibrate", "--max-candidates", int_text(1, None), ("--max-candidates",)),
    ("calibrate", "--seed", int_text(0, None), ("--seed",)),
]


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize(
    ("command", "option", "values", "names"),
    OPTION_ROWS,
    ids=[f"{c}{o}" for c, o, *_ in OPTION_ROWS],
)
def test_invalid_option_values_exit_2(
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
        with inside(tmp_path / f"e{next(serial)}"):
            cli_refused(f"CLI {command}", [*BASE[command], option, text], *names)

    check()


# ----------------------------------------------------------------------------- specs, --set
@pytest.mark.parametrize("profile", PROFILES)
def test_malformed_vary_and_family_exit_2(profile: dict[str, int], tmp_path: Path) -> None:
    serial = itertools.count()

    @hsettings(profile["specs"])
    @given(
        malformed_spec(),
        st.sampled_from(["bifurcation --vary", "bifurcation --family", "poincare --vary"]),
    )
    def check(spec: tuple[str, tuple[str, ...]], where: str) -> None:
        text, names = spec
        command, option = where.split()
        args = [a for a in BASE[command] if a not in ("--vary", "omega=1:2:2", "omega=1.5")]
        if option == "--family":
            other = "xi=0.05,0.07" if not text.startswith("xi") else "backlash.sun_planet=1,2"
            args += ["--vary", other, "--family", text]
        else:
            args += ["--vary", text]
        with inside(tmp_path / f"e{next(serial)}"):
            cli_refused(f"CLI {command}", args, *names, option, "vary", "family", "axis")

    check()


def _invalid_set_text(name: str) -> st.SearchStrategy[str]:
    """NAME=TEXT where TEXT is no valid value of NAME on the default gear set."""
    if name == "omega":
        return st.one_of(NOT_NUMBER_TEXT, st.sampled_from(["0", "-1", "1e7", "nan", "inf"]))
    kind = FIELDS[name].kind if name in FIELDS else "float"
    if kind == "str":
        return invalid_values(name).filter(lambda v: isinstance(v, str) and "\0" not in v)
    numbers = invalid_values(name).filter(
        lambda v: isinstance(v, int | float) and not isinstance(v, bool)
    )
    return st.one_of(NOT_NUMBER_TEXT, numbers.map(option_number_text))


SET_NAMES = [n for n in [*FIELDS, *ALIASES, "omega"] if not n.endswith("_harmonics")]


@st.composite
def invalid_set(draw: st.DrawFn) -> tuple[str, tuple[str, ...]]:
    how = draw(st.sampled_from(["value", "value", "value", "malformed", "unknown"]))
    if how == "malformed":
        item = draw(st.sampled_from(["xi", "=0.1", " = ", "", "omega", "=", "==1"]))
        return item, ("--set", "NAME=VALUE")
    if how == "unknown":
        name = draw(st.text(alphabet="abcdefgh_.", min_size=1, max_size=10))
        if name in SET_NAMES:
            name += "_x"
        return f"{name}=1", ("unknown parameter",)
    name = draw(st.sampled_from(SET_NAMES))
    return f"{name}={draw(_invalid_set_text(name))}", (name, *ALIASES.get(name, ()))


@pytest.mark.parametrize("profile", PROFILES)
def test_invalid_set_exits_2(profile: dict[str, int], tmp_path: Path) -> None:
    serial = itertools.count()

    @hsettings(profile["sets"])
    @given(invalid_set(), st.sampled_from(["simulate", "info", "bifurcation", "poincare"]))
    def check(item: tuple[str, tuple[str, ...]], command: str) -> None:
        text, names = item
        args = [*BASE[command], "--set", text]
        if command == "poincare" and text.startswith("omega="):
            args = [a if a != "omega=1.5" else "xi=0.05" for a in args]
        if command == "bifurcation" and text.startswith("omega="):
            args = [a if a != "omega=1:2:2" else "xi=0.05,0.07" for a in args]
        with inside(tmp_path / f"e{next(serial)}"):
            cli_refused(f"CLI {command}", args, *names)

    check()


# ----------------------------------------------------------------------------- hostile files
@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("cli") / "s.zarr"
    gc.bifurcation(
        gc.preset("hindawi2021"),
        "omega=0.8:2.4:7",
        store=path,
        transient_periods=10,
        periods=8,
        progress=False,
    )
    return path


FILE_DOORS = {
    "simulate --gearset": lambda p: [*BASE["simulate"], "--gearset", p],
    "info --gearset": lambda p: ["info", "--gearset", p],
    "bifurcation --gearset": lambda p: [*BASE["bifurcation"], "--gearset", p],
    "poincare --gearset": lambda p: [*BASE["poincare"], "--gearset", p],
    "reproduce --gearset": lambda p: [*BASE["reproduce"], "--gearset", p],
    "calibrate --landmarks": lambda p: [*BASE["calibrate"], "--landmarks", p],
    "calibrate --out": lambda p: ["calibrate", "--quick", "--max-candidates", "1", "--out", p],
    "plot STORE": lambda p: ["plot", p, "-o", "f.png"],
    "classify STORE": lambda p: ["classify", p],
}
#: Files a door may read as valid: an empty --out is a calibration not started yet, and lines
#: that are not JSON are torn lines of a killed run, skipped.
VALID_FOR = {
    "calibrate --out": {"missing", "dangling", "empty", "/dev/null", "junk_toml", "nested", "huge"}
}


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("door", sorted(FILE_DOORS))
@pytest.mark.parametrize("kind", HOSTILE_FILES)
def test_hostile_files_exit_2(
    profile: dict[str, int], door: str, kind: str, tmp_path: Path
) -> None:
    if kind in VALID_FOR.get(door, ()):
        pytest.skip(f"{kind} is valid for {door}")
    if kind.startswith("/dev/") and not os.path.exists(kind):
        pytest.skip(f"no {kind}")
    serial = itertools.count()

    @hsettings(profile["files"])
    @given(st.data())
    def check(data: st.DataObject) -> None:
        with inside(tmp_path / f"e{next(serial)}") as here:
            path = hostile_file(kind, here / "input.toml", data.draw)
            option = door.split()[1]
            cli_refused(f"CLI {door.split()[0]}", FILE_DOORS[door](str(path)), str(path), option)

    check()


CALIBRATION_LINES = [
    "5",
    "[1, 2]",
    '"text"',
    '{"key": 5}',
    '{"key": "k", "index": "1"}',
    '{"key": "k", "index": 1, "score": "high", "variables": {}}',
    '{"key": "k", "index": true, "score": 1.0, "variables": {}}',
]


@pytest.mark.parametrize("line", CALIBRATION_LINES)
def test_a_calibration_file_of_foreign_records_exits_2(line: str, tmp_path: Path) -> None:
    with inside(tmp_path) as here:
        (here / "cal.jsonl").write_text(line + "\n")
        cli_refused(
            "CLI calibrate", [*BASE["calibrate"], "--budget-minutes", "1e-6"], "cal.jsonl", "line 1"
        )


def test_init_gearset_refuses_what_is_no_file(tmp_path: Path) -> None:
    with inside(tmp_path) as here:
        os.mkfifo(here / "fifo")
        (here / "dir").mkdir()
        (here / "file").write_text("x")
        for path in ("fifo", "dir", "", "file/x.toml"):
            cli_refused(
                "CLI init-gearset", ["init-gearset", path, "--force"], path or "file", codes=(1, 2)
            )


def test_store_arguments_and_outputs_of_plot_and_classify(store: Path, tmp_path: Path) -> None:
    with inside(tmp_path):
        for args, names in [
            (["plot", str(store), "-o", "f.xyz"], ("--output",)),
            (["plot", str(store), "-o", ""], ("--output",)),
            (["plot", str(store), "-o", "f.png", "--var", "nope"], ("nope", "var")),
            (["plot", str(store), "-o", "f.png", "--planet", "0"], ("planet",)),
            (["plot", str(store), "-o", "f.png", "--planet", "9"], ("planet",)),
            (["classify", str(store), "--period-rtol", "0"], ("--period-rtol",)),
            (["classify", str(store), "--period-rtol", "nan"], ("--period-rtol",)),
            (["classify", str(store), "--period-rtol", "1"], ("--period-rtol",)),
            (["classify", str(store), "--max-period", "0"], ("--max-period",)),
            (["classify", str(store), "--max-period", "100000"], ("--max-period", "max_period")),
            (["classify", str(store), "--rtol", "0.1", "--period-rtol", "0.1"], ("--period-rtol",)),
        ]:
            cli_refused(f"CLI {args[0]}", args, *names)


@pytest.mark.parametrize("profile", PROFILES)
def test_commands_refuse_stray_arguments_and_wrong_combinations(
    profile: dict[str, int], tmp_path: Path
) -> None:
    cases = [
        (["--version", "presets"], ("--version",)),
        (["--version", "x"], ("x",)),
        (["presets", "extra"], ("extra",)),
        (["simulate", "--preset", "nope"], ("nope",)),
        (
            ["simulate", "--preset", "sheng2016-v1", "--gearset", "x.toml"],
            ("--preset", "--gearset"),
        ),
        (["simulate", *TINY, "-o", ""], ("--output",)),
        (["bifurcation", "-o", "x.zarr", *TINY], ("--vary",)),
        (
            [
                "bifurcation",
                "-o",
                "x.zarr",
                "--vary",
                "omega=1:2:2",
                "--vary",
                "xi=0.05,0.07",
                "--vary",
                "backlash.sun_planet=1,2",
                *TINY,
            ],
            ("--vary",),
        ),
        (
            ["bifurcation", "-o", "x.zarr", "--vary", "omega=1:2:2", "--set", "omega=1.5", *TINY],
            ("omega",),
        ),
        (
            [
                "bifurcation",
                "-o",
                "x.zarr",
                "--vary",
                "omega=1:2:2",
                "--workers",
                "2",
                "--dask-local",
                "2",
                *TINY,
            ],
            ("workers", "dask_local"),
        ),
        (
            ["bifurcation", "-o", "x.zarr", "--vary", "omega=1:2:2", "--direction", "down", *TINY],
            ("--direction",),
        ),
        (["poincare", "-o", "g.png", *TINY], ("--vary",)),
        (["poincare", "--vary", "omega=1.5", *TINY], ("--output",)),
        (["poincare", "--vary", "omega=1:2:100000", "-o", "g.png", *TINY], ("values",)),
        (["reproduce"], ("FIG", "--all")),
        (["reproduce", "--all"], ("-o",)),
        (["reproduce", "fig4", "--all", "-o", "r"], ("FIG", "--all")),
        (["reproduce", "fig99", "-o", "r"], ("FIG",)),
        (["reproduce", "fig4", "--preset", "nope", "-o", "r"], ("nope",)),
        (["calibrate", "--quick", "--out", ""], ("--out",)),
        (["simulate", *TINY, "-o", "file"], ("--output",)),
        (["bifurcation", "-o", "file", "--vary", "omega=1:2:2", *TINY], ("file",)),
        (["reproduce", "fig4", "--quick", "-o", "file"], ("--output",)),
        (["plot", "missing.zarr", "-o", "file/f.png"], ("missing.zarr",)),
    ]
    with inside(tmp_path / "w") as here:
        (here / "file").write_text("x")
        for args, names in cases:
            cli_refused(f"CLI {args[0]}", args, *names)


# ----------------------------------------------------------------------------- real processes
def _gearchaos(*args: str, cwd: Path, timeout: float = 120.0) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "gearchaos", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=timeout,
        stdin=subprocess.DEVNULL,
        check=False,
    )


def test_a_real_process_refuses_with_exit_2_and_one_line(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "fifo")
    for args, name in [
        (["simulate", "--rtol", "nan"], "--rtol"),
        (["info", "--gearset", "fifo"], "fifo"),  # a FIFO opened blocking would hang here
        (["bifurcation", "-o", "x.zarr", "--vary", "omega=1:2:1e12"], "omega"),
        (["calibrate", "--landmarks", "fifo"], "fifo"),
    ]:
        proc = _gearchaos(*args, cwd=tmp_path)
        assert proc.returncode == 2, (args, proc.stderr)
        lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
        assert len(lines) == 1 and lines[0].startswith("error:"), proc.stderr
        assert name in lines[0] and "Traceback" not in proc.stderr
    assert sorted(os.listdir(tmp_path)) == ["fifo"]


def test_sigterm_during_a_sweep_exits_130_with_one_line_and_the_store_resumes(
    tmp_path: Path,
) -> None:
    args = [
        "bifurcation",
        "-o",
        "s.zarr",
        "--vary",
        "omega=0.5:3:200",
        "--transient",
        "40",
        "--periods",
        "20",
        "-q",
    ]
    proc = subprocess.Popen(
        [sys.executable, "-m", "gearchaos", *args],
        cwd=tmp_path,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 180
    while not (tmp_path / "s.zarr" / "_progress").is_dir() or not any(
        (tmp_path / "s.zarr" / "_progress").iterdir()
    ):
        assert proc.poll() is None, proc.stderr.read() if proc.stderr else ""
        assert time.monotonic() < deadline, "no task finished in time"
        time.sleep(0.02)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    if proc.returncode == 0:
        pytest.skip("the sweep finished before SIGTERM arrived")
    assert proc.returncode == 130, err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: interrupted"), err
    assert not (tmp_path / "s.zarr.lock").exists()
    done = _gearchaos(*args, "--json", cwd=tmp_path, timeout=600)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["points"] == 200
    assert math.isfinite(float(gc.open_sweep(tmp_path / "s.zarr").delta_sp.max()))
