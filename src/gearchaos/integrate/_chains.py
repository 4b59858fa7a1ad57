"""The one Python caller of the compiled integrator: :func:`run_chains`.

Single runs, batches and sweep tasks are all *chains*: C independent chains (run in parallel on
a pool of threads, :func:`run_threaded`) of L points each (run in order, each optionally
starting from its predecessor's final state). :class:`ChainRun` holds the numbers of such a
job — packed parameters, switch widths, sample times, tolerances — and nothing else, so it can
be shipped to another process or a Dask worker; :class:`ChainOutput` holds the kernel's raw outputs.
The kernel's argument list is written here and nowhere else: the arrays of a :class:`ChainRun`
(``_CHAIN_INPUTS``), its configuration record (:func:`config_record`, slots
:class:`~gearchaos.integrate.interface.Config`) and the arrays of a :class:`ChainOutput`
(``_CHAIN_OUTPUTS``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields, replace
from typing import Any

import numpy as np

from .._numba import entry_point
from ..errors import ParameterError, Status
from ..model.system import System
from .interface import Config, Info
from .settings import SampleTimes, SolverSettings
from .threads import announce_ready, pool, wait_all

__all__ = ["ChainOutput", "ChainRun", "SampleArrays", "config_record", "run_chains"]


@dataclass(frozen=True, eq=False)
class ChainRun:
    """The numbers of C chains of L points of one system kind.

    Arrays: ``Y0`` (C, n_full) initial states (system state, then ``n_tangent`` tangent
    vectors); ``P`` (C, L, n_par) packed parameters; ``SW`` (C, L, n_track) dead-zone half
    widths; ``t0``, ``t_rec``, ``period``, ``t_end`` (C, L) start, first sample, section
    interval T (the forcing period) and end times; ``samples_per_period`` the samples per
    section interval (sample j at τ_rec + jT/s; the steps end on the sections j = ks only,
    the samples between are interpolated, :func:`~gearchaos.integrate.dopri.dopri_run`);
    ``settle`` whether the transient may end early (``settle="auto"``); ``tangent_tol`` the
    factor on the error tolerances of the tangent components (1: those of the state).
    """

    kind: int
    Y0: np.ndarray
    P: np.ndarray
    SW: np.ndarray
    t0: np.ndarray
    t_rec: np.ndarray
    period: np.ndarray
    t_end: np.ndarray
    n_samples: int
    n_obs: int
    n_track: int
    n_state: int
    n_tangent: int
    rtol: float
    atol: float
    max_steps: int
    continuation: bool = False
    h_init: float = -1.0
    max_step: float = np.inf
    settle: bool = False
    tangent_tol: float = 1.0
    samples_per_period: int = 1

    @property
    def dt(self) -> np.ndarray:
        """(C, L) sample intervals T/s."""
        return self.period / self.samples_per_period

    @property
    def shape(self) -> tuple[int, int]:
        """(chains C, points per chain L)."""
        return int(self.P.shape[0]), int(self.P.shape[1])

    @classmethod
    def from_systems(
        cls,
        chains: Sequence[Sequence[System]],
        settings: SolverSettings,
        *,
        y0: np.ndarray | None = None,
        t0: float = 0.0,
        n_tangent: int = 0,
        continuation: bool = False,
        first_step: float | None = None,
        max_step: float = np.inf,
        tangent_start: np.ndarray | None = None,
        tangent_tol: float = 1.0,
    ) -> ChainRun:
        """Pack chains of systems (one kind and parameter layout) with their sample times.

        ``y0`` is None (zero start), one state (every chain) or one state per chain.
        """
        ref = chains[0][0]
        C, L = len(chains), max(len(c) for c in chains)
        n_par = ref.params.size
        P = np.zeros((C, L, n_par))
        SW = np.full((C, L, ref.n_track), np.inf)
        T = np.ones((C, L))
        for c, chain in enumerate(chains):
            for j, s in enumerate(chain):
                if s.params.size != n_par or s.kind != ref.kind:
                    raise ParameterError(
                        "all systems of a run must share kind and parameter layout (model "
                        f"kind and number of planets): system {s.name} ({s.params.size} "
                        f"parameters) differs from {ref.name} ({n_par} parameters)"
                    )
                P[c, j] = s.params
                SW[c, j] = s.switch_widths
                T[c, j] = s.period
        t_start = np.full((C, L), float(t0))
        times = settings.sample_times(T, t0=t_start)
        return cls.from_arrays(
            ref,
            P,
            SW,
            t_start,
            times,
            settings,
            y0=y0,
            n_tangent=n_tangent,
            continuation=continuation,
            first_step=first_step,
            max_step=max_step,
            tangent_start=tangent_start,
            tangent_tol=tangent_tol,
        )

    @classmethod
    def from_arrays(
        cls,
        ref: System,
        P: np.ndarray,
        SW: np.ndarray,
        t0: np.ndarray,
        times: SampleTimes,
        settings: SolverSettings,
        *,
        y0: np.ndarray | None = None,
        n_tangent: int = 0,
        continuation: bool = False,
        first_step: float | None = None,
        max_step: float = np.inf,
        tangent_start: np.ndarray | None = None,
        tangent_tol: float = 1.0,
    ) -> ChainRun:
        """A run from packed parameters ``P`` and switch widths ``SW`` (C, L, …) of systems
        like ``ref``, start times ``t0`` and sample times (C, L): the one place a run is laid
        out, for callers that pack their own points (shooting, a hot path). ``y0`` None starts
        from rest (:meth:`~gearchaos.integrate.settings.SolverSettings.rest_state`);
        ``tangent_start`` (k × n, or C × k × n) gives the tangent vectors' start, made
        orthonormal at the first sample (default: the first k basis vectors); ``tangent_tol``
        scales the error tolerances of the tangent components (1: the state's)."""
        C = P.shape[0]
        n = ref.n_state
        k = int(n_tangent)
        Y0 = np.zeros((C, n * (1 + k)))
        if y0 is None:
            y0 = settings.rest_state(n)  # from rest, perturbed off invariant subspaces
        if y0 is not None:
            Y0[:, :n] = y0
        if tangent_start is not None:
            Y0[:, n:] = np.asarray(tangent_start, dtype=np.float64).reshape(-1, n * k)
        return cls(
            kind=ref.kind,
            Y0=Y0,
            P=P,
            SW=SW,
            t0=t0,
            t_rec=times.t_rec,
            period=times.period,
            t_end=times.t_end,
            n_samples=times.n_samples,
            n_obs=ref.n_obs,
            n_track=ref.n_track,
            n_state=n,
            n_tangent=k,
            rtol=float(settings.rtol),
            atol=float(settings.atol),
            max_steps=times.max_steps,
            continuation=bool(continuation),
            h_init=-1.0 if first_step is None else float(first_step),
            max_step=float(max_step),
            settle=settings.settle == "auto",
            tangent_tol=float(tangent_tol),
            samples_per_period=int(times.samples_per_period),
        )

    @classmethod
    def concat(cls, runs: Sequence[ChainRun]) -> ChainRun:
        """One job of all chains of ``runs`` (same kind, lengths and settings)."""
        if len(runs) == 1:
            return runs[0]
        stacked: dict[str, Any] = {
            name: np.concatenate([getattr(r, name) for r in runs], axis=0) for name in _CHAIN_INPUTS
        }
        return replace(runs[0], **stacked)


@dataclass(frozen=True, eq=False)
class SampleArrays:
    """What an integration records, for one run or many: sample times ``tau`` (NaN where not
    reached), ``states`` and ``observables`` at them, the extrema ``obs_min``/``obs_max`` of the
    tracked observables over the recorded window, and the ``final_state``. Leading axes: none
    (a :class:`~gearchaos.integrate.Trajectory`), points (a batch) or chains × points."""

    tau: np.ndarray
    states: np.ndarray
    observables: np.ndarray
    obs_min: np.ndarray
    obs_max: np.ndarray
    final_state: np.ndarray


@dataclass(frozen=True, eq=False)
class ChainOutput(SampleArrays):
    """Raw outputs of :func:`run_chains`, chain and point first.

    The :class:`SampleArrays` with shapes ``tau`` (C, L, s), ``states`` (C, L, s, n_full),
    ``observables`` (C, L, s, n_obs), ``obs_min``/``obs_max`` (C, L, n_track), ``final_state``
    (C, L, n_full) with the tangent vectors; then ``info`` (C, L, len(Info)): the columns of
    :class:`~gearchaos.integrate.interface.Info` (accepted and rejected steps, time reached,
    next step size, transient periods skipped by ``settle``, steps retried to end on a contact
    switch); ``status`` (C, L)
    :class:`~gearchaos.errors.Status` codes; ``log_sums`` (C, L, k) accumulated log stretch
    factors of the tangent vectors.
    """

    info: np.ndarray
    status: np.ndarray
    log_sums: np.ndarray

    def statuses(self) -> list[Status]:
        """The status of every point, chain by chain."""
        return [Status(int(code)) for code in self.status.ravel()]

    def split(self, sizes: Sequence[int]) -> list[ChainOutput]:
        """The outputs of consecutive groups of ``sizes`` chains (inverse of
        :meth:`ChainRun.concat`)."""
        out, start = [], 0
        for size in sizes:
            out.append(
                ChainOutput(
                    **{f.name: getattr(self, f.name)[start : start + size] for f in fields(self)}
                )
            )
            start += size
        return out

    def stretch(self, n: int) -> np.ndarray:
        """(C, L, s) log stretch ln‖v₁‖ of the first tangent vector over each sample interval
        (the kernel records the tangents before renormalising them; NaN at the first sample,
        where they start, and where a sample was not reached)."""
        v = self.states[..., n : 2 * n]
        with np.errstate(divide="ignore", invalid="ignore"):
            out = np.log(np.sqrt(np.sum(v * v, axis=-1)))
        out[..., 0] = np.nan
        return out

    def lyapunov(self, dt: np.ndarray) -> np.ndarray:
        """Exponents per unit τ, (C, L, k): log stretch over the samples after the first."""
        ns = self.tau.shape[2]
        if ns < 2:
            return self.log_sums * np.nan
        return self.log_sums / ((ns - 1) * dt)[:, :, None]


def run_chains(
    run: ChainRun,
    *,
    single_thread: bool = False,
    tableau: Any = None,
    threads: int | None = None,
) -> ChainOutput:
    """Run the chains of ``run`` with the compiled Dormand–Prince kernel (or, for
    experiments, with the explicit FSAL pair ``tableau``:
    :func:`~gearchaos.integrate.methods.kernels_for`).

    The chains are spread over ``threads`` threads (default and at most
    ``numba.get_num_threads()``; blocks of chains taken in turn, so a slow chain does not
    hold up a fixed share of the others): a caller with a few short chains asks for fewer
    without changing the process's setting. ``single_thread`` pins this process to one
    thread (for worker processes that share a machine). Each chain runs the same compiled
    code whatever the threads, so results are bitwise identical. Never raises on solver
    failure: each point carries its own status.
    """
    import numba

    from .dopri import dopri_chains
    from .methods import TABLEAU_OVERRIDE, kernels_for

    if tableau is None and TABLEAU_OVERRIDE:
        tableau = TABLEAU_OVERRIDE[0]
    if tableau is not None:
        dopri_chains = kernels_for(tableau).dopri_chains
    if single_thread:
        numba.set_num_threads(1)
    C, L = run.shape
    ns, n_full = run.n_samples, run.Y0.shape[1]
    k = run.n_tangent
    # unreached samples stay NaN, never zeros that look like data
    out = ChainOutput(
        tau=np.full((C, L, ns), np.nan),
        states=np.full((C, L, ns, n_full), np.nan),
        observables=np.full((C, L, ns, run.n_obs), np.nan),
        obs_min=np.zeros((C, L, run.n_track)),
        obs_max=np.zeros((C, L, run.n_track)),
        final_state=np.zeros((C, L, n_full)),
        info=np.zeros((C, L, len(Info))),
        status=np.zeros((C, L), dtype=np.int64),
        log_sums=np.zeros((C, L, k)),
    )
    f64 = np.float64
    inputs = [np.ascontiguousarray(getattr(run, a), dtype=f64) for a in _CHAIN_INPUTS]
    outputs = [getattr(out, a) for a in _CHAIN_OUTPUTS]
    cfg = config_record(run)

    def args(lo: int, hi: int) -> tuple[Any, ...]:
        """The kernel's arguments for chains lo … hi − 1 (C-contiguous views)."""
        return (*(x[lo:hi] for x in inputs), cfg, *(x[lo:hi] for x in outputs))

    entry = entry_point(dopri_chains, run.kind, *args(0, C))
    kind = int(run.kind)
    most = numba.get_num_threads()
    use = most if threads is None else max(1, min(int(threads), most))
    run_threaded(lambda lo, hi: entry(kind, *args(lo, hi)), C, use)
    return out


def config_record(run: ChainRun) -> np.ndarray:
    """The configuration record of ``run`` for the kernel: slot ``s`` of
    :class:`~gearchaos.integrate.interface.Config` holds the field of ``run`` named
    ``s.name.lower()``, as a float64 (integers and flags exactly, up to 2⁵³)."""
    return np.array([float(getattr(run, s.name.lower())) for s in Config], dtype=np.float64)


#: the ChainRun arrays the kernel reads (then the configuration record) and the ChainOutput
#: arrays it fills, chain axis first, in the kernel's argument order
_CHAIN_INPUTS = ("Y0", "P", "SW", "t0", "t_rec", "period", "t_end")
_CHAIN_OUTPUTS = (
    "tau", "states", "observables", "obs_min", "obs_max", "final_state", "info", "status",
    "log_sums",
)  # fmt: skip


def run_threaded(call: Any, n: int, threads: int) -> None:
    """``call(lo, hi)`` over blocks that cover ``range(n)``, on ``threads`` daemon threads that
    take the blocks in turn (``call`` must release the GIL: a ``nogil`` kernel). A block is
    about an eighth of a thread's share, so an uneven load still spreads. From the main thread
    even one block runs on a worker, so that Ctrl-C or SIGTERM interrupts the wait at once
    (:mod:`.threads`); an interrupt cancels the blocks not yet started, and the running ones
    finish in the background (compiled code cannot be stopped) without holding the process."""
    import threading

    threads = max(1, min(int(threads), n))
    if threads == 1 and threading.current_thread() is not threading.main_thread():
        announce_ready()
        call(0, n)  # a sweep driver's (or Dask worker's) single block runs where it is
        return
    workers = pool(threads)
    size = max(1, n // (8 * threads))
    wait_all([workers.submit(call, lo, min(lo + size, n)) for lo in range(0, n, size)])
