"""The motion verdict's rules for a point without a confirmed period: λ₁ over windows and the
band tests of the section (:func:`decide_by_exponent`).

Each extension of the run is a *window* with its own λ₁ ± σ (block means) and its bias bound
θ = c_θ/t (t the window's duration). With c the confidence factor:

* **chaos** when the interval lies above the bound, λ₁ − cσ > θ, or when it is positive,
  λ₁ − cσ > 0, and the 0–1 test says chaos on every band (every subsequence x_{j::n} of some
  n ≤ 4, so that bands visited in turn do not hide it) — in the latest window *and* in the one
  before it (a chaotic transient that ends between them is not chaos), and, where the settings
  ask for it, over a window of at least ``confirm_periods``;
* **QP** when the interval lies within the bound, 0 ≤ λ₁ + cσ ≤ θ, the window is at least two
  of the longest periods looked for long (a long period is seen first), no unstable orbit
  holds the motion, no stable orbit found by shooting may still be approached (a record too
  short to measure the approach runs on: a spiral onto an orbit keeps its cyclic order too),
  and the section shows a torus: for some n ≤ ``max_bands`` every subsequence x_{j::n}
  keeps its cyclic order (the rotation test, :func:`~gearchaos.analysis.bands.circle_order`),
  or some shift brings every point back close to itself (uniform recurrence,
  :func:`~gearchaos.analysis.bands.uniform_return`), or the 0–1 test is regular for every n;
* otherwise the run is extended (the second window as long as the first, each later one twice
  as long, so θ and σ shrink), and when
  the budget is spent the point is ``unresolved`` with the reason.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...analysis.bands import circle_order, uniform_return
from ...analysis.chaos01 import MIN_LENGTH as MIN_LENGTH_01, chaos01
from ...analysis.classify import K_CHAOS, K_REGULAR
from ...analysis.motion import Motion
from .evidence import Verdict

__all__ = ["SectionTests", "Window", "decide_by_exponent", "section_tests"]

#: Subsequence strides of the 0–1 test (bands visited in turn).
K01_STRIDES = (1, 2, 3, 4)
#: Fraction of rank shifts in one window for the rotation test to pass.
MIN_ORDER = 0.9
#: Largest uniform return (relative to the set's largest extent) of a torus: measured
#: 0.004–0.033 on tori of ``sheng2016`` (Ω = 3.3325, 1.0408, 2.5732 over 1600 periods; up to
#: 0.10 over 400), 0.18–0.69 on chaotic sets (``sheng2016`` Ω = 3.2338, 2.5, 2.45 and
#: ``hindawi2021``'s two-band weak chaos at Ω = 2.5, over 400 or 1600 periods).
MAX_RETURN = 0.1
#: A uniform return this small (the recurrence tolerance of a period, relative to the set's
#: size) is a repeating record, not a torus.
MIN_RETURN = 1e-3
#: Points of a subsequence the 0–1 test uses (its last ones): the test's cost grows with the
#: square of the length, and a few hundred points decide it.
K01_POINTS = 400


@dataclass(frozen=True)
class Window:
    """One extension: its first period (counted after the protocol's record), its length and
    its λ₁ ± σ with the bound θ."""

    start: int
    periods: int
    lle: float
    err: float
    theta: float


class SectionTests:
    """The 0–1 test and the rotation test of a window's section sequence x (m, d), each
    computed when first asked for (the 0–1 test costs far more than the rotation test, and
    most windows are decided without it): :meth:`k01` (K of every subsequence x_{j::n} of a
    stride n, on its last :data:`K01_POINTS` points), :attr:`torus_stride` (the smallest
    n ≤ ``max_bands`` whose every subsequence keeps its cyclic order; 0: none)."""

    def __init__(self, x: np.ndarray, max_bands: int) -> None:
        self.x = np.asarray(x, dtype=np.float64)
        self._k01: dict[int, tuple[float, ...]] = {}
        self._returns: tuple[float, int] | None = None
        self.torus_stride = 0
        for n in range(1, max_bands + 1):
            orders = [circle_order(self.x[j::n]) for j in range(n)]
            if not all(math.isfinite(o) for o in orders):
                break
            if all(o >= MIN_ORDER for o in orders):
                self.torus_stride = n
                break

    def k01(self, n: int) -> tuple[float, ...] | None:
        """K of each subsequence x_{j::n} (None: too short for the 0–1 test)."""
        if n not in self._k01:
            if self.x.shape[0] // n < MIN_LENGTH_01:
                return None
            self._k01[n] = tuple(chaos01(_principal(self.x[j::n][-K01_POINTS:])) for j in range(n))
        return self._k01[n]

    def chaotic(self) -> int:
        """The smallest stride n whose every subsequence has K > K_CHAOS (0: none)."""
        for n in K01_STRIDES:
            ks = self.k01(n)
            if ks is None:
                break
            if all(math.isfinite(k) and k > K_CHAOS for k in ks):
                return n
        return 0

    def returns(self) -> tuple[float, int]:
        """The uniform return (r, q) of the window's sequence
        (:func:`~gearchaos.analysis.bands.uniform_return`)."""
        if self._returns is None:
            self._returns = uniform_return(self.x)
        return self._returns

    def torus(self) -> str | None:
        """Why the section is a torus, or None: its cyclic order on each of its closed
        curves, a uniform return within :data:`MAX_RETURN` of the set's size, or a regular
        0–1 test on every band — never for a record whose every point returns within
        :data:`MIN_RETURN` (a periodic record, or one drifting along a family of orbits: the
        period candidates decide it)."""
        r, q = self.returns()
        if r <= MIN_RETURN:  # every point back on itself: a (nearly) periodic record
            return None
        if self.torus_stride:
            return f"the section keeps its cyclic order in {self.torus_stride} curve(s)"
        if r <= MAX_RETURN:
            return (
                f"every section point returns within {r:.3f} of the set's size after {q} "
                f"periods (uniform recurrence)"
            )
        if self.regular():
            return "the 0–1 test is regular on every band"
        return None

    def regular(self) -> bool:
        """K < K_REGULAR for every subsequence of every stride of :data:`K01_STRIDES` (all
        of them tested: bands visited in turn hide chaos from the shorter strides)."""
        for n in K01_STRIDES:
            ks = self.k01(n)
            if ks is None or not all(math.isfinite(k) and k < K_REGULAR for k in ks):
                return False
        return True

    def text(self) -> str:
        parts = []
        for n, ks in sorted(self._k01.items()):
            vals = ", ".join(f"{k:.2f}" for k in ks)
            parts.append(f"K = {vals}" if n == 1 else f"every {_ordinal(n)} point: {vals}")
        k = "0–1 test " + "; ".join(parts) if parts else "no 0–1 test needed"
        if self.torus_stride:
            t = f"the section keeps its cyclic order in {self.torus_stride} curve(s)"
        elif self._returns is not None and math.isfinite(self._returns[0]):
            r, q = self._returns
            t = f"no closed curve found (best uniform return {r:.3f} after {q} periods)"
        else:
            t = "no closed curve found"
        return f"{k}; {t}"


def _ordinal(n: int) -> str:
    """2nd, 3rd, 4th, 11th, 21st …"""
    tail = "th" if 10 <= n % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(n % 10, "th")
    return f"{n}{tail}"


def _principal(x: np.ndarray) -> np.ndarray:
    from ...analysis.bands import _principal as principal

    return principal(x)


def section_tests(x: np.ndarray, max_bands: int) -> SectionTests:
    """The :class:`SectionTests` of the section sequence x (m, d)."""
    return SectionTests(x, max_bands)


def _common(p: Any, w: Window, tests: SectionTests | None) -> dict[str, Any]:
    ks = tests.k01(1) if tests is not None else None
    k1 = ks[0] if ks else math.nan
    return {
        "lle": w.lle,
        "lle_error": w.err,
        "k01": k1,
        "extra_periods": p.extra,
        "record": p.record,
        "window_start": w.start,
        "window_periods": w.periods,
        "coexisting": tuple(sorted(p.coexisting.items())),
    }


def _chaotic_window(w: Window, tests: SectionTests | None, c: float) -> str | None:
    """Why the window says chaos, or None."""
    lo = w.lle - c * w.err
    if lo > w.theta:
        return f"λ₁ − {c:g}σ > θ"
    if lo > 0 and tests is not None and tests.chaotic():
        n = tests.chaotic()
        where = "the section" if n == 1 else f"every {_ordinal(n)} section point (each band)"
        return f"λ₁ − {c:g}σ > 0 and the 0–1 test K > {K_CHAOS} on {where}"
    return None


def decide_by_exponent(p: Any, vs: Any, last: bool) -> Verdict | None:
    """The rules of the module docstring for point ``p`` (its windows, its latest section
    record, an unstable orbit near it, stable orbits that coexist); None: extend again."""
    if not p.windows or not p.fresh:  # no window yet, or the record moved on since (a settle)
        return None
    w = p.windows[-1]
    if not math.isfinite(w.lle) or not math.isfinite(w.err):
        return None if not last else _unresolved(p, vs, w, None, "λ₁ could not be estimated")
    c = vs.confidence
    tests = section_tests(p.sections, vs.max_bands)
    p.tests = tests
    text = f"λ₁ = {w.lle:.4g} ± {w.err:.2g} (θ = {w.theta:.3g}) over {w.periods} periods"
    common = _common(p, w, tests)
    coexist = _coexist_text(p)
    hi = w.lle + c * w.err
    why = _chaotic_window(w, tests, c)
    # a stable orbit found by shooting that the record may still be approaching (its
    # approach not yet measurable) explains a contracting record whose recurrence gaps fall
    # below the noise floor at some long n (a slow spiral onto a 1T looks 17-periodic): run on
    if p.long_period and hi < 0 and not p.approaching:
        n = p.long_period
        return Verdict(
            label=Motion.periodic(n).format(),
            period=n,
            evidence="record_contracting",
            reason=f"the record repeats with period {n} (too long to shoot) and {text} < 0",
            **common,
        )
    if why is not None:
        before = p.windows[-2] if len(p.windows) >= 2 else None
        prev = _chaotic_window(before, p.prev_tests, c) if before is not None else None
        long_enough = w.periods >= vs.confirm_periods
        if before is not None and prev is not None and long_enough:
            return Verdict(
                label="chaos",
                period=0,
                evidence="lyapunov",
                reason=(
                    f"no period ≤ {vs.longest_period} confirmed; {text}: {why}, and so in "
                    f"the {before.periods} periods before ({prev}){coexist}"
                ),
                **common,
            )
    elif 0 <= hi <= w.theta and p.unstable is None and not p.approaching:
        long_record = p.history.shape[0] >= 2 * vs.longest_period
        torus = tests.torus() if long_record and w.periods >= vs.confirm_periods else None
        if torus is not None:
            return Verdict(
                label="QP",
                period=0,
                evidence="lyapunov",
                reason=(
                    f"no period ≤ {vs.longest_period} and no converging orbit; {text}: the "
                    f"interval lies within the bound of a regular attractor; {torus}{coexist}"
                ),
                **common,
            )
    if not last:
        return None
    return _unresolved(p, vs, w, tests, text)


def _coexist_text(p: Any) -> str:
    if not p.coexisting:
        return ""
    parts = [f"{Motion.periodic(d)} (max |μ| = {mu:.6g})" for d, mu in sorted(p.coexisting.items())]
    return "; a stable " + ", ".join(parts) + " coexists (the record does not approach it)"


def _unresolved(p: Any, vs: Any, w: Window, tests: SectionTests | None, text: str) -> Verdict:
    common = _common(p, w, tests)
    coexist = _coexist_text(p)
    hi = w.lle + vs.confidence * w.err
    if p.unstable is not None:
        d, mu, _ = p.unstable
        return Verdict(
            label="unresolved",
            period=0,
            evidence="unstable_orbit",
            max_multiplier=mu,
            reason=(
                f"the motion stays near an unstable period-{d} orbit (max |μ| = {mu:.6g}) "
                f"and was not decided within {p.extra} further periods; {text}{coexist}"
            ),
            **common,
        )
    if p.approaching:
        d = p.approaching
        return Verdict(
            label="unresolved",
            period=0,
            evidence="converging",
            reason=(
                f"a stable period-{d} orbit lies near the record, but the budget ended before "
                f"its approach could be measured; {text}{coexist}"
            ),
            **common,
        )
    if hi < 0:
        return Verdict(
            label="unresolved",
            period=0,
            evidence="contracting",
            reason=(
                f"{text} < 0: a contracting (periodic) attractor, but no period "
                f"≤ {vs.longest_period} was found or confirmed within {p.extra} further "
                f"periods{coexist}"
            ),
            **common,
        )
    extra = f"; {tests.text()}" if tests is not None else ""
    return Verdict(
        label="unresolved",
        period=0,
        evidence="ambiguous",
        reason=(
            f"{text}: neither chaos in two windows nor a torus within the bound after "
            f"{p.extra} further periods{extra}{coexist}"
        ),
        **common,
    )
