"""A sweep without verdicts stores its labels as verdicts from the record alone (issue 36, item
4): one procedure writes ``motion``, with evidence ``record``; stores of earlier versions
without verdict columns still classify as before; ``classify`` re-decides a record-mode store
with its tolerances and never touches a store's confirmed verdicts."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import zarr

import gearchaos as gc
from gearchaos.analysis.classify import classify_sections
from gearchaos.dynamics.verdict.evidence import EVIDENCE
from gearchaos.sweep import classify_dataset, classify_store
from gearchaos.sweep.verdicts import VERDICT_COLUMNS

OSC = gc.backlash_oscillator(1.0, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.6)
PERIODS = 96
REFERENCE = Path(__file__).resolve().parents[1] / "regression" / "reference"


@pytest.fixture(scope="module")
def record_store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("record") / "run.zarr"
    gc.bifurcation(
        OSC,
        "omega=0.3:2.4:24",
        store=path,
        transient_periods=100,
        periods=PERIODS,
        lyapunov=True,
        verdicts=False,
        progress=False,
    )
    return path


def _pair(ds: xr.Dataset) -> np.ndarray:
    """The first two observed section variables (the oscillator's x and ẋ), (Ω, section, 2)."""
    return np.stack([ds["x"].values, ds["x_dot"].values], axis=-1)


def _independent_labels(ds: xr.Dataset, **kw: object) -> np.ndarray:
    """The labels of the record rules, computed here from the stored sections and λ₁ with
    T = 2π/Ω from the swept Ω (not from the store's verdicts)."""
    omega = ds["omega"].values
    return classify_sections(
        _pair(ds),
        lle=ds["lle"].values,
        run_periods=PERIODS,
        forcing_period=2 * math.pi / omega,
        **kw,  # type: ignore[arg-type]
    )


def test_a_sweep_without_verdicts_stores_record_verdicts(record_store: Path) -> None:
    ds = xr.open_zarr(record_store)
    ran = ds["status"].values == 0
    assert ran.all()
    # every integrated point carries the evidence 'record', the verdict columns all there
    assert set(VERDICT_COLUMNS) <= set(ds.data_vars)
    assert np.all(ds["verdict"].values[ran] == EVIDENCE["record"])
    meanings = ds["verdict"].attrs["flag_meanings"].split()
    assert meanings[list(ds["verdict"].attrs["flag_values"]).index(EVIDENCE["record"])] == "record"
    # the labels are those of the record rules on the stored sections
    expected = _independent_labels(ds)
    stored = ds["motion"].values.astype(str)
    np.testing.assert_array_equal(stored, expected.astype(str))
    assert len(set(stored.tolist())) >= 2, stored  # the sweep crosses more than one regime
    # nothing was confirmed: no multiplier, no λ₁ error, no window, nothing added
    assert np.all(np.isnan(ds["max_multiplier"].values))
    assert np.all(np.isnan(ds["lle_error"].values))
    assert np.all(ds["extra_periods"].values == 0)
    assert np.all(ds["window_periods"].values == 0)
    # λ₁ is the one the sweep recorded, with its own attributes
    assert "method" in ds["lle"].attrs and np.all(np.isfinite(ds["lle"].values))
    # the period follows the label
    for lab, n in zip(stored, ds["period"].values, strict=True):
        assert n == (int(lab[:-1]) if lab.endswith("T") else 0)


def test_a_store_without_verdict_columns_classifies_to_the_same_labels(
    record_store: Path,
) -> None:
    ds = xr.load_dataset(record_store, engine="zarr")
    # the layout of a store written before sweeps stored their verdicts: motion, k01 and lle
    # as the classification and the sweep wrote them, no verdict columns
    old = ds.drop_vars([n for n in VERDICT_COLUMNS if n not in ("motion", "k01", "lle")])
    assert "verdict" not in old.data_vars
    relabelled = classify_dataset(old)
    np.testing.assert_array_equal(relabelled["motion"].astype(str), ds["motion"].values.astype(str))
    np.testing.assert_array_equal(relabelled["period"], ds["period"].values)
    np.testing.assert_array_equal(relabelled["k01"], ds["k01"].values)
    np.testing.assert_array_equal(relabelled["indicators_agree"], ds["indicators_agree"].values)


def test_classify_decides_a_record_store_again_with_its_tolerances(
    record_store: Path, tmp_path: Path
) -> None:
    path = tmp_path / "copy.zarr"
    shutil.copytree(record_store, path)
    before = xr.load_dataset(path, engine="zarr")
    classify_store(path, period_rtol=1e-2, max_period=2)
    after = xr.load_dataset(path, engine="zarr")
    expected = _independent_labels(before, rtol=1e-2, max_period=2).astype(str)
    np.testing.assert_array_equal(after["motion"].values.astype(str), expected)
    assert np.any(expected != before["motion"].values.astype(str))  # the tolerances mattered
    np.testing.assert_array_equal(after["verdict"].values, before["verdict"].values)
    np.testing.assert_array_equal(after["lle"].values, before["lle"].values)
    # and back: the default tolerances give the sweep's own labels again
    classify_store(path)
    again = xr.load_dataset(path, engine="zarr")
    np.testing.assert_array_equal(again["motion"].values, before["motion"].values)


def test_classify_never_rewrites_confirmed_verdicts(tmp_path: Path) -> None:
    path = tmp_path / "verdicts.zarr"
    shutil.copytree(REFERENCE / "sweep_oscillator.zarr", path)
    g = zarr.open_group(path, mode="r")
    before = {n: np.asarray(g[n][...]) for n in VERDICT_COLUMNS}
    assert set(np.unique(before["verdict"]).tolist()) - {
        EVIDENCE["record"],
        EVIDENCE["failed"],
    }  # confirmed verdicts
    classify_store(path, period_rtol=0.2, max_period=2)
    g = zarr.open_group(path, mode="r")
    for name, values in before.items():
        assert np.asarray(g[name][...]).tobytes() == values.tobytes(), name


def test_the_explorer_says_a_record_label_is_not_confirmed(record_store: Path) -> None:
    from gearchaos.explore.model import ExploreModel
    from gearchaos.sweep import open_sweep

    model = ExploreModel(open_sweep(record_store))
    assert model.evidence(model.point(0)) == "decided by record (not confirmed)"
    confirmed = ExploreModel(open_sweep(REFERENCE / "sweep_oscillator.zarr"))
    assert "not confirmed" not in confirmed.evidence(confirmed.point(0))
