"""Confirm the calibration's top candidates with the full report before one is adopted.

    .venv/bin/python paper/confirm.py [paper/calibration.jsonl] [--top 3] [--work DIR]
    .venv/bin/python paper/confirm.py --storage sqlite:///paper/calibration.db [--top 3]

The calibration scores candidates on coarse sweeps (a few hundred points). Before a candidate
becomes the default ``sheng2016`` (issue 34), each of the ``--top`` best eligible candidates —
physically plausible, and with clearances that act (every continued backlash branch changes its
multipliers or has an event, and the backlash sweeps hold double-sided impact:
:func:`gearchaos.paper.calibrate.adoption_problems`), ranked by landmark score, then
structure — gets a full ``gearchaos reproduce --all`` (every
figure at full resolution, the verdicts, the paper-protocol column), and so does today's
default for comparison (``--preset``, default ``sheng2016-v1``; or its committed report,
``--previous-report docs/report/report.json``). The counts of every report
(holds with the parameter acting, holds (constant), partly, does not hold; conclusions; wall
time) are written to ``paper/confirmation.json``, and the winner is the candidate with the
most landmarks that hold with their parameter acting, then the fewest that do not hold, then
the calibration's rank. ``paper/make_preset.py --trial N`` then writes it as ``sheng2016``.

Everything is read from the reports ``reproduce`` wrote (``DIR/trialN/report.json``); an
interrupted run resumes (``reproduce`` resumes its stores, finished reports are kept).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

from gearchaos.gearset import preset
from gearchaos.paper.accounting import verdict_counts
from gearchaos.paper.calibrate import (
    STUDY,
    adoption_problems,
    candidate_from_record,
    ranked,
    read_results,
    study_records,
)
from gearchaos.paper.conclusions import VERDICTS as CONCLUSION_VERDICTS
from gearchaos.paper.loads import load_factors
from gearchaos.paper.search_space import build_gearset

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "paper"))

from make_preset import DESCRIPTION, NAME  # noqa: E402

OUT = ROOT / "paper" / "confirmation.json"


def counts(report: dict) -> dict:
    """The counts of one ``report.json``: landmarks, the paper-protocol column, conclusions."""
    lm = [str(x.get("verdict", "not evaluated")) for x in report["landmarks"]]
    pp = [str(x.get("paper_verdict", "not evaluated")) for x in report["landmarks"]]
    cc = [str(x.get("verdict", "not evaluated")) for x in report["conclusions"]]
    return {
        "landmarks": verdict_counts(lm),
        "landmarks_paper": verdict_counts(pp),
        "conclusions": verdict_counts(cc, CONCLUSION_VERDICTS),
        "seconds": float(report["seconds"]),
    }


def _reproduce(args: list[str], out: Path) -> dict:
    report = out / "report.json"
    if not report.is_file():
        cmd = [sys.executable, "-m", "gearchaos", "reproduce", "--all", "-o", str(out), "-q"]
        t0 = time.perf_counter()
        subprocess.run([*cmd, *args], check=True, env={**os.environ, "COLUMNS": "100"})
        print(f"  {out.name}: {time.perf_counter() - t0:.0f} s", flush=True)
    return json.loads(report.read_text(encoding="utf-8"))


def _key(row: dict) -> tuple[int, int, int]:
    lm = row["counts"]["landmarks"]
    return (-lm.get("holds", 0), lm.get("does not hold", 0), row["rank"])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("log", nargs="?", default=str(ROOT / "paper" / "calibration.jsonl"))
    ap.add_argument("--storage", help="Optuna storage URL of the study (else the log)")
    ap.add_argument("--study", default=STUDY)
    ap.add_argument("--top", type=int, default=3)
    ap.add_argument("--any", action="store_true", help="confirm implausible candidates too")
    ap.add_argument("--trial", type=int, action="append", help="confirm this trial (repeatable)")
    ap.add_argument("--out", default=str(OUT), help="the summary (default paper/confirmation.json)")
    ap.add_argument("--preset", default="sheng2016-v1", help="the previous default, for comparison")
    ap.add_argument("--previous-report", help="report.json of the previous default (not rerun)")
    ap.add_argument("--work", default=str(ROOT / "paper" / "confirm"), help="report folders")
    args = ap.parse_args()
    if args.storage:
        from gearchaos.paper.study import open_study

        records = study_records(open_study(args.storage, args.study))
    else:
        records = list(read_results(args.log).values())
    order = ranked(records)
    # eligible candidates: plausible (ranges, tooth combination, loads where the study measured
    # them) and with clearances that act; ``--any`` confirms the best ones whatever their loads
    # and structure (a study without those measurements)
    top = [(i + 1, r) for i, r in enumerate(order) if args.any or not adoption_problems(r)]
    if args.trial:
        top = [(rank, r) for rank, r in enumerate(order, start=1) if r["index"] in args.trial]
    top = top[: args.top]
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    rows = []
    for rank, rec in top:
        toml = work / f"trial{rec['index']}.toml"
        # named as paper/make_preset.py would name the adopted one, so that the winner's stores
        # are those of `reproduce --all` on the new default (the report resumes from them)
        gs = build_gearset(candidate_from_record(rec)).evolve(name=NAME, description=DESCRIPTION)
        toml.write_text(gs.to_toml(), encoding="utf-8")
        rep = _reproduce(["-g", str(toml)], work / f"trial{rec['index']}")
        rows.append({
            "trial": rec["index"], "origin": rec["origin"], "rank": rank,
            "score": rec["score"], "structure": rec.get("structure"),
            "variables": rec["variables"], "counts": counts(rep), "loads": load_factors(gs),
        })  # fmt: skip
        parts = {**(rec.get("parts") or {}), "loads": rows[-1]["loads"]}
        rows[-1]["problems"] = adoption_problems({**rec, "parts": parts})
    if args.previous_report:
        base = json.loads(Path(args.previous_report).read_text(encoding="utf-8"))
    else:
        base = _reproduce(["-p", args.preset], work / args.preset)
    fit = [r for r in rows if not r["problems"]]
    winner = min(fit, key=_key) if fit else None
    result = {
        "source": f"study {args.study} ({args.storage})" if args.storage else Path(args.log).name,
        "candidates": len(records),
        "rule": (
            "among the physically plausible ones (ranges, tooth combination, peak mesh force "
            "within the teeth's strength) whose clearances act (every continued backlash "
            "branch changes its multipliers or has an event; double-sided impact in the "
            "backlash sweeps), most landmarks holding with the parameter acting, then fewest "
            "not holding, then the calibration's rank"
        ),
        "winner": None if winner is None else winner["trial"],
        "confirmed": rows,
        "previous": {
            "preset": args.preset,
            "loads": load_factors(preset(args.preset)),
            "report": args.previous_report or f"reproduce --all -p {args.preset}",
            "counts": counts(base),
        },
    }
    out = Path(args.out)
    out.write_text(json.dumps(result, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    for row in rows:
        c = row["counts"]["landmarks"]
        print(f"trial {row['trial']} (rank {row['rank']}, score {row['score']:.2f}): {c}")
    print(f"{args.preset}: {result['previous']['counts']['landmarks']}")
    print(f"winner: trial {result['winner']}; wrote {out}")


if __name__ == "__main__":
    main()
