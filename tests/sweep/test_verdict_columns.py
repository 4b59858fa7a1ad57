"""The verdict's store variables come from one table of the verdict's fields.

Every field of :class:`~gearchaos.dynamics.verdict.evidence.Verdict` is either held by a variable of
:data:`~gearchaos.sweep.verdicts.VERDICT_COLUMNS` or named in
:data:`~gearchaos.sweep.verdicts.NOT_STORED` with a reason, so a new field cannot be
forgotten; the variables keep the names, element types and fill values of the stores written
before the table (so old stores open unchanged), and a row holds the verdict's own numbers.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from gearchaos.analysis.motion import Motion
from gearchaos.dynamics.verdict.evidence import EVIDENCE, Verdict
from gearchaos.dynamics.verdict.extension import RECORD_SOURCES, VerdictRecord
from gearchaos.sweep.verdicts import (
    NOT_STORED,
    VERDICT_COLUMNS,
    VERDICT_VARIABLES,
    verdict_attrs,
    verdict_row,
)

#: The verdict variables of a sweep store as written since verdict stores exist:
#: name → (element type, fill value).
STORE_FORMAT = {
    "motion": ("<U10", ""),
    "verdict": ("int8", -1),
    "max_multiplier": ("float64", math.nan),
    "lle": ("float64", math.nan),
    "lle_error": ("float64", math.nan),
    "k01": ("float64", math.nan),
    "extra_periods": ("int64", -1),
    "window_start": ("int64", -1),
    "window_periods": ("int64", 0),
    "record": ("int8", -1),
}


def _same(a: object, b: object) -> bool:
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


def test_every_field_of_the_verdict_is_stored_or_said_not_to_be() -> None:
    fields = {f.name for f in dataclasses.fields(Verdict)}
    sources = {c.source for c in VERDICT_COLUMNS.values()}
    v = Verdict("2T", 2, "floquet")
    for s in sources:
        assert hasattr(v, s), s  # a field or a property of the verdict
    stored_fields = sources & fields
    assert not stored_fields & set(NOT_STORED)
    assert fields == stored_fields | set(NOT_STORED), sorted(
        fields ^ (stored_fields | set(NOT_STORED))
    )
    assert all(reason for reason in NOT_STORED.values())


def test_the_store_format_is_that_of_stores_written_before() -> None:
    assert list(VERDICT_VARIABLES) == list(STORE_FORMAT)
    for name, (dtype, fill) in STORE_FORMAT.items():
        _, have_dtype, have_fill = VERDICT_VARIABLES[name]
        assert np.dtype(have_dtype) == np.dtype(dtype), name
        assert _same(have_fill, fill), (name, have_fill)
    assert verdict_attrs("verdict") == {
        "flag_values": list(EVIDENCE.values()),
        "flag_meanings": " ".join(EVIDENCE),
    }
    assert verdict_attrs("record")["flag_meanings"] == "protocol extension orbit"
    assert verdict_attrs("lle") == {}


def test_a_row_holds_the_verdict_s_numbers() -> None:
    record = VerdictRecord(
        states=np.zeros((3, 2)),
        observables=np.zeros((3, 1)),
        obs_min=np.zeros(1),
        obs_max=np.zeros(1),
        final_state=np.zeros(2),
    )
    v = Verdict(
        "unresolved",
        0,
        "ambiguous",
        max_multiplier=1.25,
        lle=0.03,
        lle_error=0.004,
        k01=0.5,
        extra_periods=400,
        reason="λ₁ straddles the bound",
        record=record,
        window_start=200,
        window_periods=200,
    )
    row = verdict_row(v)
    assert row == {
        "motion": "unresolved",
        "verdict": 4,  # ambiguous
        "max_multiplier": 1.25,
        "lle": 0.03,
        "lle_error": 0.004,
        "k01": 0.5,
        "extra_periods": 400,
        "window_start": 200,
        "window_periods": 200,
        "record": 1,  # extension
    }
    assert Motion.parse(row["motion"]) == v.motion
    plain = verdict_row(Verdict("3T", 3, "floquet"))
    assert plain["record"] == RECORD_SOURCES["protocol"] == 0
    assert plain["motion"] == "3T" and plain["verdict"] == 0
    for name, value in plain.items():  # every value fits its variable's element type
        assert np.array([value], dtype=STORE_FORMAT[name][0])[0] == value or math.isnan(value)
