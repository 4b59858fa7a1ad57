"""Contact regime against speed (issue 35, item 3): ``gearchaos plot STORE --contact [--table]``.

* The ranges of :func:`gearchaos.sweep.contact.contact_ranges` are the regimes of the stored
  minimum deflections against the gear set's half backlashes (δ_min > b̄: none, −b̄ ≤ δ_min ≤ b̄:
  single-sided, below: double-sided), computed here independently per point and planet; they
  cover every swept value once per mesh and direction, neighbours differ, and each range's
  peak force is the largest tracked contact force of its points.
* The figure's bands are those ranges, one row per mesh and direction and one per planet
  where the planets differ; its top axis is the sun speed n_s = 60 f_m (z_s + z_r)/(z_s z_r)
  with f_m = Ω ω_n/2π and ω_n = √(k_m,sp/m_e) from the gear set's masses and inertias, and
  its static mesh force in newtons is T_D/(N r_bs).
* The command prints the table and refuses options that do not apply.
"""

from __future__ import annotations

import itertools
import math
import re

import numpy as np
import pytest
from figure_checks import draw
from typer.testing import CliRunner

import gearchaos as gc
from gearchaos.cli import app
from gearchaos.plot.contact import CONTACT_BAND_GID, REGIME_CODES, contact_figure
from gearchaos.plot.impact import IMPACT_COLOURS
from gearchaos.sweep.contact import contact_ranges

REGIME = {0: "none", 1: "single_sided", 2: "double_sided"}


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory):
    path = tmp_path_factory.mktemp("contact") / "resp.zarr"
    gc.response(
        gc.preset("sheng2016-v1"), "omega=0.5:3.5:7", transient_periods=20, periods=16,
        progress=False, store=path,
    )  # fmt: skip
    return path


def _expected(ds, key: str, b: float) -> np.ndarray:
    """Regime code per (direction, Ω, planet) from δ_min and b̄, independently of the store's
    classification."""
    dmin = ds[f"delta_{key}_min"].transpose("direction", "omega", "planet_all").values
    return np.where(dmin > b, 0, np.where(dmin >= -b, 1, 2))


def test_ranges_are_the_regimes_of_the_stored_deflections(store) -> None:
    ds = gc.open_sweep(store)
    gs = gc.preset("sheng2016-v1")
    omega = ds.omega.values
    ranges = contact_ranges(ds)
    for key, mesh, b in (
        ("sp", "sun_planet", gs.backlash.sun_planet),
        ("rp", "planet_ring", gs.backlash.planet_ring),
    ):
        want = _expected(ds, key, b)
        force = ds[f"contact_force_{key}_max"].transpose("direction", "omega", "planet_all")
        for d, direction in enumerate(("up", "down")):
            mine = [r for r in ranges if (r.mesh, r.direction) == (mesh, direction)]
            covered = [w for r in mine for w in omega if r.start <= w <= r.stop]
            assert covered == list(omega)  # every value once, in increasing order
            assert sum(r.points for r in mine) == omega.size
            for a, c in itertools.pairwise(mine):
                assert a.regimes != c.regimes  # maximal runs
            for r in mine:
                at = (omega >= r.start) & (omega <= r.stop)
                for codes in want[d][at]:
                    assert r.regimes == tuple(REGIME[int(c)] for c in codes)
                peak = float(force.values[d][at].max())
                assert r.peak_force == pytest.approx(peak, rel=1e-12)
    # the physics of the seed's set: no separation far below the first resonance, rattle
    # (single-sided impact) at Ω = 2, where the diagram is chaotic
    first = next(r for r in ranges if r.mesh == "sun_planet" and r.direction == "up")
    assert first.start == 0.5 and first.regime == "none"
    at2 = [r for r in ranges if r.start <= 2.0 <= r.stop and r.mesh == "sun_planet"]
    assert {r.regime for r in at2} == {"single_sided"}


def _bars(ax) -> dict[str, list[tuple[float, float, float]]]:
    """Regime → (x0, x1, row bottom) of every bar of the bands."""
    out: dict[str, list[tuple[float, float, float]]] = {}
    for coll in ax.collections:
        gid = coll.get_gid() or ""
        if not gid.startswith(CONTACT_BAND_GID + ":"):
            continue
        for path in coll.get_paths():
            v = path.vertices
            out.setdefault(gid.split(":", 1)[1], []).append(
                (float(v[:, 0].min()), float(v[:, 0].max()), float(v[:, 1].min()))
            )
    return out


def _omega_n(gs) -> float:
    """ω_n = √(k_m,sp/m_e), from the gear set's own numbers (MODEL.md §2)."""
    cos = math.cos(math.radians(gs.geometry.pressure_angle_sun))
    r_bs = gs.geometry.module * gs.teeth.sun / 2 * cos
    r_bp = gs.geometry.module * gs.teeth.planet / 2 * cos
    ms, mp = gs.inertia.sun / r_bs**2, gs.inertia.planet / r_bp**2
    return math.sqrt(gs.stiffness.sun_planet_mean * (ms + mp) / (ms * mp))


def test_figure_bands_speed_axis_and_forces(store) -> None:
    ds = gc.open_sweep(store)
    gs = gc.preset("sheng2016-v1")
    fig = contact_figure(ds)
    draw(fig)
    top, band = fig.axes[0], fig.axes[1]
    labels = [t.get_text() for t in band.get_yticklabels()]
    assert labels == ["sun–planet ↑", "sun–planet ↓", "planet–ring ↑", "planet–ring ↓"]
    bars = _bars(band)
    omega = ds.omega.values
    half = 0.5 * (omega[1] - omega[0])
    want = _expected(ds, "sp", gs.backlash.sun_planet).max(axis=-1)  # planets agree here
    for d, row in enumerate((3, 2)):  # rows from the top: up is drawn at y = 3
        for k, w in enumerate(omega):
            regime = REGIME[int(want[d][k])]
            hit = [b for b in bars[regime] if b[0] < w < b[1] and abs(b[2] - row - 0.08) < 1e-9]
            assert len(hit) == 1, (w, regime)
            assert hit[0][0] <= w - half + 1e-12 or k == 0
    for regime in bars:
        for coll in band.collections:
            if coll.get_gid() == f"{CONTACT_BAND_GID}:{regime}":
                rgb = _rgb(IMPACT_COLOURS[REGIME_CODES[regime]])
                assert np.allclose(coll.get_facecolor()[0][:3], rgb)
    # the sun speed opposite Ω: n_s = 60 f_m (z_s + z_r)/(z_s z_r)
    (rpm_axis,) = [c for c in top.child_axes if c.get_xlabel()]
    z_s, z_r = gs.teeth.sun, gs.teeth.ring
    per_omega = 60 * _omega_n(gs) / (2 * math.pi) * (z_s + z_r) / (z_s * z_r)
    np.testing.assert_allclose(
        rpm_axis.get_xlim(), np.multiply(top.get_xlim(), per_omega), rtol=1e-6
    )
    # newtons opposite the dimensionless force: the static line is T_D/(N r_bs)
    (newton,) = [c for c in top.child_axes if c.get_ylabel()]
    assert newton.get_ylabel() == "$F^c$ [N]"
    (static,) = [ln for ln in top.get_lines() if ln.get_label() == "static mesh force"]
    r_bs = gs.geometry.module * z_s / 2 * math.cos(math.radians(gs.geometry.pressure_angle_sun))
    static_n = gs.torque.input / (gs.geometry.planets * r_bs)
    scale = np.diff(newton.get_ylim())[0] / np.diff(top.get_ylim())[0]
    np.testing.assert_allclose(static.get_ydata() * scale, static_n, rtol=1e-6)


def _rgb(colour: str) -> tuple[float, float, float]:
    from matplotlib.colors import to_rgb

    return to_rgb(colour)


def test_planets_that_differ_get_a_band_each_and_words_in_the_table(store) -> None:
    ds = gc.open_sweep(store).load()
    codes = ds["contact_sp"].values.copy()
    codes[0, 3, 1] = 2  # planet 2 hits the back flank at Ω = 2 sweeping up
    ds["contact_sp"] = ds["contact_sp"].copy(data=codes)
    ranges = contact_ranges(ds)
    odd = [r for r in ranges if r.mesh == "sun_planet" and r.direction == "up" and not r.uniform]
    assert [(r.start, r.stop, r.regime) for r in odd] == [(2.0, 2.0, "double_sided")]
    assert odd[0].describe() == "double-sided: planet 2; single-sided: 1, 3, 4, 5"
    fig = contact_figure(ds)
    labels = [t.get_text() for t in fig.axes[1].get_yticklabels()]
    assert labels[:6] == [f"sun–planet {p} ↑" for p in range(1, 6)] + ["sun–planet ↓"]
    assert len(labels) == 8  # five planets up, then one band each
    double = _bars(fig.axes[1])["double_sided"]
    assert [(b[0] < 2.0 < b[1], round(b[2], 2)) for b in double] == [(True, 6.08)]  # 2nd row


def test_a_sweep_without_forces_draws_the_bands_under_the_speed_axis(store) -> None:
    ds = gc.open_sweep(store)
    plain = ds.drop_vars([v for v in ds.data_vars if v.startswith(("force_", "load_factor_"))])
    fig = contact_figure(plain)
    (ax,) = fig.axes[:1]
    assert [c.get_xlabel() for c in ax.child_axes] == ["sun speed [rpm]"]
    assert all(r.peak_force is None for r in contact_ranges(plain))


def test_two_swept_parameters_are_refused(tmp_path) -> None:
    ds = gc.bifurcation(
        gc.preset("sheng2016-v1"), ["omega=0.5:1:2", "xi=0.03:0.05:2"], transient_periods=2,
        periods=2, progress=False,
    )  # fmt: skip
    with pytest.raises(gc.ParameterError, match="needs one swept dimension"):
        contact_figure(ds)


def test_command_writes_the_figure_and_prints_the_ranges(store, tmp_path) -> None:
    out = tmp_path / "rattle.png"
    args = ["plot", str(store), "--contact", "--table", "-o", str(out)]
    result = CliRunner().invoke(app, args, env={"COLUMNS": "120"})
    assert result.exit_code == 0, result.output
    assert out.stat().st_size > 10_000
    rows = [ln for ln in result.output.splitlines() if ln.startswith("│")]
    ranges = contact_ranges(gc.open_sweep(store))
    assert len(rows) == len(ranges)
    header = next(ln for ln in result.output.splitlines() if ln.startswith("┃"))
    assert "sun speed [rpm]" in header and "peak force [N]" in header
    gs = gc.preset("sheng2016-v1")
    for line, r in zip(rows, ranges, strict=True):
        cells = [c.strip() for c in line.strip("│").split("│")]
        assert cells[0] == r.mesh.replace("_", "–") and cells[1] == r.direction
        assert cells[4] == r.describe()
        lo = float(re.split(r" … ", cells[2])[0])
        assert lo == pytest.approx(gs.sun_speed_rpm(r.start), abs=0.5)


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--table"], "--table prints the contact ranges: it needs --contact"),
        (["--contact", "--var", "delta_rp"], "--var does not apply"),
        (["--contact", "--impact", "sp"], "--impact does not apply"),
    ],
)
def test_options_that_do_not_apply_are_refused(store, tmp_path, extra, message) -> None:
    args = ["plot", str(store), *extra, "-o", str(tmp_path / "x.png")]
    result = CliRunner().invoke(app, args, env={"COLUMNS": "200"})
    assert result.exit_code == 2
    assert message in result.output
    assert not (tmp_path / "x.png").exists()
