"""The runnable code blocks of the tutorial page (``docs/tutorial/index.md``), in page order.

Conventions of the page, which :func:`blocks` reads:

* fenced blocks in ``bash`` are shell commands, in ``python`` Python code; ``text`` blocks are
  output shown to the reader and are not run;
* a block inside a content tab (``=== "Full …"`` / ``=== "Quick …"``) belongs to that variant:
  the tests run the *Quick* one, ``docs/make_tutorial_figures.py`` the *Full* one, and a Full
  command must equal its Quick twin except for numbers;
* the install block (``python3 -m venv …``) is not run: it must be the install line of
  ``.ci/run``, which CI runs from a clean clone.

:func:`script` turns the blocks of one variant into one bash script (Python blocks become
``python - <<'EOF'`` here-documents), so that ``source .venv/bin/activate`` carries over to the
commands after it, as in the reader's shell.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TUTORIAL = ROOT / "docs" / "tutorial" / "index.md"

_FENCE = re.compile(r"^(?P<indent> *)```(?P<lang>[\w-]*)")
_TAB = re.compile(r'^=== "(?P<label>[^"]+)"')
RUNNABLE = ("bash", "python")


@dataclass(frozen=True)
class Block:
    """One fenced code block: language, text, 1-based line of its fence, and its tab variant
    (``"full"``, ``"quick"`` or None outside tabs)."""

    lang: str
    code: str
    line: int
    variant: str | None

    @property
    def is_install(self) -> bool:
        return self.lang == "bash" and self.code.lstrip().startswith("python3 -m venv")


def blocks(path: Path = TUTORIAL) -> list[Block]:
    """Every fenced code block of the page, in order."""
    lines = path.read_text(encoding="utf-8").splitlines()
    out: list[Block] = []
    variant: str | None = None
    i = 0
    while i < len(lines):
        line = lines[i]
        tab = _TAB.match(line)
        if tab:
            label = tab["label"].split()[0].lower()
            if label not in ("full", "quick"):
                raise ValueError(f"{path}:{i + 1}: a tab must be 'Full …' or 'Quick …': {line!r}")
            variant = label
            i += 1
            continue
        if line.strip() and not line.startswith(" ") and not _TAB.match(line):
            variant = None  # text at the margin ends a tab group
        fence = _FENCE.match(line)
        if fence:
            indent = fence["indent"]
            body: list[str] = []
            j = i + 1
            while j < len(lines) and lines[j].rstrip() != f"{indent}```":
                body.append(lines[j][len(indent) :])
                j += 1
            if j == len(lines):
                raise ValueError(f"{path}:{i + 1}: unclosed code block")
            out.append(Block(fence["lang"], "\n".join(body) + "\n", i + 1, variant))
            i = j + 1
            continue
        i += 1
    return out


def runnable(variant: str, path: Path = TUTORIAL) -> list[Block]:
    """The blocks a reader following ``variant`` (``quick`` or ``full``) runs, in order."""
    if variant not in ("quick", "full"):
        raise ValueError(f"variant must be quick or full: got {variant!r}")
    return [
        b
        for b in blocks(path)
        if b.lang in RUNNABLE and not b.is_install and b.variant in (None, variant)
    ]


def script(variant: str, path: Path = TUTORIAL) -> str:
    """One bash script running the blocks of ``variant`` in order; each is announced on
    stderr with its line number, and the script stops at the first failing command."""
    parts = ["set -euo pipefail"]
    for b in runnable(variant, path):
        parts.append(f"echo '### tutorial block at line {b.line} ({b.lang})' >&2")
        if b.lang == "bash":
            parts.append(b.code)
        else:
            if "\nPYTHON_BLOCK\n" in f"\n{b.code}":
                raise ValueError(f"{path}:{b.line}: the block contains the here-doc delimiter")
            parts.append(f"python - <<'PYTHON_BLOCK'\n{b.code}PYTHON_BLOCK")
    return "\n".join(parts) + "\n"


def numbers_masked(code: str) -> str:
    """The code with every number replaced by ``N`` (Full and Quick twins must match so)."""
    return re.sub(r"\d+(\.\d+)?", "N", code)
