"""``gearchaos simulate``: one operating point, its motion and its summary."""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.text import Text

from .._text import escape_path
from ..integrate.settings import SIMULATION
from ..model.contract import Capabilities
from ..model.target import model_for
from . import _common as c
from ._render import add_motion_rows
from ._speeds import speed_note


@c.command()
def simulate(
    target: c.Target = c.Target(),
    protocol: c.Protocol = c.Protocol.of(SIMULATION),
    solver: c.Solver = c.Solver.of(SIMULATION),
    output: c.Output = c.Output().offering(
        "file",
        "json",
        help={
            "file": "Directory for simulation.nc (netCDF, all samples and the gear set) and "
            "simulation.png (summary figure); created if missing. Without -o nothing is "
            "written."
        },
    ),
    plot: Annotated[
        bool, typer.Option("--plot/--no-plot", help="Write the summary figure (with -o).")
    ] = True,
    verdict: c.Verdict = c.Verdict().offering(
        help={
            "verdict": "Decide the motion: an nT label confirmed by shooting (Floquet "
            "multipliers), chaos or QP by λ₁ with its error from an extension of the run, "
            "transients finished, the start from rest perturbed by 1e-6 (default). "
            "--no-verdict: labels from the record alone."
        }
    ),
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
        directory = output.directory()
        gs, omega = c.point_target(target)
        omega = c.DEFAULT_OMEGA if omega is None else omega
        settings = c.settings(protocol, solver)
        decided = verdict.decided()
        if directory is not None:
            directory.mkdir(parents=True, exist_ok=True)
        from ..dynamics.verdict.point import analyse_point

        err = c.stderr()
        spinner: contextlib.AbstractContextManager[Any] = contextlib.nullcontext()
        if not output.json and err.is_terminal:
            total = protocol.transient + protocol.periods
            what = " and the verdict" if decided else (" and λ₁" if lyapunov else "")
            name = Capabilities.of(model_for(gs, {})).period_name
            spinner = err.status(
                f"integrating {gs.name} at Ω = {omega:g}, {total:g} {name} periods{what}…"
            )
        with spinner, c.warnings_to_stderr():
            point = analyse_point(
                gs,
                {"omega": omega},
                settings,
                lyapunov=lyapunov,
                check=True,
                verdict=decided,
            )
        if lyapunov and point.lle is None and point.lyapunov_status is not None:
            c.warn(f"the Lyapunov exponent could not be computed: {point.lyapunov_status.message}")
        result, summary = point.result, point.summary
        written: list[Path] = []
        if directory is not None:
            nc = directory / "simulation.nc"
            result.save(nc)
            written.append(nc)
            if plot:
                written.append(_save_figure(result, summary, directory / "simulation.png"))

    if output.json:
        c.print_json(summary)
        for path in written:
            c.stderr().print(Text(f"wrote {escape_path(path)}"), soft_wrap=True)
        return
    from ._render import format_summary

    out = c.stdout()
    title = f"gearchaos simulation of {gs.name} at Ω = {omega:g}{speed_note(gs, omega)}"
    table = format_summary(summary, result.system, title=title)
    add_motion_rows(table, summary)
    out.print(table)
    name = result.system.capabilities.period_name
    out.print(
        Text(
            f"{protocol.transient:g} transient + {protocol.periods} recorded {name} periods, "
            f"rtol {solver.rtol:g}, atol {solver.atol:g}",
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
