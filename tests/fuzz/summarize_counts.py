"""Summarise the counts the fuzz suites record (issue 10's closing note).

Run the suites with ``GEARCHAOS_FUZZ_COUNTS=counts.jsonl`` (and the kill tests with
``GEARCHAOS_KILL_PHASES=kills.jsonl``), then::

    python tests/fuzz/summarize_counts.py counts.jsonl [kills.jsonl]

prints the inputs tried per entry point and every input that broke the rule — keyed
``"<entry> [traceback|accepted|hang|slow]"`` by :mod:`fuzz_helpers` (each also failed its
test) — and where the SIGKILLs landed.
"""

from __future__ import annotations

import json
import sys
from collections import Counter

BROKEN = ("traceback", "accepted", "hang", "slow")


def main(counts_file: str, kills_file: str | None = None) -> None:
    counts: Counter[str] = Counter()
    with open(counts_file, encoding="utf-8") as f:
        for line in f:
            counts.update(json.loads(line)["counts"])
    tried = {k: n for k, n in counts.items() if not k.endswith("]")}
    broken = {w: sum(n for k, n in counts.items() if k.endswith(f"[{w}]")) for w in BROKEN}
    width = max(map(len, tried), default=10)
    for entry, n in sorted(tried.items()):
        print(f"{entry:<{width}}  {n:>7}")
    print(f"{'total':<{width}}  {sum(tried.values()):>7}  ({len(tried)} entry points)")
    print(", ".join(f"{w}: {n}" for w, n in broken.items()))
    for k, n in sorted(counts.items()):
        if k.endswith("]"):
            print(f"  broke the rule: {k} x{n}")
    if kills_file:
        landed: Counter[str] = Counter()
        rounds = 0
        with open(kills_file, encoding="utf-8") as f:
            for line in f:
                rec = json.loads(line)
                rounds += 1
                landed.update(rec["landed"])
        print(f"kill runs: {rounds}; landed: {dict(landed)}")


if __name__ == "__main__":
    main(*sys.argv[1:3])
