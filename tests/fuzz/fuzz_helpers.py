"""The harness of the fuzz suites: a refusal must be clean, by name, and prompt (issue 10).

:func:`refused` runs one Python call that must raise :class:`ParameterError` or
:class:`StoreError` naming a culprit; :func:`cli_refused` runs one command line in-process
(``typer.testing.CliRunner``) that must exit 2 (or 1 where the CLI documents it) with one
``error:`` line naming the culprit — or click's own usage error for a value click refuses
itself — never a traceback, and without writing anything. Both count what they tried in
:data:`COUNTS` (written per module to ``$GEARCHAOS_FUZZ_COUNTS`` by ``conftest.py``): the
number of inputs per entry point, and, keyed ``"<entry> [traceback|accepted|hang|slow]"``,
every input that broke the rule (each also fails its test).

Time: a refusal takes milliseconds; :data:`CALL_SECONDS` is generous (a loaded CI machine),
and a SIGALRM after :data:`HANG_SECONDS` turns a hang (a FIFO opened blocking, a run that
should have been refused) into a failure.
"""

from __future__ import annotations

import contextlib
import decimal
import math
import os
import re
import signal
import time
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, settings, strategies as st

from gearchaos.errors import IntegrationError, ParameterError, StoreError

CALL_SECONDS = 20.0
HANG_SECONDS = 60.0

COUNTS: Counter[str] = Counter()


def hsettings(n: int) -> settings:
    """Hypothesis settings of one property: ``n`` examples, no deadline (the alarm bounds a
    call), no shrinking time wasted on slow examples."""
    return settings(
        max_examples=n,
        deadline=None,
        suppress_health_check=[
            HealthCheck.too_slow,
            HealthCheck.data_too_large,
            HealthCheck.filter_too_much,
        ],
    )


def profiles(default: dict[str, int], factor: int = 10) -> list[Any]:
    """The normal profile and, under ``-m slow``, ``factor`` times as many examples."""
    return [
        pytest.param(default, id="default"),
        pytest.param(
            {k: factor * n for k, n in default.items()}, id="long", marks=pytest.mark.slow
        ),
    ]


class Hung(Exception):
    pass


@contextlib.contextmanager
def alarm(seconds: float) -> Iterator[None]:
    def ring(signum: int, frame: object) -> None:
        raise Hung(f"no answer after {seconds} s")

    old = signal.signal(signal.SIGALRM, ring)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def _bad(entry: str, what: str, message: str) -> None:
    COUNTS[f"{entry} [{what}]"] += 1
    pytest.fail(f"{entry}: {message}")


def names_culprit(message: str, culprits: Sequence[str]) -> bool:
    """Whether ``message`` names one of ``culprits`` (``--budget-minutes`` also matches
    ``budget_minutes``: the option and the argument behind it)."""
    if not culprits:
        return True
    low = message.lower()
    for c in culprits:
        c = c.lower()
        if c in low or c.lstrip("-").replace("-", "_") in low.replace("-", "_"):
            return True
    return False


def refused(
    entry: str,
    call: Callable[[], object],
    *culprits: str,
    errors: tuple[type[BaseException], ...] = (ParameterError, StoreError),
) -> BaseException:
    """Run ``call``: it must raise one of ``errors`` with a one-line message naming one of
    ``culprits`` (none given: any message), within :data:`CALL_SECONDS`."""
    COUNTS[entry] += 1
    start = time.perf_counter()
    try:
        with alarm(HANG_SECONDS):
            call()
    except errors as exc:
        elapsed = time.perf_counter() - start
        message = str(exc)
        if elapsed > CALL_SECONDS:
            _bad(entry, "slow", f"{elapsed:.1f} s to refuse ({message})")
        assert message.strip() and "\n" not in message, f"{entry}: not one line: {message!r}"
        assert names_culprit(message, culprits), f"{entry}: {culprits} not in {message!r}"
        return exc
    except Hung:
        _bad(entry, "hang", f"hung for {HANG_SECONDS} s")
    except BaseException as exc:  # a traceback a user would see
        _bad(entry, "traceback", f"raised {type(exc).__name__}: {exc}")
    _bad(entry, "accepted", "accepted an invalid input")
    raise AssertionError  # pragma: no cover - _bad fails


def tolerated(entry: str, call: Callable[[], object], *culprits: str) -> object:
    """Run ``call`` on an input that may be valid: it returns, or raises a clean refusal
    (:class:`ParameterError`, :class:`StoreError` or :class:`IntegrationError`) naming one
    of ``culprits``; never another exception, never a hang."""
    COUNTS[entry] += 1
    try:
        with alarm(HANG_SECONDS):
            return call()
    except (ParameterError, StoreError, IntegrationError) as exc:
        message = str(exc)
        assert "\n" not in message, f"{entry}: not one line: {message!r}"
        assert names_culprit(message, culprits), f"{entry}: {culprits} not in {message!r}"
        return exc
    except Hung:
        _bad(entry, "hang", f"hung for {HANG_SECONDS} s")
    except BaseException as exc:
        _bad(entry, "traceback", f"raised {type(exc).__name__}: {exc}")
    raise AssertionError  # pragma: no cover


# ----------------------------------------------------------------------------- the CLI
_PANEL = re.compile(r"[│╭╮╰╯─]")


def _tree(root: Path) -> set[str]:
    return {os.path.relpath(os.path.join(d, f), root) for d, _, fs in os.walk(root) for f in fs} | {
        os.path.relpath(os.path.join(d, s), root) for d, ss, _ in os.walk(root) for s in ss
    }


@contextlib.contextmanager
def inside(path: Path) -> Iterator[Path]:
    """Run with ``path`` (created) as the working directory."""
    path.mkdir(parents=True, exist_ok=True)
    old = os.getcwd()
    os.chdir(path)
    try:
        yield path
    finally:
        os.chdir(old)


def cli_refused(
    entry: str,
    args: Sequence[str],
    *culprits: str,
    codes: tuple[int, ...] = (2,),
    watch: Path | None = None,
) -> str:
    """Run ``gearchaos ARGS`` in-process: exit code in ``codes``, no traceback, one
    ``error:`` line on stderr naming a culprit (or click's usage error naming it), within
    :data:`CALL_SECONDS`, and nothing created under ``watch`` (default: the working
    directory). Returns the error text."""
    from typer.testing import CliRunner

    from gearchaos.cli import app

    COUNTS[entry] += 1
    root = Path.cwd() if watch is None else watch
    before = _tree(root)
    start = time.perf_counter()
    try:
        with alarm(HANG_SECONDS):
            result = CliRunner().invoke(app, list(args))
    except Hung:
        _bad(entry, "hang", f"{list(args)} hung for {HANG_SECONDS} s")
    elapsed = time.perf_counter() - start
    exc = result.exception
    if exc is not None and not isinstance(exc, SystemExit):
        _bad(entry, "traceback", f"{list(args)} raised {type(exc).__name__}: {exc}")
    if result.exit_code == 0:
        _bad(entry, "accepted", f"{list(args)} exited 0")
    if "Traceback" in result.output:
        _bad(entry, "traceback", f"{list(args)} printed a traceback:\n{result.output}")
    if elapsed > CALL_SECONDS:
        _bad(entry, "slow", f"{list(args)} took {elapsed:.1f} s to refuse")
    assert result.exit_code in codes, (list(args), result.exit_code, result.output)
    err = result.stderr
    lines = [ln for ln in err.splitlines() if ln.strip()]
    errors = [ln for ln in lines if ln.startswith("error:")]
    if errors:
        assert len(errors) == 1, f"{list(args)}: more than one error line:\n{err}"
        text = errors[0]
    else:  # click's own refusal: "Usage: ...", then the error in a panel
        assert "Usage:" in err and "Error" in err, f"{list(args)}: no error line:\n{err}"
        text = " ".join(_PANEL.sub(" ", ln).strip() for ln in lines)
        text = re.sub(r"\s+", " ", text)
    assert names_culprit(text, culprits), f"{list(args)}: {culprits} not in {text!r}"
    created = _tree(root) - before
    assert not created, f"{list(args)} was refused but wrote {sorted(created)}"
    return text


# ----------------------------------------------------------------------------- values
def _nested(depth: int) -> object:
    value: object = [1.0]
    for _ in range(depth):
        value = [value]
    return value


#: Values that are not numbers (bools and numeric strings included).
NOT_NUMBERS = st.one_of(
    st.booleans(),
    st.text(max_size=12),
    st.sampled_from(["1e-8", "3", "0.5", " 1 ", "nan", "inf"]),
    st.binary(max_size=8),
    st.complex_numbers(allow_nan=True).filter(lambda z: z.imag != 0),
    st.dictionaries(st.text(max_size=4), st.integers(), max_size=2),
    st.integers(1, 40).map(_nested),
    st.lists(st.floats(), max_size=3),
    st.sets(st.integers(), max_size=2),
    st.decimals(allow_nan=True, allow_infinity=True),
    st.just(decimal.Decimal("1e-8")),
    st.sampled_from(
        [object(), Ellipsis, np.array([[1.0]]), np.array([1.0, 2.0]), np.bool_(True), math.sin]
    ),
)

#: Numbers that are not finite (or do not fit a float).
NON_FINITE = st.sampled_from(
    [math.nan, math.inf, -math.inf, np.float64("nan"), np.float32("inf"), 10**400, -(10**500)]
)


def reals_outside(lo: float | None, hi: float | None, *, lo_ok: bool = True, hi_ok: bool = True):
    """Finite floats (and ints) outside [lo, hi] (``*_ok``: the bound itself is valid)."""
    finite = {"allow_nan": False, "allow_infinity": False}
    parts = []
    if lo is not None:
        parts.append(st.floats(max_value=lo, exclude_max=lo_ok, **finite))
        if lo > -1e18:
            parts.append(st.integers(-(10**30), math.ceil(lo) - 1))
    if hi is not None:
        parts.append(st.floats(min_value=hi, exclude_min=hi_ok, **finite))
        if hi < 1e18:
            parts.append(st.integers(math.floor(hi) + 1, 10**30))
    return st.one_of(parts)


def ints_outside(lo: int | None, hi: int | None):
    parts = []
    if lo is not None:
        parts.append(st.integers(-(10**30), lo - 1))
    if hi is not None:
        parts.append(st.integers(hi + 1, 10**30))
    return st.one_of(parts)


def not_integers() -> st.SearchStrategy[Any]:
    """Values that are not integers: floats (3.0 too), non-numbers."""
    return st.one_of(NOT_NUMBERS, st.floats(), NON_FINITE.filter(lambda v: not isinstance(v, int)))


#: Text that is not a number when parsed by a CLI option.
NOT_NUMBER_TEXT = st.one_of(
    st.sampled_from(["", " ", "abc", "1e", "0x10", "1,5", "--", "1.2.3", "½", "1e-8x", "None"]),
    st.text(alphabet="abcxyz_-+ .,:;!?", min_size=1, max_size=10).filter(lambda s: not _parses(s)),
)


def _parses(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def option_number_text(value: Any) -> str:
    """A generated number as command-line text (``repr`` of floats, big ints in full)."""
    if isinstance(value, float):
        return repr(value)
    return str(value)


# ----------------------------------------------------------------------------- hostile files
#: Kinds of paths no reader may hang on, crash on, or read as valid input.
HOSTILE_FILES = [
    "missing",
    "directory",
    "fifo",
    "binary",
    "huge",
    "empty",
    "loop",
    "dangling",
    "under_file",
    "junk_toml",
    "nested",
    "/dev/zero",
    "/dev/urandom",
    "/dev/null",
]


def hostile_file(kind: str, path: Path, draw: Any, huge_bytes: int = 3 << 20) -> Path:
    """Create a hostile file of ``kind`` at ``path`` (devices are returned as they are)."""
    if kind.startswith("/dev/"):
        return Path(kind)
    if kind == "directory":
        path.mkdir()
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "binary":
        data = draw(st.binary(min_size=1, max_size=2_000))
        path.write_bytes(b"\xff\xfe" + data)  # never UTF-8
    elif kind == "huge":
        path.write_bytes(b"#" * huge_bytes)
    elif kind == "empty":
        path.write_bytes(b"")
    elif kind == "loop":
        other = path.with_name(path.name + ".b")
        path.symlink_to(other)
        other.symlink_to(path)
    elif kind == "dangling":
        path.symlink_to(path.with_name("nowhere"))
    elif kind == "under_file":
        path.write_text("x")
        path = path / "x.toml"
    elif kind == "junk_toml":
        path.write_text(draw(st.sampled_from(["x = [1", "= 3", "[[a]]\nb = ", "a = 1\na = 2"])))
    elif kind == "nested":
        depth = draw(st.integers(1_000, 100_000))
        path.write_text("x = " + "[" * depth + "]" * depth, encoding="utf-8")
    else:
        assert kind == "missing"
    return path
