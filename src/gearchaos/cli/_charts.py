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
