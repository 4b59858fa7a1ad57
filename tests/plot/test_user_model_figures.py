"""A model of one's own gets its own words, units and physical axes in the figures (issue 36,
item 2): the figures ask the model's capabilities (its quantities and scales, its symbols,
its contacts' names, the name of its period), never whether it is a gear set.

The model here is a two-stage train written outside the package: two backlash oscillators,
stage 1 and stage 2, whose deflections ``x_1``, ``x_2`` are lengths in units of b_0 = 20 µm
with ω_0 = 5000 rad/s (so a velocity unit is b_0 ω_0 = 0.1 m/s), contacts named ``stage1``
and ``stage2``, and a period called the tooth period. The expected axis factors are these
scales, written here, not read from the code.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any, ClassVar

import numba
import numpy as np
import pytest
from figure_checks import draw

import gearchaos as gc
from gearchaos.model import System
from gearchaos.model.contract import Contact, UserModel
from gearchaos.plot import figure_for, summary_figure
from gearchaos.sweep.result import SweepResult
from stage_scales import StageScales

LENGTH, OMEGA_0 = StageScales.length, StageScales.omega_n
#: Words, symbols and names of the planetary model that a figure of this model must not show.
PLANETARY = re.compile(r"planet|sun|_\{sp|_\{rp|sp1|\\bar\{X\}|mesh|b_c|gear set")


@numba.njit(cache=True)
def _stages_rhs(t, y, p, dydt, obs, level):  # pragma: no cover - compiled
    """Two backlash oscillators driven at Ω: x'' + 2ζx' + f(x; b_k) = 0.1 + 0.2 cos Ωτ."""
    for s in range(2):
        x, v = y[s], y[2 + s]
        b = p[2 + s]
        f = x - b if x > b else (x + b if x < -b else 0.0)
        dydt[s] = v
        dydt[2 + s] = -2.0 * p[1] * v - f + 0.1 + 0.2 * math.cos(p[0] * t)
        obs[s] = x
        obs[2 + s] = v


@dataclass(frozen=True)
class TwoStageTrain(UserModel):
    zeta: float = 0.05
    b_1: float = 1.0
    b_2: float = 0.5

    name = "two_stage_train"
    state_names = ("x_1", "x_2", "x_1_dot", "x_2_dot")
    obs_names = ("x_1", "x_2", "x_1_dot", "x_2_dot")
    n_track = 2
    rhs = _stages_rhs
    quantities: ClassVar[dict[str, str]] = {"x": "length", "x_dot": "velocity"}
    symbols: ClassVar[dict[str, Any]] = {"x": (r"\bar{q}_{%d}", r"q_{%d}/b_0", None, None)}
    parameter_symbols: ClassVar[dict[str, str]] = {"zeta": r"\zeta", "b_1": r"\bar{b}_1"}
    period_name = "tooth"
    member_name = "stage"
    default_observables = ("x", "x_dot")  # the group: x_1 first
    scales = StageScales()

    @property
    def contacts(self) -> tuple[Contact, ...]:
        return (Contact("stage1", 0, self.b_1), Contact("stage2", 1, self.b_2))

    @property
    def switch_widths(self) -> np.ndarray:
        return np.array([self.b_1, self.b_2])

    def pack(self, omega: float) -> np.ndarray:
        return np.array([omega, self.zeta, self.b_1, self.b_2])


def _axes(fig: Any) -> list[Any]:
    """Every Axes of ``fig`` with the secondary (physical) axes they carry."""
    out = []
    for ax in fig.axes:
        out += [ax, *ax.child_axes]
    return out


def _texts(fig: Any) -> list[str]:
    """Every text of ``fig``: titles, axis labels, texts and legend entries."""
    out = [t.get_text() for t in fig.texts]
    if fig._suptitle is not None:
        out.append(fig._suptitle.get_text())
    for ax in _axes(fig):
        out += [ax.title.get_text(), ax.xaxis.get_label_text(), ax.yaxis.get_label_text()]
        out += [t.get_text() for t in ax.texts]
        legend = ax.get_legend()
        if legend is not None:
            out += [t.get_text() for t in legend.get_texts()]
    return [t for t in out if t]


def _secondaries(ax: Any) -> dict[str, float]:
    """The secondary (physical) axes of ``ax``: label → physical value per unit of the
    primary axis."""
    out = {}
    for sec in ax.child_axes:
        axis = sec.yaxis if sec._orientation == "y" else sec.xaxis
        forward = sec._functions[0]
        out[axis.get_label_text()] = float(
            forward(np.array([1.0]))[0] - forward(np.array([0.0]))[0]
        )
    return out


@pytest.fixture(scope="module")
def result() -> gc.SimulationResult:
    return gc.simulate(
        System(TwoStageTrain(), 1.2), transient_periods=20, periods=20, samples_per_period=32
    )


def test_summary_figure_names_the_model_its_stages_and_its_units(result) -> None:
    fig = summary_figure(result)
    draw(fig)
    texts = _texts(fig)
    panel = next(t for t in texts if t.startswith("model: "))
    lines = panel.splitlines()
    assert lines[0] == "model: two_stage_train"
    # the contact regimes named by the model's contacts (not ": single, single")
    regimes = [ln.strip() for ln in lines if ln.startswith("   ")]
    assert [r.split(":")[0] for r in regimes] == ["stage1", "stage2"], panel
    assert all(r.split(": ")[1] in ("none", "single", "double", "?") for r in regimes)
    # the variable's symbol and definition are the model's
    assert any(r"\bar{q}_{1} = q_{1}/b_0" in t for t in texts), texts
    assert any("tooth periods" in t for t in texts), texts
    # physical axes from the model's quantities and scales: x̄ in µm, x̄' in mm/s
    history = next(ax for ax in fig.axes if ax.get_title().startswith("time history"))
    period_ms = 2e3 * math.pi / (1.2 * OMEGA_0)  # one forcing period at Ω = 1.2
    assert _secondaries(history) == pytest.approx({"[µm]": LENGTH * 1e6, "t [ms]": period_ms})
    phase = next(ax for ax in fig.axes if ax.get_title().startswith("phase portrait"))
    assert _secondaries(phase) == pytest.approx({"[µm]": LENGTH * 1e6, "[mm/s]": 0.1 * 1e3})
    # the spectrum in multiples of the model's period's frequency, in Hz opposite
    spec = next(ax for ax in fig.axes if ax.get_title().startswith("amplitude spectrum"))
    assert "multiples of the tooth frequency" in spec.get_xlabel()
    hz = 1.2 * OMEGA_0 / (2 * math.pi)  # f = Ω ω_0/2π
    assert _secondaries(spec) == pytest.approx({"frequency [Hz]": hz})
    for text in texts:
        assert not PLANETARY.search(text), text


@pytest.fixture(scope="module")
def store(tmp_path_factory) -> SweepResult:
    path = tmp_path_factory.mktemp("two_stage") / "sweep.zarr"
    gc.bifurcation(
        System(TwoStageTrain(), 1.0), "omega=0.8:1.2:5", transient_periods=30, periods=8,
        progress=False, store=path,
    )  # fmt: skip
    return SweepResult.open(path)


def test_the_explorers_point_figure_speaks_the_models_words(result) -> None:
    fig = figure_for(result, panels="point")
    draw(fig)
    texts = _texts(fig)
    assert "amplitude spectrum (tooth harmonics labelled)" in texts
    assert "two_stage_train tracks no contact forces" in texts
    history = next(ax for ax in fig.axes if ax.get_title() == "time history")
    assert _secondaries(history)["[µm]"] == pytest.approx(LENGTH * 1e6)
    for text in texts:
        assert not PLANETARY.search(text), text


def test_a_sweep_of_the_model_gets_its_symbols_and_physical_axes(store) -> None:
    fig = figure_for(store)
    draw(fig)
    texts = _texts(fig)
    assert any(t.startswith("two_stage_train") for t in texts), texts
    panel = next(ax for ax in fig.axes if ax.child_axes)
    assert _secondaries(panel) == pytest.approx({"[µm]": LENGTH * 1e6})
    assert any(r"\zeta" in t for t in texts), texts  # the fixed ζ by the model's symbol
    for text in texts:
        assert not PLANETARY.search(text), text


def test_a_branch_of_the_model_gets_its_physical_axes(tmp_path) -> None:
    path = tmp_path / "branch.nc"
    gc.continuation(System(TwoStageTrain(), 0.8), "omega=0.8:1.0", store=path)
    from gearchaos.dynamics.continuation.cascade import open_cascade

    fig = figure_for(list(open_cascade(path)))
    draw(fig)
    (ax,) = [a for a in fig.axes if a.get_xlabel()]
    assert _secondaries(ax) == pytest.approx({"[µm]": LENGTH * 1e6})
    assert fig._suptitle.get_text().startswith("two_stage_train: ")
    for text in _texts(fig):
        assert not PLANETARY.search(text), text


def test_spectrum_sidebands_come_from_the_model() -> None:
    """A gear set with eccentricities gets sidebands h ± 1/z_s around the mesh harmonics
    (the sun's speed relative to the carrier is f_m/z_s); the two-stage train, whose forcing
    has no such modulation, gets none."""
    from gearchaos.plot.timeseries import HARMONIC_GID

    gs = gc.preset("hindawi2021").evolve({"eccentricity.sun": 3e-6})
    side = 1.0 / gs.teeth.sun  # z_s, from the gear set's numbers
    with pytest.warns(UserWarning, match="non-zero eccentricity"):
        eccentric = gc.simulate(gs, omega=0.5, transient_periods=5, periods=8)
    ax = gc.plot.spectrum(eccentric, max_harmonic=3.0)
    lines = sorted(
        float(line.get_xdata()[0])
        for line in ax.lines
        if line.get_gid() == HARMONIC_GID and line.get_linestyle() == ":"
    )
    expected = sorted(r for h in (1, 2, 3) for r in (h - side, h + side) if r <= 3.0)
    assert lines == pytest.approx(expected)
    plain = gc.simulate(System(TwoStageTrain(), 1.2), transient_periods=5, periods=8)
    ax = gc.plot.spectrum(plain, max_harmonic=3.0)
    assert not [ln for ln in ax.lines if ln.get_linestyle() == ":"]


def test_time_axes_count_the_models_declared_period() -> None:
    """A model whose forcing repeats after T = 5·2π/Ω (stages at Ω and 3Ω/5) is drawn in its
    own periods: the time axis is τ/T, the section points fall on whole periods, and one
    period lasts T/ω_0 = 5·2π/(Ω ω_0) on the axis in ms (not 2π/(Ω ω_0))."""
    from two_frequency_train import PERIOD_FACTOR, TwoFrequencyTrain

    omega, s = 1.2, 16
    res = gc.simulate(
        System(TwoFrequencyTrain(), omega), transient_periods=6, periods=4, samples_per_period=s
    )
    period = PERIOD_FACTOR * 2 * math.pi / omega  # T in units of τ, from the model's forcing
    ax = gc.plot.time_history(res, "x", periods=4)
    (line,) = [ln for ln in ax.lines if ln.get_label() == r"$\bar{q}_{1}$"]
    np.testing.assert_allclose(line.get_xdata(), res.tau / period, rtol=1e-12)
    # the recorded window: 4 periods after a transient of 6, sampled s times per period
    assert line.get_xdata()[0] == pytest.approx(6.0) and line.get_xdata()[-1] == pytest.approx(
        10.0 - 1.0 / s
    )
    (points,) = [ln for ln in ax.lines if ln.get_label() == "section points"]
    np.testing.assert_allclose(points.get_xdata(), [6.0, 7.0, 8.0, 9.0], rtol=1e-12)
    ms = PERIOD_FACTOR * 2e3 * math.pi / (omega * OMEGA_0)  # one period T/ω_0 in ms
    assert _secondaries(ax)["t [ms]"] == pytest.approx(ms)
    assert "train periods" in ax.get_xlabel()
    fig = summary_figure(res)
    draw(fig)
    for text in _texts(fig):
        assert not PLANETARY.search(text), text


def test_the_spectrum_counts_the_models_declared_period() -> None:
    """The two-frequency train (stage 1 forced at Ω, stage 2 at 3Ω/5, T = 5·2π/Ω) has its
    spectrum in multiples of its period's frequency 2π/T = Ω/5, as the axis says: the line of
    stage 1 lies at 5 (Ω = 5·2π/T), labelled Ω, and the line of stage 2 at 3 (3Ω/5), labelled
    3Ω/5, each at the frequency in Hz that Ω ω_0/2π gives. Each line's height is the amplitude
    of a cosine fitted to the record at that frequency."""
    from gearchaos.plot.timeseries import HARMONIC_GID
    from two_frequency_train import PERIOD_FACTOR, TwoFrequencyTrain

    omega = 0.5  # both stages settle on their forcing's period (at 1.2 stage 1 halves it)
    res = gc.simulate(
        System(TwoFrequencyTrain(), omega), transient_periods=40, periods=8, samples_per_period=64
    )
    hz = omega * OMEGA_0 / (2 * math.pi)  # the frequency of Ω in Hz
    for var, line_at, forced in (("x_1", 5.0, omega), ("x_2", 3.0, 0.6 * omega)):
        ax = gc.plot.spectrum(res, var, max_harmonic=6.0)
        assert "multiples of the train frequency" in ax.get_xlabel()
        assert r"2\pi/T = \Omega/5" in ax.get_xlabel()
        ratio, amp = ax.get_lines()[0].get_data()
        k = int(np.argmax(amp))
        assert ratio[k] == pytest.approx(line_at)
        assert ratio[k] == pytest.approx(forced * PERIOD_FACTOR / omega)
        # the amplitude at the forced frequency, by least squares on the record itself
        tau, x = res.tau, res.series(var)
        basis = np.column_stack([np.cos(forced * tau), np.sin(forced * tau), np.ones_like(tau)])
        coef = np.linalg.lstsq(basis, x, rcond=None)[0]
        assert amp[k] == pytest.approx(math.hypot(coef[0], coef[1]), rel=1e-6)
        labels = {
            round(t.get_position()[0]): t.get_text()
            for t in ax.texts
            if t.get_gid() == HARMONIC_GID
        }
        assert labels[3] == rf"$3\Omega/5$ = {3 * hz / PERIOD_FACTOR:.0f} Hz"
        assert labels[5] == rf"$\Omega$ = {hz:.0f} Hz"
        assert _secondaries(ax) == pytest.approx({"frequency [Hz]": hz / PERIOD_FACTOR})
