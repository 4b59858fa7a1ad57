"""The charts of ``gearchaos plot``: impact maps (``--impact MESH``) and amplitude–frequency
figures (a response store with ``--branch``)."""

from __future__ import annotations

from typing import Any

from ..errors import ParameterError


def chart_figure(
    res: Any,
    impact: str | None,
    branches: list[Any],
    var: str | None,
    planet: int | None,
    sections: bool,
) -> Any:
    """The impact map of ``res`` (``impact``: a mesh name) or its amplitude–frequency figure
    with ``branches``; options that do not apply are refused by name."""
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

    return amplitude_figure(res, branches, var=var, planet=1 if planet is None else planet)
