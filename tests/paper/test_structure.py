"""Whether a calibration record's clearances act (issue 34): the confirmation adopts only a
gear set whose every continued backlash branch changes or has an event, and whose backlash
sweeps hold double-sided impact."""

from __future__ import annotations

from gearchaos.paper.structure import BRANCHES, MU_CHANGE, branch_score, clearance_problems


def _record(changes: list[tuple[float, int]], double: int) -> dict:
    branches = [
        {"axis": "backlash.sun_planet" if fig == "fig8" else "backlash.planet_ring",
         "omega": om, "change": ch, "events": ev, "reason": "", "score": branch_score(ch, ev)}
        for (fig, om), (ch, ev) in zip(BRANCHES, changes, strict=True)
    ]  # fmt: skip
    return {"parts": {"branches": branches, "double_sided_points": double}}


def test_acting_clearances_have_no_problem() -> None:
    rec = _record([(2 * MU_CHANGE, 0), (1e-8, 1), (0.3, 2), (MU_CHANGE, 0)], double=12)
    assert clearance_problems(rec) == []


def test_a_constant_branch_is_named_with_its_axis_and_speed() -> None:
    """sheng2016-v1's branch along b̄_sp at Ω = 1: max|μ| to 8 digits, no event (the issue)."""
    rec = _record([(4e-9, 0), (0.2, 1), (0.3, 2), (0.1, 1)], double=5)
    (why,) = clearance_problems(rec)
    assert why.startswith("backlash.sun_planet at Ω = 1.0") and "no event" in why


def test_a_change_just_below_the_threshold_does_not_count() -> None:
    rec = _record([(0.9 * MU_CHANGE, 0), (0.2, 1), (0.3, 2), (0.1, 1)], double=5)
    assert len(clearance_problems(rec)) == 1


def test_no_double_sided_impact_is_a_problem_even_with_changing_branches() -> None:
    rec = _record([(0.2, 1)] * 4, double=0)
    (why,) = clearance_problems(rec)
    assert "double-sided" in why


def test_a_record_without_structure_is_not_taken_for_acting() -> None:
    assert clearance_problems({"score": 20.0}) != []
    assert clearance_problems({"parts": {"loads": {}}}) != []
