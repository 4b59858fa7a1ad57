"""The API reference covers the public API, and every public function and class has a docstring.

``docs/reference/index.md`` documents each name of ``gearchaos.__all__`` with its own
``::: gearchaos.NAME`` directive, and each subpackage page documents the package as a whole
(``::: gearchaos.analysis`` renders the names of its ``__all__``). Directives name objects
through the packages, never through the private modules that define them, so that moving a
module inside a subpackage does not break the site — except for the names a module shadows
(see ``api_names.py``). That the built site really renders every name, as the right kind of
object, is checked on its inventory in ``test_site_build.py``.
"""

from __future__ import annotations

import importlib
import inspect
import re
from pathlib import Path

import pytest
from api_names import (
    NOT_DOCUMENTABLE,
    PACKAGES,
    SUBPACKAGES,
    directive_target,
    public_names,
    shadowing_module,
)

import gearchaos

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = ROOT / "docs" / "reference"
DIRECTIVE = re.compile(r"^::: *([\w.]+)", re.M)


def _directives(page: str) -> list[str]:
    return DIRECTIVE.findall((REFERENCE / page).read_text(encoding="utf-8"))


def _own_docstring(obj: object) -> str:
    """The object's own docstring: a class must not merely inherit one from a base class."""
    if inspect.isclass(obj):
        doc = vars(obj).get("__doc__")
        return doc.strip() if isinstance(doc, str) else ""
    return (getattr(obj, "__doc__", None) or "").strip()


@pytest.mark.parametrize("package", PACKAGES)
def test_public_functions_and_classes_have_docstrings(package: str) -> None:
    module = importlib.import_module(package)
    missing = [
        name
        for name in public_names(package)
        if (inspect.isclass(obj := getattr(module, name)) or inspect.isroutine(obj))
        and not _own_docstring(obj)
    ]
    assert not missing, f"public functions or classes of {package} without a docstring: {missing}"


def test_every_top_level_name_is_in_the_reference() -> None:
    documented = set(_directives("index.md"))
    missing = [
        name
        for name in public_names("gearchaos")
        if directive_target("gearchaos", name) not in documented
    ]
    assert not missing, (
        f"names of gearchaos.__all__ missing from docs/reference/index.md: {missing} "
        "(add a '::: gearchaos.NAME' directive)"
    )
    assert NOT_DOCUMENTABLE <= set(gearchaos.__all__)
    assert "__version__" in (REFERENCE / "index.md").read_text(encoding="utf-8")


@pytest.mark.parametrize("package", SUBPACKAGES)
def test_every_subpackage_has_its_page(package: str) -> None:
    page = REFERENCE / f"{package}.md"
    assert page.is_file(), f"no reference page for gearchaos.{package}"
    directives = _directives(page.name)
    assert f"gearchaos.{package}" in directives
    for name in public_names(f"gearchaos.{package}"):
        if shadowing_module(f"gearchaos.{package}", name):
            target = directive_target(f"gearchaos.{package}", name)
            assert target in directives, f"{page.name} must document {target} (shadowed name)"


def test_directives_name_objects_through_the_packages() -> None:
    """No directive reaches into a private module path (e.g. gearchaos.integrate.settings),
    except to reach a name its module shadows."""
    allowed = {f"gearchaos.{p}" for p in SUBPACKAGES}
    for package in PACKAGES:
        allowed |= {directive_target(package, name) for name in public_names(package)}
    for page in sorted(REFERENCE.glob("*.md")):
        for target in _directives(page.name):
            assert target in allowed, (
                f"{page.name}: '::: {target}' names a module path; document the object "
                "through its package (gearchaos.NAME or gearchaos.SUBPACKAGE.NAME)"
            )
