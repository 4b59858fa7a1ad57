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


@c.app.command()
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
    output: Annotated[
        Path | None,
        typer.Option("--output", "-o", help="Figure file: .png, .pdf or .svg.", show_default=False),
    ] = None,
    preset: c.PresetOpt = None,
    gearset: c.GearsetOpt = None,
    model: c.ModelOpt = None,
    set_: c.SetOpt = None,
    transient: c.TransientOpt = GALLERY_SETTINGS.transient_periods,
    periods: c.PeriodsOpt = GALLERY_SETTINGS.periods,
    with_: Annotated[
        str | None,
        typer.Option(
            "--with",
            help="Extra rows under each map: phase, spectrum or phase,spectrum.",
            show_default=False,
        ),
    ] = None,
    planet: Annotated[int, typer.Option("--planet", help="Planet of X̄_sp.")] = 1,
    rtol: c.RtolOpt = GALLERY_SETTINGS.rtol,
    atol: c.AtolOpt = GALLERY_SETTINGS.atol,
    quiet: c.QuietOpt = False,
    json_out: c.JsonOpt = False,
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
    from ..plot.figure import SAVE_FORMATS

    with c.reported_errors():
        if not vary:
            raise ParameterError(
                "--vary is required: give NAME=VALUES, e.g. --vary omega=1.2,1.5,1.875"
            )
        if output is None:
            raise ParameterError("--output is required: the figure file, e.g. -o gallery.png")
        if output.suffix.lower() not in SAVE_FORMATS:
            raise ParameterError(
                f"--output must end in one of {', '.join(SAVE_FORMATS)}: got {str(output)!r}"
            )
        from ..plot.gallery import parse_extras
        from ..sweep.spec import parse_axis

        try:
            extras = parse_extras(with_)
        except ParameterError:
            raise ParameterError(
                f"--with must be phase, spectrum or phase,spectrum: got {with_!r}"
            ) from None
        axis = parse_axis(vary)
        omega, changes = c.parse_sets(set_ or [])
        settings = c.solver_settings(transient, periods, rtol, atol)
        gs, fixed = c.sweep_target(
            preset, gearset, model, {axis.name}, omega, changes, quiet or json_out, "varied"
        )

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
            progress=not (quiet or json_out),
            planet=planet,
            settings=settings,
        )
        if output.parent != Path(""):
            output.parent.mkdir(parents=True, exist_ok=True)
        try:
            savefig(fig, output)
        finally:
            import matplotlib.pyplot as plt

            plt.close(fig)
        seconds = time.perf_counter() - t0
    if json_out:
        c.print_json(
            {
                "figure": str(output),
                "param": axis.name,
                "fixed": fixed,
                "transient_periods": transient,
                "periods": periods,
                "seconds": seconds,
                "rows": rows,
            }
        )
        return
    if quiet:
        return
    c.stdout().print(gallery_rows_table(rows, axis.name, title=f"Poincaré gallery of {gs.name}"))
    c.wrote(output)
