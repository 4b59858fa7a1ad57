"""The :class:`~gearchaos.analysis.motion.Motion` value: every label the package writes reads
back as the motion it names and prints as the same text; anything else is refused by name.

The labels are enumerated from the package's source (every string constant it passes as a
verdict's or a record classifier's label, assigns to a summary's ``motion`` or compares a label
with), so a new label written anywhere must parse; the period labels are checked for
n = 1 … 10 000 against the seed's spelling ``nT`` written here, not the module's.
"""

from __future__ import annotations

import ast
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from gearchaos.analysis.classify import MotionClass, classify_motion, sort_labels
from gearchaos.analysis.motion import LABEL_DTYPE, UNSET_TEXT, Motion, MotionKind
from gearchaos.dynamics.verdict.evidence import Verdict
from gearchaos.errors import ParameterError

SRC = Path(__file__).resolve().parents[2] / "src" / "gearchaos"

#: The words of the non-periodic kinds, as the seed and the stores spell them.
WORDS = ("QP", "chaos", "unresolved", "failed", "not run")
#: Names of what holds a label where the source compares one with a constant.
LABEL_NAMES = {"label", "lab", "labels", "motion", "last", "s"}


def _is_label_holder(node: ast.AST) -> bool:
    if isinstance(node, ast.Call) and getattr(node.func, "attr", "") == "get" and node.args:
        key = node.args[0]  # summary.get("motion")
        return isinstance(key, ast.Constant) and key.value == "motion"
    if isinstance(node, ast.Attribute):
        return node.attr in ("label", "motion")
    if isinstance(node, ast.Name):
        return node.id in LABEL_NAMES
    if isinstance(node, ast.Subscript):
        return _is_label_holder(node.value)
    return False


def _written_labels() -> dict[str, set[str]]:
    """String constants the source uses as motion labels, with the files that use them:
    ``label=`` of Verdict/MotionClass/Attractor constructors (or their first argument),
    ``summary["motion"] = ...``, and comparisons of a label (or ``summary.get("motion")``)
    with a constant."""
    found: dict[str, set[str]] = {}

    def add(node: ast.AST, where: str) -> None:
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            found.setdefault(node.value, set()).add(where)

    for path in sorted(SRC.rglob("*.py")):
        where = str(path.relative_to(SRC))
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call):
                name = getattr(node.func, "id", getattr(node.func, "attr", ""))
                if name in ("Verdict", "MotionClass", "Attractor", "BasinAttractor"):
                    for kw in node.keywords:
                        if kw.arg == "label":
                            add(kw.value, where)
                    if node.args and name == "Verdict":
                        add(node.args[0], where)
            elif isinstance(node, ast.Assign):
                for t in node.targets:
                    key = t.slice if isinstance(t, ast.Subscript) else None
                    if isinstance(key, ast.Constant) and key.value == "motion":
                        add(node.value, where)
            elif isinstance(node, ast.Compare) and _is_label_holder(node.left):
                for c in node.comparators:
                    add(c, where)
                    if isinstance(c, ast.Tuple):
                        for e in c.elts:
                            add(e, where)
    return found


def test_every_label_the_source_writes_or_compares_round_trips() -> None:
    found = _written_labels()
    # the enumeration sees the package: these are written in dynamics and analysis
    assert {"failed", "unresolved", "chaos", "QP"} <= set(found), sorted(found)
    for text, where in found.items():
        try:
            motion = Motion.parse(text)
        except ParameterError as e:  # pragma: no cover - the failure message
            pytest.fail(f"{text!r} in {sorted(where)} is not a motion label: {e}")
        if text != UNSET_TEXT:
            assert motion.format() == text, (text, sorted(where))


def test_every_kind_round_trips_and_the_words_are_the_seed_s() -> None:
    motions = [
        Motion.quasi_periodic(),
        Motion.chaos(),
        Motion.unresolved(),
        Motion.failed(),
        Motion.not_run(),
    ]
    assert [str(m) for m in motions] == list(WORDS)
    assert [m.kind for m in motions] == [k for k in MotionKind if k is not MotionKind.PERIODIC]
    for m in motions:
        assert Motion.parse(m.format()) == m
        assert m.period == 0 and not m.is_periodic
    # the store's fill value (a point not computed yet) reads as not run
    assert Motion.parse(UNSET_TEXT) == Motion.not_run()
    # a store element is a numpy string
    assert Motion.parse(np.array(["12T", "chaos"], dtype=LABEL_DTYPE)[0]) == Motion.periodic(12)


@settings(max_examples=300, deadline=None)
@given(st.integers(min_value=1, max_value=10_000))
def test_period_labels_round_trip(n: int) -> None:
    text = str(n) + "T"  # the seed's spelling, written independently of the module
    m = Motion.parse(text)
    assert m.kind is MotionKind.PERIODIC and m.is_periodic and m.period == n
    assert m == Motion.periodic(n) and str(m) == m.format() == text
    assert np.array([text], dtype=LABEL_DTYPE)[0] == text  # fits the store's labels


def test_the_longest_period_fits_the_stored_labels() -> None:
    width = np.dtype(LABEL_DTYPE).itemsize // np.dtype("<U1").itemsize
    longest = "9" * (width - 1) + "T"
    assert Motion.parse(longest).period == int("9" * (width - 1))
    with pytest.raises(ParameterError, match="'1" + "0" * (width - 1) + "T'"):
        Motion.parse("1" + "0" * (width - 1) + "T")  # would be cut short in a store
    for word in WORDS:
        assert len(word) <= width


@pytest.mark.parametrize(
    "text",
    [
        "0T",
        "01T",
        "T",
        "nT",  # a landmark's wildcard, not a motion
        "1t",
        " 1T",
        "1T ",
        "-1T",
        "1.5T",
        "²T",  # str.isdigit() is True for a superscript two
        "١T",  # an Arabic-Indic one: isdigit() True and int() reads it as 1
        "many",  # the distinct-point count's word, not a motion
        "Chaos",
        "qp",
        "≥ 9T",  # a figure's display category, not a label
    ],
)
def test_bad_text_is_refused_naming_it(text: str) -> None:
    with pytest.raises(ParameterError, match="motion label must be") as err:
        Motion.parse(text)
    assert repr(text) in str(err.value)
    assert err.value.name == "motion"


@pytest.mark.parametrize("value", [3, None, b"1T", 1.0])
def test_non_text_is_refused_naming_its_type(value: object) -> None:
    with pytest.raises(ParameterError, match="must be text: got " + type(value).__name__):
        Motion.parse(value)


def test_construction_rules() -> None:
    for bad in (0, -2, True, 2.0):
        with pytest.raises(ParameterError, match="period"):
            Motion.periodic(bad)  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match="period must be 0 for a chaos motion"):
        Motion(MotionKind.CHAOS, 3)
    with pytest.raises(ParameterError, match="reason is given only"):
        Motion(MotionKind.QUASI_PERIODIC, reason="why")
    with pytest.raises(ParameterError, match="kind must be a MotionKind"):
        Motion("chaos")  # type: ignore[arg-type]
    m = Motion.periodic(np.int64(4))
    assert type(m.period) is int and m.period == 4
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.period = 5  # type: ignore[misc]


def test_the_reason_is_evidence_not_part_of_the_label() -> None:
    a = Motion.unresolved("λ₁ straddles the bound")
    assert a == Motion.parse("unresolved") and hash(a) == hash(Motion.unresolved())
    assert str(a) == "unresolved" and a.reason == "λ₁ straddles the bound"


def test_questions() -> None:
    assert [Motion.parse(t).decided for t in ("3T", *WORDS)] == [
        True,
        True,
        True,
        False,
        False,
        False,
    ]
    assert [Motion.parse(t).regular for t in ("3T", *WORDS)] == [
        True,
        True,
        False,
        None,
        None,
        None,
    ]


def test_display_order() -> None:
    texts = ["not run", "chaos", "10T", "failed", "QP", "2T", "unresolved", "1T"]
    order = sorted(texts, key=lambda t: Motion.parse(t).sort_key)
    assert order == ["1T", "2T", "10T", "QP", "chaos", "unresolved", "failed", "not run"]
    # sort_labels keeps text that is no label, after the labels
    assert sort_labels([*texts, "many"]) == [*order, "many"]


def test_verdict_and_record_class_carry_their_motion() -> None:
    v = Verdict("unresolved", 0, "ambiguous", reason="λ₁ straddles the bound")
    assert v.motion == Motion.unresolved() and v.motion.reason == "λ₁ straddles the bound"
    assert Verdict("3T", 3, "floquet").motion == Motion.periodic(3)
    with pytest.raises(ParameterError, match=r"period must be the label's \(3 for 3T\): got 2"):
        Verdict("3T", 2, "floquet")
    with pytest.raises(ParameterError, match="'3 T'"):
        Verdict("3 T", 3, "floquet")
    # a record-only label: a sine sampled once a period (period 1) and a two-point cycle
    one = classify_motion(np.ones(200))
    two = classify_motion(np.tile([0.0, 1.0], 100))
    assert isinstance(one, MotionClass)
    assert (one.motion, two.motion) == (Motion.periodic(1), Motion.periodic(2))
    assert one.label == "1T" and two.period == 2
    bad = classify_motion(np.full(200, math.nan))
    assert bad.motion == Motion.unresolved() and "NaN" in bad.motion.reason
