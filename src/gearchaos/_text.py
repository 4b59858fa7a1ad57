r"""Text from files shown safely: control characters as visible escapes.

A gear-set name read from an orbit file, a store's title, a path typed on the command line:
text that did not come from gearchaos can hold control characters. Written raw to a terminal,
``"\x1b]0;owned\x07\x1b[2J"`` retitles the window and clears the screen; in a CSV row or a
table, a newline starts a forged row. :func:`escape_text` is the one function every such string
goes through before it reaches a terminal, a table, a figure or an export: each character that
would act instead of print (C0 and C1 controls, DEL, line and paragraph separators, format
characters such as the bidirectional overrides, and the lone surrogates that stand for
undecodable bytes of a file name) is written as a Python-style escape (``\n``, ``\x1b``,
``\u202e``); everything else, including backslashes and non-ASCII letters, is kept as it is.

A leaf module: it imports nothing from the package.
"""

from __future__ import annotations

import os
import unicodedata

__all__ = ["escape_path", "escape_text"]

#: Named escapes for the most common controls.
_NAMED = {"\n": "\\n", "\r": "\\r", "\t": "\\t"}

#: Unicode categories of characters that act instead of print: controls, format characters
#: (bidirectional overrides, zero-width characters), line and paragraph separators, and
#: surrogates.
_ACTING = frozenset({"Cc", "Cf", "Zl", "Zp", "Cs"})


def _escape_char(ch: str) -> str:
    named = _NAMED.get(ch)
    if named is not None:
        return named
    code = ord(ch)
    if 0xDC80 <= code <= 0xDCFF:  # an undecodable byte of a file name (surrogateescape)
        return f"\\x{code - 0xDC00:02x}"
    if code < 0x100:
        return f"\\x{code:02x}"
    if code < 0x10000:
        return f"\\u{code:04x}"
    return f"\\U{code:08x}"


def escape_text(value: object, *, keep: str = "") -> str:
    r"""``value`` as text that only prints: every control character is shown as an escape.

    Parameters
    ----------
    value : object
        Usually a ``str`` read from a file, a store or the command line; anything else is
        converted with ``str`` first (a path: :func:`escape_path`).
    keep : str, optional
        Characters left as they are (``"\n"`` for a message of several lines whose parts
        were escaped where they came from a file).

    Returns
    -------
    str
        The text with each character of Unicode category Cc, Cf, Zl, Zp or Cs replaced by
        ``\n``, ``\r``, ``\t``, ``\xNN``, ``\uNNNN`` or ``\UNNNNNNNN``; a lone surrogate
        U+DC80–U+DCFF (an undecodable byte ``NN`` of a file name) by ``\xNN``. Printable text
        is returned unchanged (the same object), so escaping twice changes nothing more
        than escaping once.

    Examples
    --------
    >>> escape_text("sheng2016")
    'sheng2016'
    >>> escape_text("f\x1b[2J.png")
    'f\\x1b[2J.png'
    >>> escape_text("inj\n9.99,INJECTED")
    'inj\\n9.99,INJECTED'
    """
    text = value if isinstance(value, str) else str(value)
    if text.isascii() and text.isprintable():
        return text
    out = []
    for ch in text:
        if ch.isprintable() or ch in keep or unicodedata.category(ch) not in _ACTING:
            out.append(ch)
        else:
            out.append(_escape_char(ch))
    return "".join(out)


def escape_path(path: object) -> str:
    """A file-system path (``str``, path-like or bytes) as printable text for messages:
    :func:`escape_text` of its ``os.fspath`` (bytes decoded with ``surrogateescape``, so an
    undecodable byte shows as ``\\xNN``)."""
    if isinstance(path, str | os.PathLike):
        try:
            path = os.fspath(path)
        except TypeError:
            return escape_text(repr(path))
    if isinstance(path, bytes):
        path = path.decode("utf-8", "surrogateescape")
    return escape_text(path)
