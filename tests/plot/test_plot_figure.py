"""summary_figure and savefig."""

from __future__ import annotations

import pytest

import gearchaos as gc
from gearchaos.analysis import summarize
from gearchaos.errors import ParameterError
from gearchaos.plot import savefig, summary_figure


def test_summary_figure_png(planetary: gc.SimulationResult, tmp_path) -> None:
    fig = summary_figure(planetary)
    assert len(fig.axes) == 7  # 2×3 panels and the contact-force panel (issue 12)
    assert "hindawi2021" in fig.get_suptitle()
    text = " ".join(t.get_text() for t in fig.axes[5].texts)
    assert "1T" in text and "sun–planet" in text and "status: ok" in text
    path = savefig(fig, tmp_path / "summary.png")
    data = (tmp_path / "summary.png").read_bytes()
    assert path.endswith("summary.png")
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(data) > 10_000
    assert not (tmp_path / "summary.png.partial").exists()


@pytest.mark.parametrize(("suffix", "magic"), [(".pdf", b"%PDF"), (".svg", b"<?xml")])
def test_savefig_formats(
    planetary: gc.SimulationResult, tmp_path, suffix: str, magic: bytes
) -> None:
    fig = summary_figure(planetary, summarize(planetary))
    p = tmp_path / f"s{suffix}"
    savefig(fig, p)
    assert p.read_bytes().startswith(magic)


def test_savefig_rejects_unknown_suffix(planetary: gc.SimulationResult, tmp_path) -> None:
    fig = summary_figure(planetary)
    with pytest.raises(ParameterError, match="png"):
        savefig(fig, tmp_path / "s.jpg")


def test_summary_figure_with_one_sample_per_period(tmp_path) -> None:
    r = gc.simulate(
        gc.preset("hindawi2021"),
        omega=0.5,
        transient_periods=20,
        periods=20,
        samples_per_period=1,
    )
    fig = summary_figure(r)
    assert any("samples_per_period" in t.get_text() for t in fig.axes[3].texts)
    savefig(fig, tmp_path / "one.png")


def test_summary_figure_of_a_reference_system(oscillator: gc.SimulationResult, tmp_path) -> None:
    """No sun coordinates: no empty sun-orbit panel saying so (issue 35), the text in its
    place; the oscillator's mesh force panel stays."""
    fig = summary_figure(oscillator)
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert not any("sun coordinates" in t for t in texts)
    assert [ax.get_title() for ax in fig.axes if ax.get_title().startswith("sun")] == []
    assert any(ax.get_title().startswith("mesh contact forces") for ax in fig.axes)
    savefig(fig, tmp_path / "osc.png")
