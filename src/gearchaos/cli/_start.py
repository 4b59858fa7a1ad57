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
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._checks import check_int, check_real
from .._text import escape_path, escape_text
from ..analysis.motion import Motion
from ..errors import ParameterError, StoreError
from ..model.target import Target

OMEGA = "omega"
DIRECTION = "direction"


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
        from ..model.record import model_title
        from ..model.target import model_for

        own = model_for(start.gearset, {})  # the model of the file's target
        if type(own) is not named:
            kind, name = model_title(own)
            raise ParameterError(
                f"--model {escape_text(model)} does not apply: --from {escape_path(path)} is of "
                f"the {kind} {escape_text(name)} ({type(own).__qualname__}); drop --model"
            )
    return start


def _names_a_sweep(path: str) -> bool:
    """Whether the directory ``path`` says it is a sweep store (its attributes hold
    ``sweep_toml``): read, not whether gearchaos may replace it (a store of an older version
    has no mark, and is read all the same)."""
    from ..sweep.integrity import read_json

    try:  # never through a link, never blocking on a FIFO
        attrs = read_json(os.path.join(path, ".zattrs"))
    except (OSError, ValueError):
        return False
    return isinstance(attrs, dict) and "sweep_toml" in attrs


def _load(path: str, where: dict[str, str]) -> Start:
    if os.path.isdir(path) and _names_a_sweep(path):
        return _from_store(path, where)
    from ..dynamics.continuation.branch import open_branch

    try:
        branch = open_branch(path)
    except StoreError as exc:
        branch, reason = None, str(exc)
    if branch is not None:  # a branch file: what is wrong with it is said, not tried as another
        return _from_branch(path, branch, where)
    from ..dynamics.orbits.file import open_orbit

    try:
        ds = open_orbit(path)
    except StoreError:
        raise StoreError(
            f"--from {escape_path(path)} is no sweep store, branch file or orbit file of "
            f"gearchaos (as a branch: {escape_text(reason)})"
        ) from None
    return _from_orbit(path, ds, where)


def _gearset(attrs: Any, path: str) -> Any:
    """The gear set a file records, or a :class:`~gearchaos.model.System` of the model it
    records (built only with the user's consent: ``--model``), read by the one reader of
    records (:func:`~gearchaos.model.record.recorded_target`)."""
    from ..model.record import recorded_gearset, recorded_target

    where = f"--from {escape_path(path)}"
    try:  # a damaged gear set (or two that differ) is a damaged file
        gearset = recorded_gearset(attrs, where=where)
    except ParameterError as exc:
        raise StoreError(str(exc)) from None
    target = recorded_target(attrs, gearset, where=where)
    if target is None:
        raise StoreError(
            f"{where}: its model is neither a gear set nor one it records how to build (no "
            "model_class); start it from Python (periodic_orbit(system, guess=state))"
        )
    return target


# ------------------------------------------------------------------ a file's attributes
#: Longest period of an orbit a file may record (the shooting's own bound).
MAX_PERIOD = 10_000
_MISSING = object()


def _damaged(path: str, key: str, rule: str, value: Any = _MISSING) -> StoreError:
    """The refusal of a file's attribute ``key`` that is missing or breaks ``rule``: one line
    naming the file, the attribute and the rule."""
    where = f"--from {escape_path(path)}"
    if value is _MISSING:
        return StoreError(
            f"{where}: the attribute {key} is missing ({rule}); the file is damaged or was not "
            "written by gearchaos"
        )
    plain = value.item() if isinstance(value, np.generic) else value
    shown = escape_text(repr(plain))
    shown = shown if len(shown) <= 60 else shown[:57] + "..."
    return StoreError(
        f"{where}: the attribute {key} must be {rule}: got {shown}; the file is damaged"
    )


def _int_attr(attrs: Any, key: str, path: str, lo: int, hi: int) -> int:
    """The integer attribute ``key`` in [lo, hi]."""
    value = attrs.get(key, _MISSING)
    rule = f"an integer in [{lo}, {hi}]"
    if value is _MISSING:
        raise _damaged(path, key, rule)
    try:
        return check_int(key, value, lo=lo, hi=hi)
    except ParameterError:
        raise _damaged(path, key, rule, value) from None


def _real_attr(
    attrs: Any, key: str, path: str, *, lo: float | None = None, lo_open: bool = False
) -> float:
    """The finite number attribute ``key`` (>= ``lo``, or > with ``lo_open``)."""
    value = attrs.get(key, _MISSING)
    rule = "a finite number" + ("" if lo is None else f" {'>' if lo_open else '>='} {lo:g}")
    if value is _MISSING:
        raise _damaged(path, key, rule)
    try:
        return check_real(key, value, lo=lo, lo_open=lo_open)
    except ParameterError:
        raise _damaged(path, key, rule, value) from None


def _text_attr(attrs: Any, key: str, path: str) -> str:
    value = attrs.get(key, _MISSING)
    if value is _MISSING:
        raise _damaged(path, key, "text")
    if not isinstance(value, str) or not value:
        raise _damaged(path, key, "text", value)
    return value


def _parameters(attrs: Any, path: str) -> dict[str, Any]:
    """The ``parameter:NAME`` attributes: numbers as float, text (``torque.mode``) as it is."""
    values: dict[str, Any] = {}
    for key, v in attrs.items():
        if not key.startswith("parameter:"):
            continue
        if isinstance(v, str):
            values[key.partition(":")[2]] = v
        else:
            values[key.partition(":")[2]] = _real_attr(attrs, key, path)
    return values


def _fixed(attrs: Any, path: str) -> dict[str, Any]:
    """A branch file's ``fixed`` attribute: a JSON object of parameter values."""
    text = attrs.get("fixed", _MISSING)
    if text is _MISSING:
        raise _damaged(path, "fixed", "a JSON object of parameter values")
    try:
        raw = json.loads(str(text))
    except ValueError:
        raw = None
    if not isinstance(raw, dict):
        raise _damaged(path, "fixed", "a JSON object of parameter values", text)
    values: dict[str, Any] = {}
    for key, v in raw.items():
        if isinstance(v, str):
            values[str(key)] = v
        elif isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v):
            values[str(key)] = float(v)
        else:
            raise _damaged(path, "fixed", f"a JSON object of parameter values ({key})", text)
    return values


def _state(values: Any, path: str, target: Target, params: dict[str, Any], what: str) -> np.ndarray:
    """The state ``values`` (the file's ``what``) as a vector of the states of the model at the
    recorded parameter values ``params``: the values, the state's length and its finiteness
    are the file's, checked before any shooting starts from it."""
    from ..model.target import resolve

    try:
        state = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise _damaged(path, what, "a vector of numbers", values) from None
    try:
        n = resolve(target, params).n_state
    except ParameterError as exc:
        raise StoreError(
            f"--from {escape_path(path)}: its recorded parameter values do not fit its model "
            f"({escape_text(exc)}); the file is damaged"
        ) from None
    if state.shape != (n,):
        raise StoreError(
            f"--from {escape_path(path)}: its {what} has shape {state.shape}, but the model it "
            f"records has {n} states; the file is damaged"
        )
    bad = int(np.sum(~np.isfinite(state)))
    if bad:
        raise StoreError(
            f"--from {escape_path(path)}: its {what} has {bad} entries that are NaN or "
            "infinite; the file is damaged"
        )
    return state


def _from_store(path: str, where: dict[str, str]) -> Start:
    from ..explore.compute import point_target
    from ..model.record import recorded_target
    from ..sweep.result import SweepResult

    res = SweepResult.open(path)
    ds = res.ds
    # the store's target: a model the user has not named is refused, naming the file
    recorded_target(ds.attrs, where=f"--from {escape_path(path)}")
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
        k = _stored_index(np.asarray(coord, dtype=float), value)
        if k is None:
            j = int(np.argmin(np.abs(coord - value)))
            near = _distinct(np.asarray(coord[max(0, j - 1) : j + 2], dtype=float))
            raise ParameterError(
                f"--at {dim}={where[dim]} is no point of {escape_path(path)}; the nearest stored "
                f"values are {near}: give one of them"
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
    period = Motion.parse(label).period  # the empty label of a store without verdicts: 0
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
        period=period or None,
        source=f"{escape_path(os.path.basename(path))} at {text}"
        + (f" ({escape_text(label)})" if label else ""),
        section=section,
    )


def _stored_index(coord: np.ndarray, value: float) -> int | None:
    """The index of the stored coordinate ``--at`` names: the only one within 1e-6 of the
    axis's span or equal to ``value`` at the 6 significant digits the refusal prints (so
    1.33333 names 4/3); None for none or more than one."""
    gap = np.abs(coord - value)
    digit = 10.0 ** (math.floor(math.log10(abs(value))) - 5) if value != 0 else 0.0
    tol = max(1e-6 * (float(np.ptp(coord)) or 1.0), 0.5 * digit * (1 + 1e-9))
    near = np.flatnonzero(gap <= tol)
    return int(near[np.argmin(gap[near])]) if near.size == 1 else None


def _distinct(values: np.ndarray) -> str:
    """``values`` with the fewest significant digits (6 or more) that tell them apart, as the
    user can type them back."""
    for digits in range(6, 18):
        shown = [f"{v:.{digits}g}" for v in values]
        if len(set(shown)) == len(shown):
            return ", ".join(shown)
    return ", ".join(repr(float(v)) for v in values)


def _section(attrs: Any, path: str) -> dict[str, float]:
    """The section the recorded state lies on: ``section_phase`` and ``transient_periods``."""
    out = {}
    if "section_phase" in attrs:
        out["section_phase"] = _real_attr(attrs, "section_phase", path)
    if "transient_periods" in attrs:
        out["transient_periods"] = _real_attr(attrs, "transient_periods", path, lo=0.0)
    return out


def _from_branch(path: str, ds: Any, where: dict[str, str]) -> Start:
    target = _gearset(ds.attrs, path)  # a model the user has not named: refused first
    name = _text_attr(ds.attrs, "parameter", path)
    if name not in ds:
        raise _damaged(path, "parameter", "the name of the branch's parameter", name)
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
    values = _fixed(ds.attrs, path)
    values[name] = value
    return Start(
        gearset=target,
        values=values,
        state=_state(ds["orbit_state"].values[k], path, target, values, f"orbit_state[{k}]"),
        period=_int_attr(ds.attrs, "period", path, 1, MAX_PERIOD),
        source=f"{escape_path(os.path.basename(path))} at {escape_text(name)}={value:g} "
        f"(branch point {k})",
        section=_section(ds.attrs, path),
    )


def _from_orbit(path: str, ds: Any, where: dict[str, str]) -> Start:
    target = _gearset(ds.attrs, path)  # a model the user has not named: refused first
    if where:
        raise ParameterError(f"--at does not apply to an orbit file ({path}): drop it")
    values = _parameters(ds.attrs, path)
    values[OMEGA] = _real_attr(ds.attrs, OMEGA, path, lo=0.0, lo_open=True)
    period = _int_attr(ds.attrs, "period", path, 1, MAX_PERIOD)
    return Start(
        gearset=target,
        values=values,
        state=_state(ds["orbit_state"].values, path, target, values, "orbit_state"),
        period=period,
        source=f"{escape_path(os.path.basename(path))} (period-{period} orbit "
        f"at Ω = {values[OMEGA]:g})",
        section=_section(ds.attrs, path),
    )
