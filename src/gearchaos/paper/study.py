"""The Optuna study of the calibration (:mod:`gearchaos.paper.calibrate`): its storage, the
configuration it records, trials lost with their process, the trial function and one worker.

A trial records in its user attributes who runs it (``owner``: host, pid, process start),
where it comes from (``origin``: ``base``, ``default``, ``tpe`` or ``retry of #n``), the
candidate (``variables``, ``key``, ``params``: the gear-set changes) and, once finished, the
landmark scores (``landmarks``), the structural term's parts (``parts``) and ``seconds``; its
two values are the landmark score and the structure (:data:`OBJECTIVES`).
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import socket
import time
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .._checks import check_int
from ..errors import IntegrationError, ParameterError, StoreError
from .objective import Evaluation, SweepSettings, landmark_objective
from .search_space import SearchSpace, _base, build_gearset, candidate_key, gearset_changes, suggest

__all__ = [
    "HEARTBEAT",
    "OBJECTIVES",
    "STUDY",
    "Job",
    "default_storage",
    "enqueue",
    "finished_count",
    "objective_of",
    "open_study",
    "optimize",
    "recover",
    "run_worker",
    "study_records",
]

#: Default study name (``-quick`` appended for ``quick``).
STUDY = "gearchaos-calibrate"
#: The two objectives, both maximised.
OBJECTIVES = ("landmarks", "structure")
#: Seconds between heartbeats of a running trial (Optuna fails it after two missed).
HEARTBEAT = 60


def default_storage(out: str | os.PathLike[str]) -> str:
    """``sqlite:///`` + ``out`` with the suffix ``.db`` (absolute)."""
    return "sqlite:///" + str(Path(os.path.abspath(out)).with_suffix(".db"))


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    """Optuna's notes that a feature is experimental are not the user's concern."""
    import optuna

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
        yield


def _storage(url: str, heartbeat: int) -> Any:
    import optuna
    from optuna.storages import RetryHeartbeatStaleTrialCallback

    check_int("heartbeat", heartbeat, lo=1)
    if not isinstance(url, str) or "://" not in url:
        raise ParameterError(
            f"storage must be a database URL such as sqlite:///calib.db: got {url!r}"
        )
    kw: dict[str, Any] = {}
    if url.startswith("sqlite"):
        # writers of several processes wait for the lock instead of failing
        kw["engine_kwargs"] = {"connect_args": {"timeout": 120}}
        path = url.removeprefix("sqlite:///")
        if path and path != ":memory:":
            Path(path).parent.mkdir(parents=True, exist_ok=True)
    try:
        with _quiet():
            return optuna.storages.RDBStorage(
                url,
                heartbeat_interval=heartbeat,
                grace_period=2 * heartbeat,
                heartbeat_stale_trial_callback=RetryHeartbeatStaleTrialCallback(max_retry=2),
                **kw,
            )
    except Exception as exc:  # sqlalchemy raises many types for a bad URL or file
        raise StoreError(f"storage {url!r} cannot be opened: {type(exc).__name__}: {exc}") from None


def open_study(
    storage: str,
    study: str = STUDY,
    *,
    seed: int = 0,
    config: Mapping[str, Any] | None = None,
    heartbeat: int = HEARTBEAT,
) -> Any:
    """The Optuna study ``study`` in ``storage`` (created when missing, with two maximised
    objectives and the seeded sampler). ``config`` (the objective's configuration) is recorded
    in a new study and must equal the recorded one of an existing study. Optuna's line per
    trial is silenced (its warnings stay): the calibration shows its own progress."""
    import optuna

    check_int("seed", seed, lo=0)
    if not isinstance(study, str) or not study.strip():
        raise ParameterError(f"study must be a non-empty name: got {study!r}")
    kw: dict[str, Any] = {}
    if not hasattr(optuna.trial.Trial, "set_constraint"):  # Optuna < 5: a constraints function
        kw["constraints_func"] = _constraints
    with _quiet():  # constraints are experimental in Optuna 4
        sampler = optuna.samplers.TPESampler(seed=seed, multivariate=True, constant_liar=True, **kw)
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    st = _storage(storage, heartbeat)
    try:
        s = optuna.create_study(
            storage=st,
            study_name=study,
            directions=["maximize", "maximize"],
            sampler=sampler,
            load_if_exists=True,
        )
    except ValueError as exc:
        raise StoreError(f"study {study!r} in {storage}: {exc}; use another --study") from None
    if len(s.directions) != len(OBJECTIVES):
        raise StoreError(
            f"study {study!r} in {storage} has {len(s.directions)} objective(s), a calibration "
            f"two ({', '.join(OBJECTIVES)}); use another --study"
        )
    if not s.metric_names:  # named for optuna-dashboard
        with _quiet():
            s.set_metric_names(list(OBJECTIVES))
    if config is not None:
        want = json.loads(json.dumps(dict(config), sort_keys=True))
        have = s.user_attrs.get("config")
        if have is None:
            s.set_user_attr("config", want)
        elif have != want:
            diff = sorted(k for k in set(have) | set(want) if have.get(k) != want.get(k))
            raise StoreError(
                f"study {study!r} in {storage} was made with another objective "
                f"({', '.join(diff)} differ); use another --study or the same settings"
            )
    return s


def _proc_start(pid: int) -> str | None:
    """The start time of process ``pid`` (Linux: /proc), to tell a reused pid apart."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    return stat.rsplit(")", 1)[-1].split()[19]


def _owner() -> dict[str, Any]:
    pid = os.getpid()
    return {"host": socket.gethostname(), "pid": pid, "start": _proc_start(pid)}


def _alive(owner: Any) -> bool | None:
    """Whether the process that runs a trial is alive: None when it cannot be told (another
    host, no owner)."""
    if not isinstance(owner, dict) or owner.get("host") != socket.gethostname():
        return None
    pid = owner.get("pid")
    if not isinstance(pid, int):
        return None
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    start = owner.get("start")
    return start is None or _proc_start(pid) == start


def recover(study: Any) -> list[int]:
    """Mark failed every running trial whose process on this host is gone (a kill -9, a
    crash) and enqueue it again with the same parameters; returns the numbers of those
    enqueued again (a trial killed before it drew its candidate has nothing to repeat: it is
    only marked failed)."""
    from optuna.trial import TrialState

    storage = study._storage
    study_id = storage.get_study_id_from_name(study.study_name)
    lost = []
    for t in study.get_trials(deepcopy=False, states=(TrialState.RUNNING,)):
        if _alive(t.user_attrs.get("owner")) is not False:
            continue
        trial_id = storage.get_trial_id_from_study_id_trial_number(study_id, t.number)
        with contextlib.suppress(RuntimeError, ValueError):  # another process was first
            storage.set_trial_state_values(trial_id, TrialState.FAIL)
            if t.params:
                enqueue(study, t.params, f"retry of #{t.number}")
                lost.append(t.number)
    return lost


def enqueue(study: Any, params: Mapping[str, Any], origin: str) -> None:
    if params:
        study.enqueue_trial(dict(params), user_attrs={"origin": origin})


def study_records(study: Any) -> list[dict[str, Any]]:
    """Every finished trial of a calibration study as a record (trial order)."""
    from optuna.trial import TrialState

    out = []
    for t in study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,)):
        ua = t.user_attrs
        if "variables" not in ua or t.values is None:
            continue
        out.append(
            {
                "key": ua.get("key", ""),
                "index": t.number,
                "origin": ua.get("origin", ""),
                "variables": ua["variables"],
                "params": ua.get("params", {}),
                "score": float(t.values[0]),
                "structure": float(t.values[1]),
                "landmarks": ua.get("landmarks", {}),
                "parts": ua.get("parts", {}),
                "seconds": ua.get("seconds", 0.0),
                "study": study.study_name,
            }
        )
    return out


# --------------------------------------------------------------------------- one worker
@dataclass(frozen=True)
class Job:
    """What one worker process needs to run trials on the shared study (picklable)."""

    storage: str
    study: str
    seed: int
    heartbeat: int
    space: SearchSpace
    landmarks: str | None
    settings: SweepSettings
    objective: Callable[[Any], Evaluation] | None
    trials: int | None
    max_candidates: int | None
    timeout: float | None


def _trial_function(
    space: SearchSpace, objective: Callable[[Any], Evaluation], base: Any
) -> Callable[[Any], tuple[float, float]]:
    from optuna.storages import RetryHeartbeatStaleTrialCallback

    def run(trial: Any) -> tuple[float, float]:
        trial.set_user_attr("owner", _owner())
        cand = suggest(trial, space)
        origin = trial.user_attrs.get("origin")
        if origin is None:
            frozen = trial.study.get_trials(deepcopy=False)[trial.number]
            with _quiet():
                retried = RetryHeartbeatStaleTrialCallback.retried_trial_number(frozen)
            origin = "tpe" if retried is None else f"retry of #{retried}"
            trial.set_user_attr("origin", origin)
        variables = cand.variables()
        trial.set_user_attr("variables", variables)
        trial.set_user_attr("key", candidate_key(variables))
        trial.set_user_attr("params", gearset_changes(cand, base))
        gs = build_gearset(cand, base)
        try:
            ev = objective(gs)
        except KeyboardInterrupt:  # run again on resume: nothing finished is lost
            enqueue(trial.study, trial.params, f"retry of #{trial.number}")
            raise
        trial.set_user_attr("landmarks", dict(ev.landmarks))
        trial.set_user_attr("seconds", round(float(ev.seconds), 3))
        trial.set_user_attr("parts", json.loads(json.dumps(dict(ev.parts), default=str)))
        constraint = load_constraints(ev.parts)
        trial.set_user_attr("constraints", constraint)
        if hasattr(trial, "set_constraint"):  # Optuna ≥ 5; before, _constraints reads the attr
            trial.set_constraint("load", constraint[0])
        return float(ev.score), float(ev.structure)

    return run


def load_constraints(parts: Mapping[str, Any]) -> list[float]:
    """Optuna's constraint of a trial (≤ 0 feasible): F_peak/F_allow − 1 of its loads
    (:mod:`gearchaos.paper.loads`); 0 (feasible) when they were not measured."""
    loads = parts.get("loads")
    if not isinstance(loads, Mapping):
        return [0.0]
    peak, allow = float(loads["peak_force_N"]), float(loads["allowable_force_N"])
    return [peak / allow - 1.0 if math.isfinite(peak) else 1e6]


def _constraints(trial: Any) -> Sequence[float]:
    value = trial.user_attrs.get("constraints")
    return [float(x) for x in value] if isinstance(value, list) and value else [0.0]


def objective_of(job: Job) -> Callable[[Any], Evaluation]:
    if job.objective is not None:
        return job.objective
    from .landmarks import load_landmarks

    return landmark_objective(load_landmarks(job.landmarks), job.settings)


def finished_count(study: Any) -> int:
    from optuna.trial import TrialState

    return len(study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,)))


def optimize(
    job: Job,
    study: Any,
    objective: Callable[[Any], Evaluation],
    callbacks: Sequence[Callable[[Any, Any], None]] = (),
) -> str:
    """Run trials of ``study`` in this process until a limit; returns which one stopped it."""
    from optuna.study import MaxTrialsCallback

    recover(study)
    if job.max_candidates is not None and finished_count(study) >= job.max_candidates:
        return "max_candidates"
    cbs = list(callbacks)
    if job.max_candidates is not None:
        cbs.append(MaxTrialsCallback(job.max_candidates))
    from optuna.exceptions import UpdateFinishedTrialError

    ran = [0]

    def count(st: Any, tr: Any) -> None:
        ran[0] += 1

    t0 = time.monotonic()
    func = _trial_function(job.space, objective, _base())
    while True:
        left = None if job.trials is None else job.trials - ran[0]
        budget = None if job.timeout is None else job.timeout - (time.monotonic() - t0)
        if (left is not None and left <= 0) or (budget is not None and budget <= 0):
            break
        try:
            study.optimize(
                func, n_trials=left, timeout=budget, catch=(ParameterError, IntegrationError),
                callbacks=[*cbs, count], gc_after_trial=True,
            )  # fmt: skip
            break
        except (UpdateFinishedTrialError, ValueError) as exc:
            # Another process on the same storage finished this trial first: SQLite has no
            # row locks, so two workers may pop the same enqueued trial, or a peer declared it
            # stale. Optuna says so at the write (UpdateFinishedTrialError) or, when it reads
            # the state first, as "Cannot tell a COMPLETE trial". The recorded result stands;
            # this worker goes on with the next trial.
            if isinstance(exc, ValueError) and not str(exc).startswith("Cannot tell a "):
                raise
            ran[0] += 1
            if job.max_candidates is not None and finished_count(study) >= job.max_candidates:
                break
    if job.max_candidates is not None and finished_count(study) >= job.max_candidates:
        return "max_candidates"
    if job.timeout is not None and time.monotonic() - t0 >= job.timeout:
        return "budget"
    return "trials"


def run_worker(job: Job, index: int = 0) -> str:
    """One worker of a parallel calibration (a local process or a Dask task): its own
    sampler seed (``seed + 1 + index``), the shared storage."""
    study = open_study(job.storage, job.study, seed=job.seed + 1 + index, heartbeat=job.heartbeat)
    return optimize(job, study, objective_of(job))
