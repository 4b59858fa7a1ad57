"""The seed paper's quantitative statements as data: :class:`Landmark`, its result
:class:`LandmarkResult`, whether the swept parameter acts (:class:`AxisAction`), and the
validated reading of ``landmarks.toml`` (:func:`load_landmarks`).

The kinds, keys and verdicts are described in :mod:`gearchaos.paper.landmarks`, which checks
the landmarks on sweep stores and re-exports everything here.
"""

from __future__ import annotations

import math
import re
import tomllib
from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from types import MappingProxyType
from typing import Any, Literal

from .._files import read_text_file
from ..analysis.motion import Motion
from ..errors import ParameterError
from ..gearset.mapping import flatten

__all__ = [
    "AXES",
    "CONTRASTS",
    "EVENTS",
    "KINDS",
    "VERDICTS",
    "AxisAction",
    "Landmark",
    "LandmarkResult",
    "load_landmarks",
    "recipe_for",
]

#: Swept axes a landmark may name.
AXES = ("omega", "xi", "backlash.sun_planet", "backlash.planet_ring", "clearance.sun_bearing")
#: Landmark kinds.
KINDS = ("label", "transition", "window", "negligible")
#: Sides of a label landmark's range where its labels must *not* be dominant (``contrast``):
#: the statement says they *become* dominant there.
CONTRASTS = ("below", "above")
#: Gallery → the bifurcation recipe whose sweep covers its statements.
_GALLERY_RECIPE = {"fig5": "fig4", "fig7": "fig6", "fig10": "fig9"}
#: What a landmark's ``expected`` and ``from`` lists name beside decided motions: any nT, n ≥ 2.
ANY_PERIOD = "nT"
_REL = 1e-9

Verdict = Literal["holds", "holds (constant)", "partly", "does not hold", "not evaluated"]
#: Every verdict of a landmark, in the order the counts list them. ``holds (constant)`` is a
#: hold on a panel where the swept parameter does not act (:class:`AxisAction`): it agrees with
#: the statement only because nothing changes along the axis, and is counted apart.
VERDICTS: tuple[Verdict, ...] = (
    "holds",
    "holds (constant)",
    "partly",
    "does not hold",
    "not evaluated",
)


def _close(a: float, b: float) -> bool:
    return abs(a - b) <= _REL * max(abs(a), abs(b), 1e-300) or a == b


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
        ``label``, ``transition``, ``window`` or ``negligible``.
    lo, hi, at
        Range or value in axis units (``at`` xor ``lo``/``hi``; a window needs ``lo``/``hi``).
    expected
        Accepted labels (after the change for a transition); ``nT`` = any n ≥ 2 period; empty
        for a ``negligible`` landmark.
    from_labels
        Accepted labels before the change (transitions; TOML key ``from``).
    fixed
        Every other parameter by dotted name.
    tolerance
        In axis units.
    min_fraction
        Fraction of points with an expected label needed for *holds* (label, window).
    event
        The bifurcation the statement names (``period_doubling``, ``neimark_sacker`` — the
        seed's "Hopf" — or ``period_3``, a 3T channel), or "".
    contrast
        ``below`` or ``above`` (label landmarks): the expected labels must *not* be dominant
        (fraction ≥ ``min_fraction``) over the rest of the sweep on that side of the range — the
        statement says they *become* dominant there; or "".
    max_change
        Largest change along the axis of the per-point attractor (centre and size of the
        X̄_sp1 section values), relative to the largest |X̄_sp1| on the panel, that is still
        *negligible* (``negligible`` landmarks).
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
    event: str = ""
    contrast: str = ""
    max_change: float = 0.05

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
class AxisAction:
    """Whether the swept parameter acts on one panel of a figure
    (:func:`gearchaos.paper.action.panel_action`).

    ``acts`` is True (a continued branch along the axis changes its largest multiplier by
    more than the threshold or has events, or the swept clearance is reached on the sweep),
    False (the branch is constant and the clearance never reached — or, without a branch, the
    clearance never reached and the section values unchanged along the axis) or None (could
    not be decided); ``evidence`` says what decided it, ``measured`` holds the numbers.
    """

    acts: bool | None
    evidence: str
    measured: Mapping[str, Any] = field(default_factory=dict, hash=False)

    @property
    def word(self) -> str:
        """``acts``, ``constant`` or ``undecided``."""
        return {True: "acts", False: "constant", None: "undecided"}[self.acts]


@dataclass(frozen=True)
class LandmarkResult:
    """Verdict of one landmark on one sweep: ``score`` in [0, 1], ``evidence`` in words with
    the numbers, ``measured`` the numbers themselves; ``action`` whether the swept parameter
    acts on the landmark's panel (None: not tested)."""

    landmark: Landmark
    verdict: Verdict
    score: float
    evidence: str
    measured: Mapping[str, Any] = field(default_factory=dict, hash=False)
    action: AxisAction | None = None


# ------------------------------------------------------------------------------ loading
def _number(where: str, key: str, v: Any) -> float:
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
        raise ParameterError(f"{where}: {key} must be a finite number: got {v!r}")
    return float(v)


def _decided(label: str) -> bool:
    """``label`` names a decided motion (nT, QP or chaos)."""
    try:
        return Motion.parse(label).decided
    except ParameterError:
        return False


def _labels(where: str, key: str, v: Any) -> tuple[str, ...]:
    if not isinstance(v, list) or not v or not all(isinstance(x, str) for x in v):
        raise ParameterError(f"{where}: {key} must be a non-empty list of labels: got {v!r}")
    bad = [x for x in v if x != ANY_PERIOD and not _decided(x)]
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
    "fixed", "tolerance", "min_fraction", "note", "event", "contrast", "max_change",
}  # fmt: skip
#: Bifurcations a landmark may name (``event``): checked on continued branches when the
#: report has them (:func:`gearchaos.paper.routes.landmarks_from_events`).
EVENTS = ("period_doubling", "neimark_sacker", "period_3")


def _expected(where: str, d: Mapping[str, Any]) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(expected, from) labels of a landmark table: a negligible landmark has none."""
    kind = d["kind"]
    if kind == "negligible":
        for key in ("expected", "from"):
            if key in d:
                raise ParameterError(
                    f"{where}: {key} is not for a negligible landmark (it reads section values)"
                )
        return (), ()
    if "expected" not in d:
        raise ParameterError(f"{where}: expected is required")
    expected = _labels(where, "expected", d["expected"])
    if kind == "transition":
        if "from" not in d:
            raise ParameterError(f"{where}: a transition needs from")
        return expected, _labels(where, "from", d["from"])
    if "from" in d:
        raise ParameterError(f"{where}: from is only for transitions")
    return expected, ()


def _kind_options(where: str, d: Mapping[str, Any]) -> tuple[str, float]:
    """(contrast, max_change) of a landmark table, each allowed for its kind only."""
    contrast = d.get("contrast", "")
    if "contrast" in d:
        if d["kind"] != "label":
            raise ParameterError(f"{where}: contrast is only for label landmarks")
        if contrast not in CONTRASTS:
            raise ParameterError(
                f"{where}: contrast must be one of {', '.join(CONTRASTS)}: got {contrast!r}"
            )
    max_change = 0.05
    if "max_change" in d:
        if d["kind"] != "negligible":
            raise ParameterError(f"{where}: max_change is only for negligible landmarks")
        max_change = _number(where, "max_change", d["max_change"])
        if not 0.0 < max_change <= 1.0:
            raise ParameterError(f"{where}: max_change must be in (0, 1]: got {max_change:g}")
    return contrast, max_change


def _landmark(i: int, d: Mapping[str, Any]) -> Landmark:
    where = f"landmark #{i + 1}" + (f" ({d['id']})" if isinstance(d.get("id"), str) else "")
    unknown = sorted(set(d) - _KEYS)
    if unknown:
        raise ParameterError(f"{where}: unknown keys {', '.join(unknown)}")
    for key in ("id", "figure", "panel", "quote", "axis", "kind", "fixed"):
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
    if d["kind"] in ("window", "negligible") and at is not None:
        raise ParameterError(f"{where}: a {d['kind']} landmark needs lo and hi, not at")
    expected, from_labels = _expected(where, d)
    contrast, max_change = _kind_options(where, d)
    min_fraction = _number(where, "min_fraction", d.get("min_fraction", 0.8))
    if not 0.0 < min_fraction <= 1.0:
        raise ParameterError(f"{where}: min_fraction must be in (0, 1]: got {min_fraction:g}")
    note = d.get("note", "")
    if not isinstance(note, str):
        raise ParameterError(f"{where}: note must be a string: got {note!r}")
    event = d.get("event", "")
    if event not in ("", *EVENTS):
        raise ParameterError(f"{where}: event must be one of {', '.join(EVENTS)}: got {event!r}")
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
        event=event,
        contrast=contrast,
        max_change=max_change,
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
