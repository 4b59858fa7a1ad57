"""The API reference covers the public API, and every public function and class has a docstring.

``docs/reference/index.md`` documents each name of ``gearchaos.__all__`` with its own
``::: gearchaos.NAME`` directive, and each subpackage page documents the package as a whole
(``::: gearchaos.analysis`` renders the names of its ``__all__``). Directives name objects
through the packages, never through the private modules that define them, so that moving a
module inside a subpackage does not break the site. That the site really renders every name is
checked on the built site's inventory in ``test_site_build.py``.
"""

from __future__ import annotations

import importlib
import inspect
import re
from pathlib import Path

import pytest

import gearchaos

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = ROOT / "docs" / "reference"
SUBPACKAGES = ("gearset", "model", "integrate", "analysis", "sweep", "plot", "paper")
DIRECTIVE = re.compile(r"^::: *([\w.]+)", re.M)
NOT_DOCUMENTABLE = {"__version__"}  # a plain string, described in the page's text


def _directives(page: str) -> list[str]:
    return DIRECTIVE.findall((REFERENCE / page).read_text(encoding="utf-8"))


def _own_docstring(obj: object) -> str:
    """The object's own docstring: a class must not merely inherit one from a base class."""
    if inspect.isclass(obj):
        doc = vars(obj).get("__doc__")
        return doc.strip() if isinstance(doc, str) else ""
    return (getattr(obj, "__doc__", None) or "").strip()


def _public(module_name: str) -> list[tuple[str, object]]:
    module = importlib.import_module(module_name)
    return [(name, getattr(module, name)) for name in module.__all__]


@pytest.mark.parametrize("module_name", ["gearchaos", *(f"gearchaos.{p}" for p in SUBPACKAGES)])
def test_public_functions_and_classes_have_docstrings(module_name: str) -> None:
    missing = [
        name
        for name, obj in _public(module_name)
        if (inspect.isclass(obj) or callable(obj)) and not _own_docstring(obj)
    ]
    assert not missing, f"public names of {module_name} without a docstring: {missing}"


def test_every_top_level_name_is_in_the_reference() -> None:
    documented = set(_directives("index.md"))
    missing = [
        name
        for name in gearchaos.__all__
        if name not in NOT_DOCUMENTABLE and f"gearchaos.{name}" not in documented
    ]
    assert not missing, (
        f"names of gearchaos.__all__ missing from docs/reference/index.md: {missing} "
        "(add a '::: gearchaos.NAME' directive)"
    )
    assert "__version__" in (REFERENCE / "index.md").read_text(encoding="utf-8")


def test_every_subpackage_has_its_page() -> None:
    for package in SUBPACKAGES:
        page = REFERENCE / f"{package}.md"
        assert page.is_file(), f"no reference page for gearchaos.{package}"
        assert f"gearchaos.{package}" in _directives(page.name)


def test_directives_name_objects_through_the_packages() -> None:
    """No directive reaches into a private module path (e.g. gearchaos.integrate.simulate)."""
    allowed = {f"gearchaos.{name}" for name in gearchaos.__all__}
    allowed |= {f"gearchaos.{p}" for p in SUBPACKAGES}
    for page in sorted(REFERENCE.glob("*.md")):
        for target in _directives(page.name):
            package, _, name = target.rpartition(".")
            through_package = (
                package.startswith("gearchaos.")
                and package.count(".") == 1
                and package.split(".")[1] in SUBPACKAGES
                and name in importlib.import_module(package).__all__
            )
            assert target in allowed or through_package, (
                f"{page.name}: '::: {target}' names a module path; document the object "
                "through its package (gearchaos.NAME or gearchaos.SUBPACKAGE.NAME)"
            )
