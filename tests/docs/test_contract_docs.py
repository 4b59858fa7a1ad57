"""The model contract's member list is written once (issue 36): the how-to's table of members
(``docs/howto/own-model.md``) and the member list of ``UserModel``'s docstring are what
``docs/make_contract_docs.py`` generates from :class:`~gearchaos.model.contract.Capabilities`,
and every member of the record is in both. A failure names the file; running the script
rewrites it.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

from gearchaos.model.contract import Capabilities, UserModel

ROOT = Path(__file__).resolve().parents[2]


def _generator() -> ModuleType:
    spec = importlib.util.spec_from_file_location(
        "make_contract_docs", ROOT / "docs" / "make_contract_docs.py"
    )
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


gen = _generator()
MEMBERS = [f.name for f in dataclasses.fields(Capabilities)]


def test_the_committed_member_lists_are_the_records() -> None:
    assert gen.stale() == [], "run docs/make_contract_docs.py"


def test_every_member_is_in_the_table_and_the_docstring() -> None:
    page = gen.PAGE.read_text(encoding="utf-8")
    rows = [line for line in page.splitlines() if line.startswith("| `")]
    assert len(rows) == len(MEMBERS) > 20
    for name, row in zip(MEMBERS, rows, strict=True):
        assert row.startswith((f"| `{name}` |", f"| `{name}(")), (name, row)
    doc = UserModel.__doc__ or ""
    for name in MEMBERS:
        assert f"* ``{name}`` (" in doc or f"* ``{name}(self" in doc, name
    required = [row for row in rows if row.endswith("| **required** |")]
    assert len(required) == len(Capabilities.REQUIRED)


def test_a_changed_record_is_found(tmp_path: Path) -> None:
    """The check fails when the committed text is not the record's: a page whose table lacks
    a row is stale, and the rewrite restores it."""
    page = tmp_path / "own-model.md"
    start, end = gen.MARKERS[gen.PAGE]
    table = gen.table()
    short = "\n".join(line for line in table.splitlines() if "`warn_for(" not in line)
    page.write_text(f"intro\n\n{start}\n{short}\n{end}\n\nrest\n", encoding="utf-8")
    gen.MARKERS[page] = gen.MARKERS[gen.PAGE]
    try:
        text, new = gen._replace(page, table)
    finally:
        del gen.MARKERS[page]
    assert new != text and "`warn_for(self, analysis)`" in new and new.endswith("rest\n")
