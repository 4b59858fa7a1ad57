"""The charts of ``gearchaos plot``: impact maps (``--impact MESH``) and amplitude–frequency
figures (a response store with ``--branch``: amplitude or, with ``--quantity force_peak``, peak
contact force)."""

from __future__ import annotations

from typing import Any

from ..errors import ParameterError


def check_quantity(quantity: str | None, applies: bool) -> None:
    """``--quantity`` chooses what the amplitude–frequency figure draws (a response store with
    ``--branch``); anywhere else it is refused instead of ignored."""
    if quantity is not None and not applies:
        raise ParameterError(
            "--quantity applies to the amplitude–frequency figure of a response store drawn "
            f"with --branch BRANCH.nc (without --sections, --impact or --boundaries): got "
            f"--quantity {quantity}"
        )


def chart_figure(
    res: Any,
    impact: str | None,
    branches: list[Any],
    var: str | None,
    planet: int | None,
    sections: bool,
    quantity: str | None = None,
) -> Any:
    """The impact map of ``res`` (``impact``: a mesh name) or its amplitude–frequency figure
    with ``branches`` (``quantity``: amplitude or force_peak); options that do not apply are
    refused by name."""
    if impact is not None:
        given = [
            o for o, v in (("--branch", branches), ("--sections", sections), ("--var", var)) if v
        ]
        if given:
            raise ParameterError(
                f"--impact draws the contact regime of one mesh: {', '.join(given)} does not "
                "apply to it"
            )
        from ..plot.impact import impact_figure

        return impact_figure(res, mesh=impact, planet=1 if planet is None else planet)
    from ..plot.amplitude import amplitude_figure

    return amplitude_figure(
        res,
        branches,
        var=var,
        planet=1 if planet is None else planet,
        quantity="amplitude" if quantity is None else quantity,
    )


def contact_chart(res: Any, given: dict[str, Any]) -> Any:
    """The contact figure of a 1-D sweep or response store (``--contact``); the other
    options of ``gearchaos plot`` that do not apply to it are refused by name."""
    from ..plot.contact import contact_figure

    wrong = [name for name, value in given.items() if value not in (None, False, [])]
    if wrong:
        raise ParameterError(
            "--contact draws the contact regime of every mesh of a 1-D sweep: "
            f"{', '.join(wrong)} does not apply to it"
        )
    return contact_figure(res)


def contact_table(res: Any, *, title: str) -> Any:
    """A rich table of the contact ranges of a 1-D sweep
    (:func:`~gearchaos.sweep.contact.contact_ranges`): per mesh and sweep direction the runs
    of one regime with their swept values — the sun speed in rpm first over Ω, where the gear
    set defines it — and the largest peak contact force in newtons (a response store). The
    regime column wraps (planets that differ are named), the others never do."""
    from rich.table import Table

    from ..plot._common import axis_symbol
    from ..plot.units import PhysicalScales
    from ..sweep.contact import contact_ranges
    from ._render import escape

    ranges = contact_ranges(res)
    x_name = res.line_axis("contact ranges", "contact_sp")
    scales = PhysicalScales.of_sweep(res)
    rpm = scales.factor("omega") if x_name == "omega" else None
    force = scales.factor("force")
    has_force = any(r.peak_force is not None for r in ranges)
    has_direction = any(r.direction for r in ranges)
    symbol = "Ω" if x_name == "omega" else axis_symbol(x_name).strip("$")
    table = Table(title=escape(title), title_justify="left")
    table.add_column("mesh", no_wrap=True)
    if has_direction:
        table.add_column("sweep", no_wrap=True)
    if rpm is not None:
        table.add_column(escape("sun speed [rpm]"), justify="right", no_wrap=True)
    table.add_column(escape(symbol), justify="right", no_wrap=True)
    table.add_column("contact regime", ratio=1)
    if has_force:
        unit = "N" if force is not None else "k_m,sp b_c"
        table.add_column(escape(f"peak force [{unit}]"), justify="right", no_wrap=True)

    def span(lo: float, hi: float, spec: str) -> str:
        a, b = format(lo, spec), format(hi, spec)
        return a if a == b else f"{a} … {b}"

    for r in ranges:
        cells = [r.mesh.replace("_", "–")]
        if has_direction:
            cells.append(r.direction or "")
        if rpm is not None:
            cells.append(span(r.start * rpm[0], r.stop * rpm[0], ".0f"))
        cells += [span(r.start, r.stop, ".3f" if x_name == "omega" else ".4g"), r.describe()]
        if has_force:
            f = r.peak_force
            cells.append(
                "—" if f is None else (f"{f * force[0]:.0f}" if force is not None else f"{f:.4g}")
            )
        table.add_row(*cells)
    return table
