"""Fuzzing the gear-set layer (issue 10): hostile input is refused cleanly, by name, at once.

For every dotted name of the registry, generated invalid values (wrong types, bools, NaN/inf,
numbers outside the rule or the plausible range, strings, nested lists, …) go through
``GearSet.evolve`` and through TOML text; hostile TOML (junk, wrong types, missing tables,
unknown keys, deep nesting, huge texts) goes through ``GearSet.from_toml_string``, and hostile
files (directories, symbolic-link loops, FIFOs, devices, binary, huge and deeply nested files)
through ``GearSet.from_toml``. Each call must

- raise :class:`ParameterError` or :class:`StoreError` — never another exception, never
  accept the input (a generated value is invalid by construction);
- name the culprit: the dotted parameter (or table), or the file;
- return within :data:`CALL_SECONDS` (generous: a call takes milliseconds); a SIGALRM after
  :data:`HANG_SECONDS` turns a hang (a FIFO opened blocking) into a failure.

The default run is bounded (about 10–30 s for this file); ``pytest -m slow`` runs the same
properties with :data:`LONG` examples. Set ``GEARCHAOS_FUZZ_COUNTS=file.jsonl`` to have every
test append the number of inputs it tried per entry point (what the issue's closing note
quotes).
"""

from __future__ import annotations

import dataclasses
import datetime
import json
import math
import os
import time
from collections import Counter
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fuzz_helpers import Hung, alarm
from hypothesis import HealthCheck, given, settings, strategies as st

from gearchaos.errors import ParameterError, StoreError
from gearchaos.gearset import GearSet, preset
from gearchaos.gearset.mapping import optional_tables
from gearchaos.gearset.parsing import parse_text
from gearchaos.gearset.schema import ALIASES, FIELDS, MAX_HARMONICS, META, MODULE_BOUNDED, TABLES
from gearchaos.gearset.tables import RECORD_CLASSES
from gearchaos.gearset.tomltext import float_text, string_text

CALL_SECONDS = 5.0
HANG_SECONDS = 60.0

#: Examples per test: the normal run, and under ``-m slow``.
DEFAULT = {"evolve": 20, "toml": 10, "names": 150, "hostile_text": 20, "files": 8, "set": 150}
LONG = {key: 20 * n for key, n in DEFAULT.items()}

BASE = preset("hindawi2021")  # module 4 mm, b_c = 10 µm, clearances dimensionless
BASE_DICT = BASE.to_dict()
COUNTS: Counter[str] = Counter()

PROFILES = [
    pytest.param(DEFAULT, id="default"),
    pytest.param(LONG, id="long", marks=pytest.mark.slow),
]


def _settings(n: int) -> settings:
    return settings(
        max_examples=n,
        deadline=None,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    )


# ----------------------------------------------------------------------------- the harness
def refused(entry: str, call: Callable[[], object], *culprits: str) -> BaseException:
    """Run ``call``: it must raise ParameterError/StoreError naming one of ``culprits`` (none
    given: any message) within :data:`CALL_SECONDS`."""
    COUNTS[entry] += 1
    start = time.perf_counter()
    try:
        with alarm(HANG_SECONDS):
            call()
    except (ParameterError, StoreError) as exc:
        elapsed = time.perf_counter() - start
        assert elapsed < CALL_SECONDS, f"{entry}: {elapsed:.1f} s"
        message = str(exc)
        assert message.strip() and "\n" not in message, f"{entry}: not one line: {message!r}"
        if culprits:
            assert any(c in message for c in culprits), f"{entry}: {culprits} not in {message!r}"
        return exc
    except Hung:
        pytest.fail(f"{entry}: hung for {HANG_SECONDS} s")
    except BaseException as exc:  # a traceback a user would see
        pytest.fail(f"{entry}: raised {type(exc).__name__}: {exc}")
    pytest.fail(f"{entry}: accepted an invalid input")


@pytest.fixture(scope="module", autouse=True)
def _record_counts() -> Iterator[None]:
    yield
    target = os.environ.get("GEARCHAOS_FUZZ_COUNTS")
    if target:
        with open(target, "a", encoding="utf-8") as f:
            f.write(json.dumps({"pid": os.getpid(), "counts": dict(COUNTS)}) + "\n")


# ----------------------------------------------------------------------------- invalid values
def _nested(depth: int) -> object:
    value: object = [1.0]
    for _ in range(depth):
        value = [value]
    return value


JUNK = st.one_of(
    st.none(),
    st.booleans(),
    st.text(max_size=12),
    st.binary(max_size=8),
    st.complex_numbers(allow_nan=True),
    st.dictionaries(st.text(max_size=4), st.integers(), max_size=2),
    st.integers(1, 40).map(_nested),
    st.sets(st.integers(), max_size=2),
    st.decimals(allow_nan=True, allow_infinity=True),
    st.sampled_from(
        [object(), Ellipsis, np.array([[1.0]]), np.array(5.0), np.bool_(True), b"\xff", math.sin]
    ),
)
NON_FINITE = st.sampled_from(
    [math.nan, math.inf, -math.inf, np.float64("nan"), np.float32("inf"), 10**400, -(10**500)]
)


def _bounds(name: str) -> tuple[float, bool, float, bool]:
    """(lo, lo valid, hi, hi valid): the valid interval of a number field on :data:`BASE`."""
    f = FIELDS[name]
    lo, lo_ok, hi, hi_ok = -math.inf, True, math.inf, True
    for rule in (f.rule, f.limits):
        if rule is None:
            continue
        if rule.lo is not None and rule.lo >= lo:
            lo, lo_ok = rule.lo, not rule.lo_open
        if rule.hi is not None and rule.hi <= hi:
            hi, hi_ok = rule.hi, not rule.hi_open
    if name in MODULE_BOUNDED:  # <= one module, in metres or in units of b_c
        units = MODULE_BOUNDED[name]
        scale = BASE.clearance.characteristic_length if units else 1.0
        hi, hi_ok = BASE.geometry.module / scale * (1 + 1e-9), False
    if name.endswith("_alternating"):  # k_a < k_m
        hi, hi_ok = (
            getattr(BASE.stiffness, name.split(".")[1].replace("alternating", "mean")),
            False,
        )
    return lo, lo_ok, hi, hi_ok


def _out_of_range(name: str, integer: bool, numpy: bool = True) -> st.SearchStrategy[Any]:
    """Numbers outside the valid interval of a field (integers up to 100 digits)."""
    lo, lo_ok, hi, hi_ok = _bounds(name)
    parts = []
    if integer:
        below = int(lo) - (1 if lo_ok else 0)
        above = int(hi) + (1 if hi_ok else 0)
        parts.append(st.integers(-(10**100), below))
        parts.append(st.integers(above, 10**100))
        if numpy:
            parts.append(st.integers(above, 2**62).map(np.int64))
        return st.one_of(parts)
    finite = {"allow_nan": False, "allow_infinity": False}
    if math.isfinite(lo):
        parts.append(st.floats(max_value=lo, exclude_max=lo_ok, **finite))
    if math.isfinite(hi):
        parts.append(st.floats(min_value=hi, exclude_min=hi_ok, **finite))
    return st.one_of(parts)


def invalid_values(name: str) -> st.SearchStrategy[Any]:
    """Values that no gear set accepts for ``name`` (given alone on :data:`BASE`)."""
    if name in META:
        return st.one_of(
            JUNK.filter(lambda v: not isinstance(v, str)), st.just("bad \ud800 surrogate")
        )
    if name in ALIASES:
        return st.one_of(JUNK, NON_FINITE, _out_of_range(ALIASES[name][0], integer=False))
    f = FIELDS[name]
    if f.kind == "int":
        floats = st.floats().filter(lambda x: not math.isnan(x))
        return st.one_of(JUNK, floats, NON_FINITE, _out_of_range(name, integer=True))
    if f.kind == "float":
        return st.one_of(JUNK, NON_FINITE, _out_of_range(name, integer=False))
    if f.kind == "str":
        return st.one_of(
            JUNK.filter(lambda v: not isinstance(v, str)),
            st.text(max_size=30).filter(lambda s: s not in f.choices),
        )
    assert f.kind == "floats"
    bad_item = st.one_of(JUNK, NON_FINITE, _out_of_range(name, integer=False))
    good_item = st.floats(-1e6, 1e6)
    km = getattr(BASE.stiffness, name.split(".")[1].replace("harmonics", "mean"))
    return st.one_of(
        JUNK,
        st.tuples(st.lists(good_item, max_size=3), bad_item).map(lambda t: [*t[0], t[1]]),
        st.integers(MAX_HARMONICS + 1, 300).map(lambda n: [1.0] * n),
        st.floats(km, 1e13).map(lambda k: [k]),  # k_a + |k_2| >= k_m
    )


def culprits(name: str) -> tuple[str, ...]:
    """What a message about ``name`` must mention: the name, or a field an alias sets."""
    return (name, *ALIASES.get(name, ()))


# ----------------------------------------------------------------------------- TOML writing
def _literal(value: Any) -> str:
    """A TOML literal for generated values (numbers, text, booleans, arrays, tables, dates)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return float_text(value)
    if isinstance(value, str):
        return string_text(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_literal(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{string_text(k)} = {_literal(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (datetime.date, datetime.time)):
        return value.isoformat()
    raise TypeError(value)


def dumps(data: dict[str, Any]) -> str:
    """TOML text of a mapping in gear-set layout (scalars first, then one [table] each)."""
    lines = [
        f"{string_text(k)} = {_literal(v)}" for k, v in data.items() if not isinstance(v, dict)
    ]
    for key, table in data.items():
        if isinstance(table, dict):
            lines.append(f"[{string_text(key)}]")
            lines.extend(f"{string_text(k)} = {_literal(v)}" for k, v in table.items())
    return "\n".join(lines) + "\n"


SCALAR = st.one_of(
    st.booleans(),
    st.integers(-(10**30), 10**30),
    st.floats(),
    st.text(max_size=12),
    st.dates(),
    st.times(),
)
TOML_VALUE = st.recursive(
    SCALAR,
    lambda inner: st.one_of(
        st.lists(inner, max_size=3), st.dictionaries(st.text(max_size=4), inner, max_size=3)
    ),
    max_leaves=6,
)


def invalid_toml_values(name: str) -> st.SearchStrategy[Any]:
    """Values a TOML file can hold that no gear set accepts for ``name``."""
    f = FIELDS.get(name)
    if name in META:
        return TOML_VALUE.filter(lambda v: not isinstance(v, str))
    assert f is not None
    if f.kind == "str":
        return TOML_VALUE.filter(lambda v: v not in f.choices)
    if f.kind == "floats":
        bad_item = st.one_of(st.booleans(), st.text(max_size=5), st.just(math.nan), st.dates())
        return st.one_of(
            SCALAR,
            st.dictionaries(st.text(max_size=4), SCALAR, max_size=2),
            st.tuples(st.lists(st.floats(-1e6, 1e6), max_size=3), bad_item).map(
                lambda t: [*t[0], t[1]]
            ),
            st.integers(MAX_HARMONICS + 1, 200).map(lambda n: [0.5] * n),
        )
    wrong_type = TOML_VALUE.filter(lambda v: not isinstance(v, (int, float)) or isinstance(v, bool))
    if f.kind == "int":
        floats = st.floats().map(lambda x: x)  # 34.0 is not an integer either
        return st.one_of(wrong_type, floats, _out_of_range(name, integer=True, numpy=False))
    return st.one_of(
        wrong_type,
        st.sampled_from([math.nan, math.inf, -math.inf]),
        _out_of_range(name, integer=False),
        _out_of_range(name, integer=False).map(lambda x: int(x) if abs(x) > 1e16 else x),
    )


def _with(name: str, value: Any) -> dict[str, Any]:
    data = json.loads(json.dumps(BASE_DICT))
    if name in META:
        data[name] = value
    else:
        table, key = name.split(".", 1)
        data[table][key] = value
    return data


# ----------------------------------------------------------------------------- values, by name
@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("name", [*FIELDS, *ALIASES, *META])
def test_evolve_refuses_invalid_values(profile: dict[str, int], name: str) -> None:
    @_settings(profile["evolve"])
    @given(invalid_values(name), st.booleans())
    def check(value: Any, as_keyword: bool) -> None:
        if as_keyword:
            keyword = {name.replace(".", "__"): value}
            refused("GearSet.evolve", lambda: BASE.evolve(**keyword), *culprits(name))
        refused("GearSet.evolve", lambda: BASE.evolve({name: value}), *culprits(name))

    check()


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("name", [*FIELDS, *META])
def test_toml_text_refuses_invalid_values(profile: dict[str, int], name: str) -> None:
    @_settings(profile["toml"])
    @given(invalid_toml_values(name))
    def check(value: Any) -> None:
        text = dumps(_with(name, value))
        refused("GearSet.from_toml_string", lambda: GearSet.from_toml_string(text), name)

    check()


@pytest.mark.parametrize("profile", PROFILES)
def test_evolve_refuses_unknown_names_and_non_mappings(profile: dict[str, int]) -> None:
    valid = {*FIELDS, *ALIASES, *META, *TABLES}

    @_settings(profile["names"])
    @given(
        st.one_of(st.text(max_size=40), st.integers(), st.none()).filter(lambda k: k not in valid),
        st.one_of(JUNK, st.floats()),
    )
    def check(key: Any, value: Any) -> None:
        if isinstance(key, str):
            refused("GearSet.evolve", lambda: BASE.evolve({key: value}), "unknown parameter")
        else:
            refused("GearSet.evolve", lambda: BASE.evolve({key: value}), "names must be strings")
        if not hasattr(value, "keys"):
            refused("GearSet.evolve", lambda: BASE.evolve(value), "changes must be a mapping")

    check()


@pytest.mark.parametrize("profile", PROFILES)
def test_set_text_never_raises_anything_else(profile: dict[str, int]) -> None:
    """``--set NAME=TEXT``: parse_text then evolve give a gear set or one ParameterError."""

    @_settings(profile["set"])
    @given(st.sampled_from([*FIELDS, *ALIASES, *META]), st.text(max_size=30))
    def check(name: str, raw: str) -> None:
        COUNTS["parse_text + evolve"] += 1
        try:
            BASE.evolve({name: parse_text(name, raw)})
        except ParameterError as exc:
            assert any(c in str(exc) for c in culprits(name)), str(exc)

    check()


# ----------------------------------------------------------------------------- hostile TOML text
#: Keys without a default (in required tables): leaving one out is an error.
REQUIRED_KEYS = [
    f"{table}.{f.name}"
    for table, cls in RECORD_CLASSES.items()
    for f in dataclasses.fields(cls)
    if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
]


HOSTILE_TEXTS = [
    "junk",
    "bytes",
    "drop_table",
    "drop_key",
    "table_value",
    "unknown",
    "nest",
    "long",
    "many",
]


def _hostile_text(draw: st.DrawFn, how: str) -> tuple[str, tuple[str, ...]]:
    """(TOML text, what the message must name — empty: anything)."""
    data = json.loads(json.dumps(BASE_DICT))
    if how == "junk":
        return draw(st.text(max_size=300)), ()
    if how == "bytes":
        return draw(st.binary(max_size=300)).decode("latin-1"), ()
    required = [t for t in TABLES if t not in optional_tables()]
    if how == "drop_table":
        table = draw(st.sampled_from(required))
        del data[table]
        return dumps(data), (f"[{table}]",)
    if how == "drop_key":
        name = draw(st.sampled_from(REQUIRED_KEYS))
        table, key = name.split(".")
        del data[table][key]
        return dumps(data), (f"'{name}'",)
    if how == "table_value":
        table = draw(st.sampled_from(TABLES))
        data[table] = draw(st.one_of(SCALAR, st.lists(SCALAR, max_size=3)))
        return dumps(data), (table,)
    if how == "unknown":
        key = draw(st.text("abcdefghijklmnopqrstuvwxyz_", min_size=1, max_size=12))
        where = draw(st.sampled_from([None, *TABLES]))
        if key in (*META, *TABLES) or f"{where}.{key}" in FIELDS:
            key += "_x"
        if where is None:
            data[key] = draw(SCALAR)
            return dumps(data), (key,)
        data[where][key] = draw(SCALAR)
        return dumps(data), (f"{where}.{key}",)
    if how == "nest":
        depth = draw(st.sampled_from([2, 10, 100, 500, 2_000, 50_000]))
        name = draw(st.sampled_from(list(FIELDS)))
        table, key = name.split(".")
        opener, closer = draw(st.sampled_from([("[", "]"), ("{a = ", "}")]))
        data[table][key] = "@nest@"
        nested = f"{opener * depth}1{closer * depth}"
        return dumps(data).replace(string_text("@nest@"), nested), (name, "nested too deeply")
    if how == "long":  # refused before parsing
        return "# " + "x" * draw(st.integers(1 << 20, 3 << 20)), ("characters, more than",)
    lines = draw(st.integers(100, 3_000))  # many unknown keys: parsed, then the first named
    return dumps(data) + "".join(f"k{i} = {i}\n" for i in range(lines)), ("k0",)


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("how", HOSTILE_TEXTS)
def test_hostile_toml_text_is_refused(profile: dict[str, int], how: str) -> None:
    @_settings(profile["hostile_text"])
    @given(st.data())
    def check(data: st.DataObject) -> None:
        text, names = _hostile_text(data.draw, how)
        refused("GearSet.from_toml_string", lambda: GearSet.from_toml_string(text), *names)

    check()
    refused("GearSet.from_toml_string", lambda: GearSet.from_toml_string(b"x = 1"), "TOML")  # type: ignore[arg-type]


# ----------------------------------------------------------------------------- hostile files
def _make(kind: str, path: Path, draw: st.DrawFn) -> Path:
    if kind == "directory":
        path.mkdir()
    elif kind == "loop":
        other = path.with_name(path.name + ".b")
        path.symlink_to(other)
        other.symlink_to(path)
    elif kind == "dangling":
        path.symlink_to(path.with_name("nowhere"))
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "binary":
        path.write_bytes(draw(st.binary(min_size=1, max_size=2_000)))
    elif kind == "huge":
        path.write_bytes(b"#" * draw(st.integers((1 << 20) + 1, 3 << 19)))
    elif kind == "nested":
        depth = draw(st.integers(100, 300_000))
        path.write_text("x = " + "[" * depth + "]" * depth, encoding="utf-8")
    elif kind == "invalid":
        name = draw(st.sampled_from(list(FIELDS)))
        path.write_text(dumps(_with(name, draw(invalid_toml_values(name)))), encoding="utf-8")
    elif kind == "empty":
        path.write_bytes(b"")
    elif kind == "under_file":
        path.write_text("")
        path = path / "x.toml"
    return path


FILE_KINDS = ["directory", "loop", "dangling", "fifo", "binary", "huge", "nested"]
FILE_KINDS += ["invalid", "empty", "under_file", "/dev/zero", "/dev/urandom", "/dev/null"]


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("kind", FILE_KINDS)
def test_hostile_files_are_refused(profile: dict[str, int], kind: str, tmp_path: Path) -> None:
    if kind.startswith("/dev/") and not os.path.exists(kind):
        pytest.skip(f"no {kind}")
    serial = iter(range(10**9))

    @_settings(profile["files"])
    @given(st.data())
    def check(data: st.DataObject) -> None:
        path = Path(kind) if kind.startswith("/dev/") else tmp_path / f"f{next(serial)}.toml"
        path = path if kind.startswith("/dev/") else _make(kind, path, data.draw)
        refused("GearSet.from_toml", lambda: GearSet.from_toml(path), str(path))

    check()


def test_paths_that_are_not_paths_are_refused() -> None:
    for bad in (3, None, b"x.toml", "", "a\0b", 1.5, ["x.toml"]):
        refused("GearSet.from_toml", lambda bad=bad: GearSet.from_toml(bad), "path")
