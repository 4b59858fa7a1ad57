"""Exports (issues 12, 24, 33, 35): a CSV that pandas' defaults, Python's ``csv`` module and a
spreadsheet read as it is — one row per point with units in the column names, the section
samples in a long table beside it, the provenance in a sidecar — whose values equal the
store's, and whose names can never forge a row; every store kind the package writes."""

from __future__ import annotations

import csv
import json
import math
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from scipy.io import loadmat
from sweep_helpers import SHORT
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app
from gearchaos.errors import ParameterError, StoreError


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory, sheng: gc.GearSet) -> Path:
    path = tmp_path_factory.mktemp("export") / "run.zarr"
    gc.bifurcation(
        sheng,
        "omega=0.6:2.4:4",
        family={"xi": [0.03, 0.07]},
        planets=[1, 3],
        lyapunov=True,
        store=path,
        progress=False,
        **SHORT,
    )
    return path


@pytest.fixture(scope="module")
def simulation(tmp_path_factory: pytest.TempPathFactory, sheng: gc.GearSet) -> Path:
    path = tmp_path_factory.mktemp("export") / "simulation.nc"
    gc.simulate(sheng, omega=1.3, transient_periods=8, periods=5, samples_per_period=4).save(path)
    return path


# ----------------------------------------------------------------------------- references
def sun_rpm_per_omega(gearset_toml: str, **changes: float) -> float:
    """Sun speed [rpm] at Ω = 1 from the gear set's own numbers, written out here: ω_n =
    √(k_sp/m_e), m_e = m_s m_p/(m_s + m_p), m_i = J_i/r_bi², r_bi = m z_i cos α_s/2; the mesh
    frequency ω = Ω ω_n = ω_s z_s z_r/(z_s + z_r) with the ring fixed."""
    g = tomllib.loads(gearset_toml)
    k = changes.get("stiffness.sun_planet_mean", g["stiffness"]["sun_planet_mean"])
    zs, zp, zr = g["teeth"]["sun"], g["teeth"]["planet"], g["teeth"]["ring"]
    cos_a = math.cos(math.radians(g["geometry"]["pressure_angle_sun"]))
    m = g["geometry"]["module"]
    ms = g["inertia"]["sun"] / (m * zs * cos_a / 2) ** 2
    mp = g["inertia"]["planet"] / (m * zp * cos_a / 2) ** 2
    wn = math.sqrt(k / (ms * mp / (ms + mp)))
    return wn * (zs + zr) / (zs * zr) * 60 / (2 * math.pi)


def omega_n(gearset_toml: str) -> float:
    g = tomllib.loads(gearset_toml)
    zs, zr = g["teeth"]["sun"], g["teeth"]["ring"]
    return sun_rpm_per_omega(gearset_toml) * 2 * math.pi / 60 * zs * zr / (zs + zr)


def meanings(var: xr.DataArray) -> dict[int, str]:
    codes = (
        json.loads(str(var.attrs["flag_values"]))
        if isinstance(var.attrs["flag_values"], str)
        else list(var.attrs["flag_values"])
    )
    return dict(zip(map(int, codes), var.attrs["flag_meanings"].split(), strict=True))


def read_rows(path: Path) -> list[list[str]]:
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.reader(f))


# ----------------------------------------------------------------------------- sweep stores
def test_point_table_opens_with_pandas_defaults_and_the_csv_module(
    store: Path, tmp_path: Path
) -> None:
    """Issue 35: 111 '#' lines broke pandas' default read_csv (ParserError) and split into
    columns in a spreadsheet; one row per section sample repeated every point value 16×2
    times. Now: a header row, then one row per point."""
    out = gc.export(store, tmp_path / "run.csv")
    ds = gc.open_sweep(store).load()
    df = pd.read_csv(out)  # pandas' defaults: no comment=, no skiprows
    rows = read_rows(out)
    n = ds.sizes["xi"] * ds.sizes["omega"]
    assert len(df) == n and len(rows) == n + 1
    assert all(len(r) == len(rows[0]) for r in rows)
    assert rows[0] == list(df.columns)
    assert not any(r[0].startswith("#") for r in rows)
    assert list(df.columns[:4]) == ["xi", "omega", "sun_rpm", "mesh_hz"]
    assert {"motion", "lle", "max_multiplier", "status", "contact_sp_p3"} <= set(df.columns)
    gtoml = ds.attrs["gearset_toml"]
    status_of = meanings(ds.status)
    regime_of = meanings(ds.contact_sp)
    for _, row in df.iterrows():
        point = ds.sel(xi=row["xi"], omega=row["omega"])  # exact: the values read back
        assert row["sun_rpm"] == pytest.approx(row["omega"] * sun_rpm_per_omega(gtoml), 1e-12)
        assert row["mesh_hz"] == pytest.approx(row["omega"] * omega_n(gtoml) / (2 * math.pi), 1e-12)
        assert row["motion"] == str(point.motion.values)
        assert row["status"] == status_of[int(point.status.values)]
        lle = float(point.lle.values)
        assert row["lle"] == lle or (np.isnan(row["lle"]) and np.isnan(lle))
        for p in range(1, 6):
            code = int(point.contact_sp.sel(planet_all=p).values)
            assert row[f"contact_sp_p{p}"] == regime_of[code]
            assert row[f"delta_sp_min_p{p}"] == float(point.delta_sp_min.sel(planet_all=p))
    # the csv module reads the same text
    header = rows[0]
    first = dict(zip(header, rows[1], strict=True))
    assert float(first["omega"]) == float(df["omega"].iloc[0])
    assert first["motion"] == df["motion"].iloc[0]


def test_sections_are_a_long_table_beside_the_points(store: Path, tmp_path: Path) -> None:
    gc.export(store, tmp_path / "run.csv")
    ds = gc.open_sweep(store).load()
    sec = pd.read_csv(tmp_path / "run.sections.csv")
    assert len(sec) == ds.sizes["xi"] * ds.sizes["omega"] * ds.sizes["section"]
    assert list(sec.columns[:3]) == ["xi", "omega", "section"]
    assert {"delta_sp_p1", "delta_sp_p3", "delta_sp_dot_p3"} <= set(sec.columns)
    for _, row in sec.sample(20, random_state=0).iterrows():
        at = {"xi": row["xi"], "omega": row["omega"], "section": int(row["section"])}
        for p in (1, 3):
            assert row[f"delta_sp_p{p}"] == float(ds.delta_sp.sel(at).sel(planet=p))
            assert row[f"delta_sp_dot_p{p}"] == float(ds.delta_sp_dot.sel(at).sel(planet=p))


def test_sidecar_holds_provenance_and_every_columns_unit(store: Path, tmp_path: Path) -> None:
    gc.export(store, tmp_path / "run.csv")
    ds = gc.open_sweep(store).load()
    side = json.loads((tmp_path / "run.csv.json").read_text())
    assert side["gearset"] == "hindawi2021"
    assert side["versions"]["run"]["gearchaos"] == ds.attrs["version"]
    assert side["versions"]["export"]["gearchaos"] == gc.__version__
    assert side["settings"]["rtol"] == ds.attrs["rtol"]
    assert side["protocol"]["transient_periods"] == ds.attrs["transient_periods"]
    assert side["specification"]["sweep_toml"] == ds.attrs["sweep_toml"]
    assert side["specification"]["gearset_toml"] == ds.attrs["gearset_toml"]
    assert side["scales"]["omega_n_rad_s"] == ds.attrs["omega_n_rad_s"]
    points = side["tables"]["points"]
    assert points["file"] == "run.csv" and points["rows"] == 8
    cols = points["columns"]
    assert list(cols) == list(pd.read_csv(tmp_path / "run.csv").columns)
    assert cols["sun_rpm"]["unit"] == "rpm" and cols["mesh_hz"]["unit"] == "Hz"
    assert cols["contact_sp_p1"]["values"] == ["unknown", "none", "single_sided", "double_sided"]
    assert side["tables"]["sections"]["file"] == "run.sections.csv"


def test_physical_columns_follow_the_gear_set_point_by_point(
    tmp_path: Path, sheng: gc.GearSet
) -> None:
    """A swept stiffness changes ω_n, so the sun speed per unit Ω differs from point to
    point; a clearance given in metres is written in µm and in units of b_c."""
    path = tmp_path / "k.zarr"
    gc.bifurcation(
        sheng,
        "stiffness.sun_planet_mean=4e8,8e8",
        params={"omega": 1.5},
        store=path,
        progress=False,
        **SHORT,
    )
    df = pd.read_csv(gc.export(path, tmp_path / "k.csv"))
    gtoml = sheng.to_toml()
    k_name = "stiffness.sun_planet_mean_N_per_m"
    assert list(df.columns[:4]) == [k_name, "omega", "sun_rpm", "mesh_hz"]
    for _, row in df.iterrows():
        k = row[k_name]
        assert row["omega"] == 1.5
        want = 1.5 * sun_rpm_per_omega(gtoml, **{"stiffness.sun_planet_mean": k})
        assert row["sun_rpm"] == pytest.approx(want, rel=1e-12)
    assert df["sun_rpm"].iloc[1] / df["sun_rpm"].iloc[0] == pytest.approx(math.sqrt(2), 1e-12)

    metres = sheng.evolve({"backlash.units": "m", "backlash.sun_planet": 3e-5,
                           "backlash.planet_ring": 3.5e-5})  # fmt: skip
    path = tmp_path / "b.zarr"
    gc.bifurcation(
        metres,
        "backlash.sun_planet=2e-5,4e-5",
        params={"omega": 1.5},
        store=path,
        progress=False,
        **SHORT,
    )
    df = pd.read_csv(gc.export(path, tmp_path / "b.csv"))
    b_c = tomllib.loads(metres.to_toml())["clearance"]["characteristic_length"]
    np.testing.assert_allclose(df["backlash.sun_planet_um"], [20.0, 40.0], rtol=1e-12)
    np.testing.assert_allclose(df["backlash.sun_planet_bar"], [2e-5 / b_c, 4e-5 / b_c], 1e-12)
    assert "backlash.sun_planet" not in df.columns


def test_a_response_store_has_load_factors_and_forces_in_newtons(
    tmp_path: Path, sheng: gc.GearSet
) -> None:
    path = tmp_path / "resp.zarr"
    gc.response(sheng, "omega=0.8:1.6:3", store=path, progress=False, **SHORT)
    ds = gc.open_sweep(path).load()
    df = pd.read_csv(gc.export(path, tmp_path / "resp.csv"))
    assert len(df) == 2 * 3 and list(df.columns[:2]) == ["direction", "omega"]
    g = tomllib.loads(ds.attrs["gearset_toml"])
    force = g["stiffness"]["sun_planet_mean"] * g["clearance"]["characteristic_length"]
    for _, row in df.iterrows():
        point = ds.sel(direction=row["direction"], omega=row["omega"])
        assert row["load_factor_sp"] == float(point.load_factor_sp)
        peak = float(point.force_peak_sp.sel(planet_all=2))
        assert row["force_peak_sp_p2"] == peak
        assert row["force_peak_sp_p2_N"] == pytest.approx(peak * force, rel=1e-12)
    side = json.loads((tmp_path / "resp.csv.json").read_text())
    assert side["tables"]["points"]["columns"]["force_peak_sp_p2_N"]["unit"] == "N"


# ----------------------------------------------------------------------------- other kinds
def test_basin_stores_are_exported_not_called_damaged(tmp_path: Path) -> None:
    """Issue 33: an intact basins or basin-fractions store was called "damaged … sweep_toml …
    run the sweep again" by export."""
    system = gc.duffing(1.2, delta=0.25, alpha=-1.0, beta=1.0, gamma=0.1)
    kw = {"transient_periods": 40, "periods": 8, "progress": False}
    gc.basins(system, "x=-1.8:1.8:3", "x_dot=-1.8:1.8:2", store=tmp_path / "b.zarr", **kw)
    ds = xr.open_zarr(tmp_path / "b.zarr").load()
    df = pd.read_csv(gc.export(tmp_path / "b.zarr", tmp_path / "b.csv"))
    assert len(df) == 6 and list(df.columns[:3]) == ["x_dot", "x", "omega"]
    assert "sun_rpm" not in df.columns  # a model without physical scales
    for _, row in df.iterrows():
        point = ds.sel(x_dot=row["x_dot"], x=row["x"])
        assert row["attractor"] == int(point.attractor) and row["label"] == str(point.label.values)
        assert row["final_state_x"] == float(point.final_state.sel(state="x"))
    assert not (tmp_path / "b.sections.csv").exists()
    side = json.loads((tmp_path / "b.csv.json").read_text())
    assert side["gearchaos_export"]["kind"] == "basins"
    assert side["attributes"]["attractors"] == json.loads(ds.attrs["attractors"])

    gc.basin_fractions(system, "omega=1.1,1.3", starts=4, store=tmp_path / "f.zarr", **kw)
    ds = xr.open_zarr(tmp_path / "f.zarr").load()
    df = pd.read_csv(gc.export(tmp_path / "f.zarr", tmp_path / "f.csv"))
    assert len(df) == 8 and list(df.columns[:2]) == ["omega", "start"]
    for _, row in df.iterrows():
        point = ds.sel(omega=row["omega"], start=row["start"])
        assert row["initial_state_x_dot"] == float(point.initial_state.sel(state="x_dot"))
        assert row["label"] == str(point.label.values)


def test_simulation_is_one_point_and_its_sections(simulation: Path, tmp_path: Path) -> None:
    ds = gc.open_simulation(simulation)
    df = pd.read_csv(gc.export(simulation, tmp_path / "s.csv"))
    assert len(df) == 1
    row = df.iloc[0]
    assert row["omega"] == 1.3 and row["status"] == "ok"
    assert row["sun_rpm"] == pytest.approx(1.3 * sun_rpm_per_omega(ds.attrs["gearset_toml"]))
    for p in range(1, 6):
        assert row[f"delta_sp_min_p{p}"] == ds["delta_sp_min"].sel(planet=p).item()
        assert row[f"load_factor_sp_p{p}"] == ds["load_factor_sp"].sel(planet=p).item()
    sec = pd.read_csv(tmp_path / "s.sections.csv")
    assert len(sec) == ds.sizes["section"]
    assert sec["tau"].tolist() == ds.tau.values.tolist()
    assert sec["delta_rp_p2"].iloc[2] == float(ds.delta_rp.isel(section=2).sel(planet=2))
    assert sec["x_s"].tolist() == ds.x_s.values.tolist()
    assert not any(c.endswith("_history") for c in [*df.columns, *sec.columns])


def test_other_files_are_refused_naming_what_they_are(tmp_path: Path) -> None:
    for title, attrs, what in (
        ("gearchaos branch of period-1 orbits of x", {"parameter": "omega"}, "a branch"),
        ("gearchaos periodic orbit of x", {}, "an orbit file"),
        (
            "gearchaos boundary curve",
            {"parameter": "omega", "kind": "boundary_curve"},
            "a boundary curve",
        ),
    ):
        path = tmp_path / f"{what.split()[-1]}.nc"
        xr.Dataset({"v": ("point", [1.0])}, attrs={"title": title, **attrs}).to_netcdf(
            path, engine="h5netcdf"
        )
        with pytest.raises(StoreError) as err:
            gc.export(path, tmp_path / "o.csv")
        msg = str(err.value)
        assert what in msg and "export writes sweep stores" in msg and "basin stores" in msg
        assert not (tmp_path / "o.csv").exists()


# ----------------------------------------------------------------------------- forged names
def test_names_never_forge_a_row(store: Path, tmp_path: Path) -> None:
    """Issue 33: a store path or title with a newline put a forged row into the CSV."""
    forged = tmp_path / "inj\n9.99,INJECTED,0,0.zarr"
    shutil.copytree(store, forged)  # the store under a hostile name
    out = gc.export(forged, tmp_path / "a.csv")
    ds = gc.open_sweep(store).load()
    n = ds.sizes["xi"] * ds.sizes["omega"]
    assert len(pd.read_csv(out)) == n and len(read_rows(out)) == n + 1
    assert "INJECTED" not in out.read_text()
    # labels, a coordinate and a title of a dataset carrying control characters
    hostile = ds.copy()
    labels = hostile.motion.values.astype("U40")
    labels[0, 0] = "1T\n9.99,INJECTED,0\r\x1b[2J"
    hostile["motion"] = (hostile.motion.dims, labels, hostile.motion.attrs)
    hostile.attrs["title"] = "t\n9.99,INJECTED"
    out = gc.export(hostile, tmp_path / "b.csv")
    rows = read_rows(out)
    assert len(rows) == n + 1 and all(len(r) == len(rows[0]) for r in rows)
    assert not any(r[0] == "9.99" for r in rows)
    cell = pd.read_csv(out)["motion"].iloc[0]
    assert cell == "1T\\n9.99,INJECTED,0\\r\\x1b[2J"  # the escapes, in one quoted field
    assert '"1T\\n9.99,INJECTED,0\\r\\x1b[2J"' in out.read_text()


def test_member_columns_take_the_stores_member_word_and_a_forged_one_is_refused(
    store: Path, tmp_path: Path
) -> None:
    """Issue 36: a store records ``member_name`` where its model's group members are not
    planets, and the tables name the member columns by it (``_stage1`` for ``_p1``); a value that
    is not a word (a forged row, a control sequence) is refused naming the attribute."""
    ds = gc.open_sweep(store).load()
    planetary = pd.read_csv(gc.export(ds, tmp_path / "planets.csv"))
    members = [c for c in planetary.columns if c.endswith(("_p1", "_p3"))]
    assert members  # the planets' columns, e.g. the contact regimes per planet
    ds.attrs["member_name"] = "stage"
    out = gc.export(ds, tmp_path / "stages.csv")
    renamed = pd.read_csv(out)
    assert [c for c in renamed.columns if c.endswith(("_stage1", "_stage3"))] == [
        c[: -len("p1")] + "stage" + c[-1] for c in members
    ]
    assert not [c for c in renamed.columns if c.endswith(("_p1", "_p3"))]
    sections = pd.read_csv(tmp_path / "stages.sections.csv")
    assert any(c.endswith("_stage1") for c in sections.columns)
    for forged in ("p1,INJECTED\n9.99", "\x1b[2Jstage", "", "1stage", 3):
        ds.attrs["member_name"] = forged
        with pytest.raises(StoreError, match="member_name must be a word") as err:
            gc.export(ds, tmp_path / "forged.csv")
        assert "\n" not in str(err.value) and "\x1b" not in str(err.value)


# ----------------------------------------------------------------------------- ownership
def test_an_export_replaces_only_its_own_files(store: Path, tmp_path: Path) -> None:
    out = tmp_path / "run.csv"
    gc.export(store, out)
    gc.export(store, out)  # its own files: replaced
    # a sheet edited since (saved from a spreadsheet) is the user's now
    out.write_text(out.read_text().replace("chaos", "CHAOS"))
    with pytest.raises(StoreError, match="not a export gearchaos wrote"):
        gc.export(store, out)
    assert "CHAOS" in out.read_text()
    # a file that mentions the package is not one it wrote
    mine = tmp_path / "mine.csv"
    mine.write_text("# gearchaos notes\nomega,motion\n1,1T\n")
    with pytest.raises(StoreError, match="not a export gearchaos wrote"):
        gc.export(store, mine)
    assert mine.read_text() == "# gearchaos notes\nomega,motion\n1,1T\n"
    # nor a forged sidecar that names the table without the sidecar's own digest
    fresh = tmp_path / "fresh.csv"
    gc.export(store, fresh)
    side = json.loads((tmp_path / "fresh.csv.json").read_text())
    side["gearchaos_export"]["files"]["fresh.csv"] = "0" * 64
    (tmp_path / "fresh.csv.json").write_text(json.dumps(side))
    with pytest.raises(StoreError, match="not a export gearchaos wrote"):
        gc.export(store, fresh)


def test_an_export_interrupted_between_its_files_is_replaced_by_the_next(
    store: Path, simulation: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from gearchaos.sweep import export_files

    out = tmp_path / "run.csv"
    gc.export(simulation, out)
    original, calls = export_files.write_file, []

    def stop_after_sidecar(path: str, data: bytes, *, what: str) -> str:
        calls.append(path)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return original(path, data, what=what)

    monkeypatch.setattr(export_files, "write_file", stop_after_sidecar)
    with pytest.raises(KeyboardInterrupt):
        gc.export(store, out)  # the new sidecar is written, the old tables are left
    monkeypatch.undo()
    assert calls[0].endswith("run.csv.json")
    gc.export(store, out)
    assert len(pd.read_csv(out)) == 8


# ----------------------------------------------------------------------------- MATLAB, CLI
def test_mat_of_a_store_holds_every_variable(store: Path, tmp_path: Path) -> None:
    out = gc.export(store, tmp_path / "run.mat")
    m = loadmat(out)
    ds = gc.open_sweep(store).load()
    for name in ("delta_sp", "status", "lle", "steps_accepted", "final_state"):
        np.testing.assert_array_equal(m[name], ds[name].values)
    np.testing.assert_array_equal(m["omega"].ravel(), ds.omega.values)
    assert [str(x[0]) for x in m["dims_delta_sp"].ravel()] == list(ds.delta_sp.dims)
    labels = np.array([str(x[0]) for x in m["motion"].ravel()]).reshape(ds.motion.shape)
    np.testing.assert_array_equal(labels, ds.motion.values)
    assert str(m["attrs"]["sweep_toml"][0, 0][0]) == ds.attrs["sweep_toml"]


def test_simulation_mat(simulation: Path, tmp_path: Path) -> None:
    ds = gc.open_simulation(simulation)
    m = loadmat(gc.export(simulation, tmp_path / "s.mat"))
    np.testing.assert_array_equal(m["delta_sp_history"], ds.delta_sp_history.values)
    np.testing.assert_array_equal(m["tau_sample"].ravel(), ds.tau_sample.values)


def test_cli_export_and_refusals(store: Path, tmp_path: Path) -> None:
    runner = CliRunner()
    result = runner.invoke(
        app, ["export", str(store), "--to", "csv", "-o", str(tmp_path / "a.txt")]
    )
    assert result.exit_code == 0, result.output
    assert len(pd.read_csv(tmp_path / "a.txt")) == 8
    assert (tmp_path / "a.sections.txt").is_file() and (tmp_path / "a.txt.json").is_file()
    for name in ("a.txt", "a.sections.txt", "a.txt.json"):
        assert name in result.output
    for args, needle in (
        ([str(store), "-o", str(tmp_path / "a.xlsx")], "csv, mat"),
        ([str(tmp_path / "none.zarr"), "-o", str(tmp_path / "b.csv")], "no result"),
        ([str(store), "-o", ""], "--output must be a path"),
    ):
        result = runner.invoke(app, ["export", *args])
        assert result.exit_code == 2, args
        assert needle in result.stderr and "Traceback" not in result.output
    with pytest.raises(ParameterError):
        gc.export(store, tmp_path / "x.parquet")
    with pytest.raises(StoreError):
        gc.export(tmp_path / "a.txt", tmp_path / "y.csv")
