"""Regime palette, regime bands and regime maps on hand-built sweep datasets with known labels.

The datasets have the sweep store's layout (leading swept dimensions, ``section``, ``planet``;
``status`` and ``motion`` per point; ``gearset_toml`` and ``sweep_toml`` attributes), so the
colour of every cell is known without simulating.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure

import gearchaos as gc
from gearchaos.errors import ParameterError
from gearchaos.plot import bifurcation_figure, regime_band, regime_map, sweep_figure
from gearchaos.plot.regimes import (
    REGIME_COLOURS,
    REGIME_GID,
    REGIME_ORDER,
    regime_category,
    regime_colour,
)
from gearchaos.sweep import SweepSpec

SECTIONS = 12


def sweep_dataset(
    labels: np.ndarray,
    axes: dict[str, np.ndarray],
    *,
    family: str | None = None,
    status: np.ndarray | None = None,
    direction: bool = False,
) -> xr.Dataset:
    """A sweep dataset whose point i has the motion label ``labels[i]`` (section values are
    random: only the labels matter here)."""
    rng = np.random.default_rng(3)
    shape = tuple(len(v) for v in axes.values())
    assert labels.shape == shape
    dims = tuple(axes)
    x = 3.0 + rng.normal(size=(*shape, SECTIONS, 1))
    xd = rng.normal(size=(*shape, SECTIONS, 1))
    st = np.zeros(shape, np.int8) if status is None else status.astype(np.int8)
    motion = labels.astype("<U10")
    coords: dict[str, object] = {n: np.asarray(v, float) for n, v in axes.items()}
    if direction:
        x, xd, st, motion = (np.stack([a, a]) for a in (x, xd, st, motion))
        motion[1] = np.where(motion[1] == "1T", "2T", motion[1])  # the down branch differs
        dims = ("direction", *dims)
        coords["direction"] = np.array(["up", "down"])
    coords["section"] = np.arange(SECTIONS)
    coords["planet"] = np.array([1])
    vary = {n: v for n, v in axes.items() if n != family}
    spec = SweepSpec.build(
        vary,
        family={family: axes[family]} if family else None,
        params={} if "omega" in axes else {"omega": 1.5},
        periods=SECTIONS,
        initial_conditions="continuation" if direction else "fresh",
        direction="both" if direction else "up",
    )
    return xr.Dataset(
        {
            "delta_sp": ((*dims, "section", "planet"), x),
            "delta_sp_dot": ((*dims, "section", "planet"), xd),
            "status": (dims, st),
            "motion": (dims, motion),
        },
        coords=coords,
        attrs={
            "gearset_toml": gc.preset("hindawi2021").to_toml(),
            "sweep_toml": spec.to_toml(),
            "transient_periods": 10.0,
            "periods": SECTIONS,
        },
    )


def band_bars(ax) -> dict[str, list]:
    """category -> the regime band's bar collections of that category."""
    out: dict[str, list] = {}
    for c in ax.collections:
        gid = c.get_gid() or ""
        if gid.startswith(REGIME_GID + ":"):
            out.setdefault(gid.split(":", 1)[1], []).append(c)
    return out


def x_spans(collection) -> list[tuple[float, float]]:
    spans = []
    for path in collection.get_paths():
        xs = path.vertices[:, 0]
        spans.append((float(xs.min()), float(xs.max())))
    return spans


def legend_texts(legend) -> list[str]:
    return [t.get_text() for t in legend.get_texts()]


# --------------------------------------------------------------------------- palette
def test_palette_is_fixed_and_distinct() -> None:
    assert set(REGIME_ORDER) == set(REGIME_COLOURS)
    rgba = [to_rgba(REGIME_COLOURS[c]) for c in REGIME_ORDER]
    assert len(set(rgba)) == len(rgba)  # one colour per category
    assert REGIME_ORDER[:8] == tuple(f"{n}T" for n in range(1, 9))
    assert REGIME_ORDER[8:] == ("≥ 9T", "QP", "chaos", "unresolved", "failed", "not run")


@pytest.mark.parametrize(
    ("label", "category"),
    [
        ("1T", "1T"),
        ("8T", "8T"),
        ("9T", "≥ 9T"),
        ("64T", "≥ 9T"),
        ("QP", "QP"),
        ("chaos", "chaos"),
        ("unresolved", "unresolved"),
        ("failed", "failed"),
        ("", "not run"),
        ("many", "unresolved"),
    ],
)
def test_labels_map_to_categories(label: str, category: str) -> None:
    assert regime_category(label) == category
    assert regime_colour(label) == REGIME_COLOURS[category]


# --------------------------------------------------------------------------- band
LABELS_1D = np.array(["1T", "1T", "2T", "QP", "QP", "chaos", "12T", "20T", "failed", "1T"])


def test_regime_band_draws_each_value_in_its_colour() -> None:
    omega = np.linspace(0.5, 3.2, LABELS_1D.size)
    status = (LABELS_1D == "failed").astype(np.int8)
    ds = sweep_dataset(LABELS_1D, {"omega": omega}, status=status)
    ax = regime_band(ds, legend=True)
    bars = band_bars(ax)
    present = ["1T", "2T", "≥ 9T", "QP", "chaos", "failed"]
    assert set(bars) == set(present)
    half = 0.5 * (omega[1] - omega[0])
    for cat, collections in bars.items():
        for c in collections:
            np.testing.assert_allclose(c.get_facecolor()[0], to_rgba(REGIME_COLOURS[cat]))
        spans = [s for c in collections for s in x_spans(c)]
        # the cells of this category's points, and nothing else, are covered
        inside = [x for x in omega if any(lo < x < hi for lo, hi in spans)]
        expected = [
            x for x, lab in zip(omega, LABELS_1D, strict=True) if regime_category(lab) == cat
        ]
        np.testing.assert_allclose(inside, expected)
        covered = sum(hi - lo for lo, hi in spans)
        assert covered == pytest.approx(2 * half * len(expected))
    # runs of one label are one bar: 1T at the start (two points) and at the end
    assert sorted(len(x_spans(c)) for c in bars["1T"]) == [2]
    assert len(x_spans(bars["≥ 9T"][0])) == 1
    # the legend names exactly the regimes present, in palette order
    assert legend_texts(ax.get_legend()) == present
    assert ax.get_xlim() == pytest.approx((omega[0] - half, omega[-1] + half))
    assert r"\Omega" in ax.get_xlabel()


def test_regime_band_selects_a_family_value_and_needs_one_dimension() -> None:
    xi = np.array([0.03, 0.05])
    omega = np.array([1.0, 2.0, 3.0])
    labels = np.array([["1T", "2T", "chaos"], ["1T", "1T", "1T"]])
    ds = sweep_dataset(labels, {"xi": xi, "omega": omega}, family="xi")
    assert set(band_bars(regime_band(ds, select={"xi": 0.03}))) == {"1T", "2T", "chaos"}
    assert set(band_bars(regime_band(ds, select={"xi": 0.05}))) == {"1T"}
    with pytest.raises(ParameterError, match="one swept dimension"):
        regime_band(ds)


def test_regime_band_draws_two_rows_for_both_directions() -> None:
    labels = np.array(["1T", "QP", "1T"])
    ds = sweep_dataset(labels, {"omega": np.array([1.0, 2.0, 3.0])}, direction=True)
    ax = regime_band(ds)
    bars = band_bars(ax)
    assert set(bars) == {"1T", "2T", "QP"}  # up: 1T QP 1T; down: 2T QP 2T
    assert [t.get_text() for t in ax.get_yticklabels()] == ["up", "down"]
    assert ax.get_ylim() == (0.0, 2.0)
    up_rows = {
        cat for cat, cs in bars.items() for c in cs if c.get_paths()[0].vertices[:, 1].min() >= 1
    }
    assert up_rows == {"1T", "QP"}


def test_points_never_run_are_not_run() -> None:
    labels = np.array(["1T", "failed", "failed"])
    status = np.array([0, 1, 4])  # 4: not run yet (an interrupted store)
    ds = sweep_dataset(labels, {"omega": np.array([1.0, 2.0, 3.0])}, status=status)
    assert set(band_bars(regime_band(ds))) == {"1T", "failed", "not run"}


def test_datasets_without_labels_are_refused() -> None:
    ds = sweep_dataset(LABELS_1D, {"omega": np.linspace(1, 2, LABELS_1D.size)}).drop_vars("motion")
    with pytest.raises(ParameterError, match="gearchaos classify"):
        regime_band(ds)
    with pytest.raises(ParameterError, match="motion"):
        bifurcation_figure(ds, regimes=True)


# --------------------------------------------------------------------------- map
LABELS_2D = np.array(
    [
        ["1T", "1T", "2T", "chaos"],
        ["1T", "QP", "3T", "chaos"],
        ["unresolved", "QP", "10T", "failed"],
    ]
)  # (omega, backlash.planet_ring)


def map_dataset() -> xr.Dataset:
    axes = {"omega": np.array([1.0, 1.5, 2.0]), "backlash.planet_ring": np.array([1.0, 2, 3, 4])}
    return sweep_dataset(LABELS_2D, axes, status=(LABELS_2D == "failed").astype(np.int8))


def test_regime_map_colours_every_cell_by_its_label() -> None:
    ax = regime_map(map_dataset())
    (mesh,) = [c for c in ax.collections if c.get_gid() == REGIME_GID]
    rgba = mesh.to_rgba(mesh.get_array()).reshape(4, 3, 4)  # y = b̄_rp rows, x = Ω columns
    for i in range(3):
        for j in range(4):
            np.testing.assert_allclose(rgba[j, i], to_rgba(regime_colour(LABELS_2D[i, j])))
    present = ["1T", "2T", "3T", "≥ 9T", "QP", "chaos", "unresolved", "failed"]
    assert legend_texts(ax.get_legend()) == present
    assert r"\Omega" in ax.get_xlabel()
    assert "b" in ax.get_ylabel() and "rp" in ax.get_ylabel()


def test_regime_map_needs_a_2d_grid() -> None:
    ds = sweep_dataset(LABELS_1D, {"omega": np.linspace(1, 2, LABELS_1D.size)})
    with pytest.raises(ParameterError, match="2-D"):
        regime_map(ds)


# --------------------------------------------------------------------------- figures
def test_bifurcation_figure_gets_a_band_per_panel_and_one_legend() -> None:
    xi = np.array([0.03, 0.05, 0.07])
    omega = np.linspace(1.0, 3.0, 5)
    labels = np.array(
        [["1T", "2T", "2T", "chaos", "QP"], ["1T"] * 5, ["1T", "1T", "4T", "4T", "1T"]]
    )
    ds = sweep_dataset(labels, {"xi": xi, "omega": omega}, family="xi")
    fig = bifurcation_figure(ds)
    assert isinstance(fig, Figure)
    bands = [ax for ax in fig.axes if band_bars(ax)]
    assert len(bands) == 3
    panels = [ax for ax in fig.axes if ax.get_visible() and ax not in bands]
    assert [ax.get_title(loc="left") for ax in panels] == [
        r"(a) $\xi$ = 0.03",
        r"(b) $\xi$ = 0.05",
        r"(c) $\xi$ = 0.07",
    ]
    (legend,) = fig.legends
    assert legend_texts(legend) == ["1T", "2T", "4T", "QP", "chaos"]
    # without labels, or with regimes=False: no bands
    assert not any(band_bars(ax) for ax in bifurcation_figure(ds, regimes=False).axes)
    plain = bifurcation_figure(ds.drop_vars("motion"))
    assert not any(band_bars(ax) for ax in plain.axes) and not plain.legends


def test_sweep_figure_draws_2d_stores_as_regime_maps() -> None:
    ds = map_dataset()
    fig = sweep_figure(ds)
    meshes = [c for ax in fig.axes for c in ax.collections if c.get_gid() == REGIME_GID]
    assert len(meshes) == 1
    (legend,) = fig.legends
    assert legend_texts(legend) == ["1T", "2T", "3T", "≥ 9T", "QP", "chaos", "unresolved", "failed"]
    # the distinct-point map stays available
    fig = sweep_figure(ds, regimes=False)
    assert not [c for ax in fig.axes for c in ax.collections if c.get_gid() == REGIME_GID]
    assert not fig.legends


def test_map_legend_covers_no_title() -> None:
    """The legend of a 2-D map sits under the panel: beside it at the top it covered the end
    of the title's protocol line (docs/howto/map.png)."""
    from figure_checks import assert_legends_clear_of_titles

    ds = map_dataset()
    ds.attrs.update(transient_periods=100.0, periods=100, initial_conditions="fresh")
    fig = sweep_figure(ds)
    assert fig.get_suptitle().endswith(
        "100 transient + 100 recorded periods, fresh initial conditions"
    )
    assert_legends_clear_of_titles(fig)
    (legend,) = fig.legends
    ax = fig.axes[0]
    box = legend.get_window_extent()
    assert box.y1 <= ax.get_tightbbox().y0 + 0.5  # under the panel
    assert 0 <= box.x0 and box.x1 <= fig.bbox.x1  # and inside the figure: in two rows here
