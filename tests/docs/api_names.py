"""The public names the API reference documents, and the few it must reach another way.

Griffe, which mkdocstrings uses to read the code, cannot tell a submodule from a member of the
same name (mkdocstrings/griffe#124): in ``gearchaos.plot``, ``bifurcation`` is both the module
``plot/bifurcation.py`` and the function it defines and the package exports, and griffe sees
only the module. Such a *shadowed* name is documented through its defining module
(``::: gearchaos.plot.bifurcation.bifurcation``) and filtered out of the package's own
directive. :func:`shadowing_module` finds them, so that the pages and tests follow when a
module is renamed.
"""

from __future__ import annotations

import importlib
import importlib.util
import pkgutil

import gearchaos

#: Every subpackage but the command line, read from the package (a new one must be documented;
#: the layer order is test_architecture's).
SUBPACKAGES = tuple(
    m.name for m in pkgutil.iter_modules(gearchaos.__path__) if m.ispkg and m.name != "cli"
)
PACKAGES = ("gearchaos", *(f"gearchaos.{p}" for p in SUBPACKAGES))
NOT_DOCUMENTABLE = {"__version__"}  # a plain string, described in the page's text


def public_names(package: str) -> list[str]:
    """``package.__all__`` less the names that are not documentable objects."""
    return [n for n in importlib.import_module(package).__all__ if n not in NOT_DOCUMENTABLE]


def _exporting_subpackage(package: str, name: str) -> str | None:
    if package != "gearchaos":
        return package
    module = getattr(getattr(importlib.import_module(package), name), "__module__", None) or ""
    parts = module.split(".")
    return ".".join(parts[:2]) if len(parts) > 2 and parts[0] == "gearchaos" else None


def shadowing_module(package: str, name: str) -> str | None:
    """The submodule that shadows ``package.name`` for griffe, or None.

    For a top-level name the subpackage it comes from is checked (``gearchaos.simulate`` is
    ``gearchaos.integrate.simulate``, shadowed by the module ``integrate/simulate.py``).
    """
    sub = _exporting_subpackage(package, name)
    if sub is None or not hasattr(importlib.import_module(sub), "__path__"):
        return None
    return f"{sub}.{name}" if importlib.util.find_spec(f"{sub}.{name}") is not None else None


def directive_target(package: str, name: str) -> str:
    """What a ``:::`` directive must name to render ``package.name``."""
    module = shadowing_module(package, name)
    return f"{module}.{name}" if module else f"{package}.{name}"
