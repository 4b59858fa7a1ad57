"""``gearchaos plot``: draw a sweep, response or basin store, branch files of ``gearchaos
continue`` or curve files of ``gearchaos boundary``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from ..errors import ParameterError
from . import _common as c
from .sweep import open_store


def _is_branch(path: Path) -> bool:
    """Whether ``path`` names a branch file of `gearchaos continue` (netCDF, or a Zarr branch
    with its chunk manifest) rather than a sweep store."""
    from ..dynamics.continuation.branch import MANIFEST

    if path.suffix.lower() in (".nc", ".nc4", ".h5"):
        return True
    return path.is_dir() and (path / MANIFEST).is_file()


def _is_basin_store(path: Path) -> bool:
    """Whether ``path`` is a store of `gearchaos basins` or `basin-fractions`."""
    from ..sweep._basin_store import KINDS
    from ..sweep.integrity import read_json

    try:  # never blocking on a FIFO, never reading a device without end
        attrs = read_json(str(path / ".zattrs"))
    except (OSError, ValueError):
        return False
    return isinstance(attrs, dict) and attrs.get("kind") in KINDS


#: How messages of :func:`~gearchaos.plot.figure_for` name its options: by this command's flags.
OPTION_NAMES = {
    "var": "--var", "planet": "--planet", "clearance_lines": "--clearance-lines",
    "resonances": "--resonances", "branches": "--branch", "sections": "--sections",
    "boundaries": "--boundaries", "impact": "--impact", "quantity": "--quantity",
    "contact": "--contact",
}  # fmt: skip


@c.command()
def plot(
    stores: Annotated[
        list[Path],
        typer.Argument(
            help="A sweep store of `gearchaos bifurcation` or `response`, or one or more branch "
            "files of `gearchaos continue` (drawn on their own).",
            show_default=False,
        ),
    ],
    var: Annotated[
        str | None,
        typer.Option(
            "--var",
            help="Section variable: delta_sp (X̄_sp), delta_sp_dot, delta_rp, x_s, ... "
            "[default: delta_sp]",
            show_default=False,
        ),
    ] = None,
    planet: Annotated[
        int | None,
        typer.Option(
            "--planet", help="Planet of per-planet variables. [default: 1]", show_default=False
        ),
    ] = None,
    clearance: Annotated[
        bool,
        typer.Option("--clearance-lines", help="Dashed lines at ±b̄ of the variable's clearance."),
    ] = False,
    resonances: Annotated[
        bool,
        typer.Option(
            "--resonances",
            help="Vertical lines where the 1st–3rd mesh harmonic meets a natural frequency "
            "(Ω sweeps).",
        ),
    ] = False,
    branch: Annotated[
        list[Path] | None,
        typer.Option(
            "--branch",
            help="Branch file of `gearchaos continue`, repeatable: drawn over the diagrams of its "
            "parameter (stable solid, unstable dashed, events marked and named).",
            show_default=False,
        ),
    ] = None,
    sections: Annotated[
        bool,
        typer.Option(
            "--sections",
            help="For a store of `gearchaos response`: draw its bifurcation diagram instead of "
            "the response curves.",
        ),
    ] = False,
    boundaries: Annotated[
        list[Path] | None,
        typer.Option(
            "--boundaries",
            help="Curve file of `gearchaos boundary`, repeatable: the stability chart, boundary "
            "curves over the 2-D regime map of the same two parameters (physical axes "
            "opposite, a legend naming each kind of boundary).",
            show_default=False,
        ),
    ] = None,
    impact: Annotated[
        str | None,
        typer.Option(
            "--impact",
            help="For a classified 2-D sweep of a gear set: the impact map of this mesh "
            "(sun_planet or planet_ring): no impact, single- or double-sided impact at every "
            "point, for --planet (default 1).",
            show_default=False,
        ),
    ] = None,
    chosen: Annotated[
        c.Quantity | None,
        typer.Option(
            "--quantity",
            help="For a response store with --branch: amplitude (max − min of --var) or "
            "force_peak (peak contact force of its mesh, as the response curves name it). "
            "[default: amplitude]",
            show_default=False,
        ),
    ] = None,
    contact: Annotated[
        bool,
        typer.Option(
            "--contact",
            help="For a 1-D sweep or response store of a gear set: the contact regime of every "
            "mesh (none, single- or double-sided impact; per direction, per planet where they "
            "differ) against the swept parameter, sun speed in rpm over Ω, with the peak "
            "contact force in N of a response store.",
        ),
    ] = False,
    table: Annotated[
        bool,
        typer.Option(
            "--table",
            help="With --contact: also print the ranges of the swept parameter (and sun "
            "speed) in each contact regime, with their peak contact force.",
        ),
    ] = False,
    target: c.Target = c.RECORDED_MODEL,
    output: c.Output = c.Output().offering(
        "file", help={"file": "Figure file: .png, .pdf or .svg."}, required=("file",)
    ),
) -> None:
    """Draw a sweep store: bifurcation diagrams (one panel per family value, with a band of
    motion labels under each) for a 1-D sweep, maps coloured by motion label (1T, 2T, …, QP,
    chaos) for a 2-D sweep, frequency-response curves (peak and RMS contact force, load
    factor, RMS DTE; up and down branches, jumps marked; Ω with sun rpm and mesh Hz) for a
    store of `gearchaos response`. Branch files of `gearchaos continue` are drawn on their own
    (section values against the continued parameter, stable solid, unstable dashed, events
    named), or over a sweep's diagram with --branch.

    With --boundaries, curves of `gearchaos boundary` over the 2-D map (a stability chart);
    curve files alone are drawn as a chart without a map.

    With --contact, the contact regime of every mesh along a 1-D sweep (does it rattle, and
    from which speed?); --table prints its ranges.

    Example: **gearchaos plot fig4.zarr -o fig4.png --clearance-lines**, **gearchaos plot
    branch.nc -o branch.png**, **gearchaos plot map.zarr --boundaries pd.nc -o chart.png**,
    **gearchaos plot response.zarr --contact --table -o rattle.png**
    """
    from ._start import name_model

    with c.reported_errors():
        name_model(target.model)  # symbols of your own model's variables: only with consent
        quantity = c.choice_value(chosen)
        if table and not contact:
            raise ParameterError("--table prints the contact ranges: it needs --contact")
        figure = output.figure()
        assert figure is not None  # -o is required
        import matplotlib

        matplotlib.use("Agg")
        from ..dynamics.continuation.cascade import open_cascade
        from ..dynamics.curves.file import open_curve
        from ..plot import FigureOptions, figure_for, savefig

        options = FigureOptions(
            var=var, planet=planet, clearance_lines=clearance, resonances=resonances,
            sections=sections, impact=impact, quantity=quantity, contact=contact,
            names=OPTION_NAMES,
        )  # fmt: skip
        res = None
        if all(_is_branch(p) for p in stores):
            from .boundary import is_curve_file

            if not contact and all(is_curve_file(p) for p in stores):  # a chart without a map
                source: Any = [open_curve(p) for p in stores]
                boundaries_ = [open_curve(p) for p in boundaries or []]
            else:
                source = [br for b in [*stores, *(branch or [])] for br in open_cascade(b)]
                boundaries_ = []
            fig = figure_for(source, options, boundaries=boundaries_)
        elif len(stores) > 1:
            raise ParameterError(
                "STORE must be one sweep store, or branch files only: got "
                f"{', '.join(str(p) for p in stores)}; draw branches over a sweep with "
                "--branch BRANCH.nc"
            )
        elif _is_basin_store(stores[0]):
            from ..sweep._basin_store import open_basins

            fig = figure_for(
                open_basins(stores[0]), options, where=str(stores[0]), branches=branch or []
            )
        else:
            store = stores[0]
            res = open_store(store)
            branches = [br for b in branch or [] for br in open_cascade(b)]
            curves = [open_curve(p) for p in boundaries or []] if not contact else boundaries
            fig = figure_for(
                res, options, where=str(store), branches=branches, boundaries=curves or []
            )
        if figure.parent != Path(""):
            figure.parent.mkdir(parents=True, exist_ok=True)
        savefig(fig, figure)
    c.wrote(figure)
    if table and res is not None:
        from ._charts import contact_table

        c.stdout().print(contact_table(res, title=f"contact regimes of {stores[0]}"))
