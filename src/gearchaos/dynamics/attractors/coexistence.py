"""Coexisting attractors at one operating point: :func:`attractors`.

A forced gear train with clearances often has more than one attractor at the same parameters
(a stable 1T orbit beside a chaotic attractor, two 2T orbits …); which one a simulation shows
depends on where it starts. :func:`attractors` simulates from K initial conditions in one
compiled call — the state at rest (the protocol's start, perturbed as the settings say) and
K − 1 states drawn (seeded) around the rest start's motion, each component uniform in
mid ± s·range with s = 1, 2, 3, 4 in turn, ``mid`` and ``range`` the middle and the extent of
the component over the rest start's recorded window — decides each run's motion with the
verdict (:func:`~gearchaos.dynamics.verdict.decide.decide_motion`, as a sweep decides its points:
orbits confirmed by shooting, λ₁ ± its error, transients finished) and groups the runs into
distinct attractors:

* two periodic runs are the same attractor when they have the same period n and every section
  point of one lies within ``tol`` of a section point of the other (states scaled per
  component by the spread of all runs' section points, at least 1);
* two non-periodic runs (QP, chaos, unresolved) with the same label are the same attractor
  when, for every state component, the 10 %, 50 % and 90 % quantiles of their section
  points agree to ``spread_fraction`` (0.25) of the largest extent of the two sets together;
* a periodic and a non-periodic run are never the same.

Each periodic attractor is confirmed by shooting its period-n orbit from the run's final state
(:func:`~gearchaos.dynamics.orbits.batch.periodic_orbits`), which gives its Floquet multipliers.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..._checks import check_int, check_real
from ...analysis.motion import Motion
from ...errors import ParameterError
from ...integrate._chains import ChainRun, run_chains
from ...integrate.settings import SolverSettings, split_keywords
from ...model.target import Target, resolve
from ..orbits.orbit import PeriodicOrbit
from ..verdict.decide import CONFIRM_PERIODS, confirmed_settings, decide_motion
from ..verdict.evidence import Verdict

__all__ = ["ATTRACTOR_SETTINGS", "Attractor", "attractors"]

#: Default protocol: 200 transient + 100 recorded forcing periods per start.
ATTRACTOR_SETTINGS = SolverSettings(transient_periods=200, periods=100)


@dataclass(frozen=True, eq=False)
class Attractor:
    """One attractor found from one or more starts.

    Attributes
    ----------
    label
        Motion verdict (``1T`` … ``nT``, ``QP``, ``chaos``, ``unresolved``).
    period
        n for an nT label, else 0.
    lle
        Largest Lyapunov exponent λ₁ per unit τ of its first run (the verdict's: exactly
        ln max|μ|/(nT) for a confirmed orbit).
    starts
        Indices of the starts that reached it (0 is the start at rest).
    initial_states
        (len(starts), n_state) those starts.
    final_state
        The state at the end of its first run (on the section).
    section_states
        (periods, n_state) the states at the section points of its first run.
    sections
        (periods, n_obs) the observables there.
    system
        The :class:`~gearchaos.model.System` (model and Ω).
    orbit
        The period-n orbit shot from ``final_state`` (periodic attractors), else None.
    values
        The parameter values by name it was computed at.
    verdict
        The :class:`~gearchaos.dynamics.verdict.decide.Verdict` of its first run (evidence,
        λ₁'s error, the reason).
    """

    label: str
    period: int
    lle: float
    starts: tuple[int, ...]
    initial_states: np.ndarray
    final_state: np.ndarray
    section_states: np.ndarray
    sections: np.ndarray
    system: Any
    orbit: PeriodicOrbit | None = None
    values: Mapping[str, Any] = field(default_factory=dict)
    verdict: Verdict | None = None

    @property
    def max_multiplier(self) -> float:
        """max |μ| of the orbit (NaN without one)."""
        return self.orbit.max_multiplier if self.orbit is not None else math.nan

    @property
    def stable(self) -> bool | None:
        """Whether the orbit is converged and every |μ| < 1 (None without an orbit)."""
        return None if self.orbit is None else self.orbit.stable

    def section(self, name: str, planets: Any = None) -> np.ndarray:
        """The section values of a state or observable of the first run by name (as
        :meth:`~gearchaos.dynamics.orbits.orbit.PeriodicOrbit.section`)."""
        ob = self.system.observable(name, planets)
        return np.asarray(ob.take(self.section_states, self.sections))

    def summary(self) -> dict[str, Any]:
        """A JSON-serialisable summary: ``label``, ``lle``, ``lle_error``, ``evidence``,
        ``starts``, ``section_variable`` (the model's section variable:
        :meth:`~gearchaos.model.System.section_pair`, the planetary model's ``delta_sp_1``),
        ``section`` (its distinct section values of the first run, at most 8, else its range),
        ``orbit`` (period, converged, residual, max_multiplier, stable) or None."""
        first = self.system.section_pair()[0]
        x = self.section(first)
        distinct = np.unique(np.round(x, 6))
        out: dict[str, Any] = {
            "label": self.label,
            "lle": float(self.lle),
            "lle_error": None if self.verdict is None else self.verdict.to_dict()["lle_error"],
            "evidence": None if self.verdict is None else self.verdict.evidence,
            "starts": [int(s) for s in self.starts],
            "section_variable": first,
            "section": [float(v) for v in distinct]
            if distinct.size <= 8
            else [float(np.min(x)), float(np.max(x))],
            "orbit": None,
        }
        if self.orbit is not None:
            o = self.orbit
            out["orbit"] = {
                "period": int(o.period),
                "converged": bool(o.converged),
                "residual": float(o.residual),
                "max_multiplier": float(o.max_multiplier),
                "stable": bool(o.stable),
            }
        return out


def _starts(system: Any, cfg: SolverSettings, k: int, seed: int) -> np.ndarray:
    """The start at rest and k − 1 seeded random starts around its motion."""
    from ...integrate.simulate import integrate

    m = system.n_state
    y0 = np.zeros((k, m))
    rest = cfg.rest_state(m)
    if rest is not None:
        y0[0] = rest  # the protocol's start
    traj = integrate(system, cfg.replace(samples_per_period=16))
    st = np.asarray(traj.states, dtype=float)
    ok = np.all(np.isfinite(st), axis=1)
    st = st[ok] if np.any(ok) else np.zeros((1, m))
    lo, hi = st.min(axis=0), st.max(axis=0)
    mid = 0.5 * (lo + hi)
    span = np.maximum(hi - lo, 1e-3 * np.maximum(1.0, np.abs(mid)))
    rng = np.random.default_rng(seed)
    for j in range(1, k):
        scale = 1 + (j - 1) % 4
        y0[j] = mid + rng.uniform(-1.0, 1.0, m) * scale * span
    return y0


def _given_starts(initial_states: Any, n: int) -> np.ndarray:
    """``initial_states`` as a finite (K, n) array, else a ParameterError naming it."""
    try:
        y0 = np.array(initial_states, dtype=np.float64)
    except (TypeError, ValueError):
        raise ParameterError(
            f"initial_states must be an array of shape (K, {n}): got "
            f"{type(initial_states).__name__}"
        ) from None
    if y0.ndim != 2 or y0.shape[1] != n or not 1 <= y0.shape[0] <= 10_000:
        raise ParameterError(
            f"initial_states must have shape (K, {n}) with 1 <= K <= 10000: got {y0.shape}"
        )
    if not np.all(np.isfinite(y0)):
        raise ParameterError("initial_states must be finite: got NaN or inf")
    return y0


def _same_periodic(a: np.ndarray, b: np.ndarray, tol: float) -> bool:
    d = np.max(np.abs(a[:, None, :] - b[None, :, :]), axis=2)
    return bool(np.all(d.min(axis=1) <= tol) and np.all(d.min(axis=0) <= tol))


def _same_set(a: np.ndarray, b: np.ndarray, fraction: float) -> bool:
    """Whether two section sets (points × components) are samples of one set: every
    component's 10 %, 50 % and 90 % quantiles agree to ``fraction`` of the union's extent."""
    q = np.array([0.1, 0.5, 0.9])
    qa, qb = np.quantile(a, q, axis=0), np.quantile(b, q, axis=0)
    both = np.concatenate([a, b])
    size = float(np.max(np.ptp(both, axis=0)))
    return bool(np.max(np.abs(qa - qb)) <= fraction * max(size, 1e-12))


def attractors(
    target: Target,
    *,
    starts: int = 8,
    seed: int = 0,
    settings: SolverSettings | None = None,
    params: Mapping[str, Any] | None = None,
    tol: float = 1e-4,
    spread_fraction: float = 0.25,
    initial_states: Any = None,
    confirm_periods: int = CONFIRM_PERIODS,
    **values_and_settings: Any,
) -> list[Attractor]:
    """Distinct attractors at one operating point, from several initial conditions.

    Parameters
    ----------
    target
        A :class:`~gearchaos.gearset.GearSet` or a :class:`~gearchaos.model.System`.
    starts
        K, the number of initial conditions: the state at rest and K − 1 seeded random states
        around the rest start's motion (see the module doc).
    seed
        Seed of the random starts.
    settings, params, **values_and_settings
        Parameter values by name (``omega=1.5``; dotted names in ``params``) and solver
        settings (``transient_periods`` (200), ``periods`` (100), ``rtol``, ``atol`` …), as
        for :func:`~gearchaos.dynamics.orbits.orbit.periodic_orbit`.
    tol
        Two periodic runs are one attractor when their section states agree to ``tol``
        (scaled per component by max(1, spread)).
    spread_fraction
        Two non-periodic runs with one label are one attractor when the quantiles of their
        section sets agree to this fraction of their extent.
    initial_states
        (K, n_state) explicit starts instead of the rest start and the random ones (``starts``
        and ``seed`` are then unused); the basins of :mod:`gearchaos.dynamics.attractors.basins`
        find
        their catalogue of attractors from a sample of their own starts this way.
    confirm_periods
        A chaotic or quasi-periodic run is listed only after a last window of at least this
        many periods confirms it (default 2000): a chaotic transient that ends on an orbit
        within it is that orbit's run, and is merged with it.

    Returns
    -------
    list of Attractor
        Distinct attractors, the one reached from rest first, then by how many starts reached
        them. Periodic ones carry their shot orbit (multipliers, stability); every one carries
        λ₁ (> 0 for chaos, < 0 for a stable orbit: ln max|μ| / nT).
    """
    from ..orbits.batch import periodic_orbits

    k = check_int("starts", starts, lo=1, hi=10_000)
    check_int("seed", seed, lo=0)
    check_real("tol", tol, lo=0.0, lo_open=True)
    check_real("spread_fraction", spread_fraction, lo=0.0, hi=1.0, lo_open=True)
    values, cfg = split_keywords(
        values_and_settings, settings, params, ATTRACTOR_SETTINGS, door=attractors, target=target
    )
    cfg = cfg.replace(samples_per_period=1)
    system = resolve(target, values)
    if initial_states is None:
        y0 = _starts(system, cfg, k, seed)
    else:
        y0 = _given_starts(initial_states, system.n_state)
        k = y0.shape[0]
    run = ChainRun.from_systems([[system]] * k, cfg, y0=y0)
    out = run_chains(run)
    m = system.n_state
    states = out.states[:, 0, :, :m].copy()
    obs = out.observables[:, 0].copy()
    finals = out.final_state[:, 0, :m].copy()
    verdicts = decide_motion(
        target,
        [values] * k,
        [system] * k,
        states,
        finals,
        out.status[:, 0] == 0,
        cfg,
        confirmed_settings(confirm_periods),
    )
    for j, v in enumerate(verdicts):
        if v.record is not None:  # the finished record the verdict is about
            n_rec = states.shape[1]
            states[j] = v.record.states[-n_rec:]
            obs[j] = v.record.observables[-n_rec:]
            finals[j] = v.record.final_state
    labels = [v.label for v in verdicts]
    lle = np.array([v.lle for v in verdicts])
    runs = [j for j in range(k) if labels[j] != "failed"]
    finite = np.concatenate([states[j] for j in runs]) if runs else np.ones((1, m))
    scale = np.maximum(1.0, np.ptp(finite, axis=0))
    groups: list[list[int]] = []
    for j in runs:
        lab = str(labels[j])
        motion = Motion.parse(lab)
        for g in groups:
            i = g[0]
            if str(labels[i]) != lab:
                continue
            a, b = states[j] / scale, states[i] / scale
            n = motion.period
            same = (
                _same_periodic(a[-n:], b[-n:], tol)
                if motion.is_periodic
                else _same_set(a, b, spread_fraction)
            )
            if same:
                g.append(j)
                break
        else:
            groups.append([j])
    groups.sort(key=lambda g: (g[0] != 0, -len(g)))
    found = []
    for g in groups:
        lab = str(labels[g[0]])
        n = Motion.parse(lab).period
        found.append(
            Attractor(
                label=lab,
                period=n,
                lle=float(lle[g[0]]),
                starts=tuple(g),
                initial_states=y0[g],
                final_state=finals[g[0]].copy(),
                section_states=states[g[0]].copy(),
                sections=obs[g[0]].copy(),
                system=system,
                values=dict(values),
                verdict=verdicts[g[0]],
            )
        )
    for n in sorted({a.period for a in found if a.period}):
        idx = [i for i, a in enumerate(found) if a.period == n]
        orbits = periodic_orbits(
            target,
            [values] * len(idx),
            period=n,
            guesses=np.stack([found[i].final_state for i in idx]),
            settings=cfg,
        )
        for i, orb in zip(idx, orbits, strict=True):
            found[i] = dataclasses.replace(found[i], orbit=orb)
    return found
