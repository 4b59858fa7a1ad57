"""The one escape of text from files (issue 33): control characters never reach a terminal,
a table, a figure or an export raw."""

from __future__ import annotations

import unicodedata

from hypothesis import given, strategies as st

from gearchaos._text import escape_path, escape_text


def test_terminal_sequences_and_row_breaks_are_shown_as_escapes() -> None:
    assert escape_text("\x1b]0;owned\x07\x1b[2J") == "\\x1b]0;owned\\x07\\x1b[2J"
    assert escape_text("inj\n9.99,INJECTED,0,0.zarr") == "inj\\n9.99,INJECTED,0,0.zarr"
    assert escape_text("a\rb\tc\x7fd\x85e") == "a\\rb\\tc\\x7fd\\x85e"
    assert escape_text("left\u202eright\u2028") == "left\\u202eright\\u2028"
    # letters, symbols and spaces of any script print as they are
    assert escape_text("Ω = 1.5, δ̄ sun–planet\u00a0ü") == "Ω = 1.5, δ̄ sun–planet\u00a0ü"
    assert escape_text(1.5) == "1.5"


def test_paths_show_undecodable_bytes_and_controls() -> None:
    assert escape_path(b"/x/\xff\x1b[2J.png") == "/x/\\xff\\x1b[2J.png"
    assert escape_path("/x/\udcff.nc") == "/x/\\xff.nc"
    from pathlib import Path

    assert escape_path(Path("f\x1b[2J.png")) == "f\\x1b[2J.png"


@given(st.text())
def test_the_result_only_prints_and_escaping_is_idempotent(text: str) -> None:
    out = escape_text(text)
    acting = {"Cc", "Cf", "Zl", "Zp", "Cs"}
    assert not [c for c in out if unicodedata.category(c) in acting]
    assert escape_text(out) == out
    out.encode("utf-8")  # no lone surrogate left: every terminal encoding can write it
    # nothing printable is lost: removing the escapes' text leaves the printable characters
    kept = [c for c in text if unicodedata.category(c) not in acting]
    it = iter(out)
    assert all(any(c == o for o in it) for c in kept)
