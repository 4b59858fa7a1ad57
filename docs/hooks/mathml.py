"""MkDocs hook: render the site's math as MathML at build time (no JavaScript, no network).

``pymdownx.arithmatex`` (generic mode) finds ``$...$`` and ``$$...$$`` in the Markdown, skipping
code, and wraps the LaTeX in ``<span class="arithmatex">\\(...\\)</span>`` or
``<div class="arithmatex">\\[...\\]</div>``. This hook replaces each of those by the MathML that
:mod:`latex2mathml` makes of it; browsers draw MathML natively, so the built site needs no
MathJax or KaTeX download. A formula latex2mathml cannot convert fails the build, naming it.
"""

from __future__ import annotations

import html
import re
from typing import Any

from latex2mathml.converter import convert

_BLOCK = re.compile(r'<div class="arithmatex">\s*\\\[(.*?)\\\]\s*</div>', re.S)
_INLINE = re.compile(r'<span class="arithmatex">\\\((.*?)\\\)</span>', re.S)


def _mathml(tex: str, display: str, page: Any) -> str:
    source = html.unescape(tex).strip()
    try:
        return convert(source, display=display)
    except Exception as exc:  # latex2mathml raises several types for unknown commands
        where = getattr(getattr(page, "file", None), "src_path", "?")
        raise ValueError(f"{where}: cannot convert the formula {source!r}: {exc}") from exc


def on_page_content(html_text: str, page: Any, **_: Any) -> str:
    """Replace arithmatex's LaTeX wrappers by MathML (block formulas first)."""
    html_text = _BLOCK.sub(
        lambda m: f'<div class="math">{_mathml(m.group(1), "block", page)}</div>', html_text
    )
    return _INLINE.sub(
        lambda m: f'<span class="math">{_mathml(m.group(1), "inline", page)}</span>', html_text
    )
