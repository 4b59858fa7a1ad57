"""Basin fractions across a parameter: :func:`basin_fractions` and :func:`fractions`.

At every value of one parameter, ``starts`` random initial states (the same seeded uniform
draws at every value: common random numbers, so differences between values are not sampling
noise of different draws) are labelled by the attractor they reach exactly as the starts of a
basin image are (:mod:`gearchaos.sweep.basins`); attractors of neighbouring values are linked
into tracks (:func:`~gearchaos.dynamics.attractors.basins.link_tracks`), and :func:`fractions`
gives the
share of starts on each track with its Wilson confidence interval
(:func:`~gearchaos.analysis.fractions.wilson_interval`): "how likely is rattle at this speed".
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from typing import Any

import numpy as np

from .._checks import check_bool, check_int, check_real
from ..dynamics.attractors.basins import FAILED
from ..dynamics.verdict.decide import CONFIRM_PERIODS
from ..errors import ParameterError
from ..integrate.settings import SolverSettings
from ..model.target import Target, resolve
from .basins import (
    _base_state,
    _Job,
    _jsonable,
    _match_options,
    _run,
    _split,
    check_starts_memory,
)
from .spec import parse_axis

__all__ = ["basin_fractions", "fractions"]


def _box_starts(
    target: Target,
    values: list[dict[str, Any]],
    box: Any,
    base_state: Any,
    starts: int,
    seed: int,
    cfg: SolverSettings,
) -> np.ndarray:
    """(P, S, n) starts: the same seeded uniform draws u ∈ [−1, 1]ⁿ at every parameter value
    (common random numbers), mapped to the box."""
    from ..integrate.simulate import integrate

    systems = [resolve(target, v) for v in values]
    n, names = systems[0].n_state, list(systems[0].state_names)
    u = np.random.default_rng(seed).uniform(-1.0, 1.0, (starts, n))
    out = np.empty((len(values), starts, n))
    base = _base_state(systems[0], base_state)
    if box is not None and not isinstance(box, Mapping):
        raise ParameterError(f"box must be a mapping of state names to (low, high): got {box!r}")
    for p, system in enumerate(systems):
        if box is None:  # around the motion from rest: mid ± 2·range of every component
            st = np.asarray(integrate(system, cfg.replace(samples_per_period=16)).states)
            st = (
                st[np.all(np.isfinite(st), axis=1)]
                if np.any(np.all(np.isfinite(st), axis=1))
                else np.zeros((1, n))
            )
            lo, hi = st.min(axis=0), st.max(axis=0)
            mid = 0.5 * (lo + hi)
            span = np.maximum(hi - lo, 1e-3 * np.maximum(1.0, np.abs(mid)))
            out[p] = mid + 2.0 * u * span
            continue
        out[p] = base
        for k, bounds in box.items():
            if k not in names:
                raise ParameterError(
                    f"box names an unknown state {k!r}: the states are {', '.join(names)}"
                )
            try:
                lo_, hi_ = (float(b) for b in bounds)
            except (TypeError, ValueError):
                raise ParameterError(f"box[{k!r}] must be (low, high): got {bounds!r}") from None
            if not (np.isfinite(lo_) and np.isfinite(hi_) and lo_ < hi_):
                raise ParameterError(f"box[{k!r}] must be finite with low < high: got {bounds!r}")
            j = names.index(k)
            out[p, :, j] = 0.5 * (lo_ + hi_) + 0.5 * (hi_ - lo_) * u[:, j]
    return out


def basin_fractions(
    target: Target,
    vary: Any,
    *,
    starts: int = 200,
    box: Mapping[str, Any] | None = None,
    base_state: Any = None,
    seed: int = 0,
    confidence: float = 0.95,
    params: Mapping[str, Any] | None = None,
    settings: SolverSettings | None = None,
    store: str | os.PathLike[str] | None = None,
    overwrite: bool = False,
    progress: bool = True,
    sample: int = 16,
    tol: float = 1e-4,
    spread_fraction: float = 0.25,
    confirm_periods: int = CONFIRM_PERIODS,
    chunk_points: int = 1000,
    **values_and_settings: Any,
) -> Any:
    """Across a parameter, the fraction of random starts ending on each attractor.

    At every value of ``vary`` (``"omega=1:2:40"``), ``starts`` initial states are drawn
    uniformly in ``box`` (a mapping ``{state: (low, high)}``, the other states at
    ``base_state``; None: every state in mid ± 2·range of the motion from rest there), with
    the same seeded draws at every value. Each start is labelled as in :func:`basins`;
    attractors of neighbouring values are linked into tracks
    (:func:`~gearchaos.dynamics.attractors.basins.link_tracks`). Other arguments as for
    :func:`basins`
    (``confirm_periods``: the last window that confirms a chaotic or QP attractor, default
    2000, stored in the ``confirm_periods`` attribute).

    Returns
    -------
    xarray.Dataset
        The store's variables (dims: the parameter, ``start``; ``initial_state`` too) and
        :func:`fractions` of them: ``fraction``, ``fraction_low``, ``fraction_high`` and
        ``count`` by (parameter, ``track``: an attractor followed across the parameter), the
        Wilson interval at ``confidence``.
    """
    kw = dict(values_and_settings)
    values, cfg, where = _split(kw, settings, params, basin_fractions, target)
    ax = parse_axis(vary)
    if ax.name in values:
        raise ParameterError(f"{ax.name} is both varied and fixed; choose one")
    n_starts = check_int("starts", starts, lo=1, hi=10_000_000)
    seed = check_int("seed", seed, lo=0)
    sample = check_int("sample", sample, lo=1, hi=10_000)
    check_real("confidence", confidence, lo=0.0, hi=1.0, lo_open=True, hi_open=True)
    match = _match_options(tol, spread_fraction, confirm_periods)
    row_values = [{**values, ax.name: v} for v in ax.values]
    n_state = resolve(target, row_values[0]).n_state
    check_starts_memory(
        "the basin fractions vary × starts", len(ax.values), n_starts, n_state, "starts"
    )
    pts = _box_starts(target, row_values, box, base_state, n_starts, seed, cfg)
    spec = {
        "vary": [ax.name, list(ax.values)],
        "starts": n_starts,
        "box": None if box is None else {k: [float(b) for b in v] for k, v in sorted(box.items())},
        "base_state": None
        if base_state is None
        else [float(v) for v in _base_state(resolve(target, row_values[0]), base_state)],
        "values": {k: _jsonable(v) for k, v in sorted(values.items())},
        "sample": sample,
        "seed": seed,
        **match,
    }
    job = _Job(
        target,
        "basin_fractions",
        (ax.name, "start"),
        {ax.name: np.array(ax.values), "start": np.arange(n_starts)},
        row_values,
        pts,
        cfg,
        spec,
        check_int("chunk_points", chunk_points, lo=1),
    )
    ds = _run(
        job,
        store,
        check_bool("overwrite", overwrite),
        where,
        check_bool("progress", progress),
        sample,
        seed,
        match,
    )
    return ds.merge(fractions(ds, confidence=confidence))


def fractions(ds: Any, *, confidence: float = 0.95) -> Any:
    """Basin fractions of a ``basin_fractions`` store: per parameter value and attractor
    track, the ``count`` of starts, the ``fraction`` and its Wilson interval
    ``fraction_low``/``fraction_high`` (:func:`~gearchaos.analysis.fractions.wilson_interval`),
    with the coordinates ``track`` (the attractor's track id; −2 the failed starts),
    ``track_label``, ``track_found_at`` (the parameter value where the track's attractor is
    first found) and ``track_position`` (there, the first state of its first section point, or
    the median over its set; NaN for the failed starts)."""
    import xarray as xr

    from ..analysis.fractions import wilson_interval

    if ds.attrs.get("kind") != "basin_fractions":
        raise ParameterError(
            f"fractions need a basin_fractions store: got kind {ds.attrs.get('kind')!r}"
        )
    param = ds.attrs["dims"][0]
    codes = np.asarray(ds["attractor"].values)
    cats = json.loads(ds.attrs["attractors"])
    tracks = json.loads(ds.attrs["tracks"])
    ids = sorted({t for row in tracks for t in row})
    labels: dict[int, str] = {}
    for p, row in enumerate(tracks):
        for c, t in enumerate(row):
            labels.setdefault(t, cats[str(p)]["entries"][c]["label"])
    has_failed = bool(np.any(codes == FAILED))
    cols = ids + ([FAILED] if has_failed else [])
    count = np.zeros((codes.shape[0], len(cols)), dtype=np.int64)
    col = {t: j for j, t in enumerate(cols)}
    for p in range(codes.shape[0]):
        for c in np.unique(codes[p]):
            if c == FAILED:
                count[p, col[FAILED]] = int(np.sum(codes[p] == c))
            elif c >= 0:
                count[p, col[tracks[p][int(c)]]] += int(np.sum(codes[p] == c))
    present = np.zeros(count.shape, dtype=bool)
    found: dict[int, tuple[float, float]] = {}  # track -> (parameter value, first state there)
    for p, row in enumerate(tracks):
        for c, t in enumerate(row):
            present[p, col[t]] = True
            if t not in found:
                from ..dynamics.attractors.basins import BasinAttractor

                e = BasinAttractor.from_record(cats[str(p)]["entries"][c])
                where = e.section_states[0, 0] if e.period else np.median(e.section_states[:, 0])
                found[t] = (float(ds[param].values[p]), float(where))
    if has_failed:
        present[:, col[FAILED]] = True
    nan2 = (math.nan, math.nan)
    n = np.sum(codes != -1, axis=1)[:, None]
    low, high = wilson_interval(count, np.broadcast_to(n, count.shape), confidence)
    with np.errstate(invalid="ignore", divide="ignore"):
        frac = count / n
    dims = (param, "track")
    out = xr.Dataset(
        {
            "count": (dims, count),
            "fraction": (dims, frac),
            "fraction_low": (dims, low),
            "fraction_high": (dims, high),
            "present": (dims, present),
        },
        coords={
            param: ds[param].values,
            "track": np.array(cols),
            "track_label": (
                "track",
                np.array([labels.get(t, "failed") for t in cols], dtype="U10"),
            ),
            "track_found_at": ("track", np.array([found.get(t, nan2)[0] for t in cols])),
            "track_position": ("track", np.array([found.get(t, nan2)[1] for t in cols])),
        },
    )
    out["fraction"].attrs["confidence"] = float(confidence)
    out["fraction"].attrs["interval"] = "Wilson score interval"
    return out
