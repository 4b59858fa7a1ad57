"""Write the model contract's member list where the docs show it, from the record itself.

The model contract is one frozen record, :class:`gearchaos.model.contract.Capabilities`: a
field per member, whose metadata says what the member is and what a model that does not give
it gets. This script writes the table of members of the how-to *Your own gear model*
(``docs/howto/own-model.md``) and the member list of the docstring of
:class:`~gearchaos.model.contract.UserModel` from those fields, between markers::

    <!-- contract-members -->
    | member | what it is | if the model does not give it |
    …
    <!-- /contract-members -->

Run from the repository root with the project's environment:
``.venv/bin/python docs/make_contract_docs.py [--check]``; ``--check`` rewrites nothing and
exits 1 naming the files that differ. ``tests/docs/test_contract_docs.py`` runs the check.
"""

from __future__ import annotations

import dataclasses
import re
import sys
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from gearchaos.model.contract import Capabilities  # noqa: E402

PAGE = ROOT / "docs" / "howto" / "own-model.md"
SOURCE = ROOT / "src" / "gearchaos" / "model" / "contract.py"
#: The markers of the generated text in each file.
MARKERS = {
    PAGE: ("<!-- contract-members -->", "<!-- /contract-members -->"),
    SOURCE: ("<!-- members -->", "<!-- /members -->"),
}
#: Width of the docstring's lines, its indentation included (the project's line length).
WIDTH = 100
INDENT = "    "


def _members() -> list[tuple[str, str, str | None]]:
    """(shown name, what it is, what a model without it gets or None) of every field."""
    out = []
    for f in dataclasses.fields(Capabilities):
        meta = f.metadata
        out.append((meta["shown"] or f.name, meta["doc"], meta["otherwise"]))
    return out


def table() -> str:
    """The how-to's table: one row per member, the required ones first."""
    rows = [
        "| member | what it is | if the model does not give it |",
        "|---|---|---|",
    ]
    for shown, doc, otherwise in _members():
        rows.append(f"| `{shown}` | {doc} | {otherwise or '**required**'} |")
    return "\n".join(rows)


def _rst(text: str) -> str:
    """Markdown inline code as the docstrings write it (``x``)."""
    return re.sub(r"`([^`]+)`", r"``\1``", text)


def members_doc() -> str:
    """The docstring's list: one bullet per member, wrapped to :data:`WIDTH`."""
    lines = []
    for shown, doc, otherwise in _members():
        tail = "(required)" if otherwise is None else f"(otherwise: {otherwise})"
        text = _rst(f"`{shown}` {tail}: {doc}.")
        lines += textwrap.wrap(
            text,
            WIDTH,
            initial_indent=f"{INDENT}* ",
            subsequent_indent=f"{INDENT}  ",
            break_on_hyphens=False,
            break_long_words=False,
        )
    return "\n".join(lines)


def generated() -> dict[Path, str]:
    """What goes between the markers of each file."""
    return {PAGE: table(), SOURCE: members_doc()}


def _replace(path: Path, body: str) -> tuple[str, str]:
    """(the file's text, the text with ``body`` between its markers)."""
    start, end = MARKERS[path]
    text = path.read_text(encoding="utf-8")
    indent = INDENT if path == SOURCE else ""
    pattern = re.compile(re.escape(start) + r".*?" + re.escape(end), re.S)
    if len(pattern.findall(text)) != 1:
        raise SystemExit(f"{path.relative_to(ROOT)} must hold {start} … {end} once")
    new = pattern.sub(lambda _: f"{start}\n{body}\n{indent}{end}", text)
    return text, new


def stale() -> list[str]:
    """The files whose generated text differs from the record's."""
    out = []
    for path, body in generated().items():
        text, new = _replace(path, body)
        if new != text:
            out.append(str(path.relative_to(ROOT)))
    return out


def main(argv: list[str]) -> int:
    if "--check" in argv:
        found = stale()
        for name in found:
            print(f"{name}: the model contract's members differ from Capabilities; run "
                  "docs/make_contract_docs.py")  # fmt: skip
        return 1 if found else 0
    for path, body in generated().items():
        text, new = _replace(path, body)
        if new != text:
            path.write_text(new, encoding="utf-8")
            print(f"wrote {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
