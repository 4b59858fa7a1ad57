"""The commands and code on the other pages of the site name things that exist.

The tutorial runs in full (``test_tutorial.py``); the how-to and concept pages show commands
whose runs take minutes or need a cluster. Here every ``gearchaos`` command line on those
pages is checked against the command line interface itself — the subcommand exists and
accepts every option given — and every Python block compiles and imports only names that
``gearchaos`` has. That catches a renamed option or function before a reader does.
"""

from __future__ import annotations

import ast
import functools
import importlib
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PAGES = sorted(
    p
    for p in DOCS.rglob("*.md")
    if p.parent.name in ("howto", "concepts", "reference") or p == DOCS / "index.md"
)
BLOCK = re.compile(r"^( *)```(bash|python)\n(.*?)^\1```", re.S | re.M)


def _blocks(page: Path, lang: str) -> list[str]:
    out = []
    for indent, found, code in BLOCK.findall(page.read_text(encoding="utf-8")):
        if found == lang:
            out.append("\n".join(line[len(indent) :] for line in code.splitlines()))
    return out


def _commands(page: Path) -> list[list[str]]:
    commands = []
    for code in _blocks(page, "bash"):
        for line in code.replace("\\\n", " ").splitlines():
            line = line.split(" #", 1)[0].strip()
            if line.startswith("gearchaos "):
                commands.append(shlex.split(line))
    return commands


@functools.cache
def _help(subcommand: str) -> str:
    proc = subprocess.run(
        [sys.executable, "-m", "gearchaos", subcommand, "--help"],
        capture_output=True,
        text=True,
        env={**os.environ, "COLUMNS": "250", "NO_COLOR": "1", "TERM": "dumb"},
    )
    assert proc.returncode == 0, f"gearchaos {subcommand} --help failed:\n{proc.stderr}"
    return proc.stdout


def test_pages_show_commands() -> None:
    assert sum(len(_commands(p)) for p in PAGES) >= 15


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(DOCS)))
def test_commands_use_existing_subcommands_and_options(page: Path) -> None:
    for tokens in _commands(page):
        sub = tokens[1]
        text = _help(sub)
        for token in tokens[2:]:
            if token.startswith("-") and not re.fullmatch(r"-\d.*", token):
                option = token.split("=", 1)[0]
                assert re.search(rf"(?<![\w-]){re.escape(option)}(?![\w-])", text), (
                    f"{page.relative_to(DOCS)}: 'gearchaos {sub}' has no option {option} "
                    f"(command: {' '.join(tokens)})"
                )


def _gearchaos_names(tree: ast.AST) -> list[tuple[str, str]]:
    """(module, name) pairs a block takes from gearchaos: imports and ``gc.NAME``."""
    aliases = {"gearchaos"}
    pairs: list[tuple[str, str]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] == "gearchaos":
                    pairs.append((a.name, ""))
                    if a.asname:
                        aliases.add(a.asname)
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("gearchaos"):
            pairs += [(node.module or "", a.name) for a in node.names]
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Attribute)
            and isinstance(node.value, ast.Name)
            and node.value.id in aliases
        ):
            pairs.append(("gearchaos", node.attr))
        elif (
            isinstance(node, ast.Attribute)
            and isinstance(node.value, ast.Attribute)
            and isinstance(node.value.value, ast.Name)
            and node.value.value.id in aliases
        ):
            pairs.append((f"gearchaos.{node.value.attr}", node.attr))
    return pairs


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(DOCS)))
def test_python_blocks_compile_and_name_existing_objects(page: Path) -> None:
    for code in _blocks(page, "python"):
        tree = ast.parse(code, filename=str(page))
        for module, name in _gearchaos_names(tree):
            assert not name or hasattr(_resolve(module), name), (
                f"{page.relative_to(DOCS)}: {module} has no {name}"
            )


def _resolve(dotted: str) -> object:
    """The module or object ``dotted`` names (``gearchaos.GearSet`` is a class)."""
    try:
        return importlib.import_module(dotted)
    except ImportError:
        parent, _, attr = dotted.rpartition(".")
        return getattr(_resolve(parent), attr)
