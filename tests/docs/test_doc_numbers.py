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


_BRANCH = """period-2 branch of sheng2016 in omega
│ stable 1.5 … 1.56944 (8588.4 … 8986 rpm)    │                         49 points │
│ unstable 1.5694 … 1.5 (8985.7 … 8588.4 rpm) │                         54 points │
┃ kind           ┃ omega ± uncertainty ┃ sun speed [rpm] ┃ multiplier              ┃ detail ┃
│ {kind:<14} │ 1.569437771 ± 6e-09 │ 8986            │ 1+0i (|μ| 1)            │        │
│ neimark_sacker │ 1.52924668 ± 6e-08  │ 8755.9          │ -0.8876+0.4606i (|μ| 1) │        │
"""
_ATTRACTORS = "│ 2T     │ -0.01332 │ {starts} │ -16.312, -14.391     │ max |μ| = 0.8944, {kind} │\n"


def test_the_readmes_continuation_claim_is_checked(monkeypatch: pytest.MonkeyPatch) -> None:
    """The README says the 2T orbit is stable from Ω = 1.5 up to a fold where its branch turns
    back: a branch that ends its stable stretch otherwise is prose out of date."""
    printed = {"text": _BRANCH.format(kind="fold")}
    monkeypatch.setattr(gen, "run", lambda command, cwd: printed["text"])
    assert gen._continuation(Path(".")) == {"fold": "1.569"}
    printed["text"] = _BRANCH.format(kind="period_doubling")  # no fold ends it
    with pytest.raises(gen.ProseOutOfDate, match="fold"):
        gen._continuation(Path("."))
    printed["text"] = _BRANCH.format(kind="fold").replace("│ stable", "│ unstable")
    with pytest.raises(gen.ProseOutOfDate, match="stable"):
        gen._continuation(Path("."))


def test_the_readmes_attractor_claim_is_checked(monkeypatch: pytest.MonkeyPatch) -> None:
    """The README says all eight starts at Ω = 1.5 end on one stable 2T orbit."""
    every = "0, 1, 2, 3, 4, 5, 6, 7"
    printed = {"text": _ATTRACTORS.format(starts=every, kind="stable")}
    monkeypatch.setattr(gen, "run", lambda command, cwd: printed["text"])
    assert gen._attractors(Path(".")) == {"mu": "0.894"}
    two = _ATTRACTORS.format(starts="0, 1, 2, 3", kind="stable")
    printed["text"] = two + two.replace("0, 1, 2, 3", "4, 5, 6, 7").replace("2T", "chaos", 1)
    with pytest.raises(gen.ProseOutOfDate, match="eight starts"):
        gen._attractors(Path("."))
    printed["text"] = _ATTRACTORS.format(starts=every, kind="unstable")
    with pytest.raises(gen.ProseOutOfDate, match="no longer stable"):
        gen._attractors(Path("."))


#: A made-up Full sweep in the shape step 4 describes: (lo, hi, label, contact regime, X̄).
_WINDOWS = [
    (0.05, 0.38, "1T", 0, 3.6), (0.42, 0.52, "chaos", 2, -5.0), (0.53, 0.55, "chaos", 2, -5.0),
    (0.56, 0.64, "chaos", 2, -5.0), (0.66, 0.69, "chaos", 2, -5.0), (0.71, 0.74, "chaos", 2, -5.0),
    (0.75, 0.79, "5T", 2, -5.0), (0.79, 0.82, "QP", 2, -5.0), (0.83, 0.93, "1T", 2, -9.0),
    (0.94, 1.40, "chaos", 2, -5.0), (1.44, 1.54, "2T", 2, -15.0), (1.541, 1.57, "chaos", 2, 5.0),
    (1.59, 1.92, "chaos", 2, 5.0), (1.97, 2.12, "chaos", 1, 5.0), (2.13, 2.24, "chaos", 1, 5.0),
    (2.25, 2.29, "QP", 1, 5.0), (2.32, 2.35, "2T", 1, 5.0), (2.41, 2.44, "chaos", 2, -5.0),
    (2.52, 2.55, "QP", 1, 5.0), (2.56, 2.89, "chaos", 1, 5.0), (2.90, 2.93, "chaos", 1, 5.0),
    (3.00, 3.04, "3T", 1, 2.0), (3.10, 4.0, "1T", 1, 2.6),
]  # fmt: skip


def _made_up_sweep(change: dict[int, tuple[str, int]] | None = None) -> tuple[object, dict]:
    import numpy as np
    import xarray as xr

    omega = np.round(np.linspace(0.05, 4.0, 800), 6)
    motion = np.full(omega.size, "chaos", dtype=object)
    contact = np.full(omega.size, 2)
    x = np.zeros(omega.size)
    values: dict[str, str] = {}
    for n, (lo, hi, label, regime, level) in enumerate(_WINDOWS, start=1):
        label, regime = (change or {}).get(n, (label, regime))
        inside = (omega >= lo) & (omega <= hi)
        motion[inside], contact[inside], x[inside] = label, regime, level
        first, last = omega[inside][0], omega[inside][-1]
        values[f"w{n}.{label}.lo"], values[f"w{n}.{label}.hi"] = f"{first:.3f}", f"{last:.3f}"
        values[f"w{n}.{label}.mean"] = repr(level)
    planets = np.broadcast_to(contact[:, None], (omega.size, 5))
    ds = xr.Dataset(
        {
            "motion": ("omega", motion.astype(str)),
            "contact_sp": (("omega", "planet_all"), planets.copy()),
            "contact_rp": (("omega", "planet_all"), planets.copy()),
            "delta_sp": (("omega", "planet"), np.stack([x, x], axis=1)),
        },
        coords={"omega": omega, "planet": [1, 2]},
        attrs={"clearance_sun_planet": 3.0},
    )
    ds["contact_sp"].attrs["flag_meanings"] = "unknown none single_sided double_sided"
    return ds, values


def test_the_tutorials_sweep_claims_are_checked() -> None:
    """Step 4's claims about the Full sweep: the contact regime of its 1T and 2T windows, the
    window order and the chaotic stretches. A sweep that differs is prose out of date."""
    gen._fig4a_claims(*_made_up_sweep())  # the sweep the page describes passes
    for change, words in (
        ({9: ("1T", 1)}, "double_sided on every mesh"),  # its 1T without back-flank impact
        ({23: ("1T", 2)}, "single_sided on every mesh"),
        ({1: ("1T", 1)}, "none on every mesh"),  # the quasi-static 1T rattling
        ({11: ("3T", 2)}, "window 11 of the listing is no longer 2T"),
        ({10: ("QP", 2)}, "no longer chaos"),
    ):
        with pytest.raises(gen.ProseOutOfDate, match=words):
            gen._fig4a_claims(*_made_up_sweep(change))
