"""``mkdocs build --strict`` succeeds offline, and the built site renders the whole public API.

The inventory the build writes (``objects.inv``, Sphinx format) lists every object the API
reference rendered; every name of ``gearchaos.__all__`` and of each documented subpackage's
``__all__`` must be in it. The pages load nothing from the network (no CDN scripts, styles or
fonts) and the model's equations are rendered as MathML. The API reference's tables show types
in their Type column and no unresolved ``<autoref>`` tag (``reference_tables.py``).
"""

from __future__ import annotations

import importlib
import inspect
import os
import re
import subprocess
import sys
import zlib
from pathlib import Path

from api_names import PACKAGES, directive_target, public_names
from reference_tables import defects, is_type

ROOT = Path(__file__).resolve().parents[2]
REMOTE_ASSET = re.compile(r"<(?:script|link|img)\b[^>]*(?:src|href)=\"(?:https?:)?//", re.I)


def _inventory(path: Path) -> dict[str, set[str]]:
    """Object name → roles (``py:function`` …) of a Sphinx v2 inventory (4 header lines,
    then zlib-compressed lines ``name role priority uri title``)."""
    raw = path.read_bytes()
    body = raw.split(b"\n", 4)[4]
    out: dict[str, set[str]] = {}
    for line in zlib.decompress(body).decode("utf-8").splitlines():
        if line.strip():
            name, role = line.split(" ", 2)[:2]
            out.setdefault(name, set()).add(role)
    return out


def _role(obj: object) -> str | None:
    """The inventory role an object must be rendered as (None: any)."""
    if inspect.isclass(obj):
        return "py:class"
    if inspect.isroutine(obj):
        return "py:function"
    return None


def _build(out: Path) -> None:
    mkdocs = Path(sys.executable).parent / "mkdocs"
    cmd = [str(mkdocs)] if mkdocs.exists() else [sys.executable, "-m", "mkdocs"]
    proc = subprocess.run(
        [*cmd, "build", "--strict", "--site-dir", str(out)],
        cwd=ROOT,
        env={**os.environ, "NO_MKDOCS_2_WARNING": "1"},
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, f"mkdocs build --strict failed:\n{proc.stderr[-6000:]}"


def test_site_builds_offline_and_renders_the_public_api(tmp_path: Path) -> None:
    """One build (about half a minute), then every check on it."""
    _build(tmp_path)
    _check_pages(tmp_path)
    _check_api_reference(tmp_path)
    _check_reference_tables(tmp_path)
    _check_no_network_assets(tmp_path)
    _check_mathml(tmp_path)


def _check_pages(site: Path) -> None:
    for page in (
        "index.html",
        "tutorial/index.html",
        "concepts/model.html",
        "concepts/sections.html",
        "concepts/motion-labels.html",
        "howto/gearset.html",
        "howto/maps.html",
        "howto/hysteresis.html",
        "howto/resume.html",
        "howto/dask.html",
        "howto/reproduce.html",
        "reference/index.html",
        "MODEL.html",
        "reproduction.html",
        "figures.html",
        "report/index.html",
    ):
        assert (site / page).is_file(), f"the built site lacks {page}"


def _check_api_reference(site: Path) -> None:
    """Every public name is in the inventory, functions as functions and classes as classes
    (a name shadowed by its module would otherwise be rendered as the module)."""
    roles = _inventory(site / "objects.inv")
    missing, wrong = [], []
    for package in PACKAGES:
        module = importlib.import_module(package)
        for name in public_names(package):
            target = directive_target(package, name)
            if target not in roles:
                missing.append(target)
            elif (role := _role(getattr(module, name))) and role not in roles[target]:
                wrong.append(f"{target} ({sorted(roles[target])}, expected {role})")
    assert not missing, f"public names the API reference does not render: {missing}"
    assert not wrong, f"public names rendered as the wrong kind of object: {wrong}"


def _check_reference_tables(site: Path) -> None:
    """No page shows a raw ``<autoref>`` tag, and every Type cell of the API reference's
    tables is a type (a numpydoc ``name : sentence`` puts the sentence there)."""
    found = {
        str(page.relative_to(site)): bad
        for page in sorted(site.rglob("*.html"))
        if (bad := defects(page.read_text(encoding="utf-8")))
    }
    assert not found, (
        "API reference tables with a sentence or a raw autoref in the Type column (write "
        f"'name' alone, the description indented below it, for an annotated field): {found}"
    )


#: What mkdocstrings rendered for ``Event`` when its docstring read ``kind : one of
#: :data:`EVENT_KINDS`.`` (issue 24): the sentence in the Type column, the role escaped.
_BROKEN_ROWS = """<table><thead><tr><th>Name</th><th>Type</th><th>Description</th></tr></thead>
<tbody><tr class="doc-section-item"><td><code>kind</code></td>
<td><code>one of &lt;autoref identifier=&#34;gearchaos.dynamics.continuation.events.EVENT_KINDS&#34;
optional&gt;&lt;code&gt;EVENT_KINDS&lt;/code&gt;&lt;/autoref&gt;.</code></td><td></td></tr>
<tr><td><code>arclength</code></td><td><code>the branch&#39;s arclength at the event.</code></td>
<td></td></tr><tr><td><code>value</code></td><td><code>float</code></td><td>The value.</td></tr>
</tbody></table>"""


def test_reference_table_check_finds_sentences_and_raw_autorefs() -> None:
    found = defects(_BROKEN_ROWS)
    assert sum("raw autoref" in f for f in found) == 2
    assert [f.split(":")[0] for f in found if "Type cell" in f] == ["kind", "arclength"]
    for good in (
        "float",
        "dict[str, Any]",
        "int | None",
        "Sequence[dict[str, Any] | None] | None",
        "numpy.ndarray",
        "tuple of str",
        "list of (str, str)",
        "mapping of str to object",
        "str or os.PathLike",
        "(figure, rows)",
        "",
    ):
        assert is_type(good), good
    for bad in (
        "n, in forcing periods T = 2π/Ω.",
        "(n_state,) the state at the end",
        "how it ended",
    ):
        assert not is_type(bad), bad


def _check_no_network_assets(site: Path) -> None:
    offenders = [
        str(page.relative_to(site))
        for page in site.rglob("*.html")
        if REMOTE_ASSET.search(page.read_text(encoding="utf-8", errors="replace"))
    ]
    assert not offenders, f"pages that load scripts, styles or images from the network: {offenders}"


def _check_mathml(site: Path) -> None:
    html = (site / "concepts" / "model.html").read_text(encoding="utf-8")
    assert html.count("<math") >= 10
    assert 'class="arithmatex"' not in html  # every formula was converted


def test_readme_documentation_section_is_what_ci_runs() -> None:
    """The README's one build command is the one .ci/run runs, and it links the entry page."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    match = re.search(r"^## Documentation\n(.*?)(?=^## |\Z)", text, flags=re.S | re.M)
    assert match, "README has no Documentation section"
    (command,) = re.findall(r"```bash\n(.*?)\n```", match.group(1), flags=re.S)
    assert command == ".venv/bin/mkdocs build --strict"
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    assert command in ci
    assert "(site/index.html)" in match.group(1)
