"""Results are bitwise equal to the reference written before the plumbing refactor (issue 9).

``make_reference.py`` wrote ``reference/`` with the code as it stood before the refactor; this
test makes the same calls with the code as it stands and compares every array byte for byte
and every attribute (except the library versions) exactly, reading the Zarr arrays raw so that
no decoding can hide a difference.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import zarr
from make_reference import (
    REF,
    SIMULATE,
    SWEEP_CONTINUATION,
    SWEEP_FRESH,
    SWEEP_OSCILLATOR,
    gearset,
    oscillator,
)

import gearchaos as gc

#: Attributes that name the software that wrote a file rather than what it computed (issue
#: 33: ``gearchaos_output``, the mark only gearchaos writes, a digest of the others).
VERSION_ATTRS = frozenset(
    {"version", "numba_version", "numpy_version", "scipy_version", "gearchaos_output"}
)

#: simulate.nc was last regenerated for issue 32 (the samples between sections interpolated),
#: the sweep stores for issue 32's verdict (windows, records continued onto their orbit, the λ₁
#: window stored); both hold every earlier change (issues 12, 24, 25) themselves.


#: The model reference of a gear set (issue 36): the planetary model, whose fields are the gear
#: set. The reference files were written before gear sets recorded it.
PLANETARY_MODEL = "gearchaos.model.planetary:PlanetaryModel"


#: Evidence codes added to the flag legend of ``verdict`` since the references were written
#: (issue 36: ``record``, the labels of sweeps without verdicts): a reference store holds none
#: of them, and its legend is the new one without them.
ADDED_EVIDENCE = {"record": 8}


def _legend_of_reference(a: dict[str, object], b: dict[str, object]) -> dict[str, object]:
    """The attributes ``a`` of a new ``verdict`` array with the added evidence codes taken
    out of its legend, where the reference ``b`` lacks them (the legend otherwise equal)."""
    values, meanings = a.get("flag_values"), a.get("flag_meanings")
    if not isinstance(values, list) or not isinstance(meanings, str):
        return a
    pairs = [
        (v, m)
        for v, m in zip(values, meanings.split(), strict=True)
        if not (ADDED_EVIDENCE.get(m) == v and m not in str(b.get("flag_meanings")).split())
    ]
    return {
        **a,
        "flag_values": [v for v, _ in pairs],
        "flag_meanings": " ".join(m for _, m in pairs),
    }


def _same_attrs(a: dict[str, object], b: dict[str, object], where: str) -> None:
    if where == "verdict":
        a = _legend_of_reference(a, b)
    if "model_class" not in b and b.get("gearset_toml"):  # a gear set's file, written before
        a = dict(a)
        assert a.pop("model_class") == PLANETARY_MODEL, f"{where}: model_class"
        fields = json.loads(str(a.pop("model_fields")))
        assert fields == {"gearset": b["gearset_toml"]}, f"{where}: model_fields"
    if "member_name" in a and "member_name" not in b and "model_parameters" in b:
        # issue 36: a store of a model whose group members are not planets names them (the
        # built-in oscillator's are the default, "member"), for the column names of its tables
        a = dict(a)
        assert a.pop("member_name") == "member", f"{where}: member_name"
    ka, kb = set(a) - VERSION_ATTRS, set(b) - VERSION_ATTRS
    assert ka == kb, f"{where}: attributes differ: {sorted(ka ^ kb)}"
    for k in ka:
        assert a[k] == b[k], f"{where}: attribute {k!r} differs"


def _same_bytes(x: np.ndarray, y: np.ndarray, where: str) -> None:
    assert x.dtype == y.dtype, f"{where}: dtype {x.dtype} != {y.dtype}"
    assert x.shape == y.shape, f"{where}: shape {x.shape} != {y.shape}"
    if x.dtype.kind in "fc":
        bad = int(np.sum(~((x == y) | (np.isnan(x) & np.isnan(y)))))
        assert bad == 0, f"{where}: {bad} values differ"
    assert x.tobytes() == y.tobytes(), f"{where}: not bitwise equal"


def _assert_same_store(new: Path, ref: Path) -> None:
    g_new = zarr.open_group(os.fspath(new), mode="r")
    g_ref = zarr.open_group(os.fspath(ref), mode="r")
    _same_attrs(dict(g_new.attrs), dict(g_ref.attrs), "store")
    names_new = sorted(k for k, _ in g_new.arrays())
    names_ref = sorted(k for k, _ in g_ref.arrays())
    assert names_new == names_ref
    for name in names_new:
        a, b = g_new[name], g_ref[name]
        _same_attrs(dict(a.attrs), dict(b.attrs), name)
        _same_bytes(np.asarray(a[...]), np.asarray(b[...]), name)


@pytest.mark.parametrize(
    ("name", "kw", "oscillating"),
    [
        ("sweep_fresh.zarr", SWEEP_FRESH, False),
        ("sweep_continuation.zarr", SWEEP_CONTINUATION, False),
        ("sweep_oscillator.zarr", SWEEP_OSCILLATOR, True),
    ],
)
def test_sweep_store_is_bitwise_equal_to_reference(
    tmp_path: Path, name: str, kw: dict[str, object], oscillating: bool
) -> None:
    kw = dict(kw)
    vary = kw.pop("vary")
    target = oscillator() if oscillating else gearset()
    gc.bifurcation(target, vary, store=os.fspath(tmp_path / name), **kw)  # type: ignore[arg-type]
    _assert_same_store(tmp_path / name, REF / name)


def test_simulate_result_is_bitwise_equal_to_reference(tmp_path: Path) -> None:
    """``simulate.nc`` (8 samples per period) was regenerated for issue 32, when the samples
    between the sections came to be interpolated instead of ending steps; it holds every
    change of the stores' conversions above already."""
    res = gc.simulate(gearset(), **SIMULATE)  # type: ignore[arg-type]
    res.save(tmp_path / "simulate.nc")
    new = xr.load_dataset(tmp_path / "simulate.nc", engine="h5netcdf")
    ref = xr.load_dataset(REF / "simulate.nc", engine="h5netcdf")
    _same_attrs(new.attrs, ref.attrs, "simulate.nc")
    assert sorted(new.variables) == sorted(ref.variables)
    for name in ref.variables:
        _same_attrs(new[name].attrs, ref[name].attrs, str(name))
        _same_bytes(np.asarray(new[name].values), np.asarray(ref[name].values), str(name))


def test_redefined_load_factor_is_the_peak_contact_force_over_the_static_force() -> None:
    """The one redefined variable: max |F̄ᶜ| over the window (tracked extrema) / (T̄_D/N),
    at least the largest sampled contact force (the extrema see between the samples)."""
    res = gc.simulate(gearset(), **SIMULATE)  # type: ignore[arg-type]
    ds = res.to_dataset()
    td, _ = res.system.model.parameters.loads(res.omega)
    static = td / res.system.model.n_planets
    for m in ("sp", "rp"):
        sampled = np.abs(ds[f"contact_force_{m}_history"].values).max(axis=0) / static
        lf = ds[f"load_factor_{m}"].values
        assert np.all(lf >= sampled * (1 - 1e-12))
        assert np.all(lf <= sampled * 1.05)
