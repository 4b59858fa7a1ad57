"""``gearchaos export``: a sweep store or a simulation file as CSV or MATLAB ``.mat``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from . import _common as c


@c.command()
def export(
    source: Annotated[
        Path,
        typer.Argument(
            help="Sweep, response or basin store (RUN.zarr) or simulation file (simulation.nc).",
            show_default=False,
        ),
    ],
    to: Annotated[
        c.ExportFormat | None,
        typer.Option(
            "--to",
            help="csv (TABLE.csv: one row per point; TABLE.sections.csv: the section samples; "
            "TABLE.csv.json: the provenance and every column's unit) or mat (MATLAB, every "
            "variable). Default: from the suffix of --output.",
            show_default=False,
        ),
    ] = None,
    output: c.Output = c.Output().offering(
        "file", help={"file": "File to write (.csv or .mat)."}, required=("file",)
    ),
) -> None:
    """Export a result for spreadsheets and other tools: CSV tables or a MATLAB .mat file.

    The CSV has one row per point, with the units in the column names: the swept parameters,
    omega, sun_rpm and mesh_hz (for a gear set), then motion, lle, max_multiplier, the contact
    regimes per planet, load factors and peak forces (also in N) of a response... Section
    samples go to a long table beside it (TABLE.sections.csv: one row per point and sample);
    the provenance (versions, gear set, sweep, solver settings, protocol) and the unit and
    meaning of every column to the sidecar TABLE.csv.json. pandas.read_csv and spreadsheets
    open both tables as they are. The .mat file holds every variable and coordinate, dimension
    names and attributes.

    Exports sweep stores (bifurcation), response stores, basin and basin-fraction stores and
    simulation files.

    Example: **gearchaos export resp.zarr -o resp.csv**
    """
    from ..sweep.exports import write_export

    with c.reported_errors():
        written = write_export(source, output.required_path(), to=c.choice_value(to))
    for p in written:
        c.wrote(p)
