"""``gearchaos response``: frequency-response curves (dynamic mesh forces) over a parameter."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape
from rich.text import Text

from .._text import escape_path
from ..errors import ParameterError
from ..sweep.spec import RESPONSE_SOLVER
from . import _common as c
from ._render import sweep_summary


@c.app.command()
def response(
    output: Annotated[
        Path,
        typer.Option(
            "--output",
            "-o",
            help="Zarr store to write (e.g. response.zarr); run again to resume.",
            show_default=False,
        ),
    ],
    vary: Annotated[
        str,
        typer.Option(
            "--vary",
            "-v",
            help="NAME=VALUES of the swept parameter, e.g. omega=0.3:2.5:221 "
            "(start:stop:count, log:start:stop:count or a,b,c).",
            show_default=False,
        ),
    ],
    preset: c.PresetOpt = None,
    gearset: c.GearsetOpt = None,
    model: c.ModelOpt = None,
    set_: c.SetOpt = None,
    direction: Annotated[
        str,
        typer.Option(
            "--direction",
            help="up, down or both: continuation in that direction (both shows the jumps "
            "between coexisting branches).",
        ),
    ] = "both",
    transient: c.TransientOpt = RESPONSE_SOLVER.transient_periods,
    periods: Annotated[
        int, typer.Option("--periods", help="Mesh periods recorded at every point.")
    ] = RESPONSE_SOLVER.periods,
    samples_per_period: Annotated[
        int,
        typer.Option("--samples-per-period", help="Samples per mesh period for the RMS values."),
    ] = RESPONSE_SOLVER.samples_per_period,
    rtol: c.RtolOpt = RESPONSE_SOLVER.rtol,
    atol: c.AtolOpt = RESPONSE_SOLVER.atol,
    workers: c.WorkersOpt = None,
    overwrite: c.OverwriteOpt = False,
    quiet: c.QuietOpt = False,
    json_out: c.JsonOpt = False,
) -> None:
    """Frequency response: dynamic mesh forces, load factors and transmission errors along a
    parameter, swept up and down by continuation.

    Every point starts from the final state of its neighbour (MODEL.md §8 protocol otherwise:
    TRANSIENT periods discarded, PERIODS recorded). Per point and mesh (sun–planet, planet–ring,
    every planet) the store holds the RMS and peak **contact** force (zero while the teeth are
    apart; peaks tracked inside every integration step), the dynamic load factor (peak contact
    force over the static mesh force T_D/(N r_bs)) and the RMS dynamic transmission error (the
    fluctuating part of the mesh deflection), besides the Poincaré sections of a bifurcation
    sweep. Draw it with **gearchaos plot STORE -o response.png**: curves over Ω with the sun
    speed in rpm and the mesh frequency in Hz, up and down branches, jumps marked.

    Example: **gearchaos response --vary omega=0.3:2.5:221 -o response.zarr**
    """

    with c.reported_errors(), c.interruptible():
        if direction not in ("up", "down", "both"):
            raise ParameterError(f"--direction must be up, down or both: got {direction!r}")
        settings = c.solver_settings(transient, periods, rtol, atol, samples_per_period)
        omega, changes = c.parse_sets(set_ or [])
        swept = {vary.split("=", 1)[0].strip()}
        gs, fixed = c.sweep_target(preset, gearset, model, swept, omega, changes, quiet or json_out)

        from .. import sweep

        res, seconds = c.run_sweep(
            sweep.response,
            gs,
            vary,
            settings=settings,
            output=output,
            overwrite=overwrite,
            workers=workers,
            quiet=quiet,
            direction=direction,
            params=fixed,
        )
        ds = res.ds
        lf = {
            m: float(ds[f"load_factor_{m}"].max()) for m in ("sp", "rp") if f"load_factor_{m}" in ds
        }

    result = {
        **sweep_summary(res, output, seconds),
        **{f"load_factor_{m}_max": v for m, v in lf.items()},
    }
    title = f"gearchaos frequency response of {gs.name}"
    table = c.sweep_report(title, res, result, json_out=json_out, quiet=quiet)
    if table is None:
        return
    for m, v in lf.items():
        table.add_row(f"largest load factor {m}", f"{v:.4g}")
    table.add_row("seconds", f"{seconds:.3g}")
    table.add_row("store", escape(str(output)))
    out = c.stdout()
    out.print(table)
    shown, stem = escape_path(output), escape_path(output.stem)
    out.print(Text(f"next: gearchaos plot {shown} -o {stem}.png", style="dim"))
