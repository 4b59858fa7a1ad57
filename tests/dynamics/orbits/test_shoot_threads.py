"""A shooting chooses its threads per call (issue 36, item 5): one or two chains run on one
thread and more on as many as there are chains, up to numba's setting, which the call never
changes (before, ``shoot`` set ``numba.set_num_threads`` around its run and set it back)."""

from __future__ import annotations

import numba
import numpy as np
import pytest

import gearchaos as gc
from gearchaos.dynamics.orbits.shooting import shoot
from gearchaos.integrate import _chains
from gearchaos.integrate.settings import SolverSettings


@pytest.mark.parametrize("chains", [1, 2, 3])
def test_shoot_asks_for_its_threads_and_sets_none(
    chains: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    asked: list[int] = []
    set_to: list[int] = []
    run_threaded = _chains.run_threaded

    def recording(call: object, n: int, threads: int) -> None:
        asked.append(threads)
        run_threaded(call, n, threads)

    monkeypatch.setattr(_chains, "run_threaded", recording)
    monkeypatch.setattr(numba, "set_num_threads", set_to.append)
    systems = [gc.backlash_oscillator(1.0 + 0.1 * k) for k in range(chains)]
    y = np.zeros((chains, 2))
    shot = shoot(systems, y, 2, SolverSettings(), tangents=False)
    assert all(shot.ok(c) for c in range(chains))
    assert set_to == []
    assert asked == [1 if chains <= 2 else min(chains, numba.get_num_threads())]
