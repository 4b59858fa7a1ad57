"""Where ``gearchaos orbit`` and ``gearchaos continue`` start: ``--from PATH --at NAME=VALUE``.

PATH is a sweep store (the state a point of the sweep ended in), a branch file (the orbit of the
branch point nearest the value) or an orbit file (``gearchaos orbit -o ORBIT.nc``). The start
carries the gear set those files were computed for, the point's parameter values and the
section the state lies on, so that the shooting starts from the same state on the same section.
"""

from __future__ import annotations

import json
import math
import os
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._text import escape_path, escape_text
from ..errors import ParameterError, StoreError

OMEGA = "omega"
DIRECTION = "direction"
PERIOD_LABEL = re.compile(r"^(\d+)T$")


@dataclass(frozen=True)
class Start:
    """A start read from a file: gear set, parameter values (Ω included), the state on the
    section, the section's settings, the period the file knows (or None) and a description."""

    gearset: Any
    values: dict[str, Any]
    state: np.ndarray
    period: int | None
    source: str
    section: dict[str, float] = field(default_factory=dict)


def parse_at(text: str | None) -> dict[str, str]:
    """``--at omega=1.5,backlash.sun_planet=2`` as {name: text}; empty for None."""
    out: dict[str, str] = {}
    for item in [] if text is None else text.split(","):
        name, sep, value = item.partition("=")
        name, value = name.strip(), value.strip()
        if not sep or not name or not value:
            raise ParameterError(
                f"--at must be NAME=VALUE[,NAME=VALUE…], e.g. --at omega=1.5: got {text!r}"
            )
        if name in out:
            raise ParameterError(f"--at names {name} twice: got {text!r}")
        out[name] = value
    return out


def _number(name: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ParameterError(f"--at {name} must be a number: got {text!r}") from None
    if not math.isfinite(value):
        raise ParameterError(f"--at {name} must be finite: got {text!r}")
    return value


def name_model(model: str | None) -> type | None:
    """The class ``--model`` names, or ``None``: naming it is the user's consent to build it
    again from the files the command reads
    (:func:`~gearchaos.model.loading.load_model_class`); a file's own record never imports
    anything."""
    if model is None:
        return None
    from ..model.loading import load_model_class

    return load_model_class(model)


def load_start(path: str, at: str | None, model: str | None = None) -> Start:
    """The start at ``--at`` in the sweep store, branch file or orbit file ``path``; a model
    the file records is built again only when it is a reference system of gearchaos, or the
    one ``model`` (``--model``) names, or an installed one
    (:func:`~gearchaos.model.loading.rebuild_model`)."""
    if not isinstance(path, str) or not path:
        raise ParameterError(f"--from must be a path: got {path!r}")
    where = parse_at(at)
    named = name_model(model)
    if not os.path.lexists(path):
        raise ParameterError(f"--from {escape_path(path)}: no such file or directory")
    start = _load(path, where)
    if named is not None:
        target = start.gearset
        own = getattr(target, "model", None) if not hasattr(target, "evolve") else None
        if type(own) is not named:
            what = "a gear set" if own is None else f"the model {type(own).__qualname__}"
            raise ParameterError(
                f"--model {escape_text(model)} does not apply: --from {escape_path(path)} is of "
                f"{what}; drop --model"
            )
    return start


def _load(path: str, where: dict[str, str]) -> Start:
    from ..sweep.store import is_sweep_store

    if os.path.isdir(path) and is_sweep_store(path):
        return _from_store(path, where)
    from ..dynamics.branch import open_branch

    try:
        return _from_branch(path, open_branch(path), where)
    except StoreError:
        pass
    from ..dynamics.orbit_file import open_orbit

    try:
        ds = open_orbit(path)
    except StoreError:
        raise StoreError(
            f"--from {escape_path(path)} is no sweep store, branch file or orbit file of gearchaos"
        ) from None
    return _from_orbit(path, ds, where)


def _gearset(attrs: Any, path: str) -> Any:
    """The gear set a file records, or a :class:`~gearchaos.model.System` of the model it
    records (built only with the user's consent: ``--model``)."""
    from ..gearset import GearSet

    text = str(attrs.get("gearset_toml", ""))
    if not text:
        from ..model import System
        from ..model.loading import rebuild_model

        model = rebuild_model(attrs, where=f"--from {escape_path(path)}")
        if model is None:
            raise StoreError(
                f"--from {escape_path(path)}: its model is neither a gear set (no gearset_toml) "
                "nor one it records how to build (no model_class); start it from Python "
                "(periodic_orbit(system, guess=state))"
            )
        return System(model, 1.0)
    return GearSet.from_toml_string(text)


def _from_store(path: str, where: dict[str, str]) -> Start:
    from ..explore.compute import point_target
    from ..sweep.result import SweepResult

    res = SweepResult.open(path)
    ds = res.ds
    if res.base_gearset is None:  # a model the user has not named is refused, naming the file
        from ..model.loading import rebuild_model

        rebuild_model(ds.attrs, where=f"--from {escape_path(path)}")
    if "final_state" not in ds:
        raise StoreError(f"--from {path}: the store holds no final states to start from")
    index: dict[str, Any] = {}
    chosen: dict[str, float] = {}
    dims = [d for d in res.lead_dims]
    unknown = sorted(set(where) - set(dims))
    if unknown:
        raise ParameterError(
            f"--at names {', '.join(unknown)}, which {path} does not sweep; it sweeps "
            f"{', '.join(dims)}"
        )
    for dim in dims:
        coord = ds[dim].values
        if dim == DIRECTION:
            want = where.get(dim, str(coord[0]))
            if want not in [str(c) for c in coord]:
                raise ParameterError(
                    f"--at direction must be one of {', '.join(map(str, coord))}: got {want!r}"
                )
            index[dim] = want
            continue
        if dim not in where:
            if coord.size == 1:
                index[dim] = coord[0]
                chosen[dim] = float(coord[0])
                continue
            raise ParameterError(
                f"--at must name {dim} (the store sweeps it over {coord.size} values, "
                f"{coord.min():g} … {coord.max():g}), e.g. --at {dim}={coord[coord.size // 2]:g}"
            )
        value = _number(dim, where[dim])
        span = float(np.ptp(coord)) or 1.0
        k = int(np.argmin(np.abs(coord - value)))
        if abs(float(coord[k]) - value) > 1e-6 * span:
            near = ", ".join(f"{c:g}" for c in coord[max(0, k - 1) : k + 2])
            raise ParameterError(
                f"--at {dim}={value:g} is no point of {path}; the nearest stored values are {near}"
            )
        index[dim] = coord[k]
        chosen[dim] = float(coord[k])
    point = ds.sel(index)
    state = np.asarray(point["final_state"].values, dtype=np.float64)
    label = str(point["motion"].values) if "motion" in point else ""
    text = ", ".join(f"{k}={v:g}" for k, v in chosen.items())
    if int(point["status"].values) != 0 or not np.all(np.isfinite(state)):
        raise StoreError(f"--from {path} at {text}: that point's integration failed")
    gs, values = point_target(res, chosen)
    match = PERIOD_LABEL.match(label)
    spec = res.spec
    section = {}
    if spec is not None:
        section = {
            "section_phase": float(spec.solver.section_phase),
            "transient_periods": float(spec.solver.transient_periods),
        }
    return Start(
        gearset=gs,
        values=values,
        state=state,
        period=int(match.group(1)) if match else None,
        source=f"{escape_path(os.path.basename(path))} at {text}"
        + (f" ({escape_text(label)})" if label else ""),
        section=section,
    )


def _section(attrs: Any) -> dict[str, float]:
    return {k: float(attrs[k]) for k in ("section_phase", "transient_periods") if k in attrs}


def _from_branch(path: str, ds: Any, where: dict[str, str]) -> Start:
    target = _gearset(ds.attrs, path)  # a model the user has not named: refused first
    name = str(ds.attrs["parameter"])
    if set(where) != {name}:
        raise ParameterError(
            f"--at must name the branch's parameter alone for --from {path}: --at "
            f"{name}=VALUE; got {', '.join(where) or 'nothing'}"
        )
    value = _number(name, where[name])
    lam = np.asarray(ds[name].values, dtype=float)
    lo, hi = float(np.min(lam)), float(np.max(lam))
    if not lo <= value <= hi:
        raise ParameterError(
            f"--at {name}={value:g} is off the branch of {path}, which covers {lo:g} … {hi:g}"
        )
    k = int(np.argmin(np.abs(lam - value)))
    values = {str(key): _value(v) for key, v in json.loads(str(ds.attrs["fixed"])).items()}
    values[name] = value
    return Start(
        gearset=target,
        values=values,
        state=np.asarray(ds["orbit_state"].values[k], dtype=np.float64),
        period=int(ds.attrs["period"]),
        source=f"{escape_path(os.path.basename(path))} at {escape_text(name)}={value:g} "
        f"(branch point {k})",
        section=_section(ds.attrs),
    )


def _value(v: Any) -> Any:
    """A stored parameter value: numbers as float, text (``torque.mode``) as it is."""
    return v if isinstance(v, str) else float(v)


def _from_orbit(path: str, ds: Any, where: dict[str, str]) -> Start:
    target = _gearset(ds.attrs, path)  # a model the user has not named: refused first
    if where:
        raise ParameterError(f"--at does not apply to an orbit file ({path}): drop it")
    values = {
        key.partition(":")[2]: _value(v)
        for key, v in ds.attrs.items()
        if key.startswith("parameter:")
    }
    values[OMEGA] = float(ds.attrs["omega"])
    return Start(
        gearset=target,
        values=values,
        state=np.asarray(ds["orbit_state"].values, dtype=np.float64),
        period=int(ds.attrs["period"]),
        source=f"{escape_path(os.path.basename(path))} (period-{int(ds.attrs['period'])} orbit "
        f"at Ω = {values[OMEGA]:g})",
        section=_section(ds.attrs),
    )
