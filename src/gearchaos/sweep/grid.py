"""From a :class:`SweepSpec` to work: systems per grid point, chains, tasks and their arrays.

Grid points are addressed by their index tuple over ``spec.dims``. The store is chunked so
that each *task* writes its own Zarr chunks and nothing else:

* ``fresh`` — a task is a block of consecutive points along the last dimension; every point is
  its own chain of length one (zero initial state);
* ``continuation`` — a task is one chain: the whole first varied axis at fixed other indices,
  traversed upwards or downwards, each point starting from its predecessor's final state.

Tasks carry only numbers (packed parameter vectors), so any executor — the numba thread pool,
local processes or a Dask cluster — runs them with the same compiled kernel and produces
bitwise-identical results.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..dynamics.lyapunov import random_tangents
from ..errors import ParameterError
from ..integrate._chains import ChainRun
from ..model.system import System
from ..model.target import OMEGA, Target, check_names, model_for, split_omega
from .spec import SweepSpec

__all__ = ["Grid", "Task"]


@dataclass(frozen=True)
class Task:
    """One unit of work: a block of the grid (``block`` slices over ``spec.dims``)."""

    index: int
    block: tuple[slice, ...]
    chains: tuple[tuple[tuple[int, ...], ...], ...]  # per chain: grid index tuples in run order

    @property
    def n_points(self) -> int:
        return sum(len(c) for c in self.chains)

    @property
    def shape(self) -> tuple[int, ...]:
        """Shape of the task's block of the grid."""
        return tuple(b.stop - b.start for b in self.block)

    def points(self) -> list[tuple[int, int, tuple[int, ...], tuple[int, ...]]]:
        """Every point in run order: (chain, place in the chain, grid index, index within the
        task's block)."""
        starts = tuple(b.start for b in self.block)
        return [
            (c, j, idx, tuple(i - s for i, s in zip(idx, starts, strict=True)))
            for c, chain in enumerate(self.chains)
            for j, idx in enumerate(chain)
        ]


class Grid:
    """Maps grid indices to systems and lays out tasks for a spec and a target."""

    def __init__(self, target: Target, spec: SweepSpec, *, chunk_points: int | None = None):
        self.spec = spec
        self.target = target
        self.fixed = dict(spec.fixed)
        names = [a.name for a in spec.axes]
        check_names(target, [*names, *self.fixed])
        self.fixed_omega, self._fixed_changes = split_omega(self.fixed)
        model_for(target, self._fixed_changes)  # the fixed values are valid (or refused) first
        if OMEGA not in names and self.fixed_omega is None:
            if isinstance(target, System):
                self.fixed_omega = target.omega
            else:
                raise ParameterError(
                    "omega must be swept or fixed (e.g. omega=1.5 or params={'omega': 1.5}; "
                    "--set omega=1.5 on the command line)"
                )
        self.shape = spec.shape
        self.dims = spec.dims
        lead = len(self.dims) - len(spec.axes)  # 1 when there is a direction dimension
        self._lead = lead
        if spec.initial_conditions == "continuation":
            axis0 = lead + (1 if spec.family is not None else 0)
            chunks = [1] * len(self.shape)
            chunks[axis0] = self.shape[axis0]
            self.chain_axis: int | None = axis0
        else:
            last = self.shape[-1]
            if chunk_points is None:
                chunk_points = max(4, min(64, math.ceil(int(np.prod(self.shape)) / 64)))
            chunks = [1] * len(self.shape)
            chunks[-1] = min(last, int(chunk_points))
            self.chain_axis = None
        self.chunks = tuple(chunks)
        self._model_cache: dict[tuple[Any, ...], Any] = {}
        self.reference = self.system(tuple(0 for _ in self.shape))

    # ------------------------------------------------------------------ systems
    def values_at(self, idx: tuple[int, ...]) -> dict[str, Any]:
        """Parameter assignment (fixed overrides and axis values) of a grid point."""
        vals = dict(self.fixed)
        for k, a in enumerate(self.spec.axes):
            vals[a.name] = a.values[idx[self._lead + k]]
        return vals

    def system(self, idx: tuple[int, ...]) -> System:
        omega, changes = split_omega(self.values_at(idx))
        key = tuple(sorted(changes.items()))
        model = self._model_cache.get(key)
        if model is None:
            model = model_for(self.target, changes)
            if len(self._model_cache) > 4096:
                self._model_cache.clear()
            self._model_cache[key] = model
        if omega is None:
            assert self.fixed_omega is not None  # checked in __init__
            omega = self.fixed_omega
        return System(model, omega)

    def base_model(self) -> Any:
        """The model of the target with the fixed values (not a grid point's)."""
        return model_for(self.target, self._fixed_changes)

    # ------------------------------------------------------------------ tasks
    def tasks(self) -> Iterator[Task]:
        ranges = [range(0, n, c) for n, c in zip(self.shape, self.chunks, strict=True)]
        for ti, starts in enumerate(itertools.product(*ranges)):
            block = tuple(
                slice(s, min(s + c, n))
                for s, c, n in zip(starts, self.chunks, self.shape, strict=True)
            )
            idxs = list(itertools.product(*(range(b.start, b.stop) for b in block)))
            axis = self.chain_axis
            chains: tuple[tuple[tuple[int, ...], ...], ...]
            if axis is None:
                chains = tuple((i,) for i in idxs)
            else:
                d = self.spec.directions[block[0].start] if self._lead else self.spec.direction
                order = sorted(idxs, key=lambda i: i[axis], reverse=d == "down")
                chains = (tuple(order),)
            yield Task(ti, block, chains)

    @property
    def n_tasks(self) -> int:
        return int(
            np.prod([math.ceil(n / c) for n, c in zip(self.shape, self.chunks, strict=True)])
        )

    def task_run(self, task: Task) -> ChainRun:
        """The numbers a worker needs to run ``task``: its chains of packed systems."""
        spec = self.spec
        systems = [[self.system(i) for i in chain] for chain in task.chains]
        n = systems[0][0].n_state
        return ChainRun.from_systems(
            systems,
            spec.solver,
            n_tangent=int(spec.recorded_lyapunov),
            continuation=spec.initial_conditions == "continuation",
            # the random start of max_lyapunov: one λ₁ for a point, whatever computes it
            tangent_start=random_tangents(n, 1) if spec.recorded_lyapunov else None,
        )
