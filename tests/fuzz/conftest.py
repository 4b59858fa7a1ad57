"""Fixtures of the fuzz suites: the shared harness, and the counts each module records."""

from __future__ import annotations

import json
import os
from collections.abc import Iterator

import pytest

pytest.register_assert_rewrite("fuzz_helpers")


@pytest.fixture(scope="module", autouse=True)
def _record_harness_counts() -> Iterator[None]:
    """Append the counts of :mod:`fuzz_helpers` (inputs tried per entry point, and how many
    ended in a traceback, an acceptance or a hang) to ``$GEARCHAOS_FUZZ_COUNTS``, per module."""
    from fuzz_helpers import COUNTS

    COUNTS.clear()
    yield
    target = os.environ.get("GEARCHAOS_FUZZ_COUNTS")
    if target and COUNTS:
        with open(target, "a", encoding="utf-8") as f:
            f.write(json.dumps({"pid": os.getpid(), "counts": dict(COUNTS)}) + "\n")
    COUNTS.clear()
