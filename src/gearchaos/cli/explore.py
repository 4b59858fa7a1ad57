"""``gearchaos explore``: the browser explorer of a sweep store (:mod:`gearchaos.explore`)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.text import Text

from .._text import escape_path
from ..errors import ParameterError
from . import _common as c


@c.command()
def explore(
    store: Annotated[
        Path,
        typer.Argument(help="Sweep store written by `gearchaos bifurcation`.", show_default=False),
    ],
    port: Annotated[int, typer.Option("--port", help="Port on localhost; 0 picks a free one.")] = 0,
    no_browser: Annotated[
        bool, typer.Option("--no-browser", help="Do not open a browser; only print the URL.")
    ] = False,
    var: Annotated[
        str | None,
        typer.Option(
            "--var",
            help="Section variable drawn (default: the store's first observed one, delta_sp "
            "(X̄_sp) for gear sets).",
            show_default=False,
        ),
    ] = None,
    planet: Annotated[int, typer.Option("--planet", help="Planet of per-planet variables.")] = 1,
    boundaries: Annotated[
        list[Path] | None,
        typer.Option(
            "--boundaries",
            help="Boundary-curve file (gearchaos boundary) drawn over the regime map of a 2-D "
            "sweep; repeatable.",
            show_default=False,
        ),
    ] = None,
    target: c.Target = c.RECORDED_MODEL,
) -> None:
    """Explore a sweep store in the browser: its bifurcation diagram with the band of motion
    labels (or the regime map of a 2-D sweep). Click a point, or move the slider, to see its
    stored Poincaré section, label and λ₁; the phase portrait, time histories with the contact
    force, spectrum, recomputed λ₁ and Floquet multipliers follow from a background worker.
    Box-zoom and press *Finer sweep* to sweep the shown range into a sibling store
    RUN.zoom/... (resumable). Prints the URL; Ctrl-C stops the server.

    Example: **gearchaos explore fig4.zarr --no-browser**
    """
    from ._start import name_model
    from .sweep import open_store

    with c.reported_errors():
        name_model(target.model)  # a finer sweep of your own model's store: only with your consent
        if not 0 <= port <= 65535:
            raise ParameterError(f"--port must be an integer in 0..65535: got {port}")
        open_store(store)
        from ..explore import serve

        def ready(url: str) -> None:
            out = c.stdout()
            out.print(
                Text.assemble(
                    ("explorer of ", "dim"), (escape_path(store), "bold"), (" at ", "dim")
                ),
                soft_wrap=True,
                end="",
            )
            out.print(url, soft_wrap=True, highlight=False)
            out.print(Text("Ctrl-C stops it", style="dim"))
            out.file.flush()

        serve(
            store, port=port, show=not no_browser, var=var, planet=planet, ready=ready,
            boundaries=[str(b) for b in boundaries or []],
        )  # fmt: skip
    c.stdout().print(Text("explorer stopped", style="dim"))
