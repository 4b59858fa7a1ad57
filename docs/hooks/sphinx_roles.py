"""Griffe extension: turn the Sphinx roles of gearchaos' docstrings into cross-references.

The docstrings are numpydoc with Sphinx roles (``:func:`detect_period```,
``:class:`~gearchaos.model.System```), which mkdocstrings would print verbatim. This extension
rewrites each role, before the docstring is parsed, into an *optional* mkdocs-autorefs
reference: a link when the target is documented on the site, plain code otherwise (never a
build warning). Relative names are resolved in the docstring's own scope; ``~`` keeps only
the last component as the link text, as in Sphinx.
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


class SphinxRoles(griffe.Extension):
    """Rewrite Sphinx roles in every docstring griffe loads."""

    def on_instance(self, *, obj: griffe.Object, **_: Any) -> None:
        if obj.docstring is not None and ":" in obj.docstring.value:
            obj.docstring.value = _rewrite(obj, obj.docstring.value)
