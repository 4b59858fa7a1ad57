"""One front door from what was loaded to its figure: :func:`figure_for`.

``gearchaos plot`` and the explorer both hand over what they loaded — a simulation result, a
sweep or response store (:class:`~gearchaos.sweep.SweepResult`), continued branches, boundary
curves or a basin store — with the options of :class:`FigureOptions`, and get its figure;
which figure a source gets, and which options apply to it, is decided here once. Options that
do not apply are refused by name (:attr:`FigureOptions.names`: the command line passes its
flags, ``--var``), never ignored where the command line refused them.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

from ..errors import ParameterError

__all__ = ["PANELS", "FigureOptions", "figure_for"]

#: Layouts of a simulation's figure: the one-page ``summary``
#: (:func:`~gearchaos.plot.figure.summary_figure`) or the explorer's 2×2 ``point`` figure
#: (:func:`~gearchaos.plot.figure.point_figure`).
PANELS = ("summary", "point")


@dataclass(frozen=True)
class FigureOptions:
    """What to draw of a source (every field optional; see :func:`figure_for` for which
    applies to which source)."""

    #: The variable (section variable of a store; state, observable or group of a result).
    var: str | None = None
    #: The member (planet) of per-member variables (default 1).
    planet: int | None = None
    #: Dashed lines at ±b̄ of the variable's clearance (sweeps, branches).
    clearance_lines: bool = False
    #: Lines where a mesh harmonic meets a natural frequency (Ω sweeps, branches).
    resonances: bool = False
    #: Continued branches (datasets) drawn over a sweep's diagrams, or over a response
    #: store's amplitude–frequency figure.
    branches: Sequence[Any] = ()
    #: A response store drawn as its bifurcation diagram, not its response curves.
    sections: bool = False
    #: Boundary curves (datasets) drawn over a 2-D regime map: the stability chart.
    boundaries: Sequence[Any] = ()
    #: The impact map of this mesh (``sun_planet``, ``planet_ring``) of a classified 2-D sweep.
    impact: str | None = None
    #: What the amplitude–frequency figure draws: ``amplitude`` or ``force_peak``.
    quantity: str | None = None
    #: The contact regime of every mesh along a 1-D sweep or response store.
    contact: bool = False
    #: Layout of a simulation's figure (:data:`PANELS`).
    panels: str = "summary"
    #: Forcing periods of a simulation's time histories.
    history_periods: float = 10.0
    #: The summary a simulation's figure shows (computed when not given).
    summary: Mapping[str, Any] | None = None
    #: What the source is called in messages (its file).
    where: str = ""
    #: How messages name each option (field → name; the command line gives its flags).
    names: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))

    def __post_init__(self) -> None:
        if self.panels not in PANELS:
            raise ParameterError(f"panels must be one of {', '.join(PANELS)}: got {self.panels!r}")

    def name(self, option: str) -> str:
        """How messages name ``option`` (a field)."""
        return str(self.names.get(option, option))

    def given(self, *options: str) -> list[str]:
        """The names of those ``options`` that are given (not None, False or empty)."""
        return [self.name(o) for o in options if getattr(self, o) not in (None, False, [], ())]


def figure_for(source: Any, options: FigureOptions | None = None, **kw: Any) -> Any:
    """The figure of ``source`` with ``options`` (or the fields of :class:`FigureOptions` as
    keywords), as ``gearchaos plot`` and the explorer draw it.

    * a :class:`~gearchaos.SimulationResult`: its one-page summary (``panels="summary"``) or
      the explorer's 2×2 figure of one point (``panels="point"``);
    * a :class:`~gearchaos.sweep.SweepResult` (or its dataset): with ``contact`` the contact
      regime of every mesh; with ``boundaries`` the stability chart over its regime map; with
      ``impact`` an impact map; a response store with ``branches`` (and no ``sections``) its
      amplitude–frequency figure; a response store its response curves (``sections``: its
      bifurcation diagram); any other sweep :func:`~gearchaos.plot.sweep_figure`;
    * a basin store (a dataset of kind ``basins`` or ``basin_fractions``): its image or
      fraction curves;
    * a sequence of datasets: boundary curves (kind ``boundary_curve``) as a stability chart
      without a map, continued branches as :func:`~gearchaos.plot.branch.branch_figure`.

    Returns a matplotlib Figure; options that do not apply to the source are refused
    (:class:`~gearchaos.errors.ParameterError`) by :attr:`FigureOptions.names`.
    """
    opts = dataclasses.replace(options or FigureOptions(), **kw)
    from ..integrate.result import SimulationResult

    if isinstance(source, SimulationResult):
        return _simulation(source, opts)
    if isinstance(source, list | tuple):
        return _files(list(source), opts)
    from ..sweep._basin_store import KINDS

    attrs = getattr(getattr(source, "ds", source), "attrs", {})
    if attrs.get("kind") in KINDS:
        return _basins(source, opts)
    from ..sweep.result import SweepResult

    return _sweep(SweepResult.of(source), opts)


def _simulation(result: Any, opts: FigureOptions) -> Any:
    from .figure import point_figure, summary_figure

    planet = 1 if opts.planet is None else opts.planet
    if opts.panels == "point":
        return point_figure(result, opts.var, planet, opts.history_periods)
    summary = None if opts.summary is None else dict(opts.summary)
    return summary_figure(
        result, summary=summary, planet=planet, history_periods=opts.history_periods
    )


def _files(datasets: list[Any], opts: FigureOptions) -> Any:
    """Continued branches, or boundary curves alone (a stability chart without a map)."""
    if opts.contact:
        raise ParameterError(
            f"{opts.name('contact')} draws a sweep or response store, not branch or curve files"
        )
    if datasets and all(d.attrs.get("kind") == "boundary_curve" for d in datasets):
        from .stability import stability_figure

        return stability_figure([*datasets, *opts.boundaries], None)
    if opts.sections or opts.quantity:
        option = opts.name("sections") if opts.sections else opts.name("quantity")
        raise ParameterError(f"{option} applies to response stores, not branch files")
    from .branch import branch_figure

    return branch_figure(
        [*datasets, *opts.branches],
        var=opts.var,
        planet=1 if opts.planet is None else opts.planet,
        clearance_lines=opts.clearance_lines,
        resonances=opts.resonances,
    )


def check_quantity(opts: FigureOptions, applies: bool) -> None:
    """``quantity`` chooses what the amplitude–frequency figure draws (a response store with
    branches); anywhere else it is refused instead of ignored."""
    if opts.quantity is not None and not applies:
        n = opts.name
        raise ParameterError(
            f"{n('quantity')} applies to the amplitude–frequency figure of a response store "
            f"drawn with {n('branches')} BRANCH.nc (without {n('sections')}, {n('impact')} or "
            f"{n('boundaries')}): got {n('quantity')} {opts.quantity}"
        )


def _basins(ds: Any, opts: FigureOptions) -> Any:
    from .basins import basins_figure

    check_quantity(opts, False)
    given = opts.given("var", "planet", "branches", "sections", "contact")
    if given:
        raise ParameterError(f"{', '.join(given)} do(es) not apply to the basin store {opts.where}")
    return basins_figure(ds)


def _sweep(res: Any, opts: FigureOptions) -> Any:
    branches = list(opts.branches)
    response = res.ds.attrs.get("kind") == "response"
    if not opts.contact:
        check_quantity(
            opts,
            bool(branches and response) and not (opts.sections or opts.boundaries or opts.impact),
        )
    if opts.contact:
        from .contact import contact_figure

        wrong = opts.given(
            "var", "planet", "clearance_lines", "resonances", "branches", "sections",
            "boundaries", "impact", "quantity",
        )  # fmt: skip
        if wrong:
            raise ParameterError(
                f"{opts.name('contact')} draws the contact regime of every mesh of a 1-D sweep: "
                f"{', '.join(wrong)} does not apply to it"
            )
        return contact_figure(res)
    planet = 1 if opts.planet is None else opts.planet
    if opts.boundaries:
        from .stability import stability_figure

        return stability_figure(list(opts.boundaries), res)
    if opts.impact is not None:
        given = opts.given("branches", "sections", "var")
        if given:
            raise ParameterError(
                f"{opts.name('impact')} draws the contact regime of one mesh: "
                f"{', '.join(given)} does not apply to it"
            )
        from .impact import impact_figure

        return impact_figure(res, mesh=opts.impact, planet=planet)
    if branches and response and not opts.sections:
        from .amplitude import amplitude_figure

        quantity = "amplitude" if opts.quantity is None else opts.quantity
        return amplitude_figure(res, branches, var=opts.var, planet=planet, quantity=quantity)
    if response and not opts.sections:
        given = opts.given("var", "planet")
        if given:  # the response curves draw every mesh's contact force, no section
            raise ParameterError(
                f"{' and '.join(given)} {'does' if len(given) == 1 else 'do'} not apply to "
                f"the frequency-response figure of {opts.where}; add {opts.name('sections')} "
                "to draw its bifurcation diagram of one variable"
            )
        from .response import response_figure

        return response_figure(res)
    from .maps import sweep_figure

    return sweep_figure(
        res,
        var=opts.var,
        planet=planet,
        clearance_lines=opts.clearance_lines,
        resonances=opts.resonances,
        branches=branches,
    )
