"""Motion labels are read and written in one place: no module but
:mod:`gearchaos.analysis.motion` takes a label apart or spells ``nT`` by hand.

Read from the source with :mod:`ast` (like ``test_architecture``). A module breaks the rule
when it

* slices a label: ``label[:-1]`` of a name or attribute that holds one (``lab``, ``label``,
  ``motion`` …), or ``x[:-1].isdigit()`` of anything;
* tests or strips a ``"T"`` suffix: ``.endswith("T")``, ``.removesuffix("T")``,
  ``.rstrip("T")`` …;
* compiles or matches a regular expression that accepts a period label (``12T``);
* spells a period label: an f-string with ``T`` right after a replacement field
  (``f"{n}T"``), or ``str(n) + "T"``.

The rule is checked on snippets of the code it replaced first, so the test cannot pass by
seeing nothing.
"""

from __future__ import annotations

import ast
import itertools
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "src" / "gearchaos"
MOTION_MODULE = ROOT / "analysis" / "motion.py"
#: Names that hold a label (a slice of one is a parse).
LABEL_NAME = re.compile(r"^(lab|labels?|motions?|verdict|text|head|s)$")
SUFFIX_METHODS = {"endswith", "removesuffix", "rstrip", "strip", "partition", "rpartition"}
REGEX_FUNCTIONS = {"compile", "match", "fullmatch", "search", "findall", "finditer", "sub"}


def _is_drop_last(node: ast.AST) -> bool:
    """``[:-1]``."""
    if not (isinstance(node, ast.Subscript) and isinstance(node.slice, ast.Slice)):
        return False
    sl = node.slice
    up = sl.upper
    return (
        sl.lower is None
        and sl.step is None
        and isinstance(up, ast.UnaryOp)
        and isinstance(up.op, ast.USub)
        and isinstance(up.operand, ast.Constant)
        and up.operand.value == 1
    )


def _holder_name(node: ast.AST) -> str:
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        return node.attr
    return ""


def _accepts_period_label(pattern: str) -> bool:
    try:
        rx = re.compile(pattern)
    except re.error:
        return False
    # the match takes the digits and the T, and the T matters (12Q is not taken whole)
    m, other = rx.search("12T"), rx.search("12Q")
    takes = m is not None and m.group(0)[:1].isdigit() and m.group(0).endswith("T")
    return takes and (other is None or other.group(0) != "12Q")


def label_parses(source: str) -> list[str]:
    """What in ``source`` takes a label apart or spells one, as ``line: what``."""
    out: list[str] = []
    for node in ast.walk(ast.parse(source)):
        line = getattr(node, "lineno", 0)
        if _is_drop_last(node):
            assert isinstance(node, ast.Subscript)
            if LABEL_NAME.match(_holder_name(node.value)):
                out.append(f"{line}: {_holder_name(node.value)}[:-1]")
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            method = node.func.attr
            if method in ("isdigit", "isdecimal", "isnumeric") and _is_drop_last(node.func.value):
                out.append(f"{line}: [:-1].{method}()")
            args = [a.value for a in node.args if isinstance(a, ast.Constant)]
            if method in SUFFIX_METHODS and "T" in args:
                out.append(f'{line}: .{method}("T")')
            if method in REGEX_FUNCTIONS and args and isinstance(args[0], str):
                if _accepts_period_label(args[0]):
                    out.append(f"{line}: regular expression {args[0]!r} reads nT")
        if isinstance(node, ast.JoinedStr):
            parts = node.values
            for a, b in itertools.pairwise(parts):
                if (
                    isinstance(a, ast.FormattedValue)
                    and isinstance(b, ast.Constant)
                    and isinstance(b.value, str)
                    and re.match(r"T(\W|$)", b.value)
                ):
                    out.append(f"{line}: f-string spells nT")
        if (
            isinstance(node, ast.BinOp)
            and isinstance(node.op, ast.Add)
            and isinstance(node.right, ast.Constant)
            and node.right.value == "T"
        ):
            out.append(f'{line}: ... + "T"')
    return out


#: Lines of the code the rule replaced (issue 36), each a parse or spelling of a label.
OLD_CODE = [
    'periodic = lab.endswith("T") and lab[:-1].isdigit()',
    'return int(label[:-1]) if label.endswith("T") and label[:-1].isdigit() else 0',
    "head = label[:-1]",
    'if motion.endswith("T") and motion[:-1].isdigit():\n    pass',
    '_PERIODIC = re.compile(r"^(\\d+)T$")',
    '_LABEL_RE = re.compile(r"^(?:[1-9][0-9]*T|nT|QP|chaos)$")',
    'label = f"{n}T"',
    'parts = [f"{d}T (max |μ| = {mu:.6g})" for d, mu in pairs]',
    '_LONG = f"≥ {MAX + 1}T"',
    'text = str(n) + "T"',
]
#: Code that is no label parse and must pass.
INNOCENT = [
    "g = shot.end[0] - z[:-1]",
    'base = contact.rstrip("_0123456789xy") if contact[-1:].isdigit() else contact',
    "if tail.isdigit():\n    pass",
    'x = f"{sym}(k)"',
    'title = rf"$t\\,/\\,T$ ({name} periods)"',
    'rx = re.compile(r"^fig[0-9]+$")',
    'rx = re.compile(r"[0-9]+(\\.[0-9]+)*")',
    'rx = re.compile(r"(?P<name>[^:]*)(?::[0-9]{0,5})?")',
    "label = Motion.periodic(n).format()",
]


@pytest.mark.parametrize("code", OLD_CODE)
def test_the_rule_sees_the_code_it_replaced(code: str) -> None:
    assert label_parses(code), code


@pytest.mark.parametrize("code", INNOCENT)
def test_the_rule_passes_code_that_reads_no_label(code: str) -> None:
    assert not label_parses(code), code


def test_only_the_motion_module_parses_or_spells_labels() -> None:
    paths = sorted(ROOT.rglob("*.py"))
    assert len(paths) > 100 and MOTION_MODULE in paths
    # the module itself spells nT: the rule sees it
    assert label_parses(MOTION_MODULE.read_text(encoding="utf-8"))
    bad = [
        f"{p.relative_to(ROOT)}:{hit}"
        for p in paths
        if p != MOTION_MODULE
        for hit in label_parses(p.read_text(encoding="utf-8"))
    ]
    assert not bad, (
        "labels taken apart or spelled by hand (use gearchaos.analysis.motion.Motion):\n"
        + "\n".join(bad)
    )
