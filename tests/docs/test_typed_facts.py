"""No measured value is typed into the how-to pages or the tutorial (issue 35, item 5).

A value the prose states as found by a run — ``Ω ≈ 3.42``, ``3.16 ≲ Ω ≲ 3.4`` — goes stale
when the code changes (maps.md said no chaos from ξ = 0.07 on while its figure showed some;
hysteresis.md gave ranges its band did not show). Such values are generated from the run
between ``<!-- gen:… -->`` markers (``docs/make_doc_numbers.py``), or the page has a test of
its own that checks them. Here every ``≈``, ``≲`` or ``≳`` next to a number in the prose (not
in code blocks, not inside markers) of those pages is refused, except on the pages listed in
:data:`CHECKED_BY`.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGES = [*sorted((ROOT / "docs" / "howto").glob("*.md")), ROOT / "docs" / "tutorial" / "index.md"]
#: Pages whose measured values a test of their own checks against the run.
CHECKED_BY = {"own-model.md": "tests/docs/test_howto_own_model.py"}
APPROXIMATE = re.compile(r"(?:[≈≲≳] ?[−-]?\d[\d.]*|\d[\d.]* ?[≲≳])")


def typed_values(text: str) -> list[str]:
    """The approximate values of ``text``'s prose, with a little context."""
    text = re.sub(r"<!-- gen:.*?<!-- /gen -->", "", text, flags=re.S)
    text = re.sub(r"^( *)```.*?^\1```", "", text, flags=re.S | re.M)
    text = re.sub(r"`[^`\n]*`", "", text)
    return [text[max(0, m.start() - 30) : m.end() + 10] for m in APPROXIMATE.finditer(text)]


def test_typed_values_are_found() -> None:
    page = "up to Ω ≈ 3.42, over 3.16 ≲ Ω ≲ 3.4; Ω ≈ <!-- gen:x.y -->1.0<!-- /gen -->\n"
    found = typed_values(page + "```bash\necho ≈ 2\n```\n")
    assert len(found) == 3  # the generated value and the code block are not typed values


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_no_measured_value_is_typed(page: Path) -> None:
    if page.name in CHECKED_BY:
        assert (ROOT / CHECKED_BY[page.name]).is_file()
        return
    found = typed_values(page.read_text(encoding="utf-8"))
    assert not found, (
        f"{page.name} types measured values {found}: generate them from the run "
        "(docs/make_doc_numbers.py) or remove them"
    )
