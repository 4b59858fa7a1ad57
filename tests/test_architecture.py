"""The package's layering holds: no import cycle between modules, no import from a lower layer
to a higher one (``gearset → model → integrate → analysis → dynamics → sweep → plot → paper →
cli``), the layers hold their concepts (analysis pure, the integrator driven from dynamics),
no module over 600 lines, and the layers above the model read the model contract's record
instead of probing the model for its members.

Imports are read from the source with :mod:`ast`, *including imports inside functions* (a lazy
import hides a cycle from Python but not from a reader), and resolved to the module they load:
``from .. import sweep`` loads ``gearchaos.sweep``, ``from .._version import __version__`` loads
``gearchaos._version``. A package's ``__init__`` counts as a module of its package's layer.

The tests mirror the source (issue 36, item 7): every folder ``tests/<pkg>/`` but the
cross-cutting ones is a package ``src/gearchaos/<pkg>/``, and its test modules use that package.
Outside ``gearset/`` and ``model/``, the lines that ask "is it a gear set?" are counted, and the
count never grows (issue 36's target is zero).
"""

from __future__ import annotations

import ast
import dataclasses
import re
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
    for name in ("lyapunov", "orbits.orbit", "orbits.shooting", "continuation.arclength",
                 "continuation.branch", "continuation.events", "attractors.coexistence",
                 "verdict.decide", "orbits.batch"):  # fmt: skip
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
    (
        "dynamics/continuation/branch.py",
        "kind",
    ): "hasattr(start, 'kind') asks whether a branch's start is "
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


# --------------------------------------------------------------- the tests mirror the source

TESTS = Path(__file__).resolve().parent
#: Folders of tests/ about behaviour across the layers, which mirror no package.
CROSS_CUTTING = {
    "fuzz": "malformed input to every front door",
    "regression": "stores of whole runs compared with frozen references",
    "docs": "the documentation's commands, numbers and figures",
    "examples": "the examples/ scripts, run as users run them",
    "cli": "the command line, which drives every layer",
}
#: Test modules of a package's folder that reach it only through a running process.
NO_IMPORT = {
    "explore/test_browser.py": "drives `gearchaos explore` in headless Chromium",
    "explore/test_server_guard.py": "sends requests to a `gearchaos explore` server process",
    "explore/test_cli_explore.py": "the `explore` command's refusals, before a server starts",
}


def _facade() -> dict[str, str]:
    """Package (``dynamics``, ``gearset``, ``errors`` …) of each name of the top-level API, read
    from ``gearchaos/__init__.py`` (its imports, lazy subpackages and lazy attributes)."""
    out: dict[str, str] = {}
    for node in ast.walk(ast.parse((ROOT / "__init__.py").read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.level == 1 and node.module:
            for alias in node.names:
                out[alias.asname or alias.name] = node.module.split(".")[0]
        elif isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Name):
            value = ast.literal_eval(node.value) if node.targets[0].id.startswith("_LAZY") else ()
            if isinstance(value, tuple):
                out.update({name: name for name in value})
            elif isinstance(value, dict):
                out.update({name: where.split(".")[0] for name, where in value.items()})
    return out


def _uses_module(path: Path, prefix: str) -> bool:
    """Whether the test module ``path`` uses the module or subpackage ``prefix``
    (``gearchaos.dynamics.orbits``): imports from it, or imports a name of a package above it
    (``from gearchaos.dynamics import periodic_orbit``, ``gc.periodic_orbit``) defined in it."""
    import importlib

    tree = ast.parse(path.read_text(encoding="utf-8"))
    aliases = {"gearchaos"}
    for node in ast.walk(tree):
        names: list[tuple[str, str | None]] = []
        if isinstance(node, ast.Import):
            names = [(alias.name, None) for alias in node.names]
            aliases.update(a.asname for a in node.names if a.name == "gearchaos" and a.asname)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names = [(node.module, alias.name) for alias in node.names]
        for module, name in names:
            if module == prefix or module.startswith(prefix + "."):
                return True
            if name and prefix.startswith(module + ".") and module.startswith("gearchaos"):
                obj = getattr(importlib.import_module(module), name, None)
                if str(getattr(obj, "__module__", "")).startswith(prefix):
                    return True
    import gearchaos

    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
            if node.value.id in aliases:
                obj = getattr(gearchaos, node.attr, None)
                if str(getattr(obj, "__module__", "")).startswith(prefix):
                    return True
    return False


def _packages_used(path: Path, facade: dict[str, str]) -> set[str]:
    """Packages of gearchaos a test module uses: ``gearchaos.<pkg>`` imports, and the package
    of each top-level name it imports or reads as ``gc.<name>``."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    used: set[str] = set()
    aliases: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                parts = alias.name.split(".")
                if parts[0] == "gearchaos" and len(parts) > 1:
                    used.add(parts[1])
                elif alias.name == "gearchaos":
                    aliases.add(alias.asname or "gearchaos")
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            parts = node.module.split(".")
            if parts[0] == "gearchaos" and len(parts) > 1:
                used.add(parts[1])
            elif node.module == "gearchaos":
                used.update(facade.get(alias.name, alias.name) for alias in node.names)
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
            if node.value.id in aliases:
                used.add(facade.get(node.attr, node.attr))
    return used


def _test_folders() -> list[Path]:
    return sorted(
        d
        for d in TESTS.iterdir()
        if d.is_dir() and not d.name.startswith((".", "_")) and any(d.rglob("*.py"))
    )


def test_every_test_folder_mirrors_a_package() -> None:
    """Issue 36, item 7: ``tests/<pkg>/`` holds the tests of ``src/gearchaos/<pkg>/``."""
    folders = [d.name for d in _test_folders()]
    assert {"analysis", "dynamics", "model", "fuzz"} <= set(folders), folders
    orphans = [
        name
        for name in folders
        if name not in CROSS_CUTTING and not (ROOT / name / "__init__.py").is_file()
    ]
    assert not orphans, f"test folders without a package src/gearchaos/<name>/: {orphans}"


def test_each_test_module_uses_the_package_its_folder_mirrors() -> None:
    """A module of ``tests/<pkg>/`` imports from ``gearchaos.<pkg>`` or uses a name of the
    top-level API that ``gearchaos.<pkg>`` defines (``gc.attractors`` is ``dynamics``'s): a test
    of code that moved to another package moves with it."""
    facade = _facade()
    assert facade["attractors"] == "dynamics" and facade["preset"] == "gearset", facade
    misplaced = []
    for folder in _test_folders():
        if folder.name in CROSS_CUTTING:
            continue
        for path in sorted(folder.rglob("test_*.py")):
            key = path.relative_to(TESTS).as_posix()
            used = _packages_used(path, facade)
            if folder.name not in used and key not in NO_IMPORT:
                misplaced.append(f"tests/{key} uses {sorted(used)}, not gearchaos.{folder.name}")
            sub = path.parent.relative_to(folder).parts
            if sub and not (ROOT / folder.name / Path(*sub) / "__init__.py").is_file():
                misplaced.append(f"tests/{key} is in a folder no package src/gearchaos/ has")
            elif sub and not _uses_module(path, ".".join(("gearchaos", folder.name, *sub))):
                misplaced.append(f"tests/{key} does not use gearchaos.{folder.name}.{sub[0]}")
    stale = [key for key in NO_IMPORT if not (TESTS / key).is_file()]
    assert not stale, f"NO_IMPORT names test modules that are gone: {stale}"
    assert not misplaced, "test modules in the folder of a package they do not use:\n" + (
        "\n".join(misplaced)
    )


# ------------------------------------------------------------- "is it a gear set?" switches

#: Lines outside ``gearset/`` and ``model/`` that ask "is it a gear set?" (see
#: :func:`gear_set_switches`). Counted when this test was written (main at b782aa6): 65 lines in
#: 29 modules (sweep 21, plot 20, cli 7, paper 6, dynamics 4, analysis 3, explore 3, integrate 1).
#: Issue 36's target is zero: the upper layers ask the model (its contacts, quantities,
#: names), never whether it is a gear set. Each reduction lowers this number; it never grows.
#: After plot/, cli/ and explore/ asked the model (figures, figure_for): 42, of which the 7
#: left in those layers carry a ``# gear-set switch:`` reason. A switch that carries one
#: (:data:`REASON`) is not counted: after sweep, analysis, dynamics, integrate and paper asked
#: the model too, none is left unexplained.
GEAR_SET_SWITCHES = 0
#: The comment that explains a switch that must stay: ``# gear-set switch: <reason>`` on the
#: line the switch starts on, or alone on the line above it, with a reason of a few words.
REASON = re.compile(r"#\s*gear-set switch:\s*(\S+\s+){2,}\S")
#: Names that hold a gear set, or say whether there is one.
GEAR_SET_NAMES = {"gs", "gearset", "base_gearset", "planetary", "is_planetary"}
#: Keys of a summary, store attribute or model member that hold the gear set.
GEAR_SET_KEYS = {"gearset", "gearset_toml"}
GEAR_SET_CLASSES = {"GearSet", "PlanetaryModel"}
#: ``hasattr`` probes that tell a gear set apart (``evolve`` is the gear set's duck type).
GEAR_SET_PROBES = {"gearset", "evolve"}
#: The planetary model's mesh labels: a comparison with them asks "is it a planetary train?".
PLANETARY_MESHES = ("sp", "rp")


def _holds_gear_set(node: ast.AST) -> bool:
    """``gs``, ``res.gearset``, ``summary.get("gearset")``, ``attrs["gearset_toml"]``,
    ``getattr(model, "gearset", None)``, ``planetary`` …"""
    if isinstance(node, ast.Name | ast.Attribute):
        return (node.id if isinstance(node, ast.Name) else node.attr) in GEAR_SET_NAMES
    if isinstance(node, ast.Subscript):
        return isinstance(node.slice, ast.Constant) and node.slice.value in GEAR_SET_KEYS
    if isinstance(node, ast.Call):
        func, args = node.func, node.args
        if isinstance(func, ast.Attribute) and func.attr == "get" and args:
            return isinstance(args[0], ast.Constant) and args[0].value in GEAR_SET_KEYS
        if isinstance(func, ast.Name) and func.id == "getattr" and len(args) >= 2:
            return isinstance(args[1], ast.Constant) and args[1].value in GEAR_SET_KEYS
    return False


def _class_names(node: ast.AST) -> set[str]:
    if isinstance(node, ast.Tuple):
        return set().union(*(_class_names(e) for e in node.elts))
    if isinstance(node, ast.BinOp):  # System | GearSet
        return _class_names(node.left) | _class_names(node.right)
    return {node.id} if isinstance(node, ast.Name) else set()


def _truth_operands(test: ast.AST) -> list[ast.AST]:
    """What a truth test tests, through ``not``, ``and`` and ``or``."""
    if isinstance(test, ast.UnaryOp) and isinstance(test.op, ast.Not):
        return _truth_operands(test.operand)
    if isinstance(test, ast.BoolOp):
        return [t for value in test.values for t in _truth_operands(value)]
    return [test]


def _is_switch(node: ast.AST) -> bool:
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and len(node.args) == 2:
        name, (_, second) = node.func.id, node.args
        if name == "isinstance":
            return bool(_class_names(second) & GEAR_SET_CLASSES)
        if name == "hasattr":
            return isinstance(second, ast.Constant) and second.value in GEAR_SET_PROBES
    if isinstance(node, ast.Compare):
        sides = [node.left, *node.comparators]
        constants = [s.value for s in sides if isinstance(s, ast.Constant)]
        meshes = [
            tuple(e.value if isinstance(e, ast.Constant) else None for e in s.elts)
            for s in sides
            if isinstance(s, ast.List | ast.Tuple)
        ]
        if "planetary" in constants or PLANETARY_MESHES in meshes:
            return True
        return None in constants and any(_holds_gear_set(s) for s in sides)
    return False


def gear_set_switches(source: str) -> list[int]:
    """Lines of ``source`` that ask "is it a gear set?" without saying why (a line counts once;
    a line that carries a :data:`REASON` comment is not counted):

    * ``isinstance(x, GearSet)`` or ``PlanetaryModel`` (also in a tuple or a union);
    * ``hasattr(x, "gearset")``, ``hasattr(x, "evolve")``;
    * a gear set compared with ``None`` (``gs is None``, ``res.gearset is not None``,
      ``summary.get("gearset") is None``, ``getattr(m, "gearset", None) is None`` …);
    * a gear set, or whether there is one, as a truth test (``if gs``, ``x if planetary
      else y``, ``if attrs.get("gearset_toml")``, also in a comprehension's ``if``);
    * a comparison with the model name ``"planetary"`` or the mesh labels ``["sp", "rp"]``.
    """
    lines: set[int] = set()
    for node in ast.walk(ast.parse(source)):
        if _is_switch(node):
            lines.add(node.lineno)
        tests: list[ast.AST] = []
        if isinstance(node, ast.If | ast.IfExp | ast.While | ast.Assert):
            tests = [node.test]
        elif isinstance(node, ast.comprehension):
            tests = list(node.ifs)
        for operand in (t for test in tests for t in _truth_operands(test)):
            if _holds_gear_set(operand):
                lines.add(operand.lineno)
    text = source.splitlines()
    return sorted(n for n in lines if not _explained(text, n))


def _explained(text: list[str], n: int) -> bool:
    """Whether line ``n`` (from 1) of ``text`` carries a :data:`REASON`, or follows a comment
    line that does."""
    above = text[n - 2].strip() if n >= 2 else ""
    return bool(REASON.search(text[n - 1])) or (
        above.startswith("#") and bool(REASON.search(above))
    )


def test_the_switch_counter_sees_every_kind_of_switch() -> None:
    """The counter on one snippet per pattern, and on code that asks the model instead."""
    switches = [
        "ok = isinstance(target, GearSet)",
        "ok = isinstance(t, System | GearSet)",
        "ok = isinstance(m, (System, PlanetaryModel))",
        'ok = hasattr(target, "evolve")',
        'ok = hasattr(model, "gearset")',
        "x = 1 if gs is not None else 2",
        "if res.base_gearset is None:\n    pass",
        'ok = summary.get("gearset") is None',
        'ok = getattr(model, "gearset", None) is None',
        'if attrs.get("gearset_toml"):\n    pass',
        'ok = [d for d in stores if d.attrs["gearset_toml"]]',
        "x = 1 if planetary else 2",
        "while not (a and gs):\n    pass",
        'ok = attrs.get("model") == "planetary"',
        'ok = labels == ["sp", "rp"]',
    ]
    for snippet in switches:
        assert gear_set_switches(snippet) == [1], snippet
    model_asks = [
        "names = [c.name for c in system.contacts]",
        'gs = getattr(model, "gearset", None)',  # a probe, not yet a switch
        "if system.scales is None:\n    pass",
        "ok = isinstance(target, System)",
        'ok = hasattr(model, "scales")',
        'ok = kind == "planet"',
    ]
    for snippet in model_asks:
        assert gear_set_switches(snippet) == [], snippet
    assert gear_set_switches("if gs is None and planetary:\n    pass") == [1]  # once a line
    # a switch that says why it stays is not counted; an empty or one-word reason is no reason
    why = "  # gear-set switch: the paper draws only the seed's gear set"
    assert gear_set_switches(f"x = 1 if gs is None else 2{why}") == []
    assert gear_set_switches(f"x = 1\ny = 1 if gs is None else 2{why}\nz = gs is None") == [3]
    above = f"{why.strip()}\ny = 1 if gs is None else 2\nz = gs is None"
    assert gear_set_switches(above) == [3]  # a reason alone on the line above explains one line
    assert gear_set_switches(f"x = 1{why}\ny = 1 if gs is None else 2") == [2]  # not code's
    for unexplained in ("# gear-set switch:", "# gear-set switch: because", "# gear switch: a b c"):
        assert gear_set_switches(f"x = 1 if gs is None else 2  {unexplained}") == [1], unexplained


def test_gear_set_switches_outside_gearset_and_model_do_not_grow() -> None:
    """Issue 36: outside ``gearset/`` and ``model/``, code asks the model, not "is it a gear
    set?". Today's count is recorded in :data:`GEAR_SET_SWITCHES`; the target is zero."""
    counts: dict[str, int] = {}
    for path in sorted(ROOT.rglob("*.py")):
        rel = path.relative_to(ROOT)
        if rel.parts[0] in ("gearset", "model"):
            continue
        found = gear_set_switches(path.read_text(encoding="utf-8"))
        if found:
            counts[rel.as_posix()] = len(found)
    total = sum(counts.values())
    table = "\n".join(f"  {n:3d}  {m}" for m, n in sorted(counts.items(), key=lambda kv: -kv[1]))
    assert total <= GEAR_SET_SWITCHES, (
        f'{total} lines outside gearset/ and model/ ask "is it a gear set?" (at most '
        f"{GEAR_SET_SWITCHES}: ask the model for its contacts, quantities and names instead):\n"
        f"{table}"
    )


#: The subpackages of ``dynamics`` by concept (issue 36, item 5) and what each may import:
#: ``lyapunov → orbits → continuation → curves`` and ``orbits → verdict → attractors``.
DYNAMICS_ROOMS = {
    "lyapunov": set(),
    "orbits": {"lyapunov"},
    "continuation": {"lyapunov", "orbits"},
    "curves": {"lyapunov", "orbits", "continuation"},
    "verdict": {"lyapunov", "orbits"},
    "attractors": {"lyapunov", "orbits", "verdict"},
}


def _room(module: str) -> str | None:
    parts = module.split(".")
    return parts[2] if len(parts) > 2 and parts[1] == "dynamics" else None


def test_dynamics_is_split_by_concept_and_its_rooms_import_one_way() -> None:
    """``dynamics/`` holds only its rooms (and its facade), and a room imports only the rooms
    below it."""
    top = sorted(p.name for p in (ROOT / "dynamics").iterdir() if not p.name.startswith("_"))
    assert top == sorted([*(r for r in DYNAMICS_ROOMS if r != "lyapunov"), "lyapunov.py"]), top
    graph = _graph()
    bad = []
    seen = set()
    for module, deps in graph.items():
        room = _room(module)
        if room is None:
            continue
        seen.add(room)
        for dep in deps:
            other = _room(dep)
            if other is not None and other != room and other not in DYNAMICS_ROOMS[room]:
                bad.append(f"{module} ({room}) imports {dep} ({other})")
    assert seen == set(DYNAMICS_ROOMS), seen
    assert not bad, "imports between the rooms of dynamics against their order:\n" + "\n".join(
        sorted(bad)
    )


def _calls(tree: ast.AST, name: str) -> list[int]:
    """Lines of the calls of ``name`` (by its bare or attribute name) in ``tree``."""
    return [
        node.lineno
        for node in ast.walk(tree)
        if isinstance(node, ast.Call)
        and (
            (isinstance(node.func, ast.Name) and node.func.id == name)
            or (isinstance(node.func, ast.Attribute) and node.func.attr == name)
        )
    ]


def test_one_newton_corrector_and_no_per_point_parallel_arrays() -> None:
    """Issue 36, item 5: the orbits and continuation rooms solve Pⁿ_λ(y) − y = 0 with one
    corrector over K points (``dynamics/orbits/corrector.py``): no other module there evaluates
    the map (``shoot``) or takes a Newton step of an orbit, and ``periodic_orbits`` keeps no
    per-point state in parallel arrays (no element assignments ``a[k] = …`` in it). The
    boundary curves' corrector (``curves/tracing.py``) solves another system (the orbit and a
    test function in two parameters) and is not counted here."""
    shooters, steppers = [], []
    for room in ("orbits", "continuation"):
        for path in sorted((ROOT / "dynamics" / room).glob("*.py")):
            tree = ast.parse(path.read_text(encoding="utf-8"))
            name = f"{room}/{path.name}"
            if _calls(tree, "shoot") and name != "orbits/corrector.py":
                shooters.append(name)
            if _calls(tree, "newton_step") and name not in (
                "orbits/corrector.py",
                "continuation/arclength.py",  # the branch's tangent: one linear solve
            ):
                steppers.append(name)
    assert not shooters, f"map evaluations outside the corrector: {shooters}"
    assert not steppers, f"Newton steps outside the corrector: {steppers}"
    arclength = ast.parse((ROOT / "dynamics/continuation/arclength.py").read_text("utf-8"))
    assert len(_calls(arclength, "newton_step")) == 1
    batch = ast.parse((ROOT / "dynamics/orbits/batch.py").read_text(encoding="utf-8"))
    (fn,) = [
        n for n in ast.walk(batch) if isinstance(n, ast.FunctionDef) and n.name == "periodic_orbits"
    ]
    element_writes = [
        node.lineno
        for node in ast.walk(fn)
        if isinstance(node, (ast.Assign, ast.AugAssign))
        and any(
            isinstance(t, ast.Subscript)
            for t in (node.targets if isinstance(node, ast.Assign) else [node.target])
        )
    ]
    assert not element_writes, f"per-point arrays written in periodic_orbits: {element_writes}"
    assert _calls(fn, "correct_points"), "periodic_orbits does not call the corrector"
