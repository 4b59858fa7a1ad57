"""classify_motion and friends: labels of synthetic attractors whose nature is known.

Periodic sequences are built periodic, the irrational rotation is quasi-periodic, the logistic
map at r = 4 and the Hénon map are chaotic; disagreement is provoked by handing the classifier
an LLE that contradicts the sequence.
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np
import pytest
from reference_maps import henon, logistic, rotation

from gearchaos.analysis.classify import (
    LLE_C,
    MotionClass,
    classify_motion,
    classify_sections,
    lle_threshold_for,
    regime_table,
    sort_labels,
    spectral_broadband,
)
from gearchaos.errors import ParameterError

T = 2 * math.pi / 1.5  # forcing period at Ω = 1.5
RUN: dict[str, Any] = {"run_periods": 200, "forcing_period": T}
THETA = LLE_C / (200 * T)


def cycle(n: int, m: int, noise: float = 1e-6, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    a = 2 * math.pi * (np.arange(m) % n) / n
    return np.column_stack([np.cos(a), 0.5 * np.sin(a)]) + noise * rng.uniform(-1, 1, (m, 2))


def test_lle_threshold_is_c_over_run_time() -> None:
    assert lle_threshold_for(200, T) == pytest.approx(10.0 / (200 * T), rel=1e-15)
    assert lle_threshold_for(400, T) == pytest.approx(lle_threshold_for(200, T) / 2, rel=1e-15)
    with pytest.raises(ParameterError, match="run_periods"):
        lle_threshold_for(0, T)


@pytest.mark.parametrize("n", [1, 2, 3, 5, 7])
def test_periodic_sequences_are_nT(n: int) -> None:
    mc = classify_motion(cycle(n, 300), lle=-0.05, **RUN)
    assert (mc.label, mc.period, mc.agree, mc.note) == (f"{n}T", n, True, "")
    assert mc.regular is True


def test_quasi_periodic_rotation_with_zero_lle() -> None:
    mc = classify_motion(rotation(1000), lle=0.0, **RUN)
    assert mc.label == "QP"
    assert mc.period is None
    assert mc.agree, mc.note
    assert mc.k01 is not None and mc.k01 < 0.2
    assert mc.broadband is False
    assert mc.lle_threshold == pytest.approx(THETA)


@pytest.mark.parametrize("seq", [logistic(1000), henon(1000)], ids=["logistic", "henon"])
def test_chaotic_maps_with_positive_lle(seq: np.ndarray) -> None:
    mc = classify_motion(seq, lle=0.4, **RUN)
    assert mc.label == "chaos"
    assert mc.agree, mc.note
    assert mc.k01 is not None and mc.k01 > 0.8
    assert mc.broadband is True
    assert mc.regular is False


def test_without_lle_the_01_test_decides() -> None:
    assert classify_motion(logistic(1000)).label == "chaos"
    mc = classify_motion(rotation(1000))
    assert (mc.label, mc.agree) == ("QP", True)
    assert "0–1 test" in mc.note


def test_lle_says_chaos_01_says_regular_is_reported() -> None:
    mc = classify_motion(rotation(1000), lle=0.4, **RUN)
    assert mc.label == "chaos"  # the LLE verdict is kept ...
    assert mc.agree is False  # ... but the disagreement is reported
    assert "0–1 test" in mc.note and "regular" in mc.note
    assert "spectrum" in mc.note


def test_lle_says_regular_indicators_say_chaos_is_reported() -> None:
    mc = classify_motion(logistic(1000), lle=0.0, **RUN)
    assert mc.label == "QP"
    assert mc.agree is False
    assert "0–1 test" in mc.note and "spectrum" in mc.note


def test_lle_threshold_tied_to_run_length() -> None:
    rot = rotation(300)
    assert classify_motion(rot, lle=0.9 * THETA, **RUN).label == "QP"
    assert classify_motion(rot, lle=-0.9 * THETA, **RUN).label == "QP"
    assert classify_motion(rot, lle=1.1 * THETA, **RUN).label == "chaos"
    # a longer run lowers the threshold: the same exponent is now chaos
    longer: dict[str, Any] = {"run_periods": 400, "forcing_period": T}
    assert classify_motion(rot, lle=0.9 * THETA, **longer).label == "chaos"
    # lle_threshold is a floor under c/(run_periods·T)
    mc = classify_motion(rot, lle=1.1 * THETA, lle_threshold=2 * THETA, **RUN)
    assert (mc.label, mc.lle_threshold) == ("QP", pytest.approx(2 * THETA))
    assert classify_motion(rot, lle=0.05, lle_threshold=0.1).label == "QP"


def test_contracting_without_period_is_unresolved() -> None:
    mc = classify_motion(rotation(300), lle=-0.1, **RUN)
    assert mc.label == "unresolved"
    assert "contracting" in mc.note


def test_periodic_with_positive_lle_disagrees() -> None:
    mc = classify_motion(cycle(3, 300), lle=0.4, **RUN)
    assert (mc.label, mc.agree) == ("3T", False)
    assert "LLE" in mc.note


def test_no_usable_information_is_unresolved() -> None:
    # too short for the 0–1 test (< 100 points), no LLE: the spectrum alone does not decide
    mc = classify_motion(rotation(80))
    assert mc.label == "unresolved"
    assert mc.k01 is None and mc.broadband is False
    # a failed integration
    pts = rotation(300)
    pts[100:] = np.nan
    mc = classify_motion(pts, lle=0.4, **RUN)
    assert mc.label == "unresolved"
    assert "NaN" in mc.note


def test_given_indicators_are_used_and_nan_means_absent() -> None:
    rot = rotation(300)
    mc = classify_motion(rot, k01=0.95, spectrum_peaks=(True, 0.1))
    assert (mc.label, mc.agree) == ("chaos", True)
    mc = classify_motion(rot, k01=0.95, spectrum_peaks=False)
    assert (mc.label, mc.agree) == ("chaos", False)
    assert classify_motion(rot, lle=math.nan, k01=math.nan, compute_indicators=False).label == (
        "unresolved"
    )


def test_argument_errors() -> None:
    with pytest.raises(ParameterError, match="threshold"):
        classify_motion(rotation(200), lle=0.1)
    with pytest.raises(ParameterError, match="forcing_period"):
        classify_motion(rotation(200), lle=0.1, run_periods=200)
    with pytest.raises(ParameterError, match="spectrum_peaks"):
        classify_motion(rotation(200), spectrum_peaks="lines")  # type: ignore[arg-type]


def test_spectral_broadband() -> None:
    # the r = 4 logistic map has zero autocorrelation at every lag ≥ 1: a white spectrum,
    # whose periodogram exceeds 100× its median with probability ~1e-30 per bin
    broadband, fraction = spectral_broadband(logistic(1000))
    assert broadband and fraction == 0.0
    # an irrational rotation is one line: the Hann window leaks < 1e-3 beyond ± 3 bins
    broadband, fraction = spectral_broadband(rotation(1000))
    assert not broadband and fraction > 0.999
    assert spectral_broadband(henon(1000))[0]
    b, f = spectral_broadband(np.full(100, 2.0))
    assert b is False and math.isnan(f)


def test_classify_sections_over_a_sweep() -> None:
    m = 300
    seqs = np.stack(
        [
            np.stack([cycle(1, m), cycle(2, m), rotation(m)]),
            np.stack([cycle(4, m), np.column_stack([logistic(m), logistic(m, x=0.3)]), henon(m)]),
        ]
    )  # shape (2, 3, m, 2)
    lle = np.array([[-0.1, -0.1, 0.0], [-0.1, 0.3, 0.4]])
    omega = np.array([1.0, 1.5, 2.0])  # forcing period varies along the swept axis
    labels = classify_sections(seqs, lle=lle, run_periods=200, forcing_period=2 * np.pi / omega)
    assert labels.shape == (2, 3)
    np.testing.assert_array_equal(labels, [["1T", "2T", "QP"], ["4T", "chaos", "chaos"]])
    full = classify_sections(seqs, details=True)  # no LLE: the 0–1 test decides
    assert isinstance(full[0, 2], MotionClass)
    assert [[c.label for c in row] for row in full] == labels.tolist()
    assert all(c.agree for c in full.ravel())
    with pytest.raises(ParameterError, match="broadcastable"):
        classify_sections(seqs, lle=np.zeros(4), run_periods=200, forcing_period=T)


def test_regime_table() -> None:
    labels = np.array([["chaos", "1T", "QP"], ["1T", "12T", "2T"]])
    table = regime_table(labels)
    assert list(table) == ["1T", "2T", "12T", "QP", "chaos"]
    assert table == {"1T": 2 / 6, "2T": 1 / 6, "12T": 1 / 6, "QP": 1 / 6, "chaos": 1 / 6}
    assert sum(table.values()) == pytest.approx(1.0, abs=1e-15)
    assert sort_labels(["unresolved", "QP", "3T", "1T"]) == ["1T", "3T", "QP", "unresolved"]
    with pytest.raises(ParameterError, match="empty"):
        regime_table([])


def test_motion_class_to_dict_is_json() -> None:
    mc = classify_motion(rotation(300), lle=math.nan, k01=0.01)
    d = mc.to_dict()
    assert d["label"] == "QP" and d["lle"] is None
    json.dumps(d)
