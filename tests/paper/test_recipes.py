"""The seed's bifurcation figures: recipe values against the issue text, quick runs end to end.

The expected numbers below are typed from the issue ("Bifurcation diagrams at scale", item 7)
and the seed's captions (Sheng et al. 2016, Figs. 4, 6, 8, 9, 11, 12), not read from the code.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from gearchaos.errors import ParameterError
from gearchaos.paper import RECIPES, get_recipe, reproduce

XI4 = [0.03, 0.05, 0.07, 0.09]
OMEGA4 = [1.0, 1.5, 2.0, 2.5]

# name: (swept name, start, stop, family name, family values, fixed)
ISSUE = {
    "fig4": (
        "omega", 0.0, 4.0, "xi", XI4,
        {"backlash.sun_planet": 3.0, "backlash.planet_ring": 3.5, "clearance.sun_bearing": 2.0},
    ),
    "fig6": (
        "backlash.sun_planet", 1.0, 10.0, "xi", XI4,
        {"omega": 1.5, "backlash.planet_ring": 3.5, "clearance.sun_bearing": 2.0},
    ),
    # the issue gives ξ = 0.11 and the Ω panels; b̄_rp = 3.5, b̄_s = 2 from the seed's caption
    "fig8": (
        "backlash.sun_planet", 1.0, 10.0, "omega", OMEGA4,
        {"xi": 0.11, "backlash.planet_ring": 3.5, "clearance.sun_bearing": 2.0},
    ),
    "fig9": (
        "backlash.planet_ring", 1.0, 16.0, "xi", XI4,
        {"omega": 1.5, "backlash.sun_planet": 3.0, "clearance.sun_bearing": 2.0},
    ),
    # b̄_sp = 3, b̄_s = 2 from the seed's caption
    "fig11": (
        "backlash.planet_ring", 1.0, 11.0, "omega", OMEGA4,
        {"xi": 0.11, "backlash.sun_planet": 3.0, "clearance.sun_bearing": 2.0},
    ),
    "fig12": (
        "clearance.sun_bearing", 1.0, 10.0, "omega", [1.5],
        {"xi": 0.05, "backlash.sun_planet": 3.0, "backlash.planet_ring": 3.5},
    ),
}  # fmt: skip


def test_every_figure_of_the_issue_has_a_recipe():
    assert set(RECIPES) == set(ISSUE)


@pytest.mark.parametrize("name", sorted(ISSUE))
def test_recipe_values_match_the_issue(name):
    swept, start, stop, fam, fam_values, fixed = ISSUE[name]
    r = RECIPES[name]
    assert r.vary.name == swept
    if name == "fig4":
        # Ω ∈ [0, 4] starting at a small positive value (the period 2π/Ω is unbounded at 0)
        assert 0.0 < r.vary.start <= 0.05
    else:
        assert r.vary.start == start
    assert r.vary.stop == stop
    assert r.family.name == fam
    assert list(r.family.values) == fam_values
    assert dict(r.fixed) == fixed
    # the seed's protocol: fresh start, 100 transient + 100 recorded periods
    kw = r.sweep_kwargs()
    assert kw["initial_conditions"] == "fresh"
    assert (kw["transient_periods"], kw["periods"]) == (100, 100)
    assert r.vary.count >= 200  # readable full diagrams
    assert 8 <= r.vary.quick_count <= 16
    # the caption states the fixed values
    for v in fixed.values():
        assert f"= {v:g}" in r.caption


def test_unknown_figure_names_the_valid_ones(tmp_path):
    with pytest.raises(ParameterError, match=r"fig4, fig6, fig8, fig9, fig11, fig12.*'fig5'"):
        reproduce("fig5", tmp_path)
    assert get_recipe("Fig4") is get_recipe("4") is RECIPES["fig4"]


@pytest.mark.parametrize("name", sorted(ISSUE))
def test_quick_reproduce(name, tmp_path):
    swept, start, stop, fam, fam_values, _ = ISSUE[name]
    recipe = RECIPES[name]
    res = reproduce(name, tmp_path, quick=True, progress=False)

    # a quick run never replaces the full figure or store
    assert res["figure"] == str(tmp_path / f"{name}-quick.png")
    assert res["store"] == str(tmp_path / f"{name}-quick.zarr")
    png = tmp_path / f"{name}-quick.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert png.stat().st_size > 10_000

    ds = xr.open_zarr(res["store"])
    n = recipe.vary.quick_count
    assert list(ds["delta_sp"].dims) == [fam, swept, "section", "planet"]
    assert ds.sizes[fam] == len(fam_values)
    assert ds.sizes[swept] == n
    assert ds.sizes["section"] == 16
    np.testing.assert_array_equal(ds[fam].values, fam_values)
    x = ds[swept].values
    if name == "fig4":
        assert 0.0 < x[0] <= 0.05
    else:
        assert x[0] == start
    assert x[-1] == stop
    assert list(ds["planet"].values) == [1]
    for attr in ("gearset_toml", "sweep_toml", "version"):
        assert ds.attrs.get(attr), attr

    status = ds["status"].values
    assert status.shape == (len(fam_values), n)
    assert res["points"] == len(fam_values) * n
    assert res["failed"] == int(np.count_nonzero(status != 0))
    ok = status == 0
    assert ok.any()
    assert np.isfinite(ds["delta_sp"].values[ok]).all()
    assert res["seconds"] > 0


def _chunk_mtimes(store: str) -> dict[str, int]:
    """Modification times of the data chunk files of a Zarr (v2 or v3) store."""
    root = Path(store)
    return {
        str(f.relative_to(root)): f.stat().st_mtime_ns
        for f in root.rglob("*")
        if f.is_file()
        and len(f.relative_to(root).parts) > 1  # inside a variable's folder
        and not f.name.startswith(".")  # Zarr v2 metadata
        and f.name != "zarr.json"  # Zarr v3 metadata
    }


def test_quick_reproduce_resumes_a_finished_store(tmp_path):
    first = reproduce("fig12", tmp_path, quick=True, progress=False)
    before = xr.open_zarr(first["store"]).load()
    chunks = _chunk_mtimes(first["store"])
    assert chunks  # data chunks exist
    again = reproduce("fig12", tmp_path, quick=True, progress=False)
    # nothing recomputed: no data chunk rewritten, same numbers, same figure path
    assert _chunk_mtimes(again["store"]) == chunks
    xr.testing.assert_identical(before, xr.open_zarr(again["store"]).load())
    assert again["figure"] == first["figure"]


def test_paper_protocol_is_the_seeds_zero_start_and_record_labels(tmp_path):
    from gearchaos.paper.recipes import PAPER_PROTOCOL
    from gearchaos.sweep import classify_dataset
    from gearchaos.sweep.result import SweepResult

    kw = RECIPES["fig12"].sweep_kwargs(quick=True, paper_protocol=True)
    assert kw["verdicts"] is False and kw["lyapunov"] is False and kw["perturbation"] == 0.0
    assert dict(PAPER_PROTOCOL) == {"verdicts": False, "lyapunov": False, "perturbation": 0.0}
    assert RECIPES["fig12"].sweep_kwargs(quick=True).get("perturbation") is None  # default start

    res = reproduce("fig12", tmp_path, quick=True, progress=False, paper_protocol=True)
    assert res["store"] == str(tmp_path / "fig12-quick-paper.zarr")  # beside, never replacing
    assert res["figure"] == str(tmp_path / "fig12-quick-paper.png")
    ds = xr.open_zarr(res["store"]).load()
    spec = SweepResult.of(ds).spec
    assert spec.solver.perturbation == 0.0 and spec.verdicts is False and spec.lyapunov is False
    ok = ds["status"].values == 0
    assert ok.all()
    # labels from the record alone (evidence record), no λ₁ recorded nor measured
    from gearchaos.dynamics.verdict.evidence import EVIDENCE

    assert np.all(ds["verdict"].values == EVIDENCE["record"])
    assert np.all(np.isnan(ds["lle"].values)) and np.all(np.isnan(ds["max_multiplier"].values))
    # from the exact zero state the identical in-phase planets never leave their symmetric
    # subspace (every mesh deflects alike) and the sun stays centred: the start was exact
    dmin = ds["delta_sp_min"].values
    np.testing.assert_allclose(dmin, np.broadcast_to(dmin[..., :1], dmin.shape), rtol=0, atol=1e-9)
    for v in ("x_s_max", "x_s_min", "y_s_max", "y_s_min"):
        assert np.abs(ds[v].values).max() < 1e-9, v
    # the labels are the record's own: re-deriving them from the stored sections agrees
    np.testing.assert_array_equal(
        ds["motion"].values.astype(str), classify_dataset(ds)["motion"].astype(str)
    )
