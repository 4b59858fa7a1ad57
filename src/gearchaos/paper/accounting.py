"""The report's accounting of the landmarks: one row per landmark with its verdict, whether the
swept parameter acts on its panel, and what the seed's own protocol says; and the counts that
every summary prints (the report page, ``report.json``, ``gearchaos reproduce --all``, the
README and docs/reproduction.md through ``docs/make_doc_numbers.py``).

Counts keep ``holds (constant)`` apart from ``holds``: a hold on a panel where the swept
parameter does not act (:mod:`.action`) agrees with the seed only because nothing changes
along the axis.

The *paper protocol* column checks the same landmarks on the sweeps of the seed's own protocol
(:data:`gearchaos.paper.recipes.PAPER_PROTOCOL`: the exact zero start, labels from the
100 + 100-period record alone), with no continued branches (the seed read its figures), so a
reader sees what the seed's method would have said beside the verdicts.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from .landmark_data import VERDICTS, AxisAction, LandmarkResult

__all__ = ["count_text", "landmark_rows", "verdict_counts"]


def verdict_counts(verdicts: Iterable[str], order: Sequence[str] = VERDICTS) -> dict[str, int]:
    """Count of each verdict, in ``order`` (every entry present, zeros included; verdicts
    outside it after them)."""
    out = {v: 0 for v in order}
    for v in verdicts:
        out[v] = out.get(v, 0) + 1
    return out


def count_text(counts: Mapping[str, int]) -> str:
    """``"13 holds, 6 holds (constant), 2 partly, …"`` (zeros left out)."""
    return ", ".join(f"{n} {v}" for v, n in counts.items() if n) or "none"


def _action_text(a: AxisAction | None) -> tuple[str, str]:
    if a is None:
        return "not tested", ""
    return a.word, a.evidence


def landmark_rows(
    stores: Mapping[str, Any],
    branches: Mapping[str, Any] | None = None,
    *,
    paper_stores: Mapping[str, Any] | None = None,
    actions: Mapping[str, AxisAction] | None = None,
    landmarks: Sequence[Any] | None = None,
) -> tuple[list[dict[str, Any]], str]:
    """(rows, note): one row per landmark — ``id``, ``figure``, ``statement``, ``evidence``,
    ``verdict``, ``acts`` (``acts`` / ``constant`` / ``undecided`` / ``not tested``) and
    ``action`` (its evidence), ``paper_verdict`` and ``paper_evidence`` (on ``paper_stores``;
    ``not evaluated`` without them) — and a note when the evaluation failed (no rows)."""
    from . import landmarks as lm_mod
    from .action import apply_actions
    from .routes import landmarks_from_events

    try:
        marks = list(landmarks) if landmarks is not None else lm_mod.load_landmarks()
        results = lm_mod.evaluate_all(marks, dict(stores))
        if branches:
            results = landmarks_from_events(results, branches)
        paper: list[LandmarkResult] = (
            lm_mod.evaluate_all(marks, dict(paper_stores)) if paper_stores else []
        )
        if actions is not None:
            results = apply_actions(results, actions)
            paper = apply_actions(paper, actions)
    except Exception as exc:
        return [], f"landmark evaluation failed: {type(exc).__name__}: {exc}"
    by_id = {r.landmark.id: r for r in paper}
    rows = []
    for r in results:
        lm = r.landmark
        acts, action = _action_text(r.action)
        p = by_id.get(lm.id)
        rows.append(
            {
                "id": lm.id,
                "figure": f"{lm.figure} {dict(lm.panel) or ''}".strip(),
                "statement": lm.quote,
                "evidence": r.evidence,
                "verdict": r.verdict,
                "acts": acts,
                "action": action,
                "paper_verdict": p.verdict if p is not None else "not evaluated",
                "paper_evidence": p.evidence if p is not None else "no paper-protocol sweep",
            }
        )
    return rows, ""
