"""Issue 36: a sweep store's contact regimes come from the model's contacts, not from whether
it is a gear set. A model written outside the package (the Kahraman–Singh gear pair of
``examples/``, one mesh contact ``mesh`` on δ̄ with half backlash b̄_h and two bearing
contacts) gets ``contact_mesh`` as a gear set gets ``contact_sp``/``contact_rp``: at every
swept Ω, the regime the per-run analysis of an independent simulation of that point gives
(:func:`gearchaos.analysis.contact.contact_regimes`), judged against the swept clearance."""

from __future__ import annotations

from pathlib import Path

import pytest
import xarray as xr

import gearchaos as gc
from gearchaos.analysis.contact import REGIMES, contact_regimes
from gearchaos.model import System
from gearchaos.model.loading import load_model_class

ROOT = Path(__file__).resolve().parents[2]
KahramanSingh1991 = load_model_class(
    f"{ROOT / 'examples' / 'kahraman_singh_1991.py'}:KahramanSingh1991"
)

#: Ω well below the mesh's loss of contact (0.9 ≲ Ω ≲ 2.1: the example's docstring) and inside
#: it, and two backlashes: the store must say what each point's own run says.
OMEGAS = [0.5, 1.5]
BACKLASHES = [0.6, 1.0]
PROTOCOL = {"transient_periods": 60, "periods": 16}


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> xr.Dataset:
    path = tmp_path_factory.mktemp("model_contacts") / "ks.zarr"
    gc.bifurcation(
        System(KahramanSingh1991(), 1.0),
        {"omega": OMEGAS},
        family={"b_h": BACKLASHES},
        store=str(path),
        progress=False,
        **PROTOCOL,
    )
    return xr.open_zarr(path)


def test_a_model_store_holds_the_regime_of_its_mesh_contact(store: xr.Dataset) -> None:
    mesh = [c for c in KahramanSingh1991().contacts if c.kind == "mesh"]
    assert [c.name for c in mesh] == ["mesh"]  # the model declares one mesh, two bearings
    assert "contact_mesh" in store.data_vars
    # bearings are judged on both extrema: a sweep stores no regime for them
    assert not [v for v in store.data_vars if v.startswith("contact_bearing")]
    code = store["contact_mesh"]
    assert set(code.dims) == {"b_h", "omega"}
    assert code.attrs["flag_meanings"] == "unknown none single_sided double_sided"
    seen = set()
    for b in BACKLASHES:
        for om in OMEGAS:
            run = gc.simulate(System(KahramanSingh1991(b_h=b), om), **PROTOCOL)
            expected = contact_regimes(run)["mesh"]
            got = int(code.sel(b_h=b, omega=om).values)
            assert got in (0, 1, 2), (b, om, got)
            assert REGIMES[got] == expected, (b, om)
            seen.add(expected)
    # the points are not all alike: the mesh keeps contact at low Ω and loses it at Ω = 1.5
    assert len(seen) >= 2, seen
