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
from fuzz_helpers import cli_refused, refused

import gearchaos as gc
from gearchaos.dynamics.orbit_file import save_orbit

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


def _forge_nc(src: Path, dst: Path, **attrs: Any) -> Path:
    """A copy of the netCDF file ``src`` with its attributes changed (``None`` removes one)."""
    import warnings

    import xarray as xr

    ds = xr.load_dataset(src, engine="h5netcdf")
    for key, value in attrs.items():
        if value is None:
            ds.attrs.pop(key, None)
        else:
            ds.attrs[key] = value
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "invalid netcdf features": as gearchaos writes them
        ds.to_netcdf(dst, engine="h5netcdf", invalid_netcdf=True)
    return dst


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
        path = _forge_nc(files[kind], tmp_path / "forged.nc", **forged)
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
        ("gearchaos.model.planetary:PlanetaryModel", {}),
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
    path = _forge_nc(files["orbit"], tmp_path / "forged.nc", model_class=spec, model_fields=text)
    out = cli_refused("orbit --from forged module", ["orbit", "--from", str(path)], CONSENT,
                      watch=tmp_path)  # fmt: skip
    assert spec in out
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
        path = _forge_nc(files["branch"], tmp_path / "forged.nc", model_class=spec)
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
    orbit = _forge_nc(files["orbit"], tmp_path / "mine.nc", model_fields=fields,
                      model_class="/gone/consented_well.py:ConsentedWell")  # fmt: skip
    args = ["orbit", "--from", str(orbit), "--json"]
    text = cli_refused("orbit --from own model", args, "--model FILE.py:ConsentedWell",
                       watch=tmp_path)  # fmt: skip
    assert "/gone/consented_well.py:ConsentedWell" in text
    other = ["--model", "gearchaos.model.library:Lorenz"]
    cli_refused("orbit --from own model, other --model", [*args, *other], "--model gave Lorenz",
                watch=tmp_path)  # fmt: skip
    result = CliRunner().invoke(
        app, [*args, "--model", "mine/consented_well_moved.py:ConsentedWell"]
    )
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    ref = gc.periodic_orbit(DUFFING, period=out["period"], **TINY)
    assert out["converged"] and ref.converged
    assert out["x_sp1"] == pytest.approx(list(ref.section("x")), abs=1e-8)
