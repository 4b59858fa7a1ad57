"""Periodic orbits by shooting on the stroboscopic map, and their Floquet multipliers.

A T-periodically forced system y' = f(τ, y), T = 2π/Ω, has the stroboscopic (Poincaré) map
P(y) = φ(τ_s + T; τ_s, y) from the section τ ≡ τ_s (mod T) to itself. A period-n orbit is a
fixed point of the n-th iterate,

    G(y) = Pⁿ(y) − y = 0,

solved by Newton's method with a backtracking (damped) step
(:func:`gearchaos.dynamics.orbits.corrector.correct`). The Jacobian is the monodromy
matrix M = DPⁿ(y) = Φ_{n−1} ⋯ Φ_1 Φ_0, the product of the one-period fundamental solutions
Φ_k = ∂y(τ_s + (k+1)T)/∂y(τ_s + kT) of the variational equations V' = J(τ, y) V that the
compiled kernel integrates with the orbit (the tangent vectors start as the identity at each
section and are not re-orthonormalised). The vector fields of gearchaos are continuous (damping
acts inside the clearances, MODEL.md §4), so no saltation matrix is needed where a contact
changes transversally; at a grazing contact the map is C¹ only (its Jacobian is continuous
but not Lipschitz), and Newton converges more slowly there.

The eigenvalues μ of M are the Floquet multipliers: the orbit is asymptotically stable when all
|μ| < 1. Their product is det M = exp(∫ tr J dτ) over nT (Liouville); for the mechanical models,
tr J = −tr(M⁻¹C).

Two levels (STYLE principle 8): :func:`periodic_orbit` for users;
:mod:`gearchaos.dynamics.orbits.shooting` (C shootings in one compiled
:func:`~gearchaos.integrate._chains.run_chains` call) and :mod:`gearchaos.dynamics.orbits.corrector`
(the Newton corrector over K points) for batches and the continuation.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..._checks import check_int, check_real
from ..._version import provenance
from ...analysis.contact import contact_regime
from ...errors import IntegrationError, ParameterError, Status
from ...integrate.settings import SolverSettings, split_keywords
from ...model.record import model_record
from ...model.system import System
from ...model.target import Target, resolve, scale_attrs
from .corrector import Problem, Solution, Start, correct
from .shooting import section_time
from .stability import STABILITY_MARGIN, stability_of, structural_multipliers

__all__ = [
    "ORBIT_SETTINGS",
    "PeriodicOrbit",
    "check_tol",
    "contact_levels",
    "minimal_period",
    "orbit_contacts",
    "periodic_orbit",
    "solve_orbit",
]

#: Orbit defaults: the guess simulation from rest runs 50 forcing periods (Newton does the rest).
ORBIT_SETTINGS = SolverSettings(transient_periods=50)

#: Bearing regimes: never touching, touching one side, touching both sides of the clearance.
BEARING_REGIMES = ("free", "single_sided", "double_sided")


# ------------------------------------------------------------------------------ contacts
def contact_levels(system: System) -> list[tuple[str, int, float, str]]:
    """The contacts of a system: (name, tracked index, half clearance, ``mesh``/``bearing``).

    The model's :attr:`~gearchaos.model.System.contacts`: planetary models
    ``sun_planet_1..N``, ``planet_ring_1..N`` (regime from min δ as in
    :mod:`gearchaos.analysis.contact`) and ``sun_bearing_x``, ``sun_bearing_y`` (regime from
    the extrema of x̄_s, ȳ_s against ±b̄_s); the backlash oscillator ``mesh``; systems without
    clearances none.
    """
    return [(c.name, int(c.column), float(c.clearance), c.kind) for c in system.contacts]


def bearing_regime(lo: float, hi: float, b: float) -> str:
    """``free`` (|x| ≤ b throughout), ``single_sided`` or ``double_sided`` contact."""
    if math.isnan(lo) or math.isnan(hi):
        return "unknown"
    touches = int(hi > b) + int(lo < -b)
    return BEARING_REGIMES[touches]


def orbit_contacts(system: System, obs_min: np.ndarray, obs_max: np.ndarray) -> dict[str, str]:
    """Contact regime of every contact of ``system`` from the extrema over an orbit."""
    out = {}
    for name, k, b, what in contact_levels(system):
        if what == "mesh":
            out[name] = contact_regime(float(obs_min[k]), b)
        else:
            out[name] = bearing_regime(float(obs_min[k]), float(obs_max[k]), b)
    return out


# ------------------------------------------------------------------------------ the orbit
@dataclass(frozen=True, eq=False)
class PeriodicOrbit:
    """A period-n orbit of the stroboscopic map and its Floquet multipliers.

    Attributes
    ----------
    system
        The :class:`~gearchaos.model.System` (model and Ω) of the orbit.
    state
        (n_state,) the orbit's state y* at the section time τ_s (``section_tau``).
    period
        n, in forcing periods T = 2π/Ω.
    multipliers
        (n_state,) complex eigenvalues of the monodromy matrix, by modulus, descending.
    residual
        ‖Pⁿ(y*) − y*‖_∞ / max(1, ‖y*‖_∞) at the returned state.
    converged
        Whether the residual fell below ``tol``.
    iterations
        Map evaluations of the Newton iteration (with and without tangents, trial
        steps included).
    monodromy
        (n_state, n_state) M = DPⁿ(y*).
    sections
        (n, n_state) the states at τ_s + kT, k = 0 … n−1.
    section_obs
        (n, n_obs) the observables there.
    obs_min
        (n_track,) minima of the tracked observables over the orbit.
    obs_max
        (n_track,) maxima of the tracked observables over the orbit.
    settings
        The solver settings of the shooting.
    status
        The integration status of the last map evaluation.
    message
        Why the iteration stopped.
    tol
        The residual tolerance.
    values
        The parameter values by name it was computed at.
    """

    system: System
    state: np.ndarray
    period: int
    multipliers: np.ndarray
    residual: float
    converged: bool
    iterations: int
    monodromy: np.ndarray
    sections: np.ndarray
    section_obs: np.ndarray
    obs_min: np.ndarray
    obs_max: np.ndarray
    settings: SolverSettings
    status: Status = Status.OK
    message: str = ""
    tol: float = 1e-9
    values: Mapping[str, Any] = field(default_factory=dict)

    # -- derived ----------------------------------------------------------------
    @property
    def omega(self) -> float:
        return self.system.omega

    @property
    def section_tau(self) -> float:
        """τ_s, the section time of ``state`` within [0, T)."""
        return section_time(self.settings, self.system)

    @functools.cached_property
    def structural(self) -> np.ndarray:
        """Mask of the multipliers equal to 1 for a structural reason (a free direction,
        :func:`~gearchaos.dynamics.orbits.stability.structural_multipliers`)."""
        if not self.multipliers.size or not np.all(np.isfinite(self.monodromy)):
            return np.zeros(self.multipliers.size, dtype=bool)
        return structural_multipliers(
            self.system, self.state, self.period, self.monodromy, self.settings
        )

    @property
    def max_multiplier(self) -> float:
        """max |μ| over the non-structural multipliers (NaN when they are unknown)."""
        if not self.multipliers.size:
            return math.nan
        return stability_of(self.multipliers, self.structural)[1]

    @property
    def stable(self) -> bool:
        """Converged and every non-structural |μ| < 1 − 10⁻⁴: the one stability criterion of
        :mod:`gearchaos.dynamics.orbits.stability`, the motion verdict's."""
        return bool(self.converged and stability_of(self.multipliers, self.structural)[0])

    @property
    def minimal_period(self) -> int:
        """The smallest d dividing n with the section points repeating after d periods (to
        max(1e-6, 100 tol) relative): 1 for a period-1 orbit found as a fixed point of P²."""
        return minimal_period(self.sections, self.tol)

    @property
    def contact(self) -> dict[str, str]:
        """Contact regime of every mesh (``none``, ``single_sided``, ``double_sided``, as in
        :mod:`gearchaos.analysis.contact`) and of the sun bearing (``free``,
        ``single_sided``, ``double_sided``) along the orbit; empty without clearances."""
        return orbit_contacts(self.system, self.obs_min, self.obs_max)

    def section(self, name: str, planets: Sequence[int] | None = None) -> np.ndarray:
        """The orbit's n section values of a state or observable by name (``delta_sp`` gives
        (n, N), ``delta_sp_1`` or ``x`` gives (n,))."""
        ob = self.system.observable(name, planets)
        return ob.take(self.sections, self.section_obs)

    def summary(self) -> dict[str, Any]:
        """A JSON-serialisable summary: ``period`` (the one shot), ``minimal_period`` (the
        orbit's own: a period-2 shooting may converge on a 1T orbit), ``converged``,
        ``residual``, ``stable``, ``stability_margin`` (stable: every non-structural
        |μ| < 1 − margin), ``max_multiplier``, ``multipliers`` ([{re, im, abs}]),
        ``section_variable`` (the model's section variable:
        :meth:`~gearchaos.model.System.section_pair`, the planetary model's ``delta_sp_1``),
        ``section`` (its n section values), ``contact`` ([{contact, regime}]) and ``message``
        (how it converged or why not; how long the guess settled)."""
        first = self.system.section_pair()[0]
        return {
            "period": int(self.period),
            "minimal_period": int(self.minimal_period),
            "converged": bool(self.converged),
            "max_multiplier": float(self.max_multiplier),
            "residual": float(self.residual),
            "stable": bool(self.stable),
            "stability_margin": STABILITY_MARGIN,
            "multipliers": [
                {"re": float(m.real), "im": float(m.imag), "abs": float(abs(m))}
                for m in self.multipliers
            ],
            "section_variable": first,
            "section": [float(v) for v in self.section(first)],
            "contact": [{"contact": k, "regime": v} for k, v in self.contact.items()],
            "message": self.message,
        }

    def save(self, path: Any) -> str:
        """Write the orbit to a netCDF-4 orbit file, the start ``gearchaos continue --from``
        reads (:func:`~gearchaos.dynamics.orbits.file.save_orbit`); returns the path."""
        from .file import save_orbit

        return save_orbit(self, path)

    # -- xarray --------------------------------------------------------------------
    def attrs(self) -> dict[str, Any]:
        """Provenance attributes (gear set TOML, model, settings, versions)."""
        return {
            "title": f"gearchaos periodic orbit of {self.system.name}",
            **model_attrs(self.system),
            "omega": self.omega,
            "period": int(self.period),
            "converged": int(self.converged),
            "residual": float(self.residual),
            "tol": float(self.tol),
            "iterations": int(self.iterations),
            "status": self.status.name.lower(),
            "message": self.message,
            "section_tau": self.section_tau,
            **{
                f"parameter:{k}": v if isinstance(v, int | float | str) else repr(v)
                for k, v in self.values.items()
            },
            **self.settings.attrs(),
            **provenance(),
        }

    def to_dataset(self) -> Any:
        """The orbit as an :class:`xarray.Dataset`: ``orbit_state`` (state), ``multiplier_re``,
        ``multiplier_im``, ``multiplier_abs`` (multiplier), ``monodromy`` (state, state_in),
        ``section_state`` (section, state), the tracked observables at the sections
        (``delta_sp`` (section, planet) …), their extrema (``delta_sp_min`` …), ``contact``
        regimes (contact); attributes as :meth:`attrs`."""
        import xarray as xr

        sys = self.system
        names = list(sys.state_names)
        ds = xr.Dataset(
            coords={
                "state": ("state", np.array(names, dtype="U16")),
                "state_in": ("state_in", np.array(names, dtype="U16")),
                "section": ("section", np.arange(self.period)),
                "multiplier": ("multiplier", np.arange(self.multipliers.size)),
            },
            attrs=self.attrs(),
        )
        ds["orbit_state"] = ("state", self.state, {"long_name": "y* at the section τ_s"})
        ds["multiplier_re"] = ("multiplier", self.multipliers.real)
        ds["multiplier_im"] = ("multiplier", self.multipliers.imag)
        ds["multiplier_abs"] = ("multiplier", np.abs(self.multipliers))
        ds["monodromy"] = (("state", "state_in"), self.monodromy, {"long_name": "M = DPⁿ(y*)"})
        ds["section_state"] = (("section", "state"), self.sections)
        for nm, cols, per_planet in sys.tracked_groups():
            vals = self.section_obs[:, cols]
            if per_planet:
                ds.coords["planet"] = ("planet", np.arange(1, cols.size + 1))
                ds[nm] = (("section", "planet"), vals)
                ds[f"{nm}_min"] = ("planet", self.obs_min[cols])
                ds[f"{nm}_max"] = ("planet", self.obs_max[cols])
            else:
                ds[nm] = ("section", vals[:, 0])
                ds[f"{nm}_min"] = float(self.obs_min[cols[0]])
                ds[f"{nm}_max"] = float(self.obs_max[cols[0]])
        contacts = self.contact
        if contacts:
            ds.coords["contact"] = ("contact", np.array(list(contacts), dtype="U16"))
            ds["contact_regime"] = ("contact", np.array(list(contacts.values()), dtype="U16"))
        return ds


def minimal_period(sections: np.ndarray, tol: float) -> int:
    """The smallest d dividing n = len(sections) with the n section points of an orbit
    repeating after d periods, to max(1e-6, 100 tol) relative to max(1, max |y|)."""
    n = int(sections.shape[0])
    scale = max(1.0, float(np.max(np.abs(sections))))
    thr = max(1e-6, 100.0 * tol) * scale
    for d in range(1, n + 1):
        if n % d == 0 and np.max(np.abs(np.roll(sections, -d, axis=0) - sections)) <= thr:
            return d
    return n


def model_attrs(system: System) -> dict[str, Any]:
    """The model's provenance: ``model``, its reference (``model_class``, ``model_fields``),
    ``gearset_toml``, ``model_parameters``, scales and clearances (the attributes sweeps and
    simulations carry: :func:`~gearchaos.model.record.model_record`)."""
    return {**model_record(system), **scale_attrs(system.model)}


# ------------------------------------------------------------------------------ front door
def default_tol(settings: SolverSettings) -> float:
    """The default Newton tolerance: rtol/10, at least 1e-12 (the map evaluated with and
    without tangents differs by ~rtol/30 relative, its noise floor is far lower)."""
    return max(1e-12, 0.1 * float(settings.rtol))


def check_tol(tol: Any, settings: SolverSettings) -> float:
    """A relative residual tolerance in (0, 0.1], or the default (:func:`default_tol`)."""
    if tol is None:
        return default_tol(settings)
    return check_real("tol", tol, lo=0.0, hi=0.1, lo_open=True)


def initial_guess(
    system: System, guess: Any, n: int, cfg: SolverSettings, what: str = "guess"
) -> np.ndarray:
    """The Newton start: a state, an orbit's state, or the section point of a simulation
    (``guess=None``: ``transient_periods`` from rest) that best repeats after n periods."""
    if isinstance(guess, PeriodicOrbit):
        return np.array(guess.state, dtype=np.float64)
    if guess is None:
        from ...integrate.simulate import integrate

        traj = integrate(system, cfg.replace(periods=2 * n, samples_per_period=1))
        if not traj.ok:
            raise IntegrationError(
                f"the guess simulation at omega={system.omega:g} failed: {traj.status.message}"
            )
        secs = traj.states[traj.section_index]
    elif hasattr(guess, "section_index") and hasattr(guess, "states"):
        secs = np.asarray(guess.states)[guess.section_index]
        if secs.shape[0] < n + 1:
            raise ParameterError(
                f"{what} must record at least {n + 1} section points for period {n}: "
                f"got {secs.shape[0]}"
            )
        secs = secs[-2 * n :] if secs.shape[0] >= 2 * n else secs
    else:
        return system.check_state(guess, what)
    m = secs.shape[0] - n
    gaps = [np.max(np.abs(secs[j + n] - secs[j])) for j in range(m)]
    return np.array(secs[int(np.argmin(gaps)) + n], dtype=np.float64)


def periodic_orbit(
    target: Target,
    *,
    period: int = 1,
    guess: Any = None,
    settings: SolverSettings | None = None,
    params: Mapping[str, Any] | None = None,
    tol: float | None = None,
    max_iterations: int = 40,
    settle: float | None = None,
    **values_and_settings: Any,
) -> PeriodicOrbit:
    """A period-n orbit by shooting, with its Floquet multipliers.

    Solves G(y) = Pⁿ(y) − y = 0 for the stroboscopic map P over one forcing period T = 2π/Ω
    by Newton's method, y ← y + λ d with (M − I) d = −G(y) and M = DPⁿ(y) from the
    variational equations (the corrector of :mod:`~gearchaos.dynamics.orbits.corrector`, K = 1):
    a quasi-Newton iteration (M updated by Broyden's formula while ‖G‖ falls at least tenfold
    per step, evaluated afresh otherwise), λ = 1 or the longest of ½ … 1/16 that lowers ‖G‖
    (evaluated together in one compiled call), every step at most ten times the size of the
    state. The multipliers are those of an evaluation with tangents within ``tol`` of the
    returned state.

    Parameters
    ----------
    target
        A :class:`~gearchaos.gearset.GearSet` or a :class:`~gearchaos.model.System`.
    period
        n, the orbit's period in forcing periods.
    guess
        The Newton start: ``None`` (simulate ``transient_periods`` from rest, then take the
        section point that best repeats after n periods; see ``settle``), a state, a
        :class:`PeriodicOrbit`, or a simulation result (:func:`gearchaos.simulate`, same
        section).
    settings, **values_and_settings
        Parameter values by name (``omega=1.2``, ``xi=0.05``; names that are not Python
        identifiers go in ``params={"backlash.sun_planet": 2.4}``) and solver settings
        (a :class:`~gearchaos.integrate.settings.SolverSettings` and/or ``rtol``, ``atol``,
        ``transient_periods`` (of the guess; default 50), ``section_phase``, ``max_steps``
        by name). The section is the one :func:`gearchaos.simulate` samples with the same
        settings.
    tol
        Tolerance of the residual ‖G(y)‖_∞ / max(1, ‖y‖_∞) and of the last Newton correction
        (relative to max(1, ‖y‖_∞)); default rtol/10, at least 1e-12.
    max_iterations
        Rounds of the Newton iteration allowed (each a trial step, the damped steps of one
        step, or a fresh Jacobian; ``iterations`` counts the map evaluations they took).
    settle
        With ``guess=None``: the most mesh periods simulated from rest for the guess (default
        16 × ``transient_periods``). While the shooting ends on no orbit or on an unstable one
        (a record that had not settled yet: the motion from rest is still leaving an unstable
        orbit), the guess simulation runs twice as long again, up to ``settle``; the first
        stable orbit found is returned, else the first converged one. ``settle =
        transient_periods`` shoots once. The orbit's ``settings.transient_periods`` says which
        settle gave its guess.

    Returns
    -------
    PeriodicOrbit
        Never raises when Newton fails: check ``converged`` and ``message``.

    Notes
    -----
    A fixed point of P (a 1T orbit) also solves G = 0 for n > 1; check
    :attr:`PeriodicOrbit.minimal_period`. Near a grazing contact the Jacobian is not
    Lipschitz and convergence slows; the multipliers change steeply there. Gear sets with
    eccentricity errors are not T-periodic (a warning says so).
    """
    n = check_int("period", period, lo=1, hi=10_000)
    values, cfg = split_keywords(
        values_and_settings, settings, params, ORBIT_SETTINGS, door=periodic_orbit, target=target
    )
    system = resolve(target, values)
    system.warn_for("Poincaré section")
    eps = check_tol(tol, cfg)
    iters = check_int("max_iterations", max_iterations, lo=1, hi=10_000)
    if guess is None:
        return settled_orbit(system, n, cfg, eps, iters, values=values, settle=settle)
    if settle is not None:
        raise ParameterError(f"settle applies to guess=None only: got settle={settle!r}")
    y = initial_guess(system, guess, n, cfg)
    return solve_orbit(system, y, n, cfg, eps, iters, values=values)


#: Default longest settle of the guess simulation, in multiples of ``transient_periods``.
SETTLE_FACTOR = 16


def settled_orbit(
    system: System,
    n: int,
    cfg: SolverSettings,
    tol: float,
    max_iterations: int,
    *,
    values: Mapping[str, Any] | None = None,
    settle: float | None = None,
    want_stable: bool = True,
) -> PeriodicOrbit:
    """The period-n orbit from simulations from rest of growing length (see ``settle`` of
    :func:`periodic_orbit`): transients T0, T0 + m, T0 + 3m, T0 + 7m, … (m = ⌈T0⌉, so the
    section phase stays that of T0) until the shooting converges (on a stable orbit when
    ``want_stable``) or the next transient would exceed ``settle``."""
    first = float(cfg.transient_periods)
    most = SETTLE_FACTOR * max(first, 1.0) if settle is None else settle
    most = check_real("settle", most, lo=first)
    step = max(1, math.ceil(first))
    tried: list[PeriodicOrbit] = []
    extra = 0
    while True:
        c = cfg.replace(transient_periods=first + extra)
        orbit = solve_orbit(
            system, initial_guess(system, None, n, c), n, c, tol, max_iterations, values=values
        )
        tried.append(orbit)
        done = orbit.stable if want_stable else orbit.converged
        extra = 2 * extra + step
        if done or first + extra > most:
            break
    if len(tried) == 1 or tried[-1].stable or (tried[-1].converged and not want_stable):
        return _settled_note(tried[-1], tried)
    converged = [o for o in tried if o.converged]
    return _settled_note(converged[0] if converged else tried[0], tried)


def _settled_note(orbit: PeriodicOrbit, tried: Sequence[PeriodicOrbit]) -> PeriodicOrbit:
    """``orbit`` with its message saying how long the guess settled (several tries)."""
    if len(tried) == 1:
        return orbit
    lo = tried[0].settings.transient_periods
    hi = tried[-1].settings.transient_periods
    used = orbit.settings.transient_periods
    periods = f"{orbit.system.capabilities.period_name} periods"  # the model's (mesh periods)
    if orbit.stable:
        why = f"guess after {used:g} {periods} from rest (tried {lo:g}–{hi:g})"
    elif orbit.converged:
        why = (
            f"no stable period-{orbit.period} orbit reached from rest in {lo:g}–{hi:g} "
            f"{periods}; this unstable one is from the {used:g}-period guess"
        )
    else:
        why = f"{orbit.message} (guesses after {lo:g}–{hi:g} {periods} from rest)"
    return replace(orbit, message=(f"converged; {why}" if orbit.converged else why))


def solve_orbit(
    system: System,
    y0: np.ndarray,
    n: int,
    cfg: SolverSettings,
    tol: float,
    max_iterations: int,
    *,
    values: Mapping[str, Any] | None = None,
) -> PeriodicOrbit:
    """The Newton corrector of :mod:`.corrector` on Pⁿ(y) − y = 0 from y0 at fixed parameters
    (the kernel of :func:`periodic_orbit`): one point, Broyden-updated M, damped steps
    evaluated together; an orbit that did not converge is its best state."""
    prob = Problem(n, cfg, tol, max_iterations, keep_failed=True)
    sol, _ = correct(prob, Start.fixed(system, y0))
    assert sol is not None  # keep_failed
    return orbit_from(system, sol, period=n, settings=cfg, tol=tol, values=dict(values or {}))


def orbit_from(system: System, sol: Solution, **kw: Any) -> PeriodicOrbit:
    """A :class:`PeriodicOrbit` from a corrector :class:`~.corrector.Solution`."""
    shot = sol.shot
    return PeriodicOrbit(
        system=system,
        state=sol.y.copy(),
        multipliers=sol.mu,
        monodromy=sol.monodromy,
        residual=sol.residual,
        iterations=sol.evals,
        sections=shot.sections[0],
        section_obs=shot.section_obs[0],
        obs_min=shot.obs_min[0],
        obs_max=shot.obs_max[0],
        converged=sol.converged,
        message=sol.message,
        status=sol.status,
        **kw,
    )
