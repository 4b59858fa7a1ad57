"""``gearchaos response``: frequency-response curves (dynamic mesh forces) over a parameter."""

from __future__ import annotations

from typing import Annotated

import typer
from rich.markup import escape
from rich.text import Text

from .._text import escape_path
from ..sweep.spec import RESPONSE_SOLVER
from . import _common as c
from ._render import sweep_summary


@c.command()
def response(
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
    target: c.Target = c.Target(),
    direction: Annotated[
        c.Direction,
        typer.Option(
            "--direction",
            help="Continuation up, down or both (both shows the jumps between coexisting "
            "branches).",
        ),
    ] = c.Direction("both"),
    protocol: c.Protocol = c.Protocol.of(RESPONSE_SOLVER).offering(
        "transient", "periods", "samples_per_period"
    ),
    solver: c.Solver = c.Solver.of(RESPONSE_SOLVER),
    execution: c.Execution = c.Execution().offering("workers"),
    output: c.Output = c.Output().offering(
        help={"file": "Zarr store to write (e.g. response.zarr); run again to resume."},
        required=("file",),
    ),
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
        settings = c.settings(protocol, solver)
        swept = {vary.split("=", 1)[0].strip()}
        gs, fixed = c.sweep_target(target, swept, output.silent)

        from .. import sweep

        with c.named_options(direction="--direction"):
            res, seconds = c.run_sweep(
                sweep.response,
                gs,
                vary,
                settings=settings,
                output=output,
                execution=execution,
                direction=str(direction.value),
                params=fixed,
            )
        ds = res.ds
        lf = {
            m: float(ds[f"load_factor_{m}"].max()) for m in ("sp", "rp") if f"load_factor_{m}" in ds
        }

    path = output.required_path()
    result = {
        **sweep_summary(res, path, seconds),
        **{f"load_factor_{m}_max": v for m, v in lf.items()},
    }
    title = f"gearchaos frequency response of {gs.name}"
    table = c.sweep_report(title, res, result, output)
    if table is None:
        return
    for m, v in lf.items():
        table.add_row(f"largest load factor {m}", f"{v:.4g}")
    table.add_row("seconds", f"{seconds:.3g}")
    table.add_row("store", escape(str(path)))
    out = c.stdout()
    out.print(table)
    shown, stem = escape_path(path), escape_path(path.stem)
    out.print(Text(f"next: gearchaos plot {shown} -o {stem}.png", style="dim"))
