"""Poincaré galleries: one titled map per value, optional phase and spectrum rows, the runner."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure

import gearchaos as gc
from gearchaos.errors import ParameterError
from gearchaos.paper.galleries import GALLERIES, ROW_KEYS, run_gallery
from gearchaos.plot import poincare_gallery
from gearchaos.plot.gallery import gallery_title, parse_extras
from gearchaos.plot.regimes import REGIME_COLOURS


def summary(motion: str, lle: float | None, status: str = "ok") -> dict:
    return {"motion": motion, "lle": lle, "status": status, "distinct_section_points": 1}


def map_axes(fig: Figure) -> list:
    """The visible Poincaré panels: those titled ``(a) …``, ``(b) …``."""
    return [ax for ax in fig.axes if ax.get_visible() and ax.get_title(loc="left").startswith("(")]


def test_title_names_value_label_and_exponent() -> None:
    assert gallery_title("omega", 1.875, summary("2T", -0.0123)) == (
        r"$\Omega$ = 1.875 · 2T · $\lambda_1$ = −0.012"
    )
    assert gallery_title("backlash.sun_planet", 3, summary("chaos", 0.068)) == (
        r"$\bar b_{sp}$ = 3 · chaos · $\lambda_1$ = 0.068"
    )
    assert gallery_title("omega", 1.5, summary("QP", None)) == r"$\Omega$ = 1.5 · QP"


def test_extras_are_checked() -> None:
    assert parse_extras("spectrum,phase") == ("phase", "spectrum")
    assert parse_extras(None) == ()
    with pytest.raises(ParameterError, match="phase, spectrum"):
        parse_extras("phase,orbit")


def test_one_panel_per_value_titled_and_framed(planetary: gc.SimulationResult) -> None:
    results = [planetary] * 5
    sums = [
        summary("1T", -0.013),
        summary("2T", -0.02),
        summary("QP", 0.001),
        summary("chaos", 0.07),
        summary("1T", None, status="max_steps"),
    ]
    values = [0.5, 1.0, 1.5, 2.0, 2.5]
    fig = poincare_gallery(results, sums, param="omega", values=values)
    panels = map_axes(fig)
    assert len(panels) == 5
    titles = [ax.get_title(loc="left") for ax in panels]
    assert titles[0] == r"(a) $\Omega$ = 0.5 · 1T · $\lambda_1$ = −0.013"
    assert titles[3].startswith(r"(d) $\Omega$ = 2 · chaos")
    assert titles[4] == r"(e) $\Omega$ = 2.5 · failed"
    for ax, label in zip(panels, ["1T", "2T", "QP", "chaos", "failed"], strict=True):
        edge = ax.spines["left"].get_edgecolor()
        np.testing.assert_allclose(edge, to_rgba(REGIME_COLOURS[label]))
    # maps have the section points; the failed panel a message
    assert all(len(ax.collections) == 1 for ax in panels[:4])
    assert panels[4].texts and not panels[4].collections
    (legend,) = fig.legends
    assert [t.get_text() for t in legend.get_texts()] == ["1T", "2T", "QP", "chaos", "failed"]


def test_phase_and_spectrum_rows(planetary: gc.SimulationResult) -> None:
    fig = poincare_gallery(
        [planetary, planetary],
        [summary("1T", -0.01), summary("1T", -0.01)],
        param="omega",
        values=[0.5, 0.5],
        with_="phase,spectrum",
    )
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert len(visible) == 6  # 2 values x (map, phase, spectrum)
    titles = [ax.get_title(loc="left") for ax in visible]
    assert titles.count("phase portrait") == 2
    assert titles.count("amplitude spectrum") == 2
    spectra = [ax for ax in visible if ax.get_title(loc="left") == "amplitude spectrum"]
    assert all(ax.get_yscale() == "log" for ax in spectra)


def test_argument_checks(planetary: gc.SimulationResult) -> None:
    with pytest.raises(ParameterError, match="one value per result"):
        poincare_gallery([planetary], [summary("1T", None)], param="omega", values=[1, 2])
    with pytest.raises(ParameterError, match="one entry per result"):
        poincare_gallery([planetary], [], param="omega", values=[1])
    with pytest.raises(ParameterError, match="at least one"):
        poincare_gallery([], [], param="omega", values=[])


def test_runner_labels_every_value_of_a_reference_system() -> None:
    # backlash oscillator held in contact by its mean load (x ≈ b + F_m, |x - b - F_m| < F_m):
    # a linear oscillator, 1T, both exponents -zeta
    system = gc.backlash_oscillator(0.6, zeta=0.1, b=1.0, f_mean=2.0, f_alt=0.3, omega_power=0)
    fig, rows = run_gallery(
        system, "omega", [0.5, 0.8], transient_periods=30, periods=40, progress=False
    )
    assert len(map_axes(fig)) == 2
    assert [list(r) for r in rows] == [list(ROW_KEYS)] * 2
    assert [r["value"] for r in rows] == [0.5, 0.8]
    for r in rows:
        assert r["motion"] == "1T"
        assert r["lle"] == pytest.approx(-0.1, abs=1e-3)
        assert r["status"] == "ok"
        # confirmed by the multipliers: λ₁ = ln max|μ| / T exactly, e^(−ζT) for this system
        assert r["evidence"] == "floquet" and r["lle_error"] == 0
        T = 2 * math.pi / r["value"]
        assert r["max_multiplier"] == pytest.approx(math.exp(-0.1 * T), rel=1e-3)


def test_runner_title_writes_fixed_values_with_symbols_and_a_true_minus() -> None:
    """The title's "at …" line is written by the figures' shared helper: symbols, and a
    negative value with U+2212 (a hyphen outside mathtext reads as a dash)."""
    system = gc.duffing(1.2, delta=0.25, alpha=-1.0, beta=1.0, gamma=0.1)
    fig, _ = run_gallery(
        system, "omega", [1.2], alpha=-1.0, transient_periods=5, periods=8, progress=False
    )
    title = fig._suptitle.get_text()
    assert "\nat $\\alpha$ = \N{MINUS SIGN}1" in title, title
    assert "= -1" not in title


def test_runner_checks_every_point_before_running() -> None:
    gs = gc.preset("hindawi2021")
    with pytest.raises(ParameterError, match=r"backlash\.sun_planet"):
        run_gallery(gs, "backlash.sun_planet", [1.0, -2.0], omega=1.5, progress=False)
    with pytest.raises(ParameterError, match="omega"):
        run_gallery(gs, "backlash.sun_planet", [1.0], progress=False)
    for fixed in ({"omega": 1.5}, {"params": {"omega": 1.5}}):
        with pytest.raises(ParameterError, match="omega is both varied and fixed") as info:
            run_gallery(gs, "omega", [1.0], progress=False, **fixed)
        assert info.value.name == "omega"
    with pytest.warns(DeprecationWarning, match=r"run_gallery\(fixed=\.\.\.\).*use params="):
        with pytest.raises(ParameterError, match="both varied and fixed"):
            run_gallery(gs, "omega", [1.0], fixed={"omega": 1.5}, progress=False)


def test_runner_speaks_the_front_doors_vocabulary() -> None:
    """Parameters by name or in params=, settings= and settings by name (issue 25); an unknown
    name is refused with the closest valid one, as by the sweeps; the old fixed= warns."""
    gs = gc.preset("hindawi2021")
    wrong = "unknown run_gallery option 'rtoll'; did you mean 'rtol'"
    with pytest.raises(ParameterError, match=wrong):
        run_gallery(gs, "xi", [0.05], omega=1.5, rtoll=1e-6, progress=False)
    with pytest.raises(ParameterError, match="'omgea'; did you mean 'omega'") as info:
        run_gallery(gs, "xi", [0.05], omgea=1.5, progress=False)
    assert info.value.name == "omgea"
    with pytest.raises(ParameterError, match="'planets'; did you mean 'planet'"):
        run_gallery(gs, "xi", [0.05], omega=1.5, planets=1, progress=False)
    with pytest.raises(ParameterError, match="given twice") as info:
        run_gallery(gs, "xi", [0.05], omega=1.5, params={"omega": 1.4}, progress=False)
    assert info.value.name == "omega"
    with pytest.raises(ParameterError, match=r"give params= only \(fixed= is its deprecated"):
        run_gallery(gs, "xi", [0.05], params={"omega": 1.5}, fixed={"omega": 1.5})
    with pytest.raises(ParameterError, match="fixed must be a mapping"):
        run_gallery(gs, "xi", [0.05], fixed=[("omega", 1.5)], progress=False)
    with pytest.raises(ParameterError, match="params must be a mapping"):
        run_gallery(gs, "xi", [0.05], params=[("omega", 1.5)], progress=False)
    with pytest.raises(ParameterError, match="settings must be a SolverSettings"):
        run_gallery(gs, "xi", [0.05], omega=1.5, settings={"rtol": 1e-8}, progress=False)


# --------------------------------------------------------------------------- recipes
# The values the seed's text names for its galleries (Sec. 3.1-3.3), and the fixed parameters
# of its captions.
SEED = {
    "fig5": (
        "omega",
        (1.35, 1.69, 1.696, 1.875, 1.926, 2.02, 2.45, 2.62, 3.03, 3.58),
        {"xi": 0.03, "backlash.sun_planet": 3, "backlash.planet_ring": 3.5},
    ),
    "fig7": (
        "backlash.sun_planet",
        (2.81, 2.85, 4.83),
        {"omega": 1.5, "xi": 0.05, "backlash.planet_ring": 3.5},
    ),
    "fig10": (
        "backlash.planet_ring",
        (1.9, 3.7, 4.41, 4.79, 4.84, 4.91, 5.39, 5.47, 5.55, 5.93, 6.0),
        {"omega": 1.5, "xi": 0.05, "backlash.sun_planet": 3},
    ),
}
RANGES = {"fig7": (1.0, 6.0), "fig10": (1.0, 9.0)}


@pytest.mark.parametrize("name", sorted(SEED))
def test_gallery_recipes_draw_the_values_the_seed_names(name: str) -> None:
    param, named, fixed = SEED[name]
    g = GALLERIES[name]
    assert g.param == param
    assert set(named) <= set(g.values)
    assert list(g.values) == sorted(g.values)
    for k, v in fixed.items():
        assert g.fixed[k] == v
    assert g.fixed["clearance.sun_bearing"] == 2
    if name in RANGES:
        lo, hi = RANGES[name]
        assert min(g.values) == lo and max(g.values) == hi


def test_titles_of_a_row_of_four_do_not_overlap(planetary: gc.SimulationResult) -> None:
    """Four panels in a row, each titled with the sun speed and λ₁ ± its error (the tutorial's
    gallery): no title reaches into its neighbour's, and the last stays inside the figure."""
    long = {"sun_speed_rpm": 4637.7, "lle_error": 0.00066, "motion": "QP", "lle": -0.0001769}
    sums = [{**summary("QP", -0.0001769), **long}] * 4
    fig = poincare_gallery(
        [planetary] * 4, sums, param="omega", values=[0.81, 0.88, 2.7, 3.02], with_="phase"
    )
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    titles = [ax._left_title for ax in map_axes(fig)]  # the artist of ax.set_title(loc="left")
    extents = [t.get_window_extent(renderer) for t in titles]
    assert len(extents) == 4
    for left, right in itertools.pairwise(extents):
        assert left.x1 < right.x0, (left, right)
    assert extents[-1].x1 <= fig.bbox.x1
