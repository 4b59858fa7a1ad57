"""The package's layering holds: no import cycle between modules, no import from a lower layer
to a higher one (``gearset → model → integrate → analysis → dynamics → sweep → plot → paper →
cli``), the layers hold their concepts (analysis pure, the integrator driven from dynamics),
no module over 600 lines, and the layers above the model read the model contract's record
instead of probing the model for its members.

Imports are read from the source with :mod:`ast`, *including imports inside functions* (a lazy
import hides a cycle from Python but not from a reader), and resolved to the module they load:
``from .. import sweep`` loads ``gearchaos.sweep``, ``from .._version import __version__`` loads
``gearchaos._version``. A package's ``__init__`` counts as a module of its package's layer.
"""

from __future__ import annotations

import ast
import dataclasses
from pathlib import Path

import pytest

from gearchaos.model.contract import Capabilities

ROOT = Path(__file__).resolve().parents[1] / "src" / "gearchaos"

#: Layers from the bottom. Leaf modules at the package top are below everything; the package
#: top (the public facade) and ``__main__`` are above everything.
LAYERS = (
    "base",
    "gearset",
    "model",
    "integrate",
    "analysis",
    "dynamics",
    "sweep",
    "plot",
    "paper",
    "explore",
    "cli",
    "facade",
)
BASE_MODULES = {"errors", "_checks", "_version", "_numba", "_files", "_output", "_text", "_marks"}
MAX_LINES = 600


def _module_name(path: Path) -> str:
    rel = path.relative_to(ROOT.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _modules() -> dict[str, Path]:
    return {_module_name(p): p for p in sorted(ROOT.rglob("*.py"))}


def _layer(module: str) -> str:
    parts = module.split(".")
    if len(parts) == 1 or parts[1] == "__main__":
        return "facade"
    if parts[1] in BASE_MODULES:
        return "base"
    return parts[1]


def _imports(module: str, path: Path, known: set[str]) -> set[str]:
    """Modules of the package that ``module`` imports anywhere in its source."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    is_package = path.name == "__init__.py"
    package = module if is_package else module.rpartition(".")[0]
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == "gearchaos":
                    out.add(alias.name)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                if node.level > 1:
                    base = base[: len(base) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] != "gearchaos":
                continue
            for alias in node.names:
                sub = f"{target}.{alias.name}"
                out.add(sub if sub in known else target)
    out.discard(module)
    return {m for m in out if m in known}


def _graph() -> dict[str, set[str]]:
    mods = _modules()
    known = set(mods)
    return {m: _imports(m, p, known) for m, p in mods.items()}


def test_the_analysis_sees_the_package() -> None:
    graph = _graph()
    assert len(graph) > 40
    # a few imports that must be found, so the test cannot pass by seeing nothing
    assert "gearchaos.integrate._chains" in graph["gearchaos.integrate.simulate"]
    assert "gearchaos.sweep.result" in graph["gearchaos.plot.bifurcation"]
    assert "gearchaos.errors" in graph["gearchaos._checks"]


def test_no_import_from_a_lower_layer_to_a_higher_one() -> None:
    graph = _graph()
    rank = {name: k for k, name in enumerate(LAYERS)}
    bad = []
    for module, deps in graph.items():
        for dep in deps:
            if rank[_layer(dep)] > rank[_layer(module)]:
                bad.append(f"{module} ({_layer(module)}) imports {dep} ({_layer(dep)})")
    assert not bad, "imports against the layering:\n" + "\n".join(sorted(bad))


def test_analysis_is_pure_and_the_integrator_is_driven_from_dynamics() -> None:
    """Issue 25's layers by concept: the analysis layer holds pure functions of recorded
    arrays (it never imports the integrator); what drives the integrator — Lyapunov
    exponents, orbits, continuation and its events, branch files, attractors, verdicts —
    lives in dynamics; modal analysis and derived quantities with the model; rendering of
    tables in the command line."""
    graph = _graph()
    mods = _modules()
    for module, deps in graph.items():
        if _layer(module) == "analysis":
            assert not any(d.startswith("gearchaos.integrate") for d in deps), (module, deps)
            assert "rich" not in mods[module].read_text(encoding="utf-8"), module
    for name in ("lyapunov", "orbits", "shooting", "arclength", "branch", "branch_events",
                 "coexistence", "verdict", "orbit_batch"):  # fmt: skip
        assert f"gearchaos.dynamics.{name}" in graph, name
        assert f"gearchaos.analysis.{name}" not in graph, name
    assert "gearchaos.model.modal" in graph and "gearchaos.model.derived" in graph


def test_no_import_cycle() -> None:
    graph = _graph()
    # Tarjan's strongly connected components
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    cycles: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    assert not cycles, "import cycles:\n" + "\n".join(" ↔ ".join(c) for c in cycles)


@pytest.mark.parametrize("path", sorted(ROOT.rglob("*.py")), ids=lambda p: _module_name(p))
def test_no_module_is_longer_than_600_lines(path: Path) -> None:
    n = len(path.read_text(encoding="utf-8").splitlines())
    assert n <= MAX_LINES, f"{path.relative_to(ROOT)} has {n} lines (split it along its concerns)"


#: The members of the model contract (the fields of its record).
MEMBERS = frozenset(f.name for f in dataclasses.fields(Capabilities))
#: ``getattr``/``hasattr`` calls naming a member of the model contract that remain outside
#: ``gearset/`` and ``model/``, by (file, member), each with the reason it stays.
MEMBER_PROBES_KEPT = {
    ("dynamics/branch.py", "kind"): "hasattr(start, 'kind') asks whether a branch's start is "
    "a continuation event (kind, value) or an orbit: no model is probed",
}


def _member_probes(source: str) -> list[tuple[int, str]]:
    """(line, member) of every ``getattr(x, "member", …)`` or ``hasattr(x, "member")`` in
    ``source`` whose name is a member of the model contract."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Name)
            and node.func.id in ("getattr", "hasattr")
            and len(node.args) >= 2
            and isinstance(node.args[1], ast.Constant)
            and node.args[1].value in MEMBERS
        ):
            out.append((node.lineno, str(node.args[1].value)))
    return out


def test_the_layers_above_the_model_read_its_record() -> None:
    """Issue 36: a member of the model contract is read from the record
    (``system.capabilities``, ``Capabilities.of(model)``), which gives every model the same
    defaults, not probed on the model with ``getattr``/``hasattr`` and a default of the
    caller's own. Outside ``gearset/`` and ``model/`` only the probes listed in
    :data:`MEMBER_PROBES_KEPT` remain (21 before the record)."""
    assert _member_probes('getattr(model, "scales", None)\nhasattr(m, "period_name")') == [
        (1, "scales"),
        (2, "period_name"),
    ]
    found = []
    for path in sorted(ROOT.rglob("*.py")):
        rel = path.relative_to(ROOT)
        if rel.parts[0] in ("gearset", "model"):
            continue
        for line, member in _member_probes(path.read_text(encoding="utf-8")):
            found.append((rel.as_posix(), line, member))
    unexplained = [f"{f}:{n} probes {m}" for f, n, m in found if (f, m) not in MEMBER_PROBES_KEPT]
    assert not unexplained, "read the model contract's record instead:\n" + "\n".join(unexplained)
    assert len(found) <= len(MEMBER_PROBES_KEPT), found
