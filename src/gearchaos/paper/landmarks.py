"""The seed paper's quantitative statements (Section 3) as data, and their check on sweep stores.

``landmarks.toml`` (packaged beside this module; a copy sits at the repository's
``paper/landmarks.toml``) holds one ``[[landmark]]`` per statement of Sheng et al. (2016)
about Figs. 4–12: the swept axis, the panel and fixed parameters, and one of three kinds:

``label``
    the motion label is one of ``expected`` over ``[lo, hi]`` (or within ``±tolerance`` of
    ``at``). Score ``min(1, f / min_fraction)`` with ``f`` the fraction of grid points whose
    label is expected; *holds* when ``f ≥ min_fraction`` (0.8 unless the landmark says
    otherwise), *partly* when ``f ≥ min_fraction / 2``.
``transition``
    reading the axis upwards, a point labelled in ``from`` is followed by one labelled in
    ``expected``, at ``at`` (or anywhere inside ``[lo, hi]``). The change is placed at the
    midpoint of the two points (``failed`` and ``unresolved`` points are skipped); ``d`` is the
    distance of the nearest change to ``at`` (or to ``[lo, hi]``). Score 1 (*holds*) for
    ``d ≤ tol``, 0.75 → 0.25 (*partly*) for ``tol < d ≤ 3 tol``, then down to 0 at ``6 tol``.
``window``
    a regime window ``lo``–``hi``: score ``0.5 min(1, f / min_fraction) + 0.25 s_lo + 0.25 s_hi``
    with ``f`` the fraction of points inside carrying an expected label and ``s_lo``, ``s_hi``
    the distance scores (as for transitions) of the window's measured edges (the nearest entry
    into / exit from the expected labels). *holds* ≥ 0.8, *partly* ≥ 0.4.

The label ``nT`` in a landmark stands for any n-periodic label with n ≥ 2.

>>> from gearchaos.paper.landmarks import load_landmarks, evaluate_all, score
>>> marks = load_landmarks()
>>> results = evaluate_all(marks, {"fig4": ds4})   # doctest: +SKIP
>>> score(results)                                  # doctest: +SKIP

Limits: a landmark is checked on the motion labels of one planet-independent sweep store; the
seed's own reading of its figures was by eye, so the verdicts measure agreement with the
labels, not with the seed's pictures. Amplitude statements are not landmarks.
"""

from __future__ import annotations

import math
import re
import tomllib
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from types import MappingProxyType
from typing import Any, Literal

import numpy as np

from .._files import read_text_file
from ..errors import ParameterError
from ..gearset.mapping import flatten
from ..sweep.result import SweepResult

__all__ = [
    "AXES",
    "KINDS",
    "Landmark",
    "LandmarkResult",
    "evaluate",
    "evaluate_all",
    "load_landmarks",
    "recipe_for",
    "score",
]

#: Swept axes a landmark may name.
AXES = ("omega", "xi", "backlash.sun_planet", "backlash.planet_ring", "clearance.sun_bearing")
#: Landmark kinds.
KINDS = ("label", "transition", "window")
#: Gallery → the bifurcation recipe whose sweep covers its statements.
_GALLERY_RECIPE = {"fig5": "fig4", "fig7": "fig6", "fig10": "fig9"}
#: Labels that say nothing about the motion: skipped when locating changes.
_NO_LABEL = ("failed", "unresolved")
_LABEL_RE = re.compile(r"^(?:[1-9][0-9]*T|nT|QP|chaos)$")
_PERIOD_RE = re.compile(r"^([1-9][0-9]*)T$")
_REL = 1e-9

Verdict = Literal["holds", "partly", "does not hold", "not evaluated"]


def _freeze(d: Mapping[str, float]) -> Mapping[str, float]:
    return MappingProxyType(dict(d))


@dataclass(frozen=True)
class Landmark:
    """One quantitative statement of the seed's Section 3.

    Attributes
    ----------
    id, figure, quote, note
        Name, seed figure (``fig4`` … ``fig12``), the seed's words, readings/contradictions.
    panel
        Family value(s) of the covering sweep, e.g. ``{"xi": 0.03}`` (also in ``fixed``).
    axis
        Swept parameter (dotted name).
    kind
        ``label``, ``transition`` or ``window``.
    lo, hi, at
        Range or value in axis units (``at`` xor ``lo``/``hi``; a window needs ``lo``/``hi``).
    expected
        Accepted labels (after the change for a transition); ``nT`` = any n ≥ 2 period.
    from_labels
        Accepted labels before the change (transitions; TOML key ``from``).
    fixed
        Every other parameter by dotted name.
    tolerance
        In axis units.
    min_fraction
        Fraction of points with an expected label needed for *holds* (label, window).
    """

    id: str
    figure: str
    panel: Mapping[str, float] = field(hash=False)
    quote: str
    axis: str
    kind: str
    expected: tuple[str, ...]
    fixed: Mapping[str, float] = field(hash=False)
    tolerance: float
    lo: float | None = None
    hi: float | None = None
    at: float | None = None
    from_labels: tuple[str, ...] = ()
    min_fraction: float = 0.8
    note: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "panel", _freeze(self.panel))
        object.__setattr__(self, "fixed", _freeze(self.fixed))

    @property
    def span(self) -> tuple[float, float]:
        """``(lo, hi)``, or ``(at, at)``."""
        if self.at is not None:
            return (self.at, self.at)
        assert self.lo is not None and self.hi is not None
        return (self.lo, self.hi)

    def where(self) -> str:
        """``"omega = 1.926"`` or ``"omega ∈ [2.45, 3.03]"``."""
        if self.at is not None:
            return f"{self.axis} = {self.at:g}"
        return f"{self.axis} ∈ [{self.lo:g}, {self.hi:g}]"


@dataclass(frozen=True)
class LandmarkResult:
    """Verdict of one landmark on one sweep: ``score`` in [0, 1], ``evidence`` in words with
    the numbers, ``measured`` the numbers themselves."""

    landmark: Landmark
    verdict: Verdict
    score: float
    evidence: str
    measured: Mapping[str, Any] = field(default_factory=dict, hash=False)


# ------------------------------------------------------------------------------ loading
def _number(where: str, key: str, v: Any) -> float:
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
        raise ParameterError(f"{where}: {key} must be a finite number: got {v!r}")
    return float(v)


def _labels(where: str, key: str, v: Any) -> tuple[str, ...]:
    if not isinstance(v, list) or not v or not all(isinstance(x, str) for x in v):
        raise ParameterError(f"{where}: {key} must be a non-empty list of labels: got {v!r}")
    bad = [x for x in v if not _LABEL_RE.match(x)]
    if bad:
        raise ParameterError(
            f"{where}: {key} labels must be 1T, 2T, …, nT, QP or chaos: got {', '.join(bad)}"
        )
    return tuple(v)


def _params(where: str, key: str, v: Any) -> dict[str, float]:
    if not isinstance(v, Mapping):
        raise ParameterError(f"{where}: {key} must be a table of parameters: got {v!r}")
    flat = flatten(v)
    for name in flat:
        if name not in AXES:
            raise ParameterError(f"{where}: {key}.{name} is not one of {', '.join(AXES)}")
    return {k: _number(where, f"{key}.{k}", x) for k, x in flat.items()}


_KEYS = {
    "id", "figure", "panel", "quote", "axis", "kind", "lo", "hi", "at", "expected", "from",
    "fixed", "tolerance", "min_fraction", "note",
}  # fmt: skip


def _landmark(i: int, d: Mapping[str, Any]) -> Landmark:
    where = f"landmark #{i + 1}" + (f" ({d['id']})" if isinstance(d.get("id"), str) else "")
    unknown = sorted(set(d) - _KEYS)
    if unknown:
        raise ParameterError(f"{where}: unknown keys {', '.join(unknown)}")
    for key in ("id", "figure", "panel", "quote", "axis", "kind", "expected", "fixed"):
        if key not in d:
            raise ParameterError(f"{where}: {key} is required")
    for key in ("id", "figure", "quote", "axis", "kind"):
        if not isinstance(d[key], str) or not d[key]:
            raise ParameterError(f"{where}: {key} must be a non-empty string: got {d[key]!r}")
    if not re.match(r"^fig[0-9]+$", d["figure"]):
        raise ParameterError(f"{where}: figure must look like 'fig4': got {d['figure']!r}")
    if d["axis"] not in AXES:
        raise ParameterError(f"{where}: axis must be one of {', '.join(AXES)}: got {d['axis']!r}")
    if d["kind"] not in KINDS:
        raise ParameterError(f"{where}: kind must be one of {', '.join(KINDS)}: got {d['kind']!r}")
    panel = _params(where, "panel", d["panel"])
    fixed = _params(where, "fixed", d["fixed"])
    if d["axis"] in fixed:
        raise ParameterError(f"{where}: the swept axis {d['axis']} must not be in fixed")
    for k, v in panel.items():
        if k not in fixed or not math.isclose(fixed[k], v, rel_tol=_REL, abs_tol=0.0):
            raise ParameterError(f"{where}: panel {k} = {v:g} must equal fixed.{k}")
    lo = _number(where, "lo", d["lo"]) if "lo" in d else None
    hi = _number(where, "hi", d["hi"]) if "hi" in d else None
    at = _number(where, "at", d["at"]) if "at" in d else None
    if at is not None and (lo is not None or hi is not None):
        raise ParameterError(f"{where}: give either at or lo/hi, not both")
    if at is None and (lo is None or hi is None):
        raise ParameterError(f"{where}: give at, or both lo and hi")
    if lo is not None and hi is not None and not lo < hi:
        raise ParameterError(f"{where}: lo must be below hi: got {lo:g}, {hi:g}")
    if d["kind"] == "window" and at is not None:
        raise ParameterError(f"{where}: a window needs lo and hi, not at")
    expected = _labels(where, "expected", d["expected"])
    if d["kind"] == "transition":
        if "from" not in d:
            raise ParameterError(f"{where}: a transition needs from")
        from_labels = _labels(where, "from", d["from"])
    elif "from" in d:
        raise ParameterError(f"{where}: from is only for transitions")
    else:
        from_labels = ()
    min_fraction = _number(where, "min_fraction", d.get("min_fraction", 0.8))
    if not 0.0 < min_fraction <= 1.0:
        raise ParameterError(f"{where}: min_fraction must be in (0, 1]: got {min_fraction:g}")
    note = d.get("note", "")
    if not isinstance(note, str):
        raise ParameterError(f"{where}: note must be a string: got {note!r}")
    mark = Landmark(
        id=d["id"],
        figure=d["figure"],
        panel=panel,
        quote=d["quote"],
        axis=d["axis"],
        kind=d["kind"],
        expected=expected,
        fixed=fixed,
        tolerance=1.0,
        lo=lo,
        hi=hi,
        at=at,
        from_labels=from_labels,
        min_fraction=min_fraction,
        note=note,
    )
    if "tolerance" in d:
        tol = _number(where, "tolerance", d["tolerance"])
    else:
        from .recipes import RECIPES

        vary = RECIPES[recipe_for(mark)].vary
        tol = 0.02 * (vary.stop - vary.start)
    if not tol > 0.0:
        raise ParameterError(f"{where}: tolerance must be > 0: got {tol:g}")
    object.__setattr__(mark, "tolerance", tol)
    return mark


#: Largest landmarks file read (the packaged one has about 30 kB).
MAX_LANDMARKS_BYTES = 4 * 2**20


def load_landmarks(path: str | Path | None = None) -> list[Landmark]:
    """Read and validate the landmarks (default: the packaged ``landmarks.toml``).

    Raises
    ------
    ParameterError
        A landmark breaks a rule (the message names it, the key, the rule and the value), or
        two landmarks share an id.
    """
    if path is None:
        text = resources.files(__package__).joinpath("landmarks.toml").read_text("utf-8")
        source = "landmarks.toml (packaged)"
    else:
        text = read_text_file(path, what="landmarks file", max_bytes=MAX_LANDMARKS_BYTES)
        source = str(path)
    try:
        data = tomllib.loads(text)
    except (tomllib.TOMLDecodeError, RecursionError, ValueError) as exc:
        raise ParameterError(f"{source}: not valid TOML: {exc}") from None
    rows = data.get("landmark")
    if not isinstance(rows, list) or not rows:
        raise ParameterError(f"{source}: needs at least one [[landmark]] table")
    marks = [_landmark(i, d) for i, d in enumerate(rows)]
    dup = [k for k, n in Counter(m.id for m in marks).items() if n > 1]
    if dup:
        raise ParameterError(f"{source}: landmark ids must be unique: repeated {', '.join(dup)}")
    return marks


def recipe_for(landmark: Landmark) -> str:
    """Name of the :data:`~gearchaos.paper.recipes.RECIPES` entry whose sweep covers
    ``landmark``: same swept axis, the panel among its family values, its fixed values equal
    to the landmark's and the landmark's range inside the swept range (± tolerance).

    Raises
    ------
    ParameterError
        No recipe covers it.
    """
    from .recipes import RECIPES

    preferred = _GALLERY_RECIPE.get(landmark.figure, landmark.figure)
    names = sorted(RECIPES, key=lambda n: n != preferred)
    lo, hi = landmark.span
    for name in names:
        r = RECIPES[name]
        if r.vary.name != landmark.axis:
            continue
        fam = landmark.fixed.get(r.family.name)
        if fam is None or not any(_close(fam, v) for v in r.family.values):
            continue
        if any(
            k not in landmark.fixed or not _close(landmark.fixed[k], v) for k, v in r.fixed.items()
        ):
            continue
        slack = 0.02 * (r.vary.stop - r.vary.start)
        if lo < r.vary.start - slack or hi > r.vary.stop + slack:
            continue
        return name
    raise ParameterError(
        f"{landmark.id}: no recipe sweeps {landmark.where()} at {dict(landmark.fixed)}"
    )


# ---------------------------------------------------------------------------- evaluation
def _close(a: float, b: float) -> bool:
    return abs(a - b) <= _REL * max(abs(a), abs(b), 1e-300) or a == b


def _matches(label: str, accepted: Sequence[str]) -> bool:
    if label in accepted:
        return True
    if "nT" in accepted:
        m = _PERIOD_RE.match(label)
        return m is not None and int(m.group(1)) >= 2
    return False


def _dist_score(d: float, tol: float) -> float:
    if d <= tol:
        return 1.0
    if d <= 3 * tol:
        return 0.75 - 0.25 * (d - tol) / tol
    return max(0.0, 0.25 * (1.0 - (d - 3 * tol) / (3 * tol)))


def _not_evaluated(mark: Landmark, why: str) -> LandmarkResult:
    return LandmarkResult(mark, "not evaluated", 0.0, why, {})


def _panel(mark: Landmark, ds: Any, planet: int) -> tuple[np.ndarray, np.ndarray] | str:
    """(axis values, labels) of the landmark's panel, sorted by axis; or why not."""
    if "motion" not in getattr(ds, "data_vars", {}):
        return "the dataset has no motion labels (classify the sweep store first)"
    motion = ds["motion"]
    if mark.axis not in motion.dims:
        return f"the dataset does not sweep {mark.axis} (dims: {', '.join(map(str, motion.dims))})"
    sel: dict[str, Any] = {}
    for dim in motion.dims:
        if dim == mark.axis:
            continue
        if dim == "planet":
            if planet not in ds["planet"].values:
                return f"planet {planet} is not in the dataset"
            sel[dim] = planet
            continue
        if dim not in mark.fixed:
            return f"the dataset has a dimension {dim} that the landmark does not fix"
        coords = np.asarray(ds[dim].values, dtype=float)
        want = mark.fixed[dim]
        j = int(np.argmin(np.abs(coords - want)))
        if not _close(float(coords[j]), want):
            have = ", ".join(f"{c:g}" for c in coords)
            return f"no panel {dim} = {want:g} in the dataset (has {have})"
        sel[dim] = j
    stored = _stored_fixed(ds)
    for k, v in stored.items():
        if k in mark.fixed and k not in motion.dims and not _close(float(v), mark.fixed[k]):
            return f"the dataset fixes {k} = {float(v):g}, the landmark {mark.fixed[k]:g}"
    named = {k: v for k, v in sel.items() if k == "planet"}
    idx = {k: v for k, v in sel.items() if k != "planet"}
    panel = motion.sel(named).isel(idx) if named else motion.isel(idx)
    x = np.asarray(ds[mark.axis].values, dtype=float)
    labels = np.asarray(panel.transpose(mark.axis).values).astype(str)
    order = np.argsort(x, kind="stable")
    x, labels = x[order], labels[order]
    tol = mark.tolerance
    lo, hi = mark.span
    if lo < x[0] - tol or hi > x[-1] + tol:
        return f"the dataset sweeps {mark.axis} over [{x[0]:g}, {x[-1]:g}], not {mark.where()}"
    return x, labels


def _stored_fixed(ds: Any) -> dict[str, Any]:
    """The sweep's numeric fixed values by dotted name (none for a dataset without a spec)."""
    if not getattr(ds, "attrs", {}).get("sweep_toml"):
        return {}
    fixed = SweepResult.of(ds).fixed
    return {k: v for k, v in fixed.items() if isinstance(v, int | float)}


def _counts(labels: np.ndarray) -> str:
    c = Counter(labels.tolist())
    return ", ".join(f"{k} {n}" for k, n in c.most_common())


def _changes(
    x: np.ndarray, labels: np.ndarray, before: Sequence[str], after: Sequence[str]
) -> list[float]:
    """Midpoints of every change, axis increasing, from a label in ``before`` to one in
    ``after`` (points labelled failed/unresolved skipped)."""
    keep = np.array([lab not in _NO_LABEL for lab in labels.tolist()], dtype=bool)
    xs, ls = x[keep], labels[keep].tolist()
    out = []
    for i in range(len(ls) - 1):
        if ls[i] != ls[i + 1] and _matches(ls[i], before) and _matches(ls[i + 1], after):
            out.append(0.5 * (float(xs[i]) + float(xs[i + 1])))
    return out


def _distance(loc: float, lo: float, hi: float) -> float:
    return max(lo - loc, 0.0, loc - hi)


def _label(mark: Landmark, x: np.ndarray, labels: np.ndarray) -> LandmarkResult:
    lo, hi = mark.span
    tol = mark.tolerance
    if mark.at is not None:
        inside = np.abs(x - mark.at) <= tol
        where = f"within ±{tol:g} of {mark.at:g}"
    else:
        inside = (x >= lo - 1e-12 * max(1.0, abs(lo))) & (x <= hi + 1e-12 * max(1.0, abs(hi)))
        where = f"in [{lo:g}, {hi:g}]"
    n = int(inside.sum())
    if n == 0:
        return _not_evaluated(mark, f"no grid point {where} (grid step too coarse)")
    sub = labels[inside]
    ok = np.array([_matches(s, mark.expected) for s in sub.tolist()], dtype=bool)
    frac = float(ok.mean())
    sc = min(1.0, frac / mark.min_fraction)
    verdict: Verdict = (
        "holds" if frac >= mark.min_fraction else "partly" if sc >= 0.5 else "does not hold"
    )
    exp = "/".join(mark.expected)
    evidence = f"{exp} at {frac:.0%} of {n} points {where} (found: {_counts(sub)})"
    measured = {"fraction": frac, "points": n, "counts": dict(Counter(sub.tolist()))}
    return LandmarkResult(mark, verdict, sc, evidence, measured)


def _transition(mark: Landmark, x: np.ndarray, labels: np.ndarray) -> LandmarkResult:
    lo, hi = mark.span
    tol = mark.tolerance
    locs = _changes(x, labels, mark.from_labels, mark.expected)
    change = f"{'/'.join(mark.from_labels)} → {'/'.join(mark.expected)}"
    target = f"{mark.at:g}" if mark.at is not None else f"[{lo:g}, {hi:g}]"
    if not locs:
        return LandmarkResult(
            mark,
            "does not hold",
            0.0,
            f"no change {change} anywhere in [{x[0]:g}, {x[-1]:g}] (expected at {target})",
            {"location": None, "distance": None, "changes": []},
        )
    dists = [_distance(v, lo, hi) for v in locs]
    j = int(np.argmin(dists))
    d = dists[j]
    sc = _dist_score(d, tol)
    verdict: Verdict = "holds" if d <= tol else "partly" if d <= 3 * tol else "does not hold"
    evidence = (
        f"change {change} at {locs[j]:.4g} (expected {target}, distance {d:.3g}, "
        f"tolerance {tol:g}); {len(locs)} such change(s) in the sweep"
    )
    measured = {"location": locs[j], "distance": d, "changes": locs}
    return LandmarkResult(mark, verdict, sc, evidence, measured)


def _window(mark: Landmark, x: np.ndarray, labels: np.ndarray) -> LandmarkResult:
    assert mark.lo is not None and mark.hi is not None
    lo, hi, tol = mark.lo, mark.hi, mark.tolerance
    inside = (x >= lo - 1e-12 * max(1.0, abs(lo))) & (x <= hi + 1e-12 * max(1.0, abs(hi)))
    n = int(inside.sum())
    if n == 0:
        return _not_evaluated(mark, f"no grid point in [{lo:g}, {hi:g}] (grid step too coarse)")
    sub = labels[inside]
    frac = float(np.mean([_matches(s, mark.expected) for s in sub.tolist()]))

    def _not_expected(lab: str) -> bool:
        return not _matches(lab, mark.expected)

    keep = np.array([lab not in _NO_LABEL for lab in labels.tolist()], dtype=bool)
    xs, ls = x[keep], labels[keep].tolist()
    ups, downs = [], []
    for i in range(len(ls) - 1):
        mid = 0.5 * (float(xs[i]) + float(xs[i + 1]))
        if _not_expected(ls[i]) and not _not_expected(ls[i + 1]):
            ups.append(mid)
        elif not _not_expected(ls[i]) and _not_expected(ls[i + 1]):
            downs.append(mid)
    # a window that touches the end of the sweep has no edge to find there
    if ls and lo <= float(xs[0]) + tol and not _not_expected(ls[0]):
        ups.append(float(xs[0]))
    if ls and hi >= float(xs[-1]) - tol and not _not_expected(ls[-1]):
        downs.append(float(xs[-1]))
    e_lo = min(ups, key=lambda v: abs(v - lo)) if ups else None
    e_hi = min(downs, key=lambda v: abs(v - hi)) if downs else None
    s_lo = _dist_score(abs(e_lo - lo), tol) if e_lo is not None else 0.0
    s_hi = _dist_score(abs(e_hi - hi), tol) if e_hi is not None else 0.0
    sc = 0.5 * min(1.0, frac / mark.min_fraction) + 0.25 * s_lo + 0.25 * s_hi
    verdict: Verdict = "holds" if sc >= 0.8 else "partly" if sc >= 0.4 else "does not hold"
    exp = "/".join(mark.expected)

    def edge(v: float | None) -> str:
        return "none" if v is None else f"{v:.4g}"

    evidence = (
        f"{exp} at {frac:.0%} of {n} points in [{lo:g}, {hi:g}] (found: {_counts(sub)}); "
        f"edges found at {edge(e_lo)}, {edge(e_hi)} (tolerance {tol:g})"
    )
    measured = {"fraction": frac, "points": n, "lower_edge": e_lo, "upper_edge": e_hi}
    return LandmarkResult(mark, verdict, sc, evidence, measured)


def evaluate(landmark: Landmark, ds: Any, *, planet: int = 1) -> LandmarkResult:
    """Check one landmark on a classified sweep dataset whose swept axis is ``landmark.axis``.

    The panel is chosen by nearest value of every non-swept dimension (it must match the
    landmark's fixed value to 1e-9 relative); fixed values stored in the sweep's ``sweep_toml``
    must agree too. When the dataset does not cover the landmark (no ``motion``, another axis,
    a missing panel, a range outside the sweep, no grid point in the range) the verdict is
    ``not evaluated`` with the reason as evidence. ``planet`` selects the planet when the
    labels carry a ``planet`` dimension.
    """
    got = _panel(landmark, ds, planet)
    if isinstance(got, str):
        return _not_evaluated(landmark, got)
    x, labels = got
    if landmark.kind == "label":
        return _label(landmark, x, labels)
    if landmark.kind == "transition":
        return _transition(landmark, x, labels)
    return _window(landmark, x, labels)


def evaluate_all(
    landmarks: Iterable[Landmark], stores: Mapping[str, Any], *, planet: int = 1
) -> list[LandmarkResult]:
    """Evaluate every landmark on the store of the recipe that covers it
    (:func:`recipe_for`; ``stores`` maps recipe names such as ``fig4`` to datasets). A landmark
    whose recipe has no store is ``not evaluated``."""
    out = []
    for m in landmarks:
        name = recipe_for(m)
        ds = stores.get(name)
        if ds is None:
            out.append(_not_evaluated(m, f"no sweep of {name} given"))
        else:
            out.append(evaluate(m, ds, planet=planet))
    return out


def score(results: Iterable[LandmarkResult]) -> float:
    """Sum of the scores (``not evaluated`` counts 0): the calibration's objective."""
    return float(sum(r.score for r in results))
