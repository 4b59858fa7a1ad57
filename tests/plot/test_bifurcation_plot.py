"""Bifurcation diagrams and distinct-point maps of sweep datasets.

Most tests build a sweep dataset by hand with the store's layout (leading swept dimensions,
``section``, ``planet``; ``status`` per point; ``gearset_toml`` and ``sweep_toml`` attributes),
with section values of known period, so every count is known without simulating. One test
runs a short sweep of the backlash oscillator through :func:`gearchaos.bifurcation`.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.figure import Figure

import gearchaos as gc
from gearchaos.errors import ParameterError
from gearchaos.model.derived import gearset_info
from gearchaos.plot import (
    axis_label,
    bifurcation,
    bifurcation_figure,
    distinct_counts,
    distinct_map,
    sweep_figure,
)
from gearchaos.sweep import SweepSpec

SECTIONS = 24  # divisible by 1, 2, 3, 4, 6, 8: every period below repeats whole


def section_values(period: int, rng: np.random.Generator, centre: float = 3.4) -> np.ndarray:
    """(x, x') of ``SECTIONS`` section points: an nT orbit visits n well separated points;
    ``period=0`` means chaotic (random points)."""
    k = np.arange(SECTIONS)
    if period == 0:
        return centre + rng.uniform(-1.0, 1.0, (2, SECTIONS))
    phase = 2.0 * np.pi * (k % period) / period + 0.3  # offset: n distinct values of x
    return np.stack([centre + 0.5 * np.cos(phase), 0.5 * np.sin(phase) + 0.1 * (k % period)])


def sweep_dataset(
    periods: np.ndarray,
    axes: dict[str, np.ndarray],
    *,
    family: str | None = None,
    status: np.ndarray | None = None,
    direction: bool = False,
    fixed: dict[str, float] | None = None,
) -> xr.Dataset:
    """A dataset with the sweep store's layout whose point i has period ``periods[i]``."""
    rng = np.random.default_rng(1)
    names = list(axes)
    shape = tuple(len(v) for v in axes.values())
    assert periods.shape == shape
    values = np.stack([section_values(int(p), rng) for p in periods.ravel()])
    x = values[:, 0].reshape(*shape, SECTIONS, 1)
    xd = values[:, 1].reshape(*shape, SECTIONS, 1)
    st = np.zeros(shape, np.int8) if status is None else status.astype(np.int8)
    dims = tuple(names)
    coords: dict[str, object] = {n: np.asarray(v, float) for n, v in axes.items()}
    if direction:
        x, xd, st = (np.stack([a, a]) for a in (x, xd, st))
        dims = ("direction", *dims)
        coords["direction"] = np.array(["up", "down"])
    coords["section"] = np.arange(SECTIONS)
    coords["planet"] = np.array([1])
    gs = gc.preset("hindawi2021")
    vary = {n: v for n, v in axes.items() if n != family}
    spec = SweepSpec.build(
        vary,
        family={family: axes[family]} if family else None,
        params=fixed or ({} if "omega" in axes else {"omega": 1.5}),
        periods=SECTIONS,
        initial_conditions="continuation" if direction else "fresh",
        direction="both" if direction else "up",
    )
    b_sp, b_rp = gs.backlash_bar()
    return xr.Dataset(
        {
            "delta_sp": ((*dims, "section", "planet"), x),
            "delta_sp_dot": ((*dims, "section", "planet"), xd),
            "status": (dims, st),
        },
        coords=coords,
        attrs={
            "gearset_toml": gs.to_toml(),
            "sweep_toml": spec.to_toml(),
            "transient_periods": 10.0,
            "periods": SECTIONS,
            "initial_conditions": spec.initial_conditions,
            "clearance_sun_planet": b_sp,
            "clearance_planet_ring": b_rp,
            "clearance_sun_bearing": gs.sun_bearing_clearance_bar(),
        },
    )


def n_dots(ax: Axes) -> int:
    return sum(len(c.get_offsets()) for c in ax.collections)


def gid_lines(ax: Axes, gid: str) -> list:
    return [line for line in ax.get_lines() if line.get_gid() == gid]


# --------------------------------------------------------------------------- labels
def test_axis_labels_use_the_paper_symbols() -> None:
    assert axis_label("omega") == r"$\Omega = \omega/\omega_n$"
    assert axis_label("xi") == r"$\xi$"
    assert axis_label("backlash.sun_planet") == r"$\bar b_{sp}$"
    assert axis_label("backlash.planet_ring") == r"$\bar b_{rp}$"
    assert axis_label("clearance.sun_bearing") == r"$\bar b_s$"
    assert axis_label("torque.input") == r"$T_D$ [N m]"
    # every gear-set field has a symbol and unit in the registry (gearset/schema.py) ...
    assert axis_label("mass.sun") == r"$m_s$ [kg]"
    # ... and a name outside it labels itself
    assert axis_label("not.a_parameter") == "not.a_parameter"


# --------------------------------------------------------------------------- bifurcation
def test_one_dot_per_section_point_of_known_period() -> None:
    periods = np.array([1, 1, 2, 3, 4, 0, 1])
    omega = np.linspace(0.5, 3.5, periods.size)
    ds = sweep_dataset(periods, {"omega": omega})
    ax = bifurcation(ds)
    assert isinstance(ax, Axes)
    assert r"\Omega" in ax.get_xlabel()
    assert ax.get_ylabel() == r"$\bar{X}_{sp1}$"
    # an nT point is n dots; the chaotic point shows all its SECTIONS values
    assert n_dots(ax) == 1 + 1 + 2 + 3 + 4 + SECTIONS + 1
    (scatter,) = ax.collections
    assert scatter.get_rasterized()
    xs = scatter.get_offsets()[:, 0]
    for x, p in zip(omega, periods, strict=True):
        assert np.sum(xs == x) == (p or SECTIONS)


def test_derivative_label_and_planet_check() -> None:
    ds = sweep_dataset(np.array([1, 2]), {"omega": np.array([1.0, 2.0])})
    ax = bifurcation(ds, var="delta_sp_dot")
    assert ax.get_ylabel() == r"$\bar{X}'_{sp1}$"
    with pytest.raises(ParameterError, match="planet"):
        bifurcation(ds, planet=2)
    with pytest.raises(ParameterError, match="var"):
        bifurcation(ds, var="nonsense")


def test_failed_points_are_skipped_and_counted() -> None:
    periods = np.array([1, 2, 1, 1])
    status = np.array([0, 3, 0, 2])
    ds = sweep_dataset(periods, {"omega": np.linspace(1, 2, 4)}, status=status)
    ax = bifurcation(ds)
    assert n_dots(ax) == 2
    notes = [t.get_text() for t in ax.texts]
    assert any("2 of 4 points failed" in t for t in notes)


def test_clearance_lines_from_attrs_and_from_the_swept_backlash() -> None:
    ds = sweep_dataset(np.array([1, 1, 2]), {"omega": np.array([1.0, 1.5, 2.0])})
    ax = bifurcation(ds, clearance_lines=True)
    lines = gid_lines(ax, "clearance")
    assert sorted(float(line.get_ydata()[0]) for line in lines) == [-3.0, 3.0]

    b = np.array([1.0, 4.0, 7.0])
    ds = sweep_dataset(np.array([1, 1, 2]), {"backlash.sun_planet": b})
    ax = bifurcation(ds, clearance_lines=True, relative=False)
    assert ax.get_xlabel() == r"$\bar b_{sp}$"
    ys = sorted(tuple(line.get_ydata()) for line in gid_lines(ax, "clearance"))
    assert ys == [tuple(-b), tuple(b)]  # ±b̄ follows the swept backlash


def test_swept_own_clearance_draws_the_deflection_beyond_it() -> None:
    """Sweeping b̄_sp, X̄_sp grows with b̄ (a thin band along the diagonal); by default the
    diagram shows X̄ − b̄ with the flank edges at 0 and −2b̄."""
    b = np.array([1.0, 4.0, 7.0])
    ds = sweep_dataset(np.array([1, 1, 2]), {"backlash.sun_planet": b})
    ds["delta_sp"] = ds["delta_sp"] + xr.DataArray(b, dims="backlash.sun_planet")
    ax = bifurcation(ds, clearance_lines=True)
    assert ax.get_ylabel() == r"$\bar{X}_{sp1} - \bar b_{sp}$"
    absolute = bifurcation(ds, relative=False)
    y_rel = np.sort(ax.collections[0].get_offsets()[:, 1])
    pts = absolute.collections[0].get_offsets()
    x_abs = np.asarray(pts[:, 0])
    y_expected = np.sort(np.asarray(pts[:, 1]) - np.interp(x_abs, b, b))
    np.testing.assert_allclose(y_rel, y_expected, atol=1e-12)
    ys = [np.asarray(line.get_ydata(), dtype=float) for line in gid_lines(ax, "clearance")]
    assert any(np.all(y == 0.0) for y in ys)  # drive-flank edge X̄ = b̄
    assert any(y.shape == b.shape and np.allclose(y, -2.0 * b) for y in ys)  # back flank
    # the y axis follows the relative values, not the diagonal
    lo, hi = ax.get_ylim()
    assert hi - lo < 0.5 * (b[-1] - b[0])


def test_resonance_lines_at_harmonics_meeting_natural_frequencies() -> None:
    omega = np.linspace(0.4, 2.0, 5)
    ds = sweep_dataset(np.ones(5, int), {"omega": omega})
    ax = bifurcation(ds, resonances=True)
    got = sorted(float(line.get_xdata()[0]) for line in gid_lines(ax, "resonance"))
    res = gearset_info(gc.preset("hindawi2021"))["omega_at_resonances"]
    want = sorted(r["omega"] for r in res if 0.4 <= r["omega"] <= 2.0)
    assert got == pytest.approx(want)
    assert len(want) >= 5
    # not on other axes
    ds = sweep_dataset(np.ones(3, int), {"xi": np.array([0.03, 0.05, 0.07])})
    assert gid_lines(bifurcation(ds, resonances=True), "resonance") == []


def test_family_needs_select_and_figure_has_one_panel_per_value() -> None:
    xi = np.array([0.03, 0.05, 0.07, 0.09])
    omega = np.linspace(0.5, 3.0, 6)
    periods = np.array([[1, 1, 2, 2, 0, 1]] * 4)
    ds = sweep_dataset(periods, {"xi": xi, "omega": omega}, family="xi")
    with pytest.raises(ParameterError, match="select"):
        bifurcation(ds)
    ax = bifurcation(ds, select={"xi": 0.05})
    assert n_dots(ax) == 1 + 1 + 2 + 2 + SECTIONS + 1
    with pytest.raises(ParameterError, match="swept values"):
        bifurcation(ds, select={"xi": 0.04})

    fig = bifurcation_figure(ds)
    assert isinstance(fig, Figure)
    panels = [a for a in fig.axes if a.get_visible()]
    assert len(panels) == 4
    titles = [a.get_title(loc="left") for a in panels]
    assert titles == [
        r"(a) $\xi$ = 0.03",
        r"(b) $\xi$ = 0.05",
        r"(c) $\xi$ = 0.07",
        r"(d) $\xi$ = 0.09",
    ]
    assert "hindawi2021" in fig.get_suptitle()
    assert r"$\bar b_{sp}$ = 3" in fig.get_suptitle()


def test_both_directions_overlay_with_a_legend() -> None:
    ds = sweep_dataset(np.array([1, 2, 1]), {"omega": np.array([1.0, 1.5, 2.0])}, direction=True)
    ax = bifurcation(ds)
    assert len(ax.collections) == 2
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[0].startswith("up") and labels[1].startswith("down")
    c_up, c_down = (tuple(c.get_facecolor()[0]) for c in ax.collections)
    assert c_up != c_down
    ax = bifurcation(ds, select={"direction": "down"})
    assert len(ax.collections) == 1 and n_dots(ax) == 4


# --------------------------------------------------------------------------- maps
def test_distinct_counts_and_map_of_a_known_grid() -> None:
    omega = np.linspace(0.5, 2.5, 5)
    b_rp = np.array([1.0, 2.0, 3.0])
    periods = np.array(
        [
            [1, 2, 3, 4, 0],
            [1, 1, 2, 8, 0],
            [6, 1, 1, 2, 3],
        ]
    ).T  # (omega, backlash.planet_ring)
    status = np.zeros_like(periods)
    status[2, 1] = 3  # one failed point
    ds = sweep_dataset(periods, {"omega": omega, "backlash.planet_ring": b_rp}, status=status)
    counts = distinct_counts(ds, max_count=6)
    want = np.where(periods == 0, 7, np.minimum(periods, 7))  # 8 points > max_count: many
    want[2, 1] = 0
    np.testing.assert_array_equal(counts.transpose("omega", "backlash.planet_ring").values, want)

    ax = distinct_map(ds, max_count=6)
    assert isinstance(ax, Axes)
    assert r"\Omega" in ax.get_xlabel() and ax.get_ylabel() == r"$\bar b_{rp}$"
    (mesh,) = ax.collections
    np.testing.assert_array_equal(np.asarray(mesh.get_array()).reshape(3, 5), want.T)
    cbar = mesh.colorbar
    labels = [t.get_text() for t in cbar.ax.get_yticklabels()]
    assert labels == ["failed", "1T", "2T", "3T", "4T", "5T", "6T", "many"]
    assert "distinct" in cbar.ax.get_ylabel()


def test_a_period_counts_only_when_recorded_twice() -> None:
    # SECTIONS = 24 recorded periods: 12T shows twice, 13T does not (it may be chaos)
    ds = sweep_dataset(
        np.array([[12, 13]]), {"omega": np.array([1.0]), "xi": np.array([0.03, 0.05])}
    )
    counts = distinct_counts(ds, max_count=16)
    assert counts.values.tolist() == [[12, 17]]


def test_sweep_figure_picks_diagram_or_maps() -> None:
    ds = sweep_dataset(np.array([1, 2, 1]), {"omega": np.array([1.0, 1.5, 2.0])})
    fig = sweep_figure(ds)
    (ax,) = fig.axes
    assert n_dots(ax) == 4

    periods = np.ones((2, 3, 2), int)
    ds = sweep_dataset(
        periods,
        {
            "xi": np.array([0.03, 0.05]),
            "omega": np.array([1.0, 1.5, 2.0]),
            "torque.input": np.array([500.0, 1000.0]),
        },
        family="xi",
    )
    fig = sweep_figure(ds)
    maps = [a for a in fig.axes if a.get_visible() and a.get_label() != "<colorbar>"]
    assert len(maps) == 2
    assert maps[0].get_title(loc="left") == r"(a) $\xi$ = 0.03"
    assert maps[0].get_ylabel() == r"$T_D$ [N m]"
    with pytest.raises(ParameterError, match="select"):
        distinct_map(ds)


# --------------------------------------------------------------------------- a real sweep
def test_linear_regime_sweep_gives_one_dot_per_omega() -> None:
    """Backlash oscillator pressed into contact (F_m ≫ F_a): linear, so 1T at every Ω."""
    system = gc.backlash_oscillator(0.8, zeta=0.3, b=1.0, f_mean=0.5, f_alt=0.05, omega_power=0)
    omega = np.linspace(0.5, 2.5, 8)
    ds = gc.bifurcation(
        system,
        {"omega": omega},
        observe=("x", "x_dot"),
        transient_periods=20,
        periods=10,
        progress=False,
    )
    assert np.all(ds.status.values == 0)
    ax = bifurcation(ds, var="x", clearance_lines=True)
    assert n_dots(ax) == omega.size
    np.testing.assert_array_equal(np.sort(ax.collections[0].get_offsets()[:, 0]), omega)
    assert ax.get_ylabel() == "$x$"
    # clearance b of the oscillator from the store's attributes
    assert sorted(float(line.get_ydata()[0]) for line in gid_lines(ax, "clearance")) == [-1, 1]
    # default variable of a reference-system store: its first observed one
    assert bifurcation(ds).get_ylabel() == "$x$"


def test_axes_follow_an_attractor_beside_the_backlash() -> None:
    """An attractor spanning X̄ ∈ [2.8, 3.25] beside b̄_sp = 3: the y limits lie within 10 % of
    the data range; +b̄ (inside) is drawn, −b̄ (far outside) is an edge note, not a limit."""
    from gearchaos.plot.units import CLEARANCE_NOTE_GID

    ds = sweep_dataset(np.zeros(5, int), {"omega": np.linspace(1.0, 2.0, 5)})
    v = ds["delta_sp"].values
    ds["delta_sp"] = (ds["delta_sp"].dims, 2.8 + 0.45 * (v - v.min()) / np.ptp(v))
    ax = bifurcation(ds, clearance_lines=True)
    lo, hi = ax.get_ylim()
    assert lo <= 2.8 and hi >= 3.25
    assert lo >= 2.8 - 0.045 and hi <= 3.25 + 0.045
    notes = [t.get_text() for t in ax.texts if t.get_gid() == CLEARANCE_NOTE_GID]
    assert len(notes) == 1 and "−" in notes[0] and "3" in notes[0]
    assert sorted(float(line.get_ydata()[0]) for line in gid_lines(ax, "clearance")) == [-3, 3]


def test_figures_name_the_gear_set_not_the_models_record() -> None:
    """One name in every figure title: the gear set's (``sheng2016``) where the store or file
    carries one, else the model's; never the record ``planetary[sheng2016]``."""
    from gearchaos.gearset.io import to_toml
    from gearchaos.plot._common import subject

    gs = gc.preset("sheng2016-v1")
    assert subject({"model": "planetary", "gearset_toml": to_toml(gs)}) == "sheng2016-v1"
    assert subject({"model": "planetary"}, gs) == "sheng2016-v1"
    assert subject({"model": "backlash_oscillator", "gearset_toml": ""}) == "backlash_oscillator"


def test_a_user_models_variable_is_drawn_with_the_models_symbol() -> None:
    """A store of a user model names its variable by the model's ``symbols`` (the optional
    member of the model contract): δ̄ of the Kahraman–Singh example, not the name ``delta``
    (docs/howto/own-model.png); a model without symbols, or one that can no longer be built,
    keeps the upright name."""
    from gearchaos.model.loading import load_model_class, model_reference

    cls = load_model_class("examples/kahraman_singh_1991.py:KahramanSingh1991")
    ds = sweep_dataset(np.array([1, 2, 1]), {"omega": np.array([1.9, 2.0, 2.1])})
    ds = ds.rename({"delta_sp": "delta", "delta_sp_dot": "delta_dot"}).isel(planet=0)
    ds.attrs = {k: v for k, v in ds.attrs.items() if not k.startswith(("gearset", "clearance"))}
    ds.attrs.update(model="kahraman_singh_1991", **model_reference(cls()))
    fig = bifurcation_figure(ds, var="delta")
    assert fig.axes[0].get_ylabel() == r"$\bar{\delta}$"
    ds.attrs["model_class"] = "no/such/file.py:Model"
    assert bifurcation_figure(ds, var="delta").axes[0].get_ylabel() == r"$\mathrm{delta}$"


def test_a_user_models_parameters_are_named_by_its_parameter_symbols() -> None:
    """A sweep of a user model's own parameter (ζ_h of the Kahraman–Singh example, three
    points, a few periods) labels its x axis and writes the title's ``at …`` line with the
    model's ``parameter_symbols``, not the field names (``zeta_h``), and lists parameters
    that no reference system shares (μ_p, κ_g, b̄_h), over two lines (one ran past both
    edges of docs/howto/own-model.png)."""
    from gearchaos.model import System
    from gearchaos.model.loading import load_model_class

    cls = load_model_class("examples/kahraman_singh_1991.py:KahramanSingh1991")
    sweep = gc.bifurcation(
        System(cls(), 2.5), "zeta_h=0.04:0.06:3", transient_periods=2, periods=2, progress=False
    )
    fig = bifurcation_figure(sweep)
    assert [ax.get_xlabel() for ax in fig.axes if ax.get_xlabel()] == [r"$\zeta_h$"]
    lines = fig.get_suptitle().split("\n")
    assert lines[1].startswith("at ") and "periods" in lines[-1]
    assert len(lines) == 4  # thirteen values: the at line broken in two, inside the figure
    at = " ".join(lines[1:-1])
    assert not re.search(r"(?<!\\)\b(zeta_|mu_|kappa_|b_h|eps|f_mean)", at)  # no field names
    assert r"$\zeta_h$" not in at  # the swept one is left out
    for shown in (r"$\zeta_p$ = 0.05", r"$\mu_p$ = 0.35", r"$\kappa_g$ = 1", r"$\bar{b}_h$ = 1"):
        assert shown in at
    assert r"$\bar{F}_m$ = 0.1" in at and r"$\varepsilon$ = 0.3" in at


def test_event_names_over_a_diagram_sit_beside_the_branch() -> None:
    """Over a bifurcation diagram an event's name goes to the side of its marker that the
    branch leaves free (docs/howto/own-model.png: "PD" sat on the curve)."""
    from figure_checks import labels_on_curves, steep_branch

    system = gc.backlash_oscillator(1.0, zeta=0.05, f_alt=0.1, f_mean=0.1)
    branch = gc.continuation(system, "omega=0.9:1.0", rtol=1e-8)
    ds = sweep_dataset(np.array([1, 2, 1, 1]), {"omega": np.array([1.0, 1.5, 2.0, 2.5])})
    steep = steep_branch(branch, "delta_sp", (1.4, 1.6), 3.0, 3.8, kind="period_doubling")
    fig = bifurcation_figure(ds, branches=[steep])
    assert [t.get_text() for t in fig.axes[0].texts if t.get_text() == "PD"] == ["PD"]
    assert labels_on_curves(fig, "branch:") == []
