"""The verdict's record mode (issue 36, item 4): labels from the record alone, with evidence
``record``, through the one decision procedure and its one :class:`Verdict` type.

The truth is the construction of the sequences: a period-3 cycle, the chaotic logistic map
x → 4x(1 − x) (λ = ln 2 per step), and a failed run; nothing is integrated."""

from __future__ import annotations

import math

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.dynamics import EVIDENCE, VerdictSettings, decide_motion
from gearchaos.dynamics.verdict.evidence import evidence_words
from gearchaos.dynamics.verdict.record import RECORD_REASON
from gearchaos.integrate.settings import SolverSettings
from gearchaos.model.target import resolve

OSC = gc.backlash_oscillator(1.0, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.2)
M = 200
SETTINGS = SolverSettings(transient_periods=10, periods=M)
RECORD = VerdictSettings(mode="record")


def _sequences() -> tuple[np.ndarray, np.ndarray]:
    cycle = np.tile(np.array([[0.1, 1.0], [0.7, -0.2], [-0.4, 0.3]]), (M // 3 + 1, 1))[:M]
    x = np.empty(M)
    x[0] = 0.2345
    for k in range(1, M):
        x[k] = 4.0 * x[k - 1] * (1.0 - x[k - 1])
    chaos = np.stack([x, np.roll(x, 1)], axis=-1)
    return np.stack([cycle, chaos, chaos]), np.array([True, True, False])


def test_record_mode_labels_from_the_record_alone() -> None:
    sections, ok = _sequences()
    systems = [resolve(OSC, {"omega": w}) for w in (1.0, 1.5, 2.0)]
    values = [{"omega": w} for w in (1.0, 1.5, 2.0)]
    # λ₁ per unit τ of the logistic map at one step per period T = 2π/Ω: ln 2 / T
    lle = np.array([-0.05, math.log(2.0) / systems[1].period, math.nan])
    finals = np.zeros((3, systems[0].n_state))
    v = decide_motion(OSC, values, systems, sections, finals, ok, SETTINGS, RECORD, lle=lle)
    assert [x.label for x in v] == ["3T", "chaos", "failed"]
    assert [x.evidence for x in v] == ["record", "record", "failed"]
    assert v[0].code == v[1].code == EVIDENCE["record"]
    assert v[0].period == 3 and v[1].period == 0
    assert v[1].lle == lle[1] and math.isnan(v[1].lle_error)
    assert math.isnan(v[0].max_multiplier) and v[0].extra_periods == 0 and v[0].record is None
    assert v[0].reason.startswith(RECORD_REASON) and "not confirmed" in v[1].reason
    assert "not confirmed" in evidence_words(v[1].evidence)
    assert evidence_words("floquet") == "floquet"


def test_record_mode_codes_are_new_and_settings_are_checked() -> None:
    # stored files use the codes: the earlier ones keep their values, record is a new one
    assert EVIDENCE["floquet"] == 0 and EVIDENCE["converging"] == 7
    assert EVIDENCE["record"] == 8 and len(set(EVIDENCE.values())) == len(EVIDENCE)
    with pytest.raises(gc.ParameterError, match="mode"):
        VerdictSettings(mode="guess")
    sections, ok = _sequences()
    systems = [resolve(OSC, {"omega": 1.0})]
    with pytest.raises(gc.ParameterError, match="lle"):
        decide_motion(
            OSC, [{"omega": 1.0}], systems, sections[:1], np.zeros((1, 2)), ok[:1], SETTINGS,
            lle=[0.1],
        )  # fmt: skip
