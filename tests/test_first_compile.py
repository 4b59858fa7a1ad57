"""The one-line first-run notice: said once per process, before a kernel that numba's disk cache
does not hold is compiled, never when every kernel loads from the cache."""

from __future__ import annotations

import pytest

import gearchaos as gc
from gearchaos import _numba


def _run() -> None:
    gc.simulate(gc.preset("sheng2016-v1"), omega=1.5, transient_periods=1, periods=1)


@pytest.mark.parametrize("cached", [False, True])
def test_notice_once_and_only_before_a_compilation(
    monkeypatch: pytest.MonkeyPatch, cached: bool
) -> None:
    calls: list[int] = []
    monkeypatch.setattr(_numba, "_in_disk_cache", lambda dispatcher, sig: cached)
    monkeypatch.setattr(_numba, "_ENTRIES", {})  # as in a fresh process
    _numba.on_first_compile(lambda: calls.append(1))
    try:
        _run()
        _run()
    finally:
        _numba.on_first_compile(None)
    assert calls == ([] if cached else [1])


def test_disk_cache_is_read_from_the_dispatcher() -> None:
    from numba import types

    from gearchaos.integrate.dopri import dopri_chains

    _run()  # compiled or loaded: either way the index is on disk now
    index = dopri_chains._cache._cache_file._load_index()
    cached_sig = next(iter(index))[0]
    assert _numba._in_disk_cache(dopri_chains, cached_sig) is True
    # a specialisation the cache does not hold (a new planet count, say): the notice is due
    assert _numba._in_disk_cache(dopri_chains, (types.literal(987654),)) is False
    assert _numba._in_disk_cache(object(), cached_sig) is True  # cannot be told: no notice


def test_the_first_compile_notice_is_given_once_across_threads() -> None:
    """A sweep's driver threads compile side by side: each may find the notice pending; it
    is given once and no thread fails (the second pop raised 'pop from empty list' and
    failed gearchaos calibrate in a fresh clone)."""
    import threading

    from gearchaos import _numba

    calls: list[int] = []
    errors: list[BaseException] = []
    _numba.on_first_compile(lambda: calls.append(1))
    start = threading.Barrier(8)

    def worker() -> None:
        start.wait()
        try:
            _numba._first_compile_notice()
        except BaseException as exc:  # any failure is the finding
            errors.append(exc)

    threads = [threading.Thread(target=worker) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    _numba.on_first_compile(None)
    assert calls == [1] and not errors
