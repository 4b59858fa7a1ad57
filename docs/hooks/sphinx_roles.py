"""Griffe extension: Sphinx roles become cross-references, ``#:`` comments docstrings.

The docstrings are numpydoc with Sphinx roles (``:func:`detect_period```,
``:class:`~gearchaos.model.System```), which mkdocstrings would print verbatim. This extension
rewrites each role, before the docstring is parsed, into an *optional* mkdocs-autorefs
reference: a link when the target is documented on the site, plain code otherwise (never a
build warning). Relative names are resolved in the docstring's own scope; ``~`` keeps only
the last component as the link text, as in Sphinx. Module constants are documented the
Sphinx way, by ``#:`` comment lines above the assignment; they become the constants' docstrings.
"""

from __future__ import annotations

import html
import re
from typing import Any

import griffe

_ROLE = re.compile(r":(?:py:)?(?:func|class|mod|meth|data|attr|exc|obj|const):`(~?)([^`<>]+)`")


def _target(obj: griffe.Object, name: str) -> str:
    """Full dotted path of ``name`` as written in ``obj``'s docstring (best effort)."""
    name = name.strip().removesuffix("()")
    if name.startswith("."):  # relative to the enclosing package: ``:mod:`.poincare```
        package = obj.package.path if obj.is_module or obj.parent else obj.path
        return f"{package}{name}"
    if "." in name and name.split(".", 1)[0] in ("gearchaos", "numpy", "xarray", "scipy"):
        return name
    head, _, rest = name.partition(".")
    try:
        resolved = obj.resolve(head)
    except Exception:  # NameResolutionError, or an alias that cannot be followed
        scope = obj.parent if obj.parent is not None else obj
        try:
            resolved = scope.resolve(head)
        except Exception:
            return name
    return f"{resolved}.{rest}" if rest else resolved


def _rewrite(obj: griffe.Object, text: str) -> str:
    def replace(match: re.Match[str]) -> str:
        tilde, name = match.groups()
        shown = name.strip().split(".")[-1] if tilde else name.strip().lstrip(".")
        target = html.escape(_target(obj, name), quote=True)
        code = f"<code>{html.escape(shown)}</code>"
        return f'<autoref identifier="{target}" optional>{code}</autoref>'

    return _ROLE.sub(replace, text)


def _doc_comment(attr: griffe.Attribute) -> str | None:
    """The ``#:`` comment lines right above an attribute's assignment, as text."""
    if not attr.lineno or attr.parent is None:
        return None
    try:
        lines = attr.module.lines  # the whole file: line numbers are absolute
    except Exception:  # no source (compiled or inspected module)
        return None
    found: list[str] = []
    i = attr.lineno - 2  # 0-based index of the line above the assignment
    while 0 <= i < len(lines) and lines[i].lstrip().startswith("#:"):
        found.insert(0, lines[i].lstrip()[2:].strip())
        i -= 1
    return "\n".join(found) or None


class SphinxRoles(griffe.Extension):
    """Rewrite Sphinx roles in every docstring griffe loads, and read the Sphinx doc-comments
    (``#: text`` above an assignment) of module constants as their docstrings."""

    def on_instance(self, *, obj: griffe.Object, **_: Any) -> None:
        if obj.docstring is not None and ":" in obj.docstring.value:
            obj.docstring.value = _rewrite(obj, obj.docstring.value)

    def on_attribute_instance(self, *, attr: griffe.Attribute, **_: Any) -> None:
        if attr.docstring is None and (text := _doc_comment(attr)):
            attr.docstring = griffe.Docstring(_rewrite(attr, text), lineno=attr.lineno, parent=attr)
