"""Data files are data (issue 33): a file never names code that runs, a file is replaced only by
a mark only gearchaos writes, and text from files reaches the terminal escaped.

Every case is a test with its expected class: ``refused`` (exit 2, one ``error:`` line naming
the culprit, nothing written), ``drawn`` (the figure is drawn without what the file cannot
give), ``kept`` (a foreign file is never replaced) or ``escaped`` (no control character of a
file or path reaches the terminal). The code-execution cases come first: a forged orbit,
branch or sweep store whose ``model_class`` names a module planted beside it (``evil/evilmod.py``,
relative or absolute) or one of the standard library (``subprocess:Popen``, ``os:system``)
must never create the marker file that importing or calling it would create.
"""

from __future__ import annotations

import json
import uuid
from pathlib import Path
from typing import Any

import pytest
from fuzz_helpers import cli_refused, hsettings, refused
from hypothesis import strategies as st

import gearchaos as gc
from forged_files import forge_nc
from gearchaos.dynamics.orbits.file import save_orbit

DUFFING = gc.duffing(1.2)
TINY = {"transient_periods": 2}

#: A module that leaves a marker file when it is imported, and again when its class is built.
EVIL = """
from pathlib import Path

Path({marker!r}).write_text("imported")


class Evil:
    def __init__(self, **kw):
        Path({marker!r}).write_text("called")
"""


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A genuine orbit file, branch file and sweep store of the Duffing oscillator (a
    reference system: their records name gearchaos.model.library:Duffing)."""
    root = tmp_path_factory.mktemp("genuine")
    orbit = gc.periodic_orbit(DUFFING, period=1, **TINY)
    save_orbit(orbit, root / "orb.nc")
    branch = gc.continuation(gc.duffing(1.0), "omega=1.0:1.1", max_points=3, **TINY)
    gc.save_branch(branch, root / "br.nc")
    gc.bifurcation(
        gc.duffing(1.0), "omega=1.0:1.1:2", store=root / "st.zarr", progress=False,
        transient_periods=2, periods=2,
    )  # fmt: skip
    return {"orbit": root / "orb.nc", "branch": root / "br.nc", "store": root / "st.zarr"}


def _forge_store(src: Path, dst: Path, **attrs: Any) -> Path:
    """A copy of the sweep store ``src`` with its root attributes changed in both metadata
    files (``.zattrs`` and the consolidated ``.zmetadata``), as a forger would."""
    import shutil

    shutil.copytree(src, dst)
    zattrs = json.loads((dst / ".zattrs").read_text())
    zattrs.update(attrs)
    (dst / ".zattrs").write_text(json.dumps(zattrs, indent=4))
    meta = json.loads((dst / ".zmetadata").read_text())
    meta["metadata"][".zattrs"].update(attrs)
    (dst / ".zmetadata").write_text(json.dumps(meta, indent=4))
    return dst


def _plant(where: Path) -> tuple[Path, str]:
    """``where/evil/evilmod_XXXX.py`` (a new module name each time: a module imported once
    stays imported in this process) and the marker it would write; returns (marker, the
    module's path relative to ``where``)."""
    marker = where / "OWNED"
    (where / "evil").mkdir(exist_ok=True)
    name = f"evil/evilmod_{uuid.uuid4().hex[:8]}.py"
    (where / name).write_text(EVIL.format(marker=str(marker)))
    return marker, name


#: What the refusal says: the model the file needs and how to give consent.
CONSENT = "--model FILE.py:"


# ------------------------------------------------------------------ 1. no code from a file
@pytest.mark.parametrize("spelling", ["relative", "absolute"])
@pytest.mark.parametrize(
    ("kind", "command"),
    [
        ("orbit", ["continue", "--from", "FILE", "--vary", "omega=1.5:1.51", "-o", "out.nc"]),
        ("orbit", ["orbit", "--from", "FILE"]),
        ("branch", ["continue", "--from", "FILE", "--at", "omega=1.0", "--vary",
                    "omega=1.0:1.1", "-o", "out.nc"]),
        ("branch", ["boundary", "--from", "FILE", "--event", "pd1", "--vary", "delta=0.1:0.2",
                    "-o", "curve.nc"]),
        ("store", ["orbit", "--from", "FILE", "--at", "omega=1.0"]),
    ],
)  # fmt: skip
def test_refused_a_forged_model_class_never_runs_the_module_beside_the_file(
    files: dict[str, Path],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    kind: str,
    command: list[str],
    spelling: str,
) -> None:
    """`continue --from orb.nc` imported evil/evilmod.py named by the file and ran it."""
    monkeypatch.chdir(tmp_path)
    marker, module = _plant(tmp_path)
    spec = (module if spelling == "relative" else str(tmp_path / module)) + ":Evil"
    forged = {"model_class": spec, "model_fields": "{}", "gearset_toml": None}
    if kind == "store":
        path = _forge_store(files["store"], tmp_path / "forged.zarr", model_class=spec)
    else:
        path = forge_nc(files[kind], tmp_path / "forged.nc", **forged)
    args = [str(path) if a == "FILE" else a for a in command]
    # a store whose metadata was edited may also be called damaged: refused either way
    culprits = (CONSENT, "damaged") if kind == "store" else (CONSENT,)
    text = cli_refused(f"{command[0]} --from forged {kind}", args, *culprits, watch=tmp_path)
    assert CONSENT not in text or f"{module}:Evil" in text
    assert not marker.exists()


@pytest.mark.parametrize(
    ("spec", "fields"),
    [
        ("subprocess:Popen", {"args": ["touch", "{marker}"]}),
        ("os:system", {"command": "touch {marker}"}),
        ("builtins:exec", {"source": "open('{marker}', 'w')"}),
        ("gearchaos.model.library:Evil", {}),
    ],
)
def test_refused_a_module_or_class_named_only_by_the_file(
    files: dict[str, Path],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    spec: str,
    fields: dict[str, Any],
) -> None:
    """`model_class = "os:system"` reached into any importable module; subprocess.Popen is a
    class, so the old loader called it with the file's fields."""
    monkeypatch.chdir(tmp_path)
    marker = tmp_path / "OWNED"
    text = json.dumps(fields).replace("{marker}", str(marker))
    path = forge_nc(files["orbit"], tmp_path / "forged.nc", model_class=spec, model_fields=text)
    out = cli_refused("orbit --from forged module", ["orbit", "--from", str(path)], CONSENT,
                      watch=tmp_path)  # fmt: skip
    assert spec in out
    assert not marker.exists()


@pytest.mark.parametrize("fields", [{}, {"command": "touch {marker}"}, {"gearset": "x = 1"}])
def test_refused_a_forged_planetary_record_names_its_fields(
    files: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch, fields: dict[str, Any]
) -> None:
    """The planetary model is gearchaos's own (issue 36: a gear set's files record it, with the
    gear set as its fields), so its record alone builds it: a forged one is refused as damaged,
    naming the rule of its fields, rather than for want of the user's consent."""
    monkeypatch.chdir(tmp_path)
    marker = tmp_path / "OWNED"
    spec = "gearchaos.model.planetary:PlanetaryModel"
    text = json.dumps(fields).replace("{marker}", str(marker))
    path = forge_nc(files["orbit"], tmp_path / "forged.nc", model_class=spec, model_fields=text)
    out = cli_refused("orbit --from forged planetary", ["orbit", "--from", str(path)],
                      "model_fields", watch=tmp_path)  # fmt: skip
    assert spec in out or "gear set" in out
    assert not marker.exists()


@pytest.mark.parametrize("kind", ["branch", "store"])
def test_drawn_a_figure_of_a_forged_file_uses_names_and_runs_nothing(
    files: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch, kind: str
) -> None:
    """`plot branch.nc` and `plot store.zarr` imported the module their record names (for the
    variables' symbols) and exited 0 with a figure: the figure falls back to the names."""
    from typer.testing import CliRunner

    from gearchaos.cli import app

    monkeypatch.chdir(tmp_path)
    marker, module = _plant(tmp_path)
    spec = f"{module}:Evil"
    if kind == "store":
        path = _forge_store(files["store"], tmp_path / "forged.zarr", model_class=spec)
    else:
        path = forge_nc(files["branch"], tmp_path / "forged.nc", model_class=spec)
    result = CliRunner().invoke(app, ["plot", str(path), "-o", "fig.png"])
    assert not marker.exists()
    assert "Traceback" not in result.output
    if result.exit_code == 0:  # drawn without the model
        assert (tmp_path / "fig.png").stat().st_size > 0
    else:  # or refused as damage, in one line
        assert result.exit_code == 2 and result.stderr.startswith("error:"), result.output


def test_refused_the_python_api_builds_no_model_a_file_names(
    files: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The explorer's recomputed point and finer sweep, and SweepResult.base_model, built the
    store's model from its record."""
    from gearchaos.explore.compute import compute_point, run_zoom
    from gearchaos.model.loading import ModelConsentError, rebuild_model
    from gearchaos.sweep.result import SweepResult

    monkeypatch.chdir(tmp_path)
    marker, module = _plant(tmp_path)
    spec = f"{tmp_path / module}:Evil"
    store = _forge_store(files["store"], tmp_path / "forged.zarr", model_class=spec)
    errors = (ModelConsentError,)
    refused("base_model", lambda: SweepResult.open(store).base_model, CONSENT, errors=errors)
    refused("compute_point", lambda: compute_point(str(store), {"omega": 1.0}), CONSENT,
            errors=errors)  # fmt: skip
    refused("run_zoom", lambda: run_zoom(str(store), {"omega": (1.0, 1.05, 2)}), CONSENT,
            errors=errors)  # fmt: skip
    attrs = {"model_class": f"{module}:Evil", "model_fields": "{}"}
    refused("rebuild_model", lambda: rebuild_model(attrs, where="f.nc"), "f.nc", errors=errors)
    assert not marker.exists()


@pytest.mark.parametrize(
    ("fields", "culprit"),
    [
        ({"kind": 1}, "kind"),
        ({"n_state": 1, "state_names": ["x"]}, "n_state"),
        ({"obs_names": ["x"], "n_track": 0}, "n_track"),
        ("[1, 2]", "model_fields"),
        ("{not json", "model_fields"),
        ({"delta": 0.1, "evil": 1}, "evil"),
    ],
)
def test_refused_a_reference_system_whose_record_changes_its_layout(
    fields: Any, culprit: str
) -> None:
    """A reference system is built again by its name, but only with parameters: another
    kernel kind or state size would make the compiled right-hand side read and write outside
    its arrays."""
    from gearchaos.errors import ParameterError
    from gearchaos.model.loading import rebuild_model

    text = fields if isinstance(fields, str) else json.dumps(fields)
    attrs = {"model_class": "gearchaos.model.library:Duffing", "model_fields": text}
    refused("rebuild_model layout", lambda: rebuild_model(attrs, where="f.nc"), culprit,
            errors=(ParameterError,))  # fmt: skip


MOVED = """
import math
from dataclasses import dataclass

import numba
import numpy as np

from gearchaos.model.contract import UserModel


@numba.njit(cache=True)
def rhs(t, y, p, dydt, obs, level):
    x, v = y[0], y[1]
    dydt[0] = v
    dydt[1] = p[4] * math.cos(p[0] * t) - p[1] * v - p[2] * x - p[3] * x * x * x
    obs[0] = x
    obs[1] = v


@dataclass(frozen=True)
class ConsentedWell(UserModel):
    delta: float = 0.3
    alpha: float = -1.0
    beta: float = 1.0
    gamma: float = 0.5
    name = "consented_well"
    state_names = ("x", "x_dot")
    obs_names = ("x", "x_dot")
    n_track = 1
    rhs = rhs

    def pack(self, omega):
        return np.array([omega, self.delta, self.alpha, self.beta, self.gamma])
"""


def test_a_users_model_runs_with_the_users_consent_only(
    files: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An orbit file of the user's own model (its record names a file this process never
    loaded): refused without --model, saying which model and how; with --model FILE.py:CLASS
    (here the same class in a file that has moved) the orbit is continued; a --model of
    another class is refused."""
    from typer.testing import CliRunner

    from gearchaos.cli import app

    monkeypatch.chdir(tmp_path)
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "consented_well_moved.py").write_text(MOVED)
    # the Duffing oscillator's own values: the orbit file's state is the user model's orbit
    fields = json.dumps({"delta": 0.1, "alpha": 1.0, "beta": 1.0, "gamma": 0.5})
    orbit = forge_nc(files["orbit"], tmp_path / "mine.nc", model_fields=fields,
                      model_class="/gone/consented_well.py:ConsentedWell")  # fmt: skip
    args = ["orbit", "--from", str(orbit), "--json"]
    text = cli_refused("orbit --from own model", args, "--model FILE.py:ConsentedWell",
                       watch=tmp_path)  # fmt: skip
    assert "/gone/consented_well.py:ConsentedWell" in text
    other = ["--model", "gearchaos.model.library:Lorenz"]
    text = cli_refused("orbit --from own model, other --model", [*args, *other],
                       "named with --model in this process", watch=tmp_path)  # fmt: skip
    # Lorenz is among them (a test process may have named others before: the registry of
    # consented classes is per process)
    assert "Lorenz" in text.split("named with --model in this process:")[1]
    result = CliRunner().invoke(
        app, [*args, "--model", "mine/consented_well_moved.py:ConsentedWell"]
    )
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    ref = gc.periodic_orbit(DUFFING, period=out["period"], **TINY)
    assert out["converged"] and ref.converged
    assert out["section"] == pytest.approx(list(ref.section("x")), abs=1e-8)


# ------------------------------------------------------------------ 2. ours by a mark only
#: Foreign text that mentions the package: the word anywhere, a made-up mark, the titles and
#: attribute names gearchaos writes.
MENTIONS = st.one_of(
    st.builds(lambda a, b: f"{a}gearchaos{b}", st.text(max_size=30), st.text(max_size=30)),
    st.builds(
        lambda a, h: f"{a} gearchaos_output:sha256:{h}",
        st.text(max_size=20),
        st.text("0123456789abcdef", min_size=64, max_size=64),
    ),
    st.sampled_from([
        "notes on my gearchaos runs",
        "gearchaos periodic orbit",
        "gearchaos simulation",
        "Creator: gearchaos 0.1.0",
        "# gearchaos export\nomega,motion\n1.0,1T\n",
        "gearchaos_output",
    ]),
)  # fmt: skip


def _foreign_netcdf(path: Path, text: str, forged_mark: str) -> None:
    """A netCDF-4 file of another program that looks like gearchaos's: its title and
    attributes mention gearchaos, it has the variables of an orbit and a branch, and a made-up
    ``gearchaos_output`` attribute."""
    import warnings

    import numpy as np
    import xarray as xr

    text = text.replace("\0", "")  # HDF5 strings hold no NUL
    ds = xr.Dataset(
        {"orbit_state": ("k", np.zeros(2)), "multiplier_re": ("k", np.zeros(2))},
        attrs={"title": f"gearchaos periodic orbit {text}", "parameter": "omega",
               "gearchaos_output": forged_mark},
    )  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds.to_netcdf(path, engine="h5netcdf", invalid_netcdf=True)


def _foreign_png(path: Path, text: str, forged_mark: str) -> None:
    """A PNG of another program with text chunks that mention gearchaos and a made-up mark."""
    from PIL import Image, PngImagePlugin

    info = PngImagePlugin.PngInfo()
    info.add_text("Software", f"gearchaos {text}"[:200])
    info.add_text("gearchaos_output", forged_mark)
    Image.new("RGB", (4, 4)).save(path, pnginfo=info)


def _foreign_store(path: Path, text: str, forged_mark: str) -> None:
    """A Zarr directory of another program whose attributes hold the names gearchaos's stores
    are recognised by, mentioning gearchaos, and a made-up mark."""
    path.mkdir()
    (path / ".zgroup").write_text('{"zarr_format": 2}')
    attrs = {
        "title": f"gearchaos sweep {text}",
        "sweep_toml": "gearchaos",
        "version": "0.1.0",
        "basin_spec": "gearchaos",
        "parameter": "omega",
        "gearchaos_output": forged_mark,
    }
    (path / ".zattrs").write_text(json.dumps(attrs))  # fmt: skip


def _tree(path: Path) -> dict[str, bytes]:
    if path.is_file():
        return {"": path.read_bytes()}
    return {str(p.relative_to(path)): p.read_bytes() for p in path.rglob("*") if p.is_file()}


@pytest.fixture(scope="module")
def results(files: dict[str, Path]) -> dict[str, Any]:
    """What each writer writes, computed once."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    ax.plot([0, 1], [1, 0])
    branch = gc.open_branch(files["branch"])
    cascade = branch.copy()
    cascade.attrs.update(cascade="[]", cascade_skipped="[]", cascade_requested=0)
    return {
        "figure": fig,
        "simulation": gc.simulate(DUFFING, transient_periods=2, periods=2),
        "orbit": gc.periodic_orbit(DUFFING, period=1, **TINY),
        "branch": branch,
        "cascade": cascade,
    }


def _writers(results: dict[str, Any], files: dict[str, Path]) -> dict[str, Any]:
    """Every writer, as (suffix, kind of foreign file, write(path))."""
    from typer.testing import CliRunner

    from gearchaos.cli import app
    from gearchaos.dynamics.continuation.cascade import save_cascade
    from gearchaos.plot import savefig
    from gearchaos.sweep.exports import export

    def init_gearset(path: Path) -> None:
        result = CliRunner().invoke(app, ["init-gearset", str(path), "--force"])
        if result.exit_code:
            raise gc.errors.StoreError(result.output.strip())

    def sweep(path: Path) -> None:
        gc.bifurcation(gc.duffing(1.0), "omega=1.0:1.1:2", store=path, overwrite=True,
                       progress=False, transient_periods=2, periods=2)  # fmt: skip

    def basins(path: Path) -> None:
        gc.basins(DUFFING, "x=-1:1:2", "x_dot=-1:1:2", store=path, overwrite=True,
                  progress=False, transient_periods=2, periods=2)  # fmt: skip

    return {
        "figure.png": (".png", "png", lambda p: savefig(results["figure"], p)),
        "figure.pdf": (".pdf", "text", lambda p: savefig(results["figure"], p)),
        "figure.svg": (".svg", "text", lambda p: savefig(results["figure"], p)),
        "simulation.nc": (".nc", "netcdf", lambda p: results["simulation"].save(p)),
        "orbit.nc": (".nc", "netcdf", lambda p: save_orbit(results["orbit"], p)),
        "branch.nc": (".nc", "netcdf", lambda p: gc.save_branch(results["branch"], p,
                                                                 overwrite=True)),
        "cascade.nc": (".nc", "netcdf", lambda p: save_cascade([results["cascade"]], p,
                                                               overwrite=True)),
        "branch.zarr": (".zarr", "store", lambda p: gc.save_branch(results["branch"], p,
                                                                    overwrite=True)),
        "sweep.zarr": (".zarr", "store", sweep),
        "basins.zarr": (".zarr", "store", basins),
        "export.csv": (".csv", "text", lambda p: export(files["store"], p)),
        "export.mat": (".mat", "text", lambda p: export(files["store"], p)),
        "gearset.toml": (".toml", "text", init_gearset),
    }  # fmt: skip


WRITERS = ["figure.png", "figure.pdf", "figure.svg", "simulation.nc", "orbit.nc", "branch.nc",
           "cascade.nc", "branch.zarr", "sweep.zarr", "basins.zarr", "export.csv",
           "export.mat", "gearset.toml"]  # fmt: skip


@pytest.mark.parametrize("writer", WRITERS)
def test_kept_no_writer_replaces_a_foreign_file_that_mentions_gearchaos(
    results: dict[str, Any], files: dict[str, Path], writer: str
) -> None:
    """`echo 'notes on my gearchaos runs' > notes.nc; orbit -o notes.nc` replaced the notes,
    and `export -o mynotes.csv` a CSV whose header mentions gearchaos: a mention, a made-up
    mark, or a file of the right format with gearchaos's titles is the user's."""
    import tempfile

    from hypothesis import given

    suffix, kind, write = _writers(results, files)[writer]

    @hsettings(12)
    @given(text=MENTIONS, structured=st.booleans(),
           digest=st.text("0123456789abcdef", min_size=64, max_size=64))  # fmt: skip
    def check(text: str, structured: bool, digest: str) -> None:
        forged = f"sha256:{digest}"
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / f"mine{suffix}"
            if structured and kind == "netcdf":
                _foreign_netcdf(path, text, forged)
            elif structured and kind == "png":
                _foreign_png(path, text, forged)
            elif kind == "store":
                _foreign_store(path, text, forged)
            else:
                path.write_bytes(text.encode("utf-8", "surrogatepass"))
            before = _tree(path)
            refused(f"{writer} over a foreign file", lambda: write(path), "gearchaos wrote",
                    errors=(gc.errors.StoreError,))  # fmt: skip
            assert _tree(path) == before

    check()


@pytest.mark.parametrize("writer", WRITERS)
def test_every_writer_replaces_what_it_wrote_and_not_once_edited(
    results: dict[str, Any], files: dict[str, Path], tmp_path: Path, writer: str
) -> None:
    """The mark holds the digest of the output: the writer replaces its own output, and a
    file (or a store's header) edited since is the user's."""
    suffix, kind, write = _writers(results, files)[writer]
    path = tmp_path / f"out{suffix}"
    write(path)
    write(path)  # its own output: replaced
    if kind == "store":  # the header (here its title) edited
        zattrs = json.loads((path / ".zattrs").read_text())
        zattrs["title"] = zattrs.get("title", "") + " (mine now)"
        (path / ".zattrs").write_text(json.dumps(zattrs))
    elif kind == "netcdf":  # an attribute edited
        forge_nc(path, tmp_path / "edited.nc", title="mine now")
        (tmp_path / "edited.nc").replace(path)
    else:  # one byte in the middle changed
        raw = bytearray(path.read_bytes())
        raw[len(raw) // 2] ^= 0x01
        path.write_bytes(bytes(raw))
    before = _tree(path)
    refused(f"{writer} over its edited output", lambda: write(path), "gearchaos wrote",
            errors=(gc.errors.StoreError,))  # fmt: skip
    assert _tree(path) == before


# ------------------------------------------------------------------ 3. text from files escaped
#: A gear-set name that retitles the terminal window and clears the screen.
HOSTILE_NAME = "\x1b]0;owned\x07\x1b[2J"


def _acting(text: str) -> list[str]:
    """The characters of ``text`` that would act on a terminal (controls but the newline)."""
    import unicodedata

    return [c for c in text if c != "\n" and unicodedata.category(c) in ("Cc", "Cf")]


@pytest.fixture(scope="module")
def gearset_orbit(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An orbit file of the sheng2016 gear set."""
    path = tmp_path_factory.mktemp("gearset_orbit") / "orb.nc"
    save_orbit(gc.periodic_orbit(gc.preset("sheng2016-v1"), omega=0.5, period=1, **TINY), path)
    return path


def test_escaped_a_gear_set_name_from_a_file_never_reaches_the_terminal_raw(
    gearset_orbit: Path, tmp_path: Path
) -> None:
    """`orbit --from orb.nc` whose gear set is named "\\x1b]0;owned\\x07\\x1b[2J" wrote the
    escape sequences to the terminal (window title, cleared screen)."""
    import re

    from typer.testing import CliRunner

    from gearchaos.cli import app

    toml = str(open_orbit_attrs(gearset_orbit)["gearset_toml"])
    hostile = json.dumps(HOSTILE_NAME)  # a TOML basic string with \\u escapes
    forged_toml = re.sub(r'(?m)^name = ".*"$', lambda m: f"name = {hostile}", toml, count=1)
    assert forged_toml != toml
    # both copies of the gear set (the model's fields and gearset_toml), as a forger would
    fields = json.dumps({"gearset": forged_toml})
    path = forge_nc(
        gearset_orbit, tmp_path / "named.nc", gearset_toml=forged_toml, model_fields=fields
    )
    result = CliRunner().invoke(app, ["orbit", "--from", str(path)])
    assert "Traceback" not in result.output
    assert not _acting(result.stdout) and not _acting(result.stderr), result.output
    assert "\\x1b]0;owned\\x07" in result.output  # shown, as escapes


def open_orbit_attrs(path: Path) -> dict[str, Any]:
    from gearchaos.dynamics.orbits.file import open_orbit

    return dict(open_orbit(path).attrs)


@pytest.mark.parametrize(
    ("case", "args", "code"),
    [
        ("plot -o", ["plot", "STORE", "-o", "f\x1b[2J.png"], 0),
        ("init-gearset", ["init-gearset", "g\x1b[2J.toml"], 0),
        ("missing --from", ["orbit", "--from", "/x\x1b[2J"], 2),
        ("bad --output", ["plot", "STORE", "-o", "f\x1b[2J.jpg\x07"], 2),
        ("missing store", ["plot", "/nowhere/\x1b]0;owned\x07.zarr", "-o", "f.png"], 2),
        ("a forged error line", ["orbit", "--from", "/x\nerror: \x1b[2J"], 2),
    ],
)
def test_escaped_paths_the_command_line_echoes(
    files: dict[str, Path],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    case: str,
    args: list[str],
    code: int,
) -> None:
    """`plot -o $'f\\e[2J.png'`, `init-gearset $'g\\e[2J.toml'` and a missing
    `--from $'/x\\e[2J'` echoed the path raw."""
    from typer.testing import CliRunner

    from gearchaos.cli import app

    monkeypatch.chdir(tmp_path)
    argv = [str(files["store"]) if a == "STORE" else a for a in args]
    result = CliRunner().invoke(app, argv)
    assert result.exit_code == code, result.output
    assert "Traceback" not in result.output
    assert not _acting(result.stdout) and not _acting(result.stderr), (case, result.output)
    assert "\\x1b" in result.output  # the path is named, its escape shown
    errors = [line for line in result.output.splitlines() if line.startswith("error:")]
    assert len(errors) == (code != 0)  # a refusal is one line, a path cannot forge another


def test_read_a_store_of_an_older_version_without_the_mark_is_still_read(
    files: dict[str, Path], tmp_path: Path
) -> None:
    """The mark decides what may be replaced, not what may be read: a store written before
    the mark existed starts an orbit as before (and is never replaced)."""
    from typer.testing import CliRunner

    from gearchaos.cli import app
    from gearchaos.sweep.store import is_sweep_store

    old = tmp_path / "old.zarr"
    import shutil

    shutil.copytree(files["store"], old)
    zattrs = json.loads((old / ".zattrs").read_text())
    del zattrs["gearchaos_output"]
    (old / ".zattrs").write_text(json.dumps(zattrs, indent=4))
    meta = json.loads((old / ".zmetadata").read_text())
    del meta["metadata"][".zattrs"]["gearchaos_output"]
    (old / ".zmetadata").write_text(json.dumps(meta, indent=4))
    assert not is_sweep_store(str(old))
    result = CliRunner().invoke(app, ["orbit", "--from", str(old), "--at", "omega=1.0", "--json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["converged"]


def test_kept_notes_that_mention_gearchaos_are_not_an_orbit_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`echo 'notes on my gearchaos runs' > notes.nc; gearchaos orbit … -o notes.nc` replaced
    the notes."""
    monkeypatch.chdir(tmp_path)
    notes = tmp_path / "notes.nc"
    notes.write_text("notes on my gearchaos runs\n")
    args = ["orbit", "--model", "gearchaos.model.library:Duffing", "--set", "omega=1.2",
            "-o", str(notes)]  # fmt: skip
    text = cli_refused("orbit -o notes.nc", args, "notes.nc", watch=tmp_path)
    assert "not a orbit file gearchaos wrote" in text
    assert notes.read_text() == "notes on my gearchaos runs\n"
