"""Progress of a sweep: a rich bar in a terminal, plain lines elsewhere (:class:`_Bar`)."""

from __future__ import annotations

import math
import sys
import time
from typing import Any

__all__: list[str] = []


class _Bar:
    """Rich progress bar (points done, points/s, ETA) on stderr in a terminal; elsewhere (a
    log file, a pipe, a batch job) a plain line when at least 5 % of the points and
    :attr:`EVERY` seconds have passed since the last one, and one at the end (a short sweep
    writes one line, an hour-long one at most twenty); silent when disabled."""

    STEP = 0.05  # fraction of the points between two plain lines
    EVERY = 10.0  # seconds between two plain lines

    def __init__(self, enabled: bool, total: int, done: int):
        self.enabled = enabled
        self.total, self.done, self.failed = total, done, 0
        self.t0 = time.perf_counter()
        self.started_at = done
        self._p: Any = None
        self._plain = False
        self._next_line = 0.0
        self._last_line = time.perf_counter()
        self._what = ""

    def __enter__(self) -> _Bar:
        if self.enabled:
            from rich.console import Console

            if not Console(stderr=True).is_terminal:
                self._plain = True
                self._next_line = self.done / max(self.total, 1) + self.STEP
                return self
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeElapsedColumn,
                TimeRemainingColumn,
            )

            self._p = Progress(
                TextColumn("[bold]sweep[/] {task.description}"),
                BarColumn(),
                MofNCompleteColumn(),
                TextColumn("points · {task.fields[rate]} points/s · failed {task.fields[failed]}"),
                TimeElapsedColumn(),
                TextColumn("ETA"),
                TimeRemainingColumn(),
                console=Console(stderr=True),
            )
            self._p.__enter__()
            self._id = self._p.add_task(
                "", total=self.total, completed=self.done, rate="–", failed=0
            )
        return self

    def __exit__(self, *exc: Any) -> None:
        if self._p is not None:
            self._p.__exit__(*exc)

    def describe(self, text: str) -> None:
        self._what = f" ({text})"
        if self._p is not None:
            self._p.update(self._id, description=f"({text})")

    def _line(self) -> str:
        dt = time.perf_counter() - self.t0
        new = self.done - self.started_at
        rate = new / dt if dt > 0 else 0.0
        left = (self.total - self.done) / rate if rate > 0 else float("nan")
        eta = time.strftime("%H:%M:%S", time.gmtime(left)) if math.isfinite(left) else "–"
        pct = 100.0 * self.done / max(self.total, 1)
        return (
            f"sweep{self._what}: {self.done} of {self.total} points ({pct:.0f} %) · "
            f"{rate:.1f} points/s · failed {self.failed} · elapsed "
            f"{time.strftime('%H:%M:%S', time.gmtime(dt))} · ETA {eta}"
        )

    def advance(self, n: int, failed: int) -> None:
        self.done += n
        self.failed += failed
        now = time.perf_counter()
        due = self.done / max(self.total, 1) >= self._next_line and now - self._last_line >= (
            self.EVERY
        )
        if self._plain and (due or self.done >= self.total):
            print(self._line(), file=sys.stderr, flush=True)
            self._last_line = now
            while self._next_line <= self.done / max(self.total, 1):
                self._next_line += self.STEP
        if self._p is not None:
            dt = time.perf_counter() - self.t0
            rate = (self.done - self.started_at) / dt if dt > 0 else 0.0
            self._p.update(self._id, advance=n, rate=f"{rate:.1f}", failed=self.failed)
