"""Commands of the seed paper: ``gearchaos reproduce`` and ``gearchaos calibrate``."""

from __future__ import annotations

import difflib
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape
from rich.text import Text

from ..errors import ParameterError
from . import _common as c
from ._render import fmt, gallery_rows_table, pairs_table

#: Figures of the seed paper that ``gearchaos reproduce`` knows: bifurcation diagrams
#: (:mod:`gearchaos.paper.recipes`) and Poincaré galleries (:data:`GALLERY_FIGURES`).
PAPER_FIGURES = ("fig4", "fig5", "fig6", "fig7", "fig8", "fig9", "fig10", "fig11", "fig12")
#: The Poincaré galleries among them (:mod:`gearchaos.paper.galleries`).
GALLERY_FIGURES = ("fig5", "fig7", "fig10")


@c.command()
def reproduce(
    figure: Annotated[
        str | None,
        typer.Argument(
            help=f"Figure of the seed paper: {', '.join(PAPER_FIGURES)} (or --all).",
            show_default=False,
        ),
    ] = None,
    all_figures: Annotated[
        bool,
        typer.Option(
            "--all",
            help=(
                "Run every figure, check the paper's conclusions and landmarks and write "
                "OUTPUT/index.html (the reproduction report)."
            ),
        ),
    ] = False,
    quick: Annotated[
        bool, typer.Option("--quick", help="A coarse version (fewer points and periods), for CI.")
    ] = False,
    paper_protocol: Annotated[
        bool | None,
        typer.Option(
            "--paper-protocol/--no-paper-protocol",
            help=(
                "The seed's own protocol: every point from the exact zero start, labels from "
                "the 100 + 100-period record alone (no verdicts, no λ₁), into FIG-paper.zarr. "
                "With --all (on by default) it fills the report's paper-protocol column."
            ),
            show_default=False,
        ),
    ] = None,
    target: c.Target = c.Target().offering("preset", "gearset_file"),
    execution: c.Execution = c.Execution().offering("workers"),
    output: c.Output = c.Output().offering(
        help={
            "file": "Directory for FIG.png and the sweep store FIG.zarr (galleries: FIG.json "
            "and FIG.csv); created if missing. Required with --all (the report)."
        }
    ),
) -> None:
    """Run the exact sweep of one of the seed paper's bifurcation figures with the default gear
    set (or --preset / --gearset) and draw it in the paper's layout (resumable like
    `gearchaos bifurcation`), or draw one of its Poincaré galleries.

    Bifurcation diagrams — fig4: Ω sweep, ξ = 0.03, 0.05, 0.07, 0.09; fig6: b̄_sp at Ω = 1.5 for
    four ξ; fig8: b̄_sp at ξ = 0.11 for Ω = 1, 1.5, 2, 2.5; fig9: b̄_rp at Ω = 1.5 for four ξ;
    fig11: b̄_rp at ξ = 0.11 for four Ω; fig12: b̄_s at ξ = 0.05, Ω = 1.5.

    Poincaré galleries (FIG.png, FIG.json and FIG.csv with value, motion, λ₁, K, distinct
    points) — fig5: Ω path at ξ = 0.03; fig7: b̄_sp ∈ [1, 6] at Ω = 1.5, ξ = 0.05; fig10:
    b̄_rp ∈ [1, 9] at Ω = 1.5, ξ = 0.05, at the values the seed's text names.

    --all runs every figure into OUTPUT, checks the conclusions of the seed's Section 4 and its
    landmarks against the runs and writes the report OUTPUT/index.html (resumable, with
    progress; the report records its own run time; --quick is a coarse version for CI), then
    prints the counts: a landmark that holds only because its swept parameter does not act
    is "holds (constant)", counted apart; the paper-protocol column (--no-paper-protocol
    leaves it out) says what the seed's own method gives.

    Example: **gearchaos reproduce fig4 -o paper/ --quick**;
    **gearchaos reproduce --all -o report/**
    """
    gs = None
    label = None
    workers = execution.workers
    quiet, json_out = output.quiet, output.json
    with c.reported_errors():
        from ..sweep.execute import Execution

        Execution(workers=workers)  # refused before any directory is made
        directory = output.directory()
    if target.names_gear_set:
        with c.reported_errors():
            gs = c.load_gearset(target)
        label = (
            f"preset {target.preset}"
            if target.preset is not None
            else f"file {target.gearset_file} ({gs.name})"
        )
    if all_figures:
        if figure is not None:
            c.fail("give either FIG or --all, not both", c.EXIT_INVALID)
        if directory is None:
            c.fail(
                "--all writes a report of many files: give its directory with -o, e.g. -o report/",
                c.EXIT_INVALID,
            )
        with c.reported_errors(), c.interruptible():
            from ..paper.report import build_report

            index = build_report(
                directory,
                quick=quick,
                progress=not (quiet or json_out),
                workers=workers,
                gearset=gs,
                gearset_label=label,
                paper_protocol=paper_protocol is not False,
            )
        counts = _report_counts(index)
        if json_out:
            c.print_json({"report": str(index), "counts": counts})
        elif not quiet:
            c.stdout().print(escape(str(index)), soft_wrap=True)
            c.stdout().print(_counts_table(counts))
        return
    if figure is None:
        c.fail("give a figure (FIG) or --all", c.EXIT_INVALID)
    directory = Path(".") if directory is None else directory
    with c.reported_errors(), c.interruptible():
        name = figure.strip().lower()
        if name not in PAPER_FIGURES:
            close = difflib.get_close_matches(name, PAPER_FIGURES, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ParameterError(
                f"FIG must be one of {', '.join(PAPER_FIGURES)}: got {figure!r}{hint}"
            )
        if name in GALLERY_FIGURES:
            if paper_protocol:
                raise ParameterError(
                    f"--paper-protocol is for the bifurcation figures, not the gallery {name} "
                    "(its values are single runs from the zero state already)"
                )
            if workers is not None and not (quiet or json_out):
                c.stderr().print(
                    Text(
                        f"--workers does not apply to {name} (a gallery runs its "
                        f"{name} values one after the other)",
                        style="dim",
                    )
                )
            import matplotlib

            matplotlib.use("Agg")
            from ..paper.galleries import reproduce_gallery

            directory.mkdir(parents=True, exist_ok=True)
            result = dict(
                reproduce_gallery(
                    name, directory, quick=quick, progress=not (quiet or json_out), gearset=gs
                )
            )
        else:
            from ..paper.recipes import reproduce as run_recipe

            directory.mkdir(parents=True, exist_ok=True)
            result = dict(
                run_recipe(
                    name,
                    directory,
                    quick=quick,
                    progress=not quiet,
                    workers=workers,
                    overwrite=output.overwrite,
                    gearset=gs,
                    paper_protocol=bool(paper_protocol),
                )
            )
    if json_out:
        c.print_json(result)
        return
    if quiet:
        return
    rows = result.pop("rows", None)
    if rows is not None:
        from ..paper.galleries import get_gallery

        c.stdout().print(
            gallery_rows_table(rows, get_gallery(name).param, title=f"Poincaré gallery {name}")
        )
    table = pairs_table(f"gearchaos reproduce {name}" + (" (quick)" if quick else ""))
    for key in ("figure", "store", "points", "failed", "seconds"):
        if key in result:
            value = result[key]
            text = f"{value:.3g}" if key == "seconds" and isinstance(value, float) else str(value)
            table.add_row(key, escape(text))
    for key, value in result.items():
        if key not in ("figure", "store", "points", "failed", "seconds"):
            table.add_row(escape(str(key)), escape(fmt(value)))
    c.stdout().print(table)


def _report_counts(index: Path) -> dict[str, dict[str, int]]:
    """The counts the report wrote beside its page (``report.json``)."""
    import json

    summary = json.loads((index.parent / "report.json").read_text(encoding="utf-8"))
    counts: dict[str, dict[str, int]] = summary["counts"]
    return counts


def _counts_table(counts: Mapping[str, Mapping[str, int]]) -> Any:
    """One row per verdict, one column per kind of count (zeros written out)."""
    from rich.table import Table

    titles = {
        "conclusions": "conclusions",
        "landmarks": "landmarks",
        "landmarks_paper": "landmarks (paper protocol)",
    }
    table = Table(title="reproduction report: verdicts")
    table.add_column("verdict")
    for key in counts:
        table.add_column(titles.get(key, key), justify="right")
    verdicts = list(dict.fromkeys(v for col in counts.values() for v in col))
    for v in verdicts:
        table.add_row(v, *(str(col.get(v, 0)) if v in col else "—" for col in counts.values()))
    table.add_row("total", *(str(sum(col.values())) for col in counts.values()))
    return table


@c.command()
def calibrate(
    landmarks: Annotated[
        Path | None,
        typer.Option(
            "--landmarks",
            help="Landmarks file (default: the packaged paper/landmarks.toml).",
            dir_okay=False,
            show_default=False,
        ),
    ] = None,
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            help=(
                "JSON-lines export of the study's finished trials, rewritten after each; "
                "best.toml is written beside it."
            ),
            dir_okay=False,
        ),
    ] = Path("calibration.jsonl"),
    storage: Annotated[
        str | None,
        typer.Option(
            "--storage",
            help=(
                "Optuna storage URL holding the trials, e.g. sqlite:///calib.db (default: "
                "sqlite:///OUT.db beside --out). Resumable; several processes may share it."
            ),
            show_default=False,
        ),
    ] = None,
    study: Annotated[
        str | None,
        typer.Option(
            "--study",
            help="Study name in the storage (default gearchaos-calibrate, -quick with --quick).",
            show_default=False,
        ),
    ] = None,
    trials: Annotated[
        int | None,
        typer.Option(
            "--trials",
            help="Trials this command runs (each worker with --workers/--dask-local/--scheduler).",
            show_default=False,
        ),
    ] = None,
    budget_minutes: Annotated[
        float,
        typer.Option("--budget-minutes", help="Stop starting trials after this many minutes."),
    ] = 110.0,
    max_candidates: Annotated[
        int | None,
        typer.Option(
            "--max-candidates",
            help="Stop once the study holds N finished trials (resumed ones included).",
            show_default=False,
        ),
    ] = None,
    seed: Annotated[
        int,
        typer.Option(
            "--seed", help="Seed of the sampler (give commands sharing a storage different seeds)."
        ),
    ] = 0,
    quick: Annotated[
        bool, typer.Option("--quick", help="At most 3 trials on tiny sweeps, for CI.")
    ] = False,
    execution: c.Execution = c.Execution().offering(
        help={
            "scheduler": "Run one optimising worker per worker of the dask.distributed "
            "scheduler at this address (tcp://HOST:8786, one you trust: Dask exchanges "
            "pickles); --storage must be reachable from every worker.",
            "dask_local": "Run the trials on a local Dask cluster with N workers.",
        }
    ),
    output: c.Output = c.Output().offering("quiet", "json"),
) -> None:
    """Search the quantities of the seed's lost Table 1 (N and tooth numbers, input torque,
    transmission-error amplitude, stiffness ratios, mass ratios, b_c, load mode) with Optuna
    (multi-objective TPE) for the gear set that reproduces the most landmarks of the seed's text
    with the report's own evaluation, and whose clearances act (double-sided impact, multipliers
    that change along the backlashes). Trials live in --storage: rerunning the command resumes
    it, a trial killed mid-way is run again, and several commands (different --seed) or
    workers can share it; `optuna-dashboard sqlite:///calibration.db` shows the study. See
    docs/reproduction.md.

    Example: **gearchaos calibrate --storage sqlite:///calib.db --max-candidates 200**
    """
    from ..paper.calibrate import calibrate as run_calibration

    show = not output.silent
    err = c.stderr()

    def on_record(rec: Mapping[str, Any], now: bool) -> None:
        if show:
            what = f"{float(rec['seconds']):.0f} s" if now else "resumed"
            err.print(
                Text(
                    f"trial {rec['index']} ({rec['origin']}): landmarks {rec['score']:.2f}, "
                    f"structure {float(rec.get('structure', 0.0)):.2f} [{what}]",
                    style="dim",
                )
            )

    with c.reported_errors():
        from ..paper.landmarks import load_landmarks

        load_landmarks(landmarks)  # a bad file is refused before anything runs
        result = run_calibration(
            landmarks,
            out,
            storage=storage,
            study=study,
            trials=trials,
            budget_minutes=budget_minutes,
            max_candidates=max_candidates,
            seed=seed,
            quick=quick,
            on_record=on_record,
            **execution.offered_values(),
        )
    summary = {
        "out": str(out),
        "storage": result.storage,
        "study": result.study,
        "best_toml": str(result.best_toml) if result.best_toml else None,
        "evaluated": result.evaluated,
        "resumed": result.reused,
        "retried": result.retried,
        "stopped": result.stopped,
        "plausible": result.plausible,
        "problems": result.problems,
        "best": result.best,
        "top": result.top(3),
    }
    if output.json:
        c.print_json(summary)
    elif not output.quiet:
        table = pairs_table("gearchaos calibrate: best candidate" + (" (quick)" if quick else ""))
        best = result.best or {}
        table.add_row("landmark score", escape(fmt(best.get("score"))))
        table.add_row("structure", escape(fmt(best.get("structure"))))
        table.add_row("trial", escape(fmt(best.get("index"))))
        for key, value in (best.get("variables") or {}).items():
            table.add_row(escape(str(key)), escape(fmt(value)))
        table.add_row("evaluated / resumed", f"{result.evaluated} / {result.reused}")
        table.add_row("study", escape(f"{result.study} in {result.storage}"))
        table.add_row("stopped", escape(result.stopped))
        table.add_row("best.toml", escape(str(result.best_toml)))
        verdict = (
            "yes: inside every range, no validation warnings"
            if result.plausible
            else "no: " + "; ".join(result.problems)
        )
        table.add_row("physically plausible", escape(verdict))
        c.stdout().print(table)
    if result.stopped == "interrupted":
        c.fail(
            f"interrupted: every finished trial is in {result.storage} (study {result.study}); "
            "run the same command again to resume",
            c.EXIT_INTERRUPTED,
        )
