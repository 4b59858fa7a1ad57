"""The thread pool that spreads chains over cores (:func:`run_threaded`): every chain runs exactly
once, in as many threads as asked for, and an error stops the blocks not yet started (results
that do not depend on the threads: tests/integrate/test_batch.py)."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from gearchaos.integrate._chains import run_threaded


@pytest.mark.parametrize("n", [1, 2, 7, 100])
@pytest.mark.parametrize("threads", [1, 2, 3, 8])
def test_blocks_cover_every_index_exactly_once(n: int, threads: int) -> None:
    hits = np.zeros(n, dtype=int)
    lock = threading.Lock()

    def call(lo: int, hi: int) -> None:
        assert 0 <= lo < hi <= n
        with lock:
            hits[lo:hi] += 1

    run_threaded(call, n, threads)
    np.testing.assert_array_equal(hits, 1)


def test_blocks_run_on_several_threads_at_once() -> None:
    # two blocks that each wait for the other: only finishes if they run concurrently
    barrier = threading.Barrier(2, timeout=30)
    names = set()

    def call(lo: int, hi: int) -> None:
        names.add(threading.current_thread().name)
        barrier.wait()

    run_threaded(call, 2, 2)
    assert len(names) == 2


def test_an_error_cancels_the_blocks_not_started() -> None:
    release = threading.Event()
    started = []

    def call(lo: int, hi: int) -> None:
        started.append(lo)
        if lo == 0:
            raise RuntimeError("boom")
        release.wait(30)  # hold the threads until the error has been handled

    with pytest.raises(RuntimeError, match="boom"):
        run_threaded(call, 64, 2)
    release.set()
    # block 0, the block the other thread holds, and at most one the first thread took next
    assert len(started) <= 3
