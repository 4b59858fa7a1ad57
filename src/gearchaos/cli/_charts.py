"""The table of ``gearchaos plot --contact --table``: the contact ranges of a 1-D sweep (its
figures come from :func:`~gearchaos.plot.figure_for`)."""

from __future__ import annotations

from typing import Any


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
