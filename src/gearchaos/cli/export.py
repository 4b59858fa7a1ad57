"""``gearchaos export``: a sweep store or a simulation file as CSV or MATLAB ``.mat``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from . import _common as c


@c.app.command()
def export(
    source: Annotated[
        Path,
        typer.Argument(
            help="Sweep store (RUN.zarr) or simulation file (simulation.nc).", show_default=False
        ),
    ],
    output: Annotated[
        str,
        typer.Option("--output", "-o", help="File to write (.csv or .mat).", show_default=False),
    ],
    to: Annotated[
        str | None,
        typer.Option(
            "--to",
            help="csv (a tidy table: one row per point and section sample) or mat (MATLAB, "
            "every variable). Default: from the suffix of --output.",
            show_default=False,
        ),
    ] = None,
) -> None:
    """Export a result for other tools: a tidy CSV table (swept parameters, section index,
    planet, then one column per variable; provenance in # header lines) or a MATLAB .mat file
    (every variable and coordinate, dimension names, attributes).

    Example: **gearchaos export fig4.zarr --to csv -o fig4.csv**
    """
    from ..sweep.exports import export as run_export

    with c.reported_errors():
        path = c.output_path(output)
        assert path is not None
        written = run_export(source, path, to=to)
    c.wrote(written)
