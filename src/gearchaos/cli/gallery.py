"""``gearchaos poincare``: a gallery of Poincaré maps along a parameter path."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer

from ..errors import ParameterError
from ..paper.galleries import GALLERY_SETTINGS
from . import _common as c
from ._render import gallery_rows_table


@c.command()
def poincare(
    vary: Annotated[
        str | None,
        typer.Option(
            "--vary",
            "-v",
            help=(
                "NAME=VALUES: one panel per value, VALUES a,b,c or start:stop:count; NAME is "
                "omega, xi or a dotted gear-set parameter, e.g. "
                "omega=1.2,1.35,1.5,1.7,1.875,1.926,2.02,2.3 or backlash.sun_planet=1:6:12."
            ),
            show_default=False,
        ),
    ] = None,
    target: c.Target = c.Target(),
    with_: Annotated[
        str | None,
        typer.Option(
            "--with",
            help="Extra rows under each map: phase, spectrum or phase,spectrum.",
            show_default=False,
        ),
    ] = None,
    planet: Annotated[int, typer.Option("--planet", help="Planet of X̄_sp.")] = 1,
    protocol: c.Protocol = c.Protocol.of(GALLERY_SETTINGS).offering("transient", "periods"),
    solver: c.Solver = c.Solver.of(GALLERY_SETTINGS),
    output: c.Output = c.Output().offering(
        "file", "quiet", "json", help={"file": "Figure file: .png, .pdf or .svg."}
    ),
) -> None:
    """A gallery of Poincaré maps (X̄_sp1 against X̄'_sp1) along a parameter path, each panel
    titled with the value, its motion label and its largest Lyapunov exponent λ₁.

    Every value is one simulation with the seed's protocol (TRANSIENT mesh periods discarded,
    PERIODS recorded) plus a Lyapunov run at the same settings; the label (1T … nT, QP, chaos,
    unresolved) uses that λ₁. Prints a table of the values (value, motion, λ₁, K of the 0–1
    test, distinct points); **--json** prints them as rows.

    Example: **gearchaos poincare --vary omega=1.2,1.35,1.5,1.7,1.875,1.926,2.02,2.3
    --with phase -o gallery.png**
    """
    with c.reported_errors():
        if not vary:
            raise ParameterError(
                "--vary is required: give NAME=VALUES, e.g. --vary omega=1.2,1.5,1.875"
            )
        path = output.figure()
        if path is None:
            raise ParameterError("--output is required: the figure file, e.g. -o gallery.png")
        from ..plot.gallery import parse_extras
        from ..sweep.spec import parse_axis

        try:
            extras = parse_extras(with_)
        except ParameterError:
            raise ParameterError(
                f"--with must be phase, spectrum or phase,spectrum: got {with_!r}"
            ) from None
        axis = parse_axis(vary)
        settings = c.settings(protocol, solver)
        gs, fixed = c.sweep_target(target, {axis.name}, output.silent, "varied")

        import matplotlib

        matplotlib.use("Agg")
        from ..paper.galleries import run_gallery
        from ..plot import savefig

        t0 = time.perf_counter()
        fig, rows = run_gallery(
            gs,
            axis.name,
            axis.values,
            params=fixed,
            with_=extras,
            progress=not output.silent,
            planet=planet,
            settings=settings,
        )
        if path.parent != Path(""):
            path.parent.mkdir(parents=True, exist_ok=True)
        try:
            savefig(fig, path)
        finally:
            import matplotlib.pyplot as plt

            plt.close(fig)
        seconds = time.perf_counter() - t0
    if output.json:
        c.print_json(
            {
                "figure": str(path),
                "param": axis.name,
                "fixed": fixed,
                "transient_periods": protocol.transient,
                "periods": protocol.periods,
                "seconds": seconds,
                "rows": rows,
            }
        )
        return
    if output.quiet:
        return
    c.stdout().print(gallery_rows_table(rows, axis.name, title=f"Poincaré gallery of {gs.name}"))
    c.wrote(path)
