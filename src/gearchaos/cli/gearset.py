"""Gear-set commands: ``gearchaos info``, ``presets`` and ``init-gearset``."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table
from rich.text import Text

from . import _common as c
from ._render import info_renderables


@c.command()
def info(
    target: c.Target = c.Target().offering("preset", "gearset_file", "sets"),
    output: c.Output = c.Output().offering("json"),
) -> None:
    """Linear properties of a gear set: radii, equivalent masses, ω_n, damping coefficients,
    dimensionless groups, mesh phasing and natural frequencies with their mode classes.

    With **--set omega=...** the operating point (mesh frequency, sun speed) is added.
    """
    with c.reported_errors():
        omega, changes = c.parse_sets(target.sets or [])
        gs = c.load_gearset(target, changes)
        omega = c.point_omega(gs, omega, changes)  # --set sun_rpm / mesh_hz: through gs
        from ..model.derived import gearset_info

        data = dict(gearset_info(gs))
        if omega is not None:
            data["operating_point"] = {
                "omega": omega,
                "mesh_frequency_rad_s": omega * gs.omega_n,
                "mesh_frequency_hz": omega * gs.omega_n / (2.0 * math.pi),
                "sun_speed_rpm": gs.sun_speed_rpm(omega),
            }
    if output.json:
        c.print_json(data)
        return
    out = c.stdout()
    out.print(Text.assemble(("gear set ", "dim"), (gs.name, "bold")))
    if gs.description:
        out.print(Text(gs.description, style="dim"))
    out.print()
    for renderable in info_renderables(data):
        out.print(renderable)


@c.command()
def presets() -> None:
    """List the built-in gear sets (use one with --preset NAME)."""
    from ..gearset import list_presets

    table = Table(title="Built-in gear sets", title_justify="left")
    table.add_column("name", style="bold cyan", no_wrap=True)
    table.add_column("description")
    for name, description in list_presets():
        table.add_row(name, description)
    c.stdout().print(table)


@c.command("init-gearset")
def init_gearset(
    file: Annotated[
        Path, typer.Argument(help="TOML file to write.", dir_okay=False, show_default=False)
    ],
    force: Annotated[
        bool,
        typer.Option(
            "--force",
            "-f",
            help="Overwrite an existing gear-set file that init-gearset wrote and nobody has "
            "edited since (never another file).",
        ),
    ] = False,
    target: c.Target = c.Target().offering("preset"),
) -> None:
    """Write a commented gear-set file to start from (the values of --preset, default
    sheng2016, every line explained); edit it, then run **gearchaos simulate --gearset FILE**."""
    from .._marks import fill_mark, placeholder
    from .._output import check_replaceable, file_has_mark, write_file
    from .._text import escape_path
    from ..gearset import template_toml

    shown = escape_path(file)
    if file.is_symlink() or (file.exists() and not file.is_file()):  # a FIFO would block
        c.fail(
            f"{shown} exists and is not a regular file (a link, directory, FIFO or device); "
            "choose another path",
            c.EXIT_INVALID,
        )
    if file.exists() and not force:
        c.fail(f"{shown} already exists; pass --force to overwrite it", c.EXIT_FAILURE)
    with c.reported_errors():
        # --force replaces only a file init-gearset wrote, as it wrote it (its mark holds)
        check_replaceable(str(file), what="gear-set file", ours=file_has_mark)
        # gearchaos's mark: the digest of the file (an edited file is the user's)
        head = f"# {placeholder()} (written by gearchaos init-gearset)\n"
        template = template_toml(target.preset or c.DEFAULT_PRESET)
        text = fill_mark((head + template).encode("utf-8"))
        # complete or not at all: a full disk leaves the old file (or none), never a part
        write_file(str(file), text, what="gear-set file")
    c.wrote(file)
    c.stdout().print(
        Text(f"next: gearchaos simulate --gearset {shown} --set omega=1.5 -o out/", style="dim")
    )
