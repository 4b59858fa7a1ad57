"""Export round trip (issue 12): the values read back from CSV and MATLAB files equal the
store's and the simulation's, bit for bit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
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


def test_csv_of_a_store_reads_back_to_its_values(store: Path, tmp_path: Path) -> None:
    out = gc.export(store, tmp_path / "run.csv")
    df = pd.read_csv(out, comment="#")
    ds = gc.open_sweep(store).load()
    assert list(df.columns[:4]) == ["xi", "omega", "section", "planet"]
    assert len(df) == ds.sizes["xi"] * ds.sizes["omega"] * ds.sizes["section"] * 2
    for _, row in df.sample(25, random_state=0).iterrows():
        at = {"xi": row["xi"], "omega": row["omega"]}
        point = ds.sel(at)
        assert row["delta_sp"] == float(
            point.delta_sp.sel(section=row["section"], planet=row["planet"])
        )
        assert row["delta_sp_dot"] == float(
            point.delta_sp_dot.sel(section=row["section"], planet=row["planet"])
        )
        assert row["motion"] == str(point.motion.values)
        assert row["status"] == int(point.status.values)
        lle = float(point.lle.values)
        assert row["lle"] == lle or (np.isnan(row["lle"]) and np.isnan(lle))
    first, second = out.read_text().splitlines()[:2]
    assert first.startswith("# gearchaos ") and " export of " in first  # the software
    assert "# gearset = hindawi2021" in second


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


def test_simulation_exports_both_ways(simulation: Path, tmp_path: Path) -> None:
    ds = gc.open_simulation(simulation)
    df = pd.read_csv(gc.export(simulation, tmp_path / "s.csv"), comment="#")
    assert len(df) == ds.sizes["section"] * ds.sizes["planet"]
    first = df[(df.section == 2) & (df.planet == 2)].iloc[0]
    assert first["tau"] == float(ds.tau[2])
    assert first["delta_rp"] == float(ds.delta_rp.isel(section=2).sel(planet=2))
    assert first["x_s"] == float(ds.x_s[2])
    m = loadmat(gc.export(simulation, tmp_path / "s.mat"))
    np.testing.assert_array_equal(m["delta_sp_history"], ds.delta_sp_history.values)
    np.testing.assert_array_equal(m["tau_sample"].ravel(), ds.tau_sample.values)


def test_cli_export_and_refusals(store: Path, tmp_path: Path) -> None:
    runner = CliRunner()
    result = runner.invoke(
        app, ["export", str(store), "--to", "csv", "-o", str(tmp_path / "a.txt")]
    )
    assert result.exit_code == 0, result.output
    assert pd.read_csv(tmp_path / "a.txt", comment="#").shape[0] > 0
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


def test_a_csv_stands_alone(tmp_path: Path, sheng: gc.GearSet) -> None:
    # issue 24: a backlash-sweep CSV named only `gearset = sheng2016`: not the changed
    # planet-ring backlash, not Ω; status and orbit codes came without a legend
    path = tmp_path / "b.zarr"
    gc.bifurcation(
        sheng.evolve({"backlash.planet_ring": 2.0}),
        "backlash.sun_planet=1:2:2",
        params={"omega": 1.5},
        store=path,
        progress=False,
        **SHORT,
    )
    out = gc.export(path, tmp_path / "b.csv")
    header = [ln for ln in out.read_text().splitlines() if ln.startswith("#")]
    text = "\n".join(header)
    assert "#   planet_ring = 2.0" in text  # the changed value, in the gear set's own TOML
    assert '"omega" = 1.5' in text  # the sweep's fixed values
    assert "# status: 0 = ok, 1 = max_steps" in text and "4 = not_run" in text
    assert "# verdict: " in text and "0 = floquet" in text
    # and the rows still read back with pandas
    import pandas as pd

    df = pd.read_csv(out, comment="#")
    assert len(df) > 0 and "status" in df.columns


def test_csv_has_every_planets_extrema_and_contact_regimes(store: Path, tmp_path: Path) -> None:
    """Issue 24: the per-planet extrema, the contact regimes (``contact_sp``) and the final
    state were left out of the CSV although its help says one column per variable; they are
    one column per planet (or state), equal to the store's values on every row of the point."""
    out = gc.export(store, tmp_path / "wide.csv")
    text = out.read_text(encoding="utf-8")
    df = pd.read_csv(out, comment="#")
    ds = gc.open_sweep(store).load()
    wide = [n for n, v in ds.data_vars.items() if "planet_all" in v.dims or "state" in v.dims]
    assert {"contact_sp", "contact_rp", "delta_sp_min", "delta_rp_max", "final_state"} <= set(wide)
    for name in wide:
        dim = "planet_all" if "planet_all" in ds[name].dims else "state"
        labels = [f"p{p}" if dim == "planet_all" else str(p) for p in ds[dim].values]
        for label, coord in zip(labels, ds[dim].values, strict=True):
            col = f"{name}_{label}"
            assert col in df.columns, col
            for _, row in df.sample(10, random_state=1).iterrows():
                want = ds[name].sel({"xi": row["xi"], "omega": row["omega"], dim: coord})
                assert row[col] == want.item(), (col, row["xi"], row["omega"])
    # five planets, though only planets 1 and 3 were observed at the section
    assert [c for c in df.columns if c.startswith("contact_sp_")] == [
        f"contact_sp_p{p}" for p in range(1, 6)
    ]
    # the coded regime columns come with their legend
    assert "# contact_sp: -1 = unknown, 0 = none, 1 = single_sided, 2 = double_sided" in text


def test_simulation_csv_has_the_extrema_of_every_planet(simulation: Path, tmp_path: Path) -> None:
    out = gc.export(simulation, tmp_path / "sim.csv")
    df = pd.read_csv(out, comment="#")
    ds = gc.open_simulation(simulation)
    for p in range(1, 6):
        assert (df[f"delta_sp_min_p{p}"] == ds["delta_sp_min"].sel(planet=p).item()).all()
    # the time samples stay rows, never columns
    assert len(df.columns) < 120
