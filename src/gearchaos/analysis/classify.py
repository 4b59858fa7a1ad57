"""Motion label of an attractor — nT-periodic, quasi-periodic or chaotic — from several indicators.

The seed names motions by eye from Poincaré maps (MODEL.md §8). :func:`classify_motion` does it
from numbers, and says when the numbers disagree instead of hiding it:

1. **Period.** If the section sequence repeats with a period n ≤ ``max_period``
   (:func:`~gearchaos.analysis.periodicity.detect_period`, tolerance relative to the attractor
   size) the label is ``nT``.
2. **Quasi-periodic or chaotic**, for a sequence with no such period, from the largest Lyapunov
   exponent λ when it is given: λ > θ → ``chaos``; |λ| ≤ θ → ``QP``; λ < −θ → ``unresolved``
   (a contracting attractor is periodic, so its period exceeds ``max_period`` or its transient
   has not died out). The threshold θ is tied to the length t = run_periods · T of the run
   that estimated λ (see :func:`lle_threshold_for`).
3. **Confirmation** by two independent indicators computed from the section sequence (or
   supplied by the caller): the 0–1 test for chaos (:func:`~gearchaos.analysis.chaos01.chaos01`;
   K > 0.8 chaotic, K < 0.2 regular, in between undecided) and the spectrum
   (:func:`spectral_broadband`; broadband → chaotic, discrete lines → regular). Without an
   LLE the 0–1 test decides (K > 0.8 → ``chaos``, K < 0.2 → ``QP``) and the spectrum confirms;
   the spectrum alone never decides, because a chaotic attractor made of thin bands has most
   of its power in a few lines.
4. **Disagreement.** The label keeps the verdict of the deciding indicator (the LLE when
   available), ``agree`` is False and ``note`` names the indicators that disagreed and their
   values. Undecided indicators (0.2 ≤ K ≤ 0.8) are reported in the note but do not count as
   disagreement.
5. Without any usable information (a non-finite section sequence, or no period, no LLE and an
   undecided or unavailable 0–1 test) the label is ``unresolved``.

:func:`classify_sections` applies the rules to every point of a sweep (period detection is
vectorised over the sweep; the 0–1 test and the spectrum run only where no period is found),
and :func:`regime_table` gives the fraction of the swept range in each regime.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Iterable
from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np

from ..errors import ParameterError
from .chaos01 import MIN_LENGTH as MIN_LENGTH_01, chaos01
from .motion import LABEL_DTYPE, Motion, MotionKind
from .periodicity import periods_of
from .spectral import spectral_broadband

__all__ = [
    "K_CHAOS",
    "K_REGULAR",
    "LABEL_DTYPE",
    "LLE_C",
    "MIN_SPECTRUM_LENGTH",
    "MotionClass",
    "classify_motion",
    "classify_sections",
    "lle_threshold_for",
    "regime_table",
    "sort_labels",
    "spectral_broadband",
]

#: 0–1 test: K above this is chaotic (Gottwald & Melbourne report K ≥ 0.9 for chaos at N ~ 10³).
K_CHAOS = 0.8
#: 0–1 test: K below this is regular.
K_REGULAR = 0.2
#: Constant c of the LLE threshold θ = c / (run_periods · T); see :func:`lle_threshold_for`.
LLE_C = 10.0
#: Shortest sequence the spectral indicator is computed on inside the classifier.
MIN_SPECTRUM_LENGTH = 64


@dataclass(frozen=True)
class MotionClass:
    """Motion label of one attractor and the indicators behind it.

    Attributes
    ----------
    label
        ``1T`` … ``nT`` (n ≤ max_period), ``QP``, ``chaos`` or ``unresolved``.
    period
        n for an ``nT`` label, else None.
    lle
        Largest Lyapunov exponent used (per unit of the time in which ``forcing_period`` is
        given, τ for gearchaos systems), or None.
    k01
        0–1 test value K, or None (periodic sequences skip the test; too short a sequence).
    broadband
        Spectral verdict: True broadband, False discrete lines, None not computed.
    agree
        False when a decisive indicator contradicts the label (see ``note``).
    note
        Why this label, and which indicators disagreed or were undecided; empty when a period
        was found and nothing contradicts it.
    lle_threshold
        Threshold θ used for the LLE, or None when no LLE was given.
    peak_fraction
        Fraction of the spectral power in discrete lines (:func:`spectral_broadband`), or None.
    """

    label: str
    period: int | None
    lle: float | None
    k01: float | None
    broadband: bool | None
    agree: bool
    note: str
    lle_threshold: float | None = None
    peak_fraction: float | None = None

    @property
    def motion(self) -> Motion:
        """The label as a :class:`~gearchaos.analysis.motion.Motion` (an ``unresolved`` one
        with the note as its reason)."""
        m = Motion.parse(self.label)
        return replace(m, reason=self.note) if m.kind is MotionKind.UNRESOLVED else m

    @property
    def regular(self) -> bool | None:
        """True for ``nT`` and ``QP``, False for ``chaos``, None for ``unresolved``."""
        return Motion.parse(self.label).regular

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-serialisable dict of the fields (non-finite floats become None)."""
        out = asdict(self)
        for key in ("lle", "k01", "lle_threshold", "peak_fraction"):
            v = out[key]
            out[key] = float(v) if v is not None and math.isfinite(v) else None
        return out


def lle_threshold_for(run_periods: float, forcing_period: float, *, lle_c: float = LLE_C) -> float:
    """Threshold θ = c / (run_periods · T) separating a zero from a positive finite-time LLE.

    Parameters
    ----------
    run_periods
        Number of forcing periods over which the LLE was averaged (after the transient).
    forcing_period
        T = 2π/Ω in the time unit of the LLE (τ for gearchaos, whose exponents are per unit τ).
    lle_c
        The constant c (default :data:`LLE_C` = 10).

    Notes
    -----
    A finite-time estimate λ(t) = ln(‖v(t)‖/‖v(0)‖)/t of the largest exponent of a regular
    attractor does not vanish: on a quasi-periodic torus the tangent vector grows at most
    linearly (shear along the torus), ‖v(t)‖ ≤ C (1 + a t), so |λ(t)| ≤ [ln C + ln(1 + a t)]/t,
    which decays like ln(t)/t; a chaotic attractor keeps λ(t) → λ > 0. A threshold ∝ 1/t
    therefore shrinks with the run as the regular estimate does (up to the slowly varying
    logarithm). c = 10 covers ln(1 + a t) ≈ 7 for runs of up to ~10³ time units with a ~ 1
    plus ln C ≈ 3 for a tangent vector whose norm varies by a factor e³ ≈ 20 along the orbit
    (impacts, the transient alignment of the initial vector). For the seed's runs (Ω = 1.5,
    T = 4.19, 200 recorded periods, t = 838) θ ≈ 0.012 per τ; 500 periods give 0.0048. A
    chaotic attractor with a smaller exponent than θ is labelled QP and the 0–1 test then
    reports the disagreement: run longer to resolve it.
    """
    for name, v in (
        ("run_periods", run_periods),
        ("forcing_period", forcing_period),
        ("lle_c", lle_c),
    ):
        if not (isinstance(v, int | float | np.number) and math.isfinite(v) and v > 0):
            raise ParameterError(f"{name} must be a finite number > 0: got {v!r}")
    return float(lle_c) / (float(run_periods) * float(forcing_period))


def _verdict_01(k: float) -> str | None:
    if k > K_CHAOS:
        return "chaos"
    if k < K_REGULAR:
        return "regular"
    return None


def _fmt(v: float) -> str:
    return f"{v:.3g}"


def _finite_or_none(v: Any, name: str) -> float | None:
    if v is None:
        return None
    try:
        f = float(v)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a number or None: got {v!r}") from None
    return f if math.isfinite(f) else None


def _spectral_input(spectrum_peaks: Any) -> tuple[bool | None, float | None]:
    if spectrum_peaks is None:
        return None, None
    if isinstance(spectrum_peaks, bool | np.bool_):
        return bool(spectrum_peaks), None
    if isinstance(spectrum_peaks, tuple) and len(spectrum_peaks) == 2:
        b, f = spectrum_peaks
        if isinstance(b, bool | np.bool_):
            return bool(b), _finite_or_none(f, "spectrum_peaks[1] (peak fraction)")
    raise ParameterError(
        "spectrum_peaks must be None, a bool (broadband) or the (broadband, peak_fraction) "
        f"pair of spectral_broadband: got {spectrum_peaks!r}"
    )


def _classify(
    p: np.ndarray,
    period: int,
    *,
    lle: float | None,
    threshold: float | None,
    k01: float | None,
    broadband: bool | None,
    peak_fraction: float | None,
    compute_indicators: bool,
    max_period: int,
) -> MotionClass:
    """Rules of the module docstring for one sequence ``p`` (m, d) whose period is known."""
    reason: list[str] = []  # why this label (first in the note)
    notes: list[str] = []  # undecided or skipped indicators (last)
    disagree: list[str] = []
    finite = bool(np.all(np.isfinite(p))) and p.shape[0] > 0

    def make(motion: Motion) -> MotionClass:
        return MotionClass(
            label=motion.format(),
            period=motion.period or None,
            lle=lle,
            k01=k01,
            broadband=broadband,
            agree=not disagree,
            note="; ".join(reason + disagree + notes),
            lle_threshold=threshold,
            peak_fraction=peak_fraction,
        )

    if not finite:
        reason.append("the section sequence is empty or holds NaN/inf (integration failed)")
        return make(Motion.unresolved())

    if period > 0:
        if lle is not None and threshold is not None and lle > threshold:
            disagree.append(
                f"LLE {_fmt(lle)} > threshold {_fmt(threshold)} says chaos, "
                f"but the section repeats with period {period}"
            )
        if k01 is not None and _verdict_01(k01) == "chaos":
            disagree.append(
                f"0–1 test K = {_fmt(k01)} says chaos, but the section repeats with period {period}"
            )
        if broadband:
            disagree.append(
                f"the spectrum is broadband, but the section repeats with period {period}"
            )
        return make(Motion.periodic(period))

    m = p.shape[0]
    if compute_indicators and k01 is None:
        if m >= MIN_LENGTH_01:
            k01 = chaos01(p)
        else:
            notes.append(f"0–1 test skipped: {m} section points < {MIN_LENGTH_01}")
    if compute_indicators and broadband is None:
        if m >= MIN_SPECTRUM_LENGTH:
            broadband, peak_fraction = spectral_broadband(p)
            if math.isnan(peak_fraction):
                peak_fraction = None
        else:
            notes.append(f"spectrum skipped: {m} section points < {MIN_SPECTRUM_LENGTH}")

    v01 = _verdict_01(k01) if k01 is not None else None
    vsp = None if broadband is None else ("chaos" if broadband else "regular")
    sp_text = "broadband" if broadband else "discrete lines"
    if peak_fraction is not None:
        sp_text += f" ({100 * peak_fraction:.3g} % of the power in lines)"

    # deciding indicator: the LLE, else a decisive 0–1 test
    if lle is not None and threshold is not None:
        if lle > threshold:
            verdict, label = "chaos", Motion.chaos()
            why = f"LLE {_fmt(lle)} > threshold {_fmt(threshold)}, no period ≤ {max_period}"
        elif lle >= -threshold:
            verdict, label = "regular", Motion.quasi_periodic()
            why = (
                f"|LLE| = {_fmt(abs(lle))} ≤ threshold {_fmt(threshold)}, no period ≤ {max_period}"
            )
        else:
            verdict, label = "regular", Motion.unresolved()
            why = (
                f"LLE {_fmt(lle)} < −threshold −{_fmt(threshold)}: a contracting (periodic) "
                f"attractor, but no period ≤ {max_period} was found (longer period or "
                "transient not decayed)"
            )
        reason.append(why)
        deciding = "LLE"
    elif v01 is not None:
        assert k01 is not None
        verdict = v01
        label = Motion.chaos() if v01 == "chaos" else Motion.quasi_periodic()
        reason.append(f"0–1 test K = {_fmt(k01)} (no LLE), no period ≤ {max_period}")
        deciding = "0–1 test"
    else:
        why = f"no period ≤ {max_period}, no LLE"
        if k01 is not None:
            why += f", 0–1 test undecided (K = {_fmt(k01)})"
        if broadband is not None:
            why += f", spectrum {sp_text} (not decisive alone)"
        reason.append(why)
        return make(Motion.unresolved())

    # confirmation by the other indicators
    if deciding == "LLE" and k01 is not None:
        if v01 is None:
            notes.append(f"0–1 test undecided (K = {_fmt(k01)})")
        elif v01 != verdict:
            disagree.append(f"0–1 test K = {_fmt(k01)} says {v01}, {deciding} says {verdict}")
    if vsp is not None and vsp != verdict:
        disagree.append(f"spectrum {sp_text} says {vsp}, {deciding} says {verdict}")
    return make(label)


def _resolve_threshold(
    lle: float | None,
    lle_threshold: float | None,
    run_periods: float | None,
    forcing_period: float | None,
    lle_c: float,
) -> float | None:
    if lle_threshold is not None and not (math.isfinite(lle_threshold) and lle_threshold >= 0):
        raise ParameterError(f"lle_threshold must be a finite number >= 0: got {lle_threshold!r}")
    theta = None
    if run_periods is not None:
        if forcing_period is None:
            raise ParameterError(
                "forcing_period (T = 2π/Ω in the LLE's time unit) is needed with run_periods: "
                "got forcing_period=None"
            )
        theta = lle_threshold_for(run_periods, forcing_period, lle_c=lle_c)
    if lle_threshold is not None:
        theta = max(float(lle_threshold), theta or 0.0)
    if lle is not None and theta is None:
        raise ParameterError(
            "an LLE needs a threshold: give run_periods and forcing_period (θ = c/(run_periods·T))"
            " or lle_threshold: got neither"
        )
    return theta


def _as_points(points: Any) -> np.ndarray:
    try:
        p = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError):
        raise ParameterError(
            "points must be section points, numbers of shape (m,) or (m, d): got "
            f"{type(points).__name__} {str(points)[:40]!r}"
        ) from None
    if p.ndim == 1:
        p = p[:, None]
    elif p.ndim != 2:
        raise ParameterError(f"points must have shape (m,) or (m, d): got shape {p.shape}")
    return p


def classify_motion(
    points: Any,
    *,
    lle: float | None = None,
    lle_threshold: float | None = None,
    run_periods: float | None = None,
    forcing_period: float | None = None,
    k01: float | None = None,
    spectrum_peaks: bool | tuple[bool, float] | None = None,
    max_period: int = 64,
    rtol: float = 1e-3,
    atol: float = 0.0,
    lle_c: float = LLE_C,
    compute_indicators: bool = True,
) -> MotionClass:
    """Motion label of one attractor from its Poincaré section sequence and optional indicators.

    Parameters
    ----------
    points
        Section sequence in recording order, shape (m,) or (m, d), e.g. columns X̄_sp1 and
        X̄'_sp1 (:func:`~gearchaos.analysis.poincare.section_points`).
    lle
        Largest Lyapunov exponent (per unit τ for gearchaos systems), or None. NaN counts as
        None.
    lle_threshold
        Lower bound of the LLE threshold θ (same unit as ``lle``).
    run_periods, forcing_period
        Number of forcing periods the LLE was averaged over and the forcing period T = 2π/Ω
        (same time unit as ``lle``); they set θ = max(lle_threshold, c/(run_periods·T))
        (:func:`lle_threshold_for`). An LLE needs ``lle_threshold`` or both of these.
    k01
        0–1 test value K computed elsewhere (e.g. on a longer record); None computes it from
        ``points`` (when no period is found and m ≥ 100). NaN counts as None.
    spectrum_peaks
        Spectral verdict computed elsewhere, e.g. ``spectral_broadband(time_history)``: a
        ``(broadband, peak_fraction)`` pair or a bool; None computes it from ``points``
        (when no period is found and m ≥ 64).
    max_period, rtol, atol
        Period detection (:func:`~gearchaos.analysis.periodicity.detect_period`).
    lle_c
        The constant c of the LLE threshold (default 10).
    compute_indicators
        False skips computing the 0–1 test and the spectrum (only given indicators are used).

    Returns
    -------
    MotionClass
        The label and the indicators behind it. The rules are those of the module docstring
        (:mod:`gearchaos.analysis.classify`).
    """
    p = _as_points(points)
    lle_v = _finite_or_none(lle, "lle")
    theta = _resolve_threshold(
        lle_v, _finite_or_none(lle_threshold, "lle_threshold"), run_periods, forcing_period, lle_c
    )
    broadband, peak_fraction = _spectral_input(spectrum_peaks)
    period = int(periods_of(p, max_period=max_period, rtol=rtol, atol=atol))
    return _classify(
        p,
        period,
        lle=lle_v,
        threshold=theta if lle_v is not None else None,
        k01=_finite_or_none(k01, "k01"),
        broadband=broadband,
        peak_fraction=peak_fraction,
        compute_indicators=compute_indicators,
        max_period=max_period,
    )


_PER_POINT = ("lle", "k01", "lle_threshold", "run_periods", "forcing_period")


def classify_sections(
    section_values: Any,
    *,
    details: bool = False,
    lle: Any = None,
    k01: Any = None,
    lle_threshold: Any = None,
    run_periods: Any = None,
    forcing_period: Any = None,
    max_period: int = 64,
    rtol: float = 1e-3,
    atol: float = 0.0,
    lle_c: float = LLE_C,
    compute_indicators: bool = True,
) -> np.ndarray:
    """Motion labels for every point of a sweep, from its stored section values.

    Parameters
    ----------
    section_values
        Array of shape (..., section, d): the section sequence of every sweep point, e.g.
        ``np.stack([x_sp1, x_sp1_dot], axis=-1)`` of a store's (direction, Ω, section)
        variables.
    details
        False (default) returns the labels; True returns the :class:`MotionClass` objects.
    lle, k01, lle_threshold, run_periods, forcing_period
        As in :func:`classify_motion`; each may be a scalar or an array broadcastable to the
        leading shape ``section_values.shape[:-2]`` (in an Ω sweep the forcing period
        T = 2π/Ω varies per point). NaN entries of ``lle`` and ``k01`` mean "not available".
    max_period, rtol, atol, lle_c, compute_indicators
        As in :func:`classify_motion`.

    Returns
    -------
    numpy.ndarray
        Labels of dtype :data:`LABEL_DTYPE` (``<U10``) and the leading shape, or an object
        array of :class:`MotionClass` with ``details=True``.

    Notes
    -----
    Period detection runs once, vectorised over all points
    (:func:`~gearchaos.analysis.periodicity.periods_of`); the 0–1 test and the spectrum are
    computed only at the points where no period is found.
    """
    v = np.asarray(section_values, dtype=np.float64)
    if v.ndim < 2:
        raise ParameterError(
            f"section_values must have shape (..., section, d): got shape {v.shape}"
        )
    lead = v.shape[:-2]
    given = {
        "lle": lle,
        "k01": k01,
        "lle_threshold": lle_threshold,
        "run_periods": run_periods,
        "forcing_period": forcing_period,
    }
    arrays: dict[str, np.ndarray | None] = {}
    for name in _PER_POINT:
        val = given[name]
        if val is None:
            arrays[name] = None
            continue
        try:
            arr = np.broadcast_to(np.asarray(val, dtype=np.float64), lead)
        except ValueError:
            raise ParameterError(
                f"{name} must be a scalar or broadcastable to the sweep shape {lead}: "
                f"got shape {np.shape(val)}"
            ) from None
        arrays[name] = arr.reshape(-1)
    periods = periods_of(v, max_period=max_period, rtol=rtol, atol=atol).reshape(-1)
    flat = v.reshape(-1, *v.shape[-2:])
    out: np.ndarray = np.empty(flat.shape[0], dtype=object if details else LABEL_DTYPE)

    def at(name: str, i: int) -> float | None:
        arr = arrays[name]
        if arr is None:
            return None
        f = float(arr[i])
        return f if math.isfinite(f) else None

    for i in range(flat.shape[0]):
        lle_i = at("lle", i)
        theta = _resolve_threshold(
            lle_i, at("lle_threshold", i), at("run_periods", i), at("forcing_period", i), lle_c
        )
        mc = _classify(
            flat[i],
            int(periods[i]),
            lle=lle_i,
            threshold=theta if lle_i is not None else None,
            k01=at("k01", i),
            broadband=None,
            peak_fraction=None,
            compute_indicators=compute_indicators,
            max_period=max_period,
        )
        out[i] = mc if details else mc.label
    return out.reshape(lead)


def _label_key(label: str) -> tuple[int, tuple[int, int], str]:
    try:
        return (0, Motion.parse(label).sort_key, label)
    except ParameterError:  # not a motion label: after them, in text order
        return (1, (0, 0), label)


def sort_labels(labels: Iterable[str]) -> list[str]:
    """Distinct labels in display order (:attr:`~gearchaos.analysis.motion.Motion.sort_key`):
    1T, 2T, …, nT, QP, chaos, unresolved, failed, not run, then any other text."""
    return sorted({str(x) for x in labels}, key=_label_key)


def regime_table(labels: Any) -> dict[str, float]:
    """Fraction of the points (e.g. of a swept range) in each motion regime.

    Parameters
    ----------
    labels
        Labels of any shape (an array from :func:`classify_sections`, or a list).

    Returns
    -------
    dict
        label → fraction of the points, in the order of :func:`sort_labels`; the fractions sum
        to 1. For a uniform grid the fraction of points is the fraction of the swept range.
    """
    flat = [str(x) for x in np.asarray(labels, dtype=object).reshape(-1)]
    if not flat:
        raise ParameterError("labels must not be empty: got 0 labels")
    counts = Counter(flat)
    total = len(flat)
    return {lab: counts[lab] / total for lab in sort_labels(counts)}
