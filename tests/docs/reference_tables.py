"""Defects of the API reference's parameter and attribute tables, read from the built HTML.

mkdocstrings renders a numpydoc section (Parameters, Attributes, Returns …) as a table whose
*Type* column is what follows ``name :``. A docstring written ``kind : one of EVENT_KINDS.``
therefore puts its sentence in the Type column, leaves the Description empty, and a Sphinx role
in that sentence reaches the page as the escaped text ``<autoref identifier=…>`` (the type is
escaped, never turned into a link). :func:`defects` finds both on a built page: a literal
``autoref`` tag anywhere, and a Type cell that is not a type expression.
"""

from __future__ import annotations

import builtins
import re
from html.parser import HTMLParser

#: Unresolved cross-references, escaped (in a type or code cell) or left as a tag.
RAW_AUTOREF = re.compile(r"&lt;/?autoref\b|<autoref\b|&amp;lt;autoref", re.I)

#: Lower-case words a numpydoc type may use besides the builtins' names.
TYPE_WORDS = frozenset(
    {
        "of",
        "or",
        "to",
        "optional",
        "default",
        "shape",
        "like",
        "array",
        "ndarray",
        "np",
        "numpy",
        "xr",
        "xarray",
        "pd",
        "os",
        "typing",
        "collections",
        "abc",
        "mapping",
        "sequence",
        "iterable",
        "callable",
        "path",
    }
    | {name for name in dir(builtins) if name.islower()}
)
_WORD = re.compile(r"[A-Za-z_]\w*")
#: A Returns entry naming the items of a tuple: ``(figure, rows)``.
_NAMED_TUPLE = re.compile(r"^\(\w+(?:, \w+)+\)$")


class _Tables(HTMLParser):
    """Every ``<table>`` of a page as its header cells and rows of cell texts."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.tables: list[tuple[list[str], list[list[str]]]] = []
        self._open: list[tuple[list[str], list[list[str]]]] = []
        self._row: list[tuple[str, str]] | None = None
        self._cell: list[str] | None = None
        self._kind = ""

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag == "table":
            self._open.append(([], []))
            self.tables.append(self._open[-1])
        elif tag == "tr" and self._open:
            self._row = []
        elif tag in ("td", "th") and self._row is not None:
            self._cell, self._kind = [], tag

    def handle_endtag(self, tag: str) -> None:
        if tag == "table" and self._open:
            self._open.pop()
        elif tag in ("td", "th") and self._cell is not None and self._row is not None:
            self._row.append((self._kind, " ".join("".join(self._cell).split())))
            self._cell = None
        elif tag == "tr" and self._row is not None and self._open:
            head, rows = self._open[-1]
            if self._row and all(kind == "th" for kind, _ in self._row):
                head[:] = [text for _, text in self._row]
            else:
                rows.append([text for _, text in self._row])
            self._row = None

    def handle_data(self, data: str) -> None:
        if self._cell is not None:
            self._cell.append(data)


def is_type(text: str) -> bool:
    """Whether a Type cell reads as a type (``dict[str, float]``, ``int or None``,
    ``list of Attractor``, ``(figure, rows)``), not a sentence (``the branch's arclength``)."""
    text = text.strip()
    if not text or _NAMED_TUPLE.match(text):
        return True
    if text[-1] in ".;:" or "'" in text or "’" in text:
        return False
    return all(
        word[0].isupper() or word in TYPE_WORDS or "_" in word or word.isupper()
        for word in _WORD.findall(text)
    )


def defects(html: str) -> list[str]:
    """``name: type cell`` of each table row whose Type is not a type, and each raw autoref."""
    found = [f"raw autoref: …{m.group(0)}…" for m in RAW_AUTOREF.finditer(html)]
    parser = _Tables()
    parser.feed(html)
    for head, rows in parser.tables:
        if "Type" not in head:
            continue
        column = head.index("Type")
        for row in rows:
            if column < len(row) and not is_type(row[column]):
                found.append(f"{row[0]}: Type cell {row[column]!r}")
    return found
