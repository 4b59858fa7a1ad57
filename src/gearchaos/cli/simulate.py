"""``gearchaos simulate``: one operating point, its motion and its summary."""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.text import Text

from .._text import escape_path
from ..errors import ParameterError
from ..integrate.settings import SIMULATION
from . import _common as c
from ._render import add_motion_rows
from ._speeds import speed_note


@c.app.command()
def simulate(
    preset: c.PresetOpt = None,
    gearset: c.GearsetOpt = None,
    model: c.ModelOpt = None,
    set_: c.SetOpt = None,
    transient: c.TransientOpt = SIMULATION.transient_periods,
    settle: c.SettleOpt = "off",
    perturbation: c.PerturbationOpt = None,
    periods: c.PeriodsOpt = SIMULATION.periods,
    samples_per_period: Annotated[
        int,
        typer.Option(
            "--samples-per-period",
            help="Samples per mesh period of the time history (figure, spectra, RMS values).",
        ),
    ] = SIMULATION.samples_per_period,
    rtol: c.RtolOpt = SIMULATION.rtol,
    atol: c.AtolOpt = SIMULATION.atol,
    output_dir: Annotated[
        str | None,
        typer.Option(
            "--output",
            "-o",
            help=(
                "Directory for simulation.nc (netCDF, all samples and the gear set) and "
                "simulation.png (summary figure); created if missing. "
                "Without -o nothing is written."
            ),
            show_default=False,
        ),
    ] = None,
    json_out: c.JsonOpt = False,
    plot: Annotated[
        bool, typer.Option("--plot/--no-plot", help="Write the summary figure (with -o).")
    ] = True,
    verdict: Annotated[
        bool,
        typer.Option(
            "--verdict/--no-verdict",
            help=(
                "Decide the motion: an nT label confirmed by shooting (Floquet multipliers), "
                "chaos or QP by λ₁ with its error from an extension of the run, transients "
                "finished, the start from rest perturbed by 1e-6. Default: labels from the "
                "record alone."
            ),
        ),
    ] = True,
    lyapunov: Annotated[
        bool,
        typer.Option(
            "--lyapunov",
            help=(
                "With --no-verdict: also compute the largest Lyapunov exponent (same "
                "transient, periods and tolerances) for the record's label."
            ),
        ),
    ] = False,
) -> None:
    """Simulate a gear set at one mesh frequency and summarise the steady response.

    Runs the seed paper's protocol (MODEL.md §8): start from rest (perturbed by 1e-6),
    adaptive Dormand–Prince 5(4), TRANSIENT mesh periods discarded, then PERIODS recorded
    with a Poincaré point
    X̄_sp1 = δ_sp1/b_c at each τ_k = 2πk/Ω. Ω is set with **--set omega=...**
    (default **1.5**). Prints the motion verdict (1T … nT confirmed by shooting with its
    largest Floquet multiplier, QP or chaos from λ₁ ± its error, or unresolved with the
    reason), the section range of X̄_sp1 and the contact regime of every mesh. With
    **--model FILE.py:CLASS** the same for your own model (its default section variable and
    its contacts; see docs/howto/own-model.md).

    Example: **gearchaos simulate --preset sheng2016 --set omega=1.5 --set xi=0.05 -o out/**
    """
    with c.reported_errors():
        output = c.output_path(output_dir)
        if output is not None and output.exists() and not output.is_dir():
            raise ParameterError(f"--output must be a directory: {str(output)!r} is a file")
        omega, changes = c.parse_sets(set_ or [])
        gs = c.load_target(preset, gearset, model, changes)
        omega = c.point_omega(gs, omega, changes)  # --set sun_rpm / mesh_hz: through gs
        omega = c.DEFAULT_OMEGA if omega is None else omega
        settings = c.solver_settings(
            transient, periods, rtol, atol, samples_per_period, settle, perturbation
        )
        if output is not None:
            output.mkdir(parents=True, exist_ok=True)
        from ..dynamics.point import analyse_point

        err = c.stderr()
        spinner: contextlib.AbstractContextManager[Any] = contextlib.nullcontext()
        if not json_out and err.is_terminal:
            total = transient + periods
            what = " and the verdict" if verdict else (" and λ₁" if lyapunov else "")
            spinner = err.status(
                f"integrating {gs.name} at Ω = {omega:g}, {total:g} mesh periods{what}…"
            )
        with spinner, c.warnings_to_stderr():
            point = analyse_point(
                gs,
                {"omega": omega},
                settings,
                lyapunov=lyapunov,
                check=True,
                verdict=verdict,
            )
        if lyapunov and point.lle is None and point.lyapunov_status is not None:
            c.warn(f"the Lyapunov exponent could not be computed: {point.lyapunov_status.message}")
        result, summary = point.result, point.summary
        written: list[Path] = []
        if output is not None:
            nc = output / "simulation.nc"
            result.save(nc)
            written.append(nc)
            if plot:
                written.append(_save_figure(result, summary, output / "simulation.png"))

    if json_out:
        c.print_json(summary)
        for path in written:
            c.stderr().print(Text(f"wrote {escape_path(path)}"), soft_wrap=True)
        return
    from ._render import format_summary

    out = c.stdout()
    title = f"gearchaos simulation of {gs.name} at Ω = {omega:g}{speed_note(gs, omega)}"
    table = format_summary(summary, title=title)
    add_motion_rows(table, summary)
    out.print(table)
    out.print(
        Text(
            f"{transient:g} transient + {periods} recorded mesh periods, "
            f"rtol {rtol:g}, atol {atol:g}",
            style="dim",
        )
    )
    for path in written:
        c.wrote(path)


def _save_figure(result: Any, summary: dict[str, Any], path: Path) -> Path:
    """The summary figure of ``result`` showing the printed ``summary`` (its verdict)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..plot import savefig, summary_figure

    fig = summary_figure(result, summary=summary)
    try:
        savefig(fig, path)
    finally:
        plt.close(fig)
    return path
