"""The numbers the docs quote from a program are what the program prints now.

``docs/make_doc_numbers.py`` pastes every such number (between ``<!-- gen:… -->`` markers) into
README.md, the tutorial, the reproduce how-to and the motion-labels page by running the
commands the pages show, reads the report's counts from ``docs/report/report.json`` and the
verdict's tolerances and budgets from its settings. These tests run the same sources and fail
when a page differs: the report, the verdict's settings and the fast commands (about 15 s)
here, the tutorial's 800-point sweep under ``-m slow``. A failure names the page, the marker,
what it shows and what the code gives; ``.venv/bin/python docs/make_doc_numbers.py`` rewrites
them (and says which prose no longer fits).
"""

from __future__ import annotations

import importlib.util
import re
import sys
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _generator() -> ModuleType:
    spec = importlib.util.spec_from_file_location(
        "make_doc_numbers", ROOT / "docs" / "make_doc_numbers.py"
    )
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


gen = _generator()
FAST = [n for n in gen.used_sources() if not gen.SOURCES[n].slow]  # with a command or not
SLOW = [n for n in gen.used_sources() if gen.SOURCES[n].slow]


def _stale(sources: list[str]) -> list[str]:
    values = gen.compute(sources)
    found = []
    for page in gen.PAGES:
        text = page.read_text(encoding="utf-8")
        used = {s for s, _, _ in gen.markers(text)}
        if used & set(sources):
            found += gen.problems(page, text, values)
    return found


def test_every_marker_names_a_source_and_every_page_shows_its_command() -> None:
    assert set(gen.used_sources()) == set(gen.SOURCES), "a source no page uses"
    found = []
    for page in gen.PAGES:
        text = page.read_text(encoding="utf-8")
        assert gen.markers(text), f"{page.name} has no generated number"
        assert text.count("<!-- gen:") == text.count("<!-- /gen -->"), f"{page.name}: unclosed"
        found += gen.problems(page, text, {})  # no values: only names and commands
    assert not found, "\n".join(found)


def test_verdict_numbers_are_the_settings_defaults() -> None:
    """The tolerances, windows and budgets the pages state are the verdict's defaults."""
    assert not (stale := _stale(["verdict"])), "\n".join(stale)


def test_power_text_writes_powers_of_ten_as_the_pages_do() -> None:
    assert gen.power_text(1e-4) == "10⁻⁴"
    assert gen.power_text(1e3) == "10³"
    assert gen.power_text(1.0) == "10⁰"
    assert gen.power_text(2e-2) == "0.02"


def test_report_counts_are_those_of_report_json() -> None:
    """The landmark and conclusion counts of the README and the how-to are the committed
    report's."""
    assert not (stale := _stale(["report"])), "\n".join(stale)


@pytest.mark.parametrize("source", FAST)
def test_quoted_output_is_what_the_command_prints(source: str) -> None:
    assert not (stale := _stale([source])), "\n".join(stale)


@pytest.mark.slow
@pytest.mark.parametrize("source", SLOW)
def test_quoted_output_of_the_full_sweep_is_what_it_prints(source: str) -> None:
    assert not (stale := _stale([source])), "\n".join(stale)


def test_a_stale_number_is_found() -> None:
    """The check compares every marker: a number typed over one, or an excerpt edited, fails."""
    values = gen.compute(["report"])
    page = gen.PAGES[0]
    text = page.read_text(encoding="utf-8")
    holds = values["report"]["landmarks.holds"]
    typed = text.replace(
        f"<!-- gen:report.landmarks.holds -->{holds}<!-- /gen -->",
        f"<!-- gen:report.landmarks.holds -->{int(holds) + 1}<!-- /gen -->",
    )
    assert typed != text
    (problem,) = gen.problems(page, typed, values)
    assert "report.landmarks.holds" in problem
    assert f"-->{int(holds) + 1}<!--" in problem and f"-->{holds}<!--" in problem
    block = gen.render(
        "<!-- gen:x.t -->\n\n```text\nold\n```\n\n<!-- /gen -->", {"x": {"t": gen.Block("new\n")}}
    )
    assert "```text\nnew\n```" in block


def test_table_rows_keep_wrapped_values() -> None:
    printed = (
        "│ motion      │ chaos │\n"
        "│ motion note │ no period ≤ 64 │\n"
        "│             │ confirmed      │\n"
    )
    rows = gen.table_rows(printed)
    assert list(rows) == ["motion", "motion note"]
    assert gen.cell(rows, "motion note") == "no period ≤ 64 confirmed"
    assert gen.excerpt(rows, ("motion note",)).count("\n") == 2
    with pytest.raises(gen.ProseOutOfDate):
        gen.excerpt(rows, ("λ₁ [1/τ]",))


_WALL_CLOCK = re.compile(
    r"\b(?:about|in|takes?|took)\s+(?:a|one|a few|\d+(?:[–-]\d+)?)\s+(?:minutes?|seconds?|hours?)\b"
)


def test_pages_state_no_unmeasured_run_times() -> None:
    """A run time depends on the machine: the pages say none ('about two minutes'), except as
    the report's own measurement."""
    found = [
        f"{page.name}: {m.group(0)!r}"
        for page in gen.PAGES
        for m in _WALL_CLOCK.finditer(page.read_text(encoding="utf-8"))
    ]
    assert not found, found
