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

import dataclasses
import itertools
import math
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..model.system import System
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


def _default_omega(target: Any, fixed: dict[str, Any]) -> float | None:
    if "omega" in fixed:
        return float(fixed["omega"])
    if isinstance(target, System):
        return target.omega
    return None


class Grid:
    """Maps grid indices to systems and lays out tasks for a spec and a target."""

    def __init__(self, target: Any, spec: SweepSpec, *, chunk_points: int | None = None):
        from ..gearset import GearSet

        self.spec = spec
        self.target = target
        self.fixed = dict(spec.fixed)
        self.is_gearset = isinstance(target, GearSet)
        if not self.is_gearset and not isinstance(target, System):
            raise ParameterError(
                f"target must be a GearSet or a System: got {type(target).__name__}"
            )
        names = [a.name for a in spec.axes]
        if "omega" not in names and _default_omega(target, self.fixed) is None:
            raise ParameterError(
                "omega must be swept or fixed (e.g. fixed={'omega': 1.5} or --set omega=1.5)"
            )
        self._validate_names()
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
        first = self.system(tuple(0 for _ in self.shape))
        self.reference = first

    # ------------------------------------------------------------------ names
    def _validate_names(self) -> None:
        names = [a.name for a in self.spec.axes] + list(self.fixed)
        if self.is_gearset:
            from ..gearset.io import field_names

            valid = set(field_names()) | {"xi", "omega"}
        else:
            model = self.target.model
            if not dataclasses.is_dataclass(model):
                valid = {"omega"}
            else:
                skip = {"kind", "name", "n_state", "n_track", "state_names", "obs_names"}
                valid = {f.name for f in dataclasses.fields(model) if f.name not in skip}
                valid.add("omega")
        for n in names:
            if n not in valid:
                import difflib

                close = difflib.get_close_matches(n, sorted(valid), n=1)
                hint = f"; did you mean {close[0]!r}?" if close else ""
                raise ParameterError(f"unknown sweep parameter {n!r}{hint}")

    # ------------------------------------------------------------------ systems
    def values_at(self, idx: tuple[int, ...]) -> dict[str, Any]:
        """Parameter assignment (fixed overrides and axis values) of a grid point."""
        vals = dict(self.fixed)
        for k, a in enumerate(self.spec.axes):
            vals[a.name] = a.values[idx[self._lead + k]]
        return vals

    def system(self, idx: tuple[int, ...]) -> System:
        vals = self.values_at(idx)
        omega = vals.pop("omega", None)
        key = tuple(sorted(vals.items()))
        model = self._model_cache.get(key)
        if model is None:
            model = self._build_model(vals)
            if len(self._model_cache) > 4096:
                self._model_cache.clear()
            self._model_cache[key] = model
        if omega is None:
            omega = _default_omega(self.target, {})
        return System(model, float(omega))

    def _build_model(self, vals: dict[str, Any]) -> Any:
        if self.is_gearset:
            from ..model.planetary import PlanetaryModel

            gs = self.target.evolve(vals) if vals else self.target
            return PlanetaryModel.from_gearset(gs)
        model = self.target.model
        if not vals:
            return model
        return dataclasses.replace(model, **vals)

    def gearset_at(self, idx: tuple[int, ...]) -> Any:
        vals = self.values_at(idx)
        vals.pop("omega", None)
        return self.target.evolve(vals) if self.is_gearset else None

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

    def task_arrays(self, task: Task) -> dict[str, Any]:
        """The numbers a worker needs to run ``task`` (packed per chain and point)."""
        spec = self.spec
        L = max(len(c) for c in task.chains)
        C = len(task.chains)
        systems = [[self.system(i) for i in chain] for chain in task.chains]
        ref = systems[0][0]
        np_ = ref.params.size
        P = np.zeros((C, L, np_))
        SW = np.full((C, L, ref.n_track), np.inf)
        T = np.ones((C, L))
        for c, chain in enumerate(systems):
            for j, s in enumerate(chain):
                if s.params.size != np_ or s.kind != ref.kind:
                    raise ParameterError(
                        "a sweep cannot change the number of planets or the model kind "
                        f"between points: {s.name} differs from {ref.name}"
                    )
                P[c, j] = s.params
                SW[c, j] = s.switch_widths
                T[c, j] = s.period
        t_rec = spec.transient_periods * T
        return {
            "kind": ref.kind,
            "Y0": np.zeros((C, ref.n_state * (1 + int(spec.lyapunov)))),
            "n_tangent": int(spec.lyapunov),
            "P": P,
            "SW": SW,
            "t_rec": t_rec,
            "dt": T.copy(),
            "n_samples": int(spec.periods),
            "t_end": t_rec + spec.periods * T,
            "n_obs": ref.n_obs,
            "n_track": ref.n_track,
            "n_state": ref.n_state,
            "rtol": float(spec.rtol),
            "atol": float(spec.atol),
            "max_steps": int(100_000 + 50_000 * (spec.transient_periods + spec.periods)),
            "continuation": spec.initial_conditions == "continuation",
        }
