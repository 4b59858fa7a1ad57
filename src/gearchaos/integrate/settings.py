"""Solver settings: one frozen, validated object from every front door down to the kernel.

:class:`SolverSettings` holds the seed's protocol (transient periods discarded, periods
recorded, samples per period, section phase) and the integrator's tolerances and step budget.
``simulate``, sweeps, Lyapunov exponents, galleries and the CLI all build one, so a setting is
validated once, with one message, whatever the entry point; :meth:`SolverSettings.sample_times`
is the one place where sample times and step budgets are computed.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import warnings
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._checks import check_choice, check_int, check_memory, check_real
from ..errors import ParameterError
from ..model.target import Target

__all__ = [
    "PERTURBATION",
    "SIMULATION",
    "UNRECORDED",
    "SampleTimes",
    "SolverSettings",
    "default_step_budget",
    "renamed_keyword",
    "rest_direction",
    "split_keywords",
]

#: Bounds of the settings (see :meth:`SolverSettings.check`).
RTOL_RANGE = (1e-14, 0.1)
ATOL_MAX = 1.0
MAX_PERIODS = 10**9
#: The shortest transient other than none, in forcing periods.
MIN_TRANSIENT = 1e-6
MAX_SAMPLES_PER_PERIOD = 10**6
MAX_STEP_BUDGET = 2**62
#: The finest time step the integrator takes where the time is τ, relative to τ: below
#: ``STEP_RESOLUTION·|τ|`` it stops with ``Status.STEP_UNDERFLOW`` (the kernel's ``hmin``).
STEP_RESOLUTION = 16.0 * 2.220446049250313e-16
#: The time variable must resolve this fraction of a forcing period T until a run ends: the
#: first step from rest of the sheng2016 gear set is about 1e-6 T, steps at contacts shorter.
TIME_RESOLUTION = 1e-8
#: The most forcing periods one run may span (start, transient, section phase and record):
#: ``STEP_RESOLUTION · span · T <= TIME_RESOLUTION · T``, about 2.8 million.
MAX_SPAN_PERIODS = TIME_RESOLUTION / STEP_RESOLUTION
#: Values of ``settle``.
SETTLE_CHOICES = ("off", "auto")
#: Default size of the perturbation of a start from rest, and the largest allowed.
PERTURBATION = 1e-6
PERTURBATION_MAX = 1e-2
#: Seed of the generator that draws the direction of that perturbation (and nothing else).
PERTURBATION_SEED = 20_161_105


def default_step_budget(periods: float) -> int:
    """The step attempts a run of ``periods`` forcing periods may take when no ``max_steps``
    is set: 100 000 + 50 000 per period (at least one period)."""
    return int(100_000 + 50_000 * max(float(periods), 1.0))


def rest_direction(n: int) -> np.ndarray:
    """The fixed unit vector u ∈ ℝⁿ along which a start from rest is perturbed: standard
    normal components from ``numpy.random.default_rng(PERTURBATION_SEED)``, normalised.
    Every component is nonzero (with probability one), so the start leaves every invariant
    subspace of the state space, the symmetric manifold of in-phase planets included."""
    u = np.random.default_rng(PERTURBATION_SEED).standard_normal(int(n))
    return u / float(np.linalg.norm(u))


@dataclass(frozen=True)
class SampleTimes:
    """Where the kernel samples: τ_j = ``t_rec`` + j ``dt`` for j < ``n_samples``
    (``dt`` = ``period``/``samples_per_period``; every ``samples_per_period``-th sample,
    τ_rec + k·``period``, is a section point, on which the steps end), then on to ``t_end``; at
    most ``max_steps`` step attempts. ``t_rec``, ``period`` and ``t_end`` are floats or arrays
    (one value per point of a sweep)."""

    t_rec: Any
    period: Any
    n_samples: int
    t_end: Any
    max_steps: int
    samples_per_period: int = 1

    @property
    def dt(self) -> Any:
        """The sample interval T/s."""
        return self.period / self.samples_per_period

    @classmethod
    def over_periods(
        cls,
        t0: Any,
        period: Any,
        *,
        first: int,
        periods: int,
        end: int,
        max_steps: int,
        samples_per_period: int = 1,
    ) -> SampleTimes:
        """The samples of a run from τ = ``t0`` (a float, or an array: one run per entry)
        with forcing period ``period`` (broadcast to ``t0``'s shape): ``periods`` forcing
        periods of ``samples_per_period`` samples each, the first at the section time
        t0 + ``first``·T, the run ending at t0 + ``end``·T (``end`` >= ``first`` + ``periods``
        − 1: a run may stop on its last sample)."""
        if first < 0 or periods < 1 or end < first + periods - 1:
            raise ValueError(
                f"sample times need 0 <= first, periods >= 1 and end >= first + periods - 1: "
                f"got first={first}, periods={periods}, end={end}"
            )
        shape = np.broadcast_shapes(np.shape(t0), np.shape(period))
        T = np.broadcast_to(np.asarray(period, dtype=float), shape).copy() if shape else period
        return cls(
            t_rec=t0 + first * T,
            period=T,
            n_samples=int(periods) * int(samples_per_period),
            t_end=t0 + end * T,
            max_steps=int(max_steps),
            samples_per_period=int(samples_per_period),
        )


@dataclass(frozen=True)
class SolverSettings:
    """The simulation protocol and the Dormand–Prince 5(4) controller settings.

    Parameters
    ----------
    transient_periods
        Forcing periods T = 2π/Ω discarded before recording (the seed: 100). Need not be an
        integer.
    periods
        Forcing periods recorded: one Poincaré section point each.
    samples_per_period
        Samples per recorded period (1: the section points only; more for time histories,
        phase portraits and spectra).
    section_phase
        Phase φ of the section: samples at τ_k = (2πk + φ)/Ω after the transient.
    rtol, atol
        Relative and absolute error tolerances of the step-size controller.
    max_steps
        Step attempts allowed before the integration gives up (``Status.MAX_STEPS``); ``None``
        allows 100 000 + 50 000 per simulated period.
    perturbation
        Size ε of the reproducible perturbation added to a start from rest (the zero state):
        the run starts at ε·u, u a fixed unit vector (:func:`rest_direction`, drawn once from a
        seeded generator, so every run, process and machine starts from the same state). A
        real gearbox is never exactly symmetric; from the exact zero state a gear set with
        identical, equally spaced, in-phase planets never leaves its symmetric subspace
        (sun centred, planets in step), and motions that are unstable to symmetry breaking
        would be reported as attractors. Default :data:`PERTURBATION` = 1e-6 (in state
        units: b_c for gear sets); 0 restores the exact symmetric start. Explicit initial
        states are never perturbed.
    settle
        ``"off"`` (the seed's protocol): always ``transient_periods`` periods of transient.
        ``"auto"``: the transient ends at the first section point x_k (τ = τ_rec − mT) after
        which the section sequence has repeated with a period n ≤ 64,
        |x_k − x_(k−n)| ≤ 1e-7 (1 + |x_k|) componentwise for max(3n, 8) section points in a
        row, never later than ``transient_periods``; the periods are then recorded from there
        (whole periods earlier, so with the same forcing phase). Chaotic and quasi-periodic
        motions never settle early.

    Notes
    -----
    Every value is checked on construction (:meth:`check`); an invalid one raises
    :class:`~gearchaos.errors.ParameterError` naming the setting, the rule and the value.
    """

    transient_periods: float = 100
    periods: int = 200
    samples_per_period: int = 1
    section_phase: float = 0.0
    rtol: float = 1e-8
    atol: float = 1e-10
    max_steps: int | None = None
    settle: str = "off"
    perturbation: float = PERTURBATION

    def __post_init__(self) -> None:
        self.check()

    # ------------------------------------------------------------------ validation
    def check(self) -> None:
        """Raise :class:`~gearchaos.errors.ParameterError` at the first invalid setting.

        Rules: ``transient_periods`` 0 or a number in [1e-6, 1e9]; ``periods`` an integer in
        [1, 1e9]; ``samples_per_period`` an integer in [1, 1e6]; ``section_phase`` a finite
        number; ``rtol`` a number in [1e-14, 0.1] (below 1e-14 the floating-point resolution
        of the time variable is reached); ``atol`` a number in (0, 1] (states are of order one:
        lengths in units of b_c); ``max_steps`` None or an integer >= 1; ``settle`` "off" or
        "auto". Booleans and strings are not numbers.
        """
        check_real("transient_periods", self.transient_periods, lo=0.0, hi=float(MAX_PERIODS))
        if 0 < self.transient_periods < MIN_TRANSIENT:
            raise ParameterError(
                f"transient_periods must be 0 or at least {MIN_TRANSIENT:g} (a shorter "
                f"transient is below any step of the integrator): got {self.transient_periods!r}",
                name="transient_periods",
            )
        check_int("periods", self.periods, lo=1, hi=MAX_PERIODS)
        check_int("samples_per_period", self.samples_per_period, lo=1, hi=MAX_SAMPLES_PER_PERIOD)
        check_real("section_phase", self.section_phase)
        check_real("rtol", self.rtol, lo=RTOL_RANGE[0], hi=RTOL_RANGE[1])
        check_real("atol", self.atol, lo=0.0, hi=ATOL_MAX, lo_open=True)
        if self.max_steps is not None:
            check_int("max_steps", self.max_steps, lo=1, hi=MAX_STEP_BUDGET)
        check_choice("settle", self.settle, SETTLE_CHOICES)
        check_real("perturbation", self.perturbation, lo=0.0, hi=PERTURBATION_MAX)

    # ------------------------------------------------------------------ construction
    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in dataclasses.fields(cls))

    @classmethod
    def build(cls, base: SolverSettings | None = None, /, **changes: Any) -> SolverSettings:
        """``base`` (default: the defaults) with ``changes`` applied; ``None`` values keep the
        base value. Unknown names are refused with the closest valid name."""
        if base is not None and not isinstance(base, SolverSettings):
            raise ParameterError(
                f"settings must be a SolverSettings or None: got {type(base).__name__}",
                name="settings",
            )
        names = cls.field_names()
        for key in changes:
            if key not in names:
                close = difflib.get_close_matches(key, names, n=1)
                hint = f"; did you mean {close[0]!r}?" if close else ""
                raise ParameterError(
                    f"unknown solver setting {key!r}{hint} (settings: {', '.join(names)})",
                    name=key,
                )
        kept = {k: v for k, v in changes.items() if v is not None or k == "max_steps"}
        if base is None:
            return cls(**kept)
        return dataclasses.replace(base, **kept)

    def replace(self, **changes: Any) -> SolverSettings:
        """A validated copy with some settings changed."""
        return SolverSettings.build(self, **changes)

    # ------------------------------------------------------------------ derived
    @property
    def n_samples(self) -> int:
        """Samples recorded: ``periods × samples_per_period``."""
        return int(self.periods) * int(self.samples_per_period)

    @property
    def step_budget(self) -> int:
        """``max_steps``, or 100 000 + 50 000 per simulated period (at least one)."""
        return self.budget_for(float(self.transient_periods) + int(self.periods))

    def budget_for(self, periods: float) -> int:
        """The step attempts a run of ``periods`` forcing periods may take: ``max_steps``,
        or :func:`default_step_budget`."""
        if self.max_steps is not None:
            return int(self.max_steps)
        return default_step_budget(periods)

    def check_span(self, start_periods: float = 0.0) -> None:
        """Refuse a run that would end where the time variable no longer resolves
        :data:`TIME_RESOLUTION` of a forcing period: it spans ``start_periods`` (the start
        time in periods), ``transient_periods``, ``section_phase``/2π and ``periods``, and at
        τ = span·T the integrator's finest step is ``STEP_RESOLUTION``·τ (then it stops with
        ``STEP_UNDERFLOW``, from the first step on). The message names the largest part."""
        parts = {
            "start time": abs(float(start_periods)),
            "transient_periods": float(self.transient_periods),
            "section_phase": abs(float(self.section_phase)) / (2.0 * math.pi),
            "periods": float(self.periods),
        }
        span = sum(parts.values())
        if span <= MAX_SPAN_PERIODS:
            return
        name = max(parts, key=lambda k: parts[k])
        shown = f"{self.section_phase:g} rad" if name == "section_phase" else f"{parts[name]:g}"
        raise ParameterError(
            f"{name} = {shown} makes a run span {span:.3g} forcing periods T; at its end the "
            f"time variable resolves only {STEP_RESOLUTION * span:.2g} T (16 ε τ, the "
            f"integrator's finest step there), coarser than the {TIME_RESOLUTION:g} T its "
            f"steps need: at most {MAX_SPAN_PERIODS:.3g} periods in all; make {name} smaller",
            name=None if name == "start time" else name,
        )

    def sample_times(self, period: Any, t0: Any = 0.0) -> SampleTimes:
        """Sample times of a run with forcing period T (a float, or an array of one T per
        point) starting at τ = ``t0``: the first sample after the transient,
        τ_rec = t0 + transient_periods·T + φT/2π, then every T/samples_per_period."""
        T = period
        start = np.max(np.abs(np.asarray(t0, dtype=float) / np.asarray(T, dtype=float)))
        self.check_span(float(start))
        phase = float(self.section_phase)
        t_rec = t0 + self.transient_periods * T
        if phase != 0.0:
            t_rec = t_rec + phase * T / (2.0 * math.pi)
        periods = int(self.periods)
        return SampleTimes.over_periods(
            t_rec,
            T,
            first=0,
            periods=periods,
            end=periods,
            max_steps=self.step_budget,
            samples_per_period=int(self.samples_per_period),
        )

    def check_memory(self, values_per_sample: int, points: int = 1, what: str = "") -> None:
        """Refuse, before allocating, outputs of ``points`` runs that record
        ``values_per_sample`` float64 values per sample."""
        nbytes = 8.0 * float(values_per_sample) * self.n_samples * float(points)
        check_memory(
            what
            or f"recording {self.periods} periods × {self.samples_per_period} samples per period",
            nbytes,
        )

    # ------------------------------------------------------------------ records
    def to_record(self) -> dict[str, Any]:
        """The settings as a record — TOML keys, store and result-file attributes — by field
        name in field order: real settings as floats, counts as ints, choices as text.

        A record leaves out a setting whose value is what a record without it means
        (:data:`UNRECORDED`: the value results had before that setting was recorded), so a
        record of the same settings written before is the same record, and
        :meth:`from_record` gives back exactly these settings (``max_steps`` None included:
        TOML has no null)."""
        out: dict[str, Any] = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.name in UNRECORDED and value == UNRECORDED[f.name]:
                continue
            out[f.name] = _KINDS[f.name](value)
        return out

    @classmethod
    def from_record(cls, record: Mapping[str, Any]) -> SolverSettings:
        """The settings of a record written by :meth:`to_record` (other keys are ignored); a
        setting it lacks has its :data:`UNRECORDED` value, one that every record holds is
        required. Invalid values raise :class:`~gearchaos.errors.ParameterError`."""
        values: dict[str, Any] = {}
        for name in cls.field_names():
            if name in record:
                value = record[name]
                # numpy scalars of netCDF attributes as Python numbers
                values[name] = value.item() if isinstance(value, np.generic) else value
            elif name in UNRECORDED:
                values[name] = UNRECORDED[name]
            else:
                raise ParameterError(f"the record has no setting {name}", name=name)
        return cls(**values)

    def attrs(self) -> dict[str, Any]:
        """The settings as result attributes: :meth:`to_record`."""
        return self.to_record()

    def rest_state(self, n: int) -> np.ndarray | None:
        """The start "from rest" of an n-dimensional system: ε·u (:func:`rest_direction`), or
        None (the exact zero state) when ``perturbation`` is 0."""
        if self.perturbation == 0.0:
            return None
        return float(self.perturbation) * rest_direction(n)


#: What a record (:meth:`SolverSettings.to_record`) without a setting means: the value results
#: had before the setting was recorded. Sweep specifications recorded neither the samples per
#: period (one: the sections) nor the section phase, max_steps, settle or the perturbation of
#: the start (they began exactly at rest); result files neither settle nor the perturbation.
UNRECORDED: dict[str, Any] = {
    "samples_per_period": 1,
    "section_phase": 0.0,
    "max_steps": None,
    "settle": "off",
    "perturbation": 0.0,
}


def _optional_int(value: Any) -> Any:
    return None if value is None else int(value)


#: How each setting is written to a record, by the field's annotation.
_KINDS: dict[str, Any] = {
    f.name: {"float": float, "int": int, "int | None": _optional_int, "str": str}[str(f.type)]
    for f in dataclasses.fields(SolverSettings)
}


#: The defaults of one simulation, the same from Python (:func:`gearchaos.simulate`,
#: :func:`~gearchaos.dynamics.verdict.point.analyse_point`) and from ``gearchaos simulate``: the
#: seed's protocol with 64 samples per mesh period (time histories, spectra, RMS values).
SIMULATION = SolverSettings(samples_per_period=64)


# ------------------------------------------------------------------ the front doors' keywords
def split_keywords(
    keywords: Mapping[str, Any],
    settings: SolverSettings | None,
    params: Mapping[str, Any] | None,
    default: SolverSettings,
    *,
    door: Any = "",
    target: Target | None = None,
    options: Iterable[str] = (),
) -> tuple[dict[str, Any], SolverSettings]:
    """The one keyword vocabulary of the front doors (``simulate``, ``bifurcation``,
    ``response``, ``periodic_orbit``, ``continuation``, ``attractors``,
    ``lyapunov_spectrum``, ``paper.run_gallery``): ``settings=`` a :class:`SolverSettings`
    (default ``default``) and setting fields by name (``rtol=1e-10``), which override it;
    ``params=`` a mapping of dotted parameter names to values (``{"backlash.sun_planet": 2.4}``)
    and parameters whose names are Python identifiers by name (``omega=1.5``, ``xi=0.05``).

    ``keywords`` are a door's remaining keyword arguments: setting fields and parameters by
    name. With ``target`` (the door's gear set or system) a keyword that is neither a setting
    nor one of its parameters is refused as an option of ``door`` (the door function itself,
    or its name), naming the closest of the door's own keywords (and ``options``, those it
    takes through ``**``), the settings and the parameters (:func:`check_keyword`). Returns
    the parameter values by name and the settings."""
    names = set(SolverSettings.field_names())
    changes = {k: v for k, v in keywords.items() if k in names}
    values = {k: v for k, v in keywords.items() if k not in names}
    if target is not None and values:
        name, own = _door(door)
        for key in values:
            check_keyword(name, target, key, {*names, *own, *options})
    for k, v in (check_params("params", params) or {}).items():
        if k in values:
            raise ParameterError(f"parameter {k!r} is given twice (keyword and params)", name=k)
        values[k] = v
    return values, SolverSettings.build(default if settings is None else settings, **changes)


def _door(door: Any) -> tuple[str, list[str]]:
    """The name of a front door and its named keywords (from its signature when ``door`` is
    the function itself)."""
    if not callable(door):
        return str(door), []
    import inspect

    kinds = (inspect.Parameter.KEYWORD_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)
    params = inspect.signature(door).parameters.values()
    return door.__name__, [p.name for p in params if p.kind in kinds]


def check_params(keyword: str, params: Any) -> Any:
    """``params`` (given as ``keyword``): None or a mapping of dotted names to values."""
    if params is not None and not isinstance(params, Mapping):
        raise ParameterError(
            f"{keyword} must be a mapping of dotted names to values "
            f"(e.g. {{'omega': 1.5}}): got {params!r}",
            name=keyword,
        )
    return params


def check_keyword(door: str, target: Target, key: str, options: Iterable[str]) -> None:
    """Refuse ``key``, given to ``door`` by name, unless it is a parameter of ``target``: the
    refusal names the closest of ``options`` (the door's other keywords) and the target's
    parameters whose names are Python identifiers."""
    from ..model.target import parameter_names  # the model layer, below this one

    names = parameter_names(target)
    if key in names:
        return
    valid = sorted({*options, *(n for n in names if n.isidentifier())})
    close = difflib.get_close_matches(key, valid, n=1)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    raise ParameterError(
        f"unknown {door} option {key!r}{hint} (a parameter whose name is not a Python "
        "identifier goes in params={name: value})",
        name=key,
    )


def renamed_keyword(door: str, old: str, new: str, value: Any, current: Any = None) -> Any:
    """``value``, given to ``door`` as ``old=``, the spelling of the keyword ``new=`` before the
    one vocabulary (:func:`split_keywords`): accepted for one more release with a
    :class:`DeprecationWarning` that names the new spelling; both at once are refused."""
    if current is not None:
        raise ParameterError(
            f"{door}: give {new}= only ({old}= is its deprecated spelling): got both", name=new
        )
    warnings.warn(
        f"{door}({old}=...) is deprecated and will be removed in the next release; "
        f"use {new}=... instead",
        DeprecationWarning,
        stacklevel=3,
    )
    return value
