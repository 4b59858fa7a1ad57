"""Calibrate the seed's lost Table 1 against the landmarks of its own text, with Optuna.

The seed (Sheng et al. 2016) lost the table of its gear set. What survives are its quantitative
statements — "1T for 0 ≤ Ω ≤ 1.35", "2T at Ω = 1.875", "chaos within b̄_rp ∈ 11.3–11.6" — kept
as data in ``paper/landmarks.toml`` (:mod:`gearchaos.paper.landmarks`). This module searches
the quantities Table 1 would have fixed (:mod:`gearchaos.paper.search_space`, ranges reviewed
against ISO 1328 and DIN 3967) for the gear set that reproduces the most landmarks with its
clearances acting.

Objective (:mod:`gearchaos.paper.objective`)
    Two values, both maximised: the landmark score of the report's own evaluation (verdicts,
    the report's protocol and tolerances, the perturbed start, event landmarks from continued
    branches) and the structural term of :mod:`gearchaos.paper.structure` (double-sided impact
    in the chaotic and multi-periodic regions of the backlash sweeps; multipliers that change
    along b̄_sp and b̄_rp).

Optimiser
    An Optuna study (multi-objective TPE, multivariate, constant liar for parallel workers;
    seeded). A new study starts with the MODEL.md §9 set (``base``) and today's default
    ``sheng2016`` (``default``) enqueued. The best candidate is the trial of highest landmark
    score, then highest structure, then the earliest (:func:`ranked`); every trial on the
    Pareto front is kept in the storage for the confirmation stage.

Storage, resuming, several processes
    Trials live in Optuna's storage (default ``sqlite:///OUT.db`` beside ``--out``; any URL
    Optuna takes, e.g. ``postgresql://…`` for a cluster) under a study name, so a run resumes
    after an interrupt or a ``kill -9`` with every finished trial kept: a trial that was
    running in a process that is gone (same host, its pid dead) is marked failed and
    enqueued again with the same parameters (``retry of #n``); on other hosts Optuna's
    heartbeat (``heartbeat`` seconds, failed after two missed beats) does the same. Ctrl-C
    enqueues the interrupted trial again. Several processes may run on one storage at once
    (``workers`` local processes, a Dask cluster at ``scheduler``, a local one of
    ``dask_local`` workers, or separate ``gearchaos calibrate`` commands with different
    ``--seed``); each runs ``study.optimize`` and stops when the study holds
    ``max_candidates`` finished trials. The study records the objective's configuration
    and refuses to be resumed with another. ``optuna-dashboard sqlite:///calibration.db``
    shows it live.

Exports
    ``--out`` (JSON lines, one finished trial each: ``key``, ``index`` = trial number,
    ``origin``, ``variables``, ``params``, ``score``, ``structure``, ``landmarks``,
    ``seconds``, ``study``), rewritten from the storage after every trial, and ``best.toml``
    beside it.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

from .._checks import check_bool, check_int, check_real
from .._files import MissingFileError, check_path, read_text_file
from ..errors import ParameterError, StoreError
from .objective import Evaluation, SweepSettings, landmark_objective, sweep_plan
from .search_space import (
    BASE_PRESET,
    DEFAULT_SPACE,
    Candidate,
    Range,
    SearchSpace,
    TeethChoice,
    _base,
    base_candidate,
    build_gearset,
    candidate_from_record,
    candidate_key,
    candidate_of,
    candidate_params,
    enumerate_teeth,
    gearset_changes,
    plausibility,
    record_gearset,
)
from .study import (
    HEARTBEAT,
    STUDY,
    Job,
    default_storage,
    enqueue,
    open_study,
    optimize,
    recover,
    run_worker,
    study_records,
)

__all__ = [
    "BASE_PRESET",
    "DEFAULT_SPACE",
    "STUDY",
    "CalibrationResult",
    "Candidate",
    "Evaluation",
    "Range",
    "SearchSpace",
    "SweepSettings",
    "TeethChoice",
    "adoption_problems",
    "base_candidate",
    "best_record",
    "build_gearset",
    "calibrate",
    "candidate_from_record",
    "candidate_key",
    "enumerate_teeth",
    "gearset_changes",
    "landmark_objective",
    "load_problems",
    "open_study",
    "plausibility",
    "ranked",
    "read_results",
    "record_gearset",
    "record_plausibility",
    "study_records",
    "sweep_plan",
]


# --------------------------------------------------------------------------- records
def read_results(path: str | os.PathLike[str]) -> dict[str, dict[str, Any]]:
    """Finished evaluations of a calibration file by candidate key (a torn last line, left by
    a kill during a write, is ignored)."""
    out: dict[str, dict[str, Any]] = {}
    try:  # a regular UTF-8 file of bounded size: never a FIFO, a device or a directory
        text = read_text_file(path, what="calibration file", max_bytes=MAX_RESULTS_BYTES)
    except MissingFileError:
        return out
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        try:
            rec = json.loads(line)
        except (json.JSONDecodeError, RecursionError):
            continue
        if not _is_record(rec):
            raise StoreError(
                f"calibration file '{path}': line {number} is not a calibration record "
                "(key, index, score, variables); use another --out file"
            )
        out[rec["key"]] = rec
    return out


#: Largest calibration file read (a record is about 2 KB: 100 000 candidates).
MAX_RESULTS_BYTES = 256 * 2**20


def _is_record(rec: Any) -> bool:
    """A line this module wrote: a key, an index, a numeric score and the variables."""
    if not isinstance(rec, dict) or not isinstance(rec.get("key"), str):
        return False
    index, score = rec.get("index"), rec.get("score")
    if isinstance(index, bool) or not isinstance(index, int):
        return False
    if isinstance(score, bool) or not isinstance(score, int | float) or math.isnan(score):
        return False
    return isinstance(rec.get("variables"), dict)


_R = TypeVar("_R", bound=Mapping[str, Any])


def load_problems(record: Mapping[str, Any]) -> list[str]:
    """Why a record's gear set is not plausible in its dynamic loads (:mod:`.loads`): its
    peak mesh force over the allowable one; empty when it is, or when its loads were not
    measured (a record of a calibration before the load check)."""
    parts = record.get("parts")
    loads = parts.get("loads") if isinstance(parts, Mapping) else None
    if not isinstance(loads, Mapping) or loads.get("plausible", True):
        return []
    return [
        f"peak mesh force {float(loads['peak_force_N']) / 1e3:.3g} kN (load factor "
        f"{float(loads['max']):.3g} at Ω = {float(loads['omega']):g}) exceeds the tooth-root "
        f"strength {float(loads['allowable_force_N']) / 1e3:.3g} kN"
    ]


def record_plausibility(record: Mapping[str, Any], space: SearchSpace = DEFAULT_SPACE) -> list[str]:
    """Reasons a calibration record is not physically plausible: its candidate's
    (:func:`plausibility`) and its loads' (:func:`load_problems`)."""
    return plausibility(candidate_from_record(record, space), space) + load_problems(record)


def adoption_problems(record: Mapping[str, Any], space: SearchSpace = DEFAULT_SPACE) -> list[str]:
    """Why a calibration record cannot become the default gear set (issue 34): it is not
    physically plausible (:func:`record_plausibility`), or its clearances do not act
    (:func:`gearchaos.paper.structure.clearance_problems`). Empty for an eligible record."""
    from .structure import clearance_problems

    return record_plausibility(record, space) + clearance_problems(record)


def _rank_key(record: Mapping[str, Any]) -> tuple[bool, float, float, int]:
    structure = record.get("structure")
    s = float(structure) if isinstance(structure, int | float) else 0.0
    return bool(load_problems(record)), -float(record["score"]), -s, int(record["index"])


def ranked(records: Iterable[_R]) -> list[_R]:
    """Calibration records best first: those plausible in their loads before the others, then
    highest landmark score, then highest structure, then the earlier trial."""
    return sorted(records, key=_rank_key)


def best_record(records: Iterable[_R]) -> _R | None:
    """The best of ``records`` (:func:`ranked`'s first), or ``None``."""
    return min(records, key=_rank_key, default=None)


# --------------------------------------------------------------------------- driver
@dataclass
class CalibrationResult:
    """What :func:`calibrate` did: every finished trial of the study in trial order, how many
    were evaluated now and how many were there before, why it stopped, and the best."""

    records: list[dict[str, Any]]
    evaluated: int
    reused: int
    stopped: str
    best: dict[str, Any] | None
    best_toml: Path | None
    problems: list[str]
    storage: str = ""
    study: str = ""
    retried: list[int] = field(default_factory=list)

    @property
    def plausible(self) -> bool:
        return self.best is not None and not self.problems

    def top(self, k: int = 3) -> list[dict[str, Any]]:
        return ranked(self.records)[:k]


def _export(path: Path, records: Sequence[Mapping[str, Any]]) -> None:
    """Write the records as JSON lines, atomically (a reader never sees half a file)."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    with tmp.open("w", encoding="utf-8") as fh:
        for rec in records:
            fh.write(json.dumps(rec, sort_keys=True) + "\n")
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)


def _check_out(path: Path, study: str) -> None:
    """``--out`` may only hold records of this study (never replace another calibration's)."""
    for rec in read_results(path).values():
        if rec.get("study") != study:
            raise StoreError(
                f"--out {path} holds records of another calibration (not of study {study!r}); "
                "choose another --out"
            )


def _config(landmarks: Sequence[Any], settings: SweepSettings, space: SearchSpace) -> dict:
    plan = sweep_plan(landmarks, settings)
    return {
        "settings": settings.to_dict(),
        "landmarks": sorted(str(m.id) for m in landmarks),
        "panels": {k: len(p.grid) for k, p in plan.items()},
        "ranges": {r.name: [r.lo, r.hi, r.log] for r in space.ranges},
        "base": BASE_PRESET,
    }


def calibrate(
    landmarks: Sequence[Any] | str | os.PathLike[str] | None = None,
    out: str | os.PathLike[str] = "calibration.jsonl",
    *,
    storage: str | None = None,
    study: str | None = None,
    trials: int | None = None,
    budget_minutes: float = 110.0,
    max_candidates: int | None = None,
    seed: int = 0,
    quick: bool = False,
    space: SearchSpace = DEFAULT_SPACE,
    objective: Callable[[Any], Evaluation] | None = None,
    settings: SweepSettings | None = None,
    on_record: Callable[[dict[str, Any], bool], None] | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    dask_local: int | None = None,
    heartbeat: int = HEARTBEAT,
) -> CalibrationResult:
    """Search ``space`` for the gear set that reproduces the most landmarks with its clearances
    acting (see the module docstring).

    Parameters
    ----------
    landmarks
        Landmark list or the path of ``landmarks.toml`` (``None``: the packaged default).
    out
        JSON-lines export of the study's finished trials; ``best.toml`` is written beside it.
    storage, study
        Optuna storage URL (default ``sqlite:///OUT.db``) and study name (default
        :data:`STUDY`, ``-quick`` appended with ``quick``).
    trials
        Trials this call runs (each worker with ``workers``/``dask_local``/``scheduler``);
        default: no limit.
    budget_minutes, max_candidates
        Stop starting trials after this much wall time, or once the study holds
        ``max_candidates`` finished trials (resumed ones included).
    seed
        Seed of the sampler (workers take ``seed + 1``, ``seed + 2``, …). Give separate
        commands on one storage different seeds.
    quick
        At most 3 finished trials on tiny sweeps (:meth:`SweepSettings.quick`), for CI.
    objective
        Gear set → :class:`Evaluation` (default :func:`landmark_objective`); picklable when run
        on workers.
    on_record
        Called with each finished record and whether it was evaluated now (progress).
    workers, scheduler, dask_local
        Run the trials in that many local processes, on the Dask cluster at ``scheduler``, or
        on a local Dask cluster of ``dask_local`` workers, all on the same storage (at most
        one of the three; default: in this process).
    heartbeat
        Seconds between heartbeats of a running trial.

    Returns
    -------
    CalibrationResult
        Ctrl-C stops after enqueuing the running trial again (``stopped == "interrupted"``).
    """
    from ..sweep.execute import Execution

    if max_candidates is not None:
        check_int("max_candidates", max_candidates, lo=1)
    if trials is not None:
        check_int("trials", trials, lo=1)
    check_real("budget_minutes", budget_minutes, lo=0.0, lo_open=True)
    check_int("seed", seed, lo=0)
    quick = check_bool("quick", quick)
    where = Execution(workers=workers, scheduler=scheduler, dask_local=dask_local)
    check_path(out, f"out must be the path of a JSON-lines file: got {out!r}")
    out_path = Path(out)
    if quick:
        max_candidates = 3 if max_candidates is None else min(max_candidates, 3)
        settings = settings or SweepSettings.quick()
    settings = settings or SweepSettings()
    name = study or (STUDY + ("-quick" if quick else ""))
    url = storage or default_storage(out_path)
    landmarks_path: str | None = None
    if objective is None:
        from .landmarks import load_landmarks

        if landmarks is None or isinstance(landmarks, str | os.PathLike):
            landmarks_path = None if landmarks is None else os.fspath(landmarks)
            lms = load_landmarks(landmarks_path)
        elif where != Execution():
            raise ParameterError(
                "workers, scheduler and dask_local load the landmarks in every worker: give "
                "landmarks as the path of a landmarks file, not a list"
            )
        else:
            lms = list(landmarks)  # type: ignore[arg-type]
        config: dict[str, Any] | None = _config(lms, settings, space)
    else:  # the caller's objective: its configuration is the caller's to keep
        config = None
    _check_out(out_path, name)
    s = open_study(url, name, seed=seed, config=config, heartbeat=heartbeat)
    before = {r["index"] for r in study_records(s)}
    if not s.trials:  # a new study starts from the §9 set and today's default
        from ..gearset import preset

        enqueue(s, candidate_params(base_candidate(_base(), space)), "base")
        default = candidate_of(preset("sheng2016"), _base(), space)
        if not plausibility(default, space):
            enqueue(s, candidate_params(default), "default")
    retried = recover(s)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    shown: set[int] = set()

    def show(now: bool) -> None:
        records = study_records(s)
        _export(out_path, records)
        for rec in records:
            if rec["index"] not in shown:
                shown.add(rec["index"])
                if on_record is not None:
                    on_record(rec, now and rec["index"] not in before)

    show(False)
    job = Job(
        url, name, seed, heartbeat, space, landmarks_path, settings,
        objective, trials, max_candidates, 60.0 * budget_minutes,
    )  # fmt: skip
    stopped = "trials"
    try:
        if where == Execution():
            obj = objective or landmark_objective(lms, settings)
            stopped = optimize(job, s, obj, [lambda st, tr: show(True)])
        else:
            stopped = _parallel(job, where, lambda: show(True))
    except KeyboardInterrupt:
        stopped = "interrupted"
    show(True)
    records = study_records(s)
    best = best_record(records)
    best_toml: Path | None = None
    problems: list[str] = []
    if best is not None:
        cand = candidate_from_record(best, space)
        problems = record_plausibility(best, space)
        best_toml = out_path.with_name("best.toml")
        best_toml.write_text(build_gearset(cand).to_toml(), encoding="utf-8")
    evaluated = sum(1 for r in records if r["index"] not in before)
    return CalibrationResult(
        records, evaluated, len(before), stopped, best, best_toml, problems, url, name, retried
    )


def _parallel(job: Job, where: Any, progress: Callable[[], None]) -> str:
    """Run :func:`run_worker` on every worker of ``where`` and wait, showing progress.

    Interrupted, local worker processes are ended at once and completely
    (:func:`~gearchaos.sweep.execute.end_pool`; the trial each one ran is enqueued again by
    :func:`~gearchaos.paper.study.recover` when the study goes on): waiting for them would take
    their whole run, and a pool left running fails in Python's exit hooks. Killed, they end
    with it (:func:`~gearchaos.sweep.execute.watch_parent`)."""
    import concurrent.futures as cf
    import multiprocessing

    from ..sweep.execute import end_pool, watch_parent

    if where.workers is not None:
        ctx = multiprocessing.get_context("spawn")
        # the workers end with this process, also when it is killed (SIGKILL, or SIGTERM's
        # default action) and cannot end them: orphans would go on running trials
        pool = cf.ProcessPoolExecutor(
            where.workers, mp_context=ctx, initializer=watch_parent, initargs=(os.getpid(),)
        )
        try:
            futures = [pool.submit(run_worker, job, i) for i in range(where.workers)]
            stopped = _wait(futures, progress)
        except BaseException:  # interrupted (a worker's error comes once every one ended)
            end_pool(pool)
            raise
        pool.shutdown(wait=True)
        return stopped
    from dask.distributed import Client, LocalCluster

    if where.scheduler is not None:
        with Client(where.scheduler, timeout=30) as client:
            n = max(1, len(client.scheduler_info().get("workers", {})))
            futures = [client.submit(run_worker, job, i, pure=False) for i in range(n)]
            return _wait(futures, progress)
    with (
        LocalCluster(
            n_workers=where.dask_local, threads_per_worker=1, processes=True,
            dashboard_address=None,
        ) as cluster,
        Client(cluster) as client,
    ):  # fmt: skip
        futures = [client.submit(run_worker, job, i, pure=False) for i in range(where.dask_local)]
        return _wait(futures, progress)


def _wait(futures: Sequence[Any], progress: Callable[[], None]) -> str:
    """Wait for the workers' futures (concurrent.futures or dask), showing progress every few
    seconds; returns why they stopped."""
    import concurrent.futures as cf

    pending = list(futures)
    while pending:
        progress()
        if isinstance(pending[0], cf.Future):
            cf.wait(pending, timeout=5.0, return_when=cf.FIRST_COMPLETED)
        else:
            from dask.distributed import wait

            with contextlib.suppress(TimeoutError):
                wait(pending, timeout=5.0, return_when="FIRST_COMPLETED")
        pending = [f for f in pending if not f.done()]
    reasons = [f.result() for f in futures]
    return "max_candidates" if "max_candidates" in reasons else reasons[0]
