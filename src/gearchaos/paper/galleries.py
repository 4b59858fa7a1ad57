"""The seed paper's Poincaré galleries (Figs. 5, 7, 10) and the runner of ``gearchaos poincare``.

Sheng et al. (2016) follow the motion along a parameter path with grids of Poincaré maps of
X̄_sp1 against X̄'_sp1 and name the motion of each map by eye. :func:`run_gallery` runs one
simulation per value (the seed's protocol: zero initial state, the transient discarded, one
section point per mesh period), computes the largest Lyapunov exponent of each
(:func:`~gearchaos.dynamics.lyapunov.max_lyapunov`, same settings) and labels it
(:func:`~gearchaos.analysis.summarize` with that LLE: 1T … nT, QP, chaos, unresolved), then
draws :func:`~gearchaos.plot.gallery.poincare_gallery`.

The recipes :data:`GALLERIES` hold the values the seed's text names for its three galleries:

======  =====================  =========================================================
figure  path                   fixed
======  =====================  =========================================================
Fig. 5  Ω (12 values)          ξ = 0.03, b̄_sp = 3, b̄_rp = 3.5, b̄_s = 2
Fig. 7  b̄_sp ∈ [1, 6] (12)     Ω = 1.5, ξ = 0.05, b̄_rp = 3.5, b̄_s = 2
Fig. 10 b̄_rp ∈ [1, 9] (14)     Ω = 1.5, ξ = 0.05, b̄_sp = 3, b̄_s = 2
======  =====================  =========================================================

The seed's panels (a)–(x) are not listed with their values; its text names some of them (the
bifurcation points it discusses). Each recipe's ``notes`` say which values are named and which
fill the named range. Limits: the default gear set stands in for the seed's lost Table 1
(MODEL.md §9 calibrated against the seed's landmarks, docs/reproduction.md), so the motion at a
given value can differ from the seed's.
"""

from __future__ import annotations

import csv
import json
import math
import os
import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

from .._checks import check_bool, check_int, check_real
from .._output import staged_file, write_file
from ..errors import ParameterError
from ..gearset import GearSet
from ..gearset.schema import display_symbol, tex
from ..integrate.settings import SolverSettings, check_params, renamed_keyword, split_keywords
from .recipes import load_figures, lookup_figure, seed_gearset

__all__ = [
    "GALLERIES",
    "PRESET",
    "QUICK_PERIODS",
    "ROW_KEYS",
    "Gallery",
    "get_gallery",
    "reproduce_gallery",
    "run_gallery",
]

#: Gear set every gallery runs on (as the bifurcation recipes).
PRESET = "sheng2016"
#: (transient, recorded) mesh periods of the full galleries (the seed discards 100).
FULL_PERIODS = (100, 500)
#: Solver settings of :func:`run_gallery` when none are given: 100 transient, 300 recorded.
GALLERY_SETTINGS = SolverSettings(transient_periods=100, periods=300)
#: (transient, recorded) mesh periods of ``quick`` galleries (the 0–1 test needs ≥ 100 points).
QUICK_PERIODS = (50, 100)
#: Keys of every row of :func:`run_gallery` (and columns of the recipes' CSV), in order.
ROW_KEYS = (
    "value",
    "motion",
    "lle",
    "lle_error",
    "evidence",
    "max_multiplier",
    "k01",
    "indicators_agree",
    "distinct_section_points",
    "status",
    "motion_note",
)


def start_text(settings: SolverSettings) -> str:
    """How a run starts, for a figure title: "start at rest (perturbed by 1e-06)"."""
    eps = float(settings.perturbation)
    return f"start at rest (perturbed by {eps:g})" if eps else "exact zero initial state"


# --------------------------------------------------------------------------- runner
def _finite(v: Any) -> float | None:
    if v is None:
        return None
    f = float(v)
    return f if math.isfinite(f) else None


def _progress(enabled: bool, total: int) -> Any:
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    return Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=Console(stderr=True),
        transient=True,
        disable=not enabled,
    )


def run_gallery(
    gs: Any,
    param: str,
    values: Sequence[float],
    *,
    params: Mapping[str, Any] | None = None,
    settings: SolverSettings | None = None,
    with_: Iterable[str] | str | None = (),
    progress: bool = True,
    planet: int = 1,
    title: str | None = None,
    fixed: Mapping[str, Any] | None = None,
    **values_and_settings: Any,
) -> tuple[Any, list[dict[str, Any]]]:
    """Simulate, measure and label every value of a parameter path and draw the gallery.

    Parameters
    ----------
    gs
        A :class:`~gearchaos.gearset.GearSet` (or a reference :class:`~gearchaos.model.System`,
        whose model fields are then the parameters).
    param, values
        The varied parameter by dotted name (``omega``, ``xi``, ``backlash.sun_planet``, …) and
        its values, in panel order.
    params
        The other parameters by dotted name (``{"backlash.sun_planet": 2.4}``), ``omega``
        included when it is not varied (required for a gear set); parameters whose names are
        Python identifiers may also be given by name (``omega=1.5``, ``xi=0.05``).
    settings
        A :class:`~gearchaos.integrate.settings.SolverSettings` (default
        :data:`GALLERY_SETTINGS`: 100 transient and 300 recorded periods) for the simulation
        and the Lyapunov exponent alike; settings given by name (``transient_periods``,
        ``periods``, ``rtol``, ``atol``, …) override it.
    with_
        ``"phase"`` and/or ``"spectrum"`` rows under each map; the simulations then record 64
        samples per period (else one, the section points only).
    progress
        A progress bar on stderr.
    planet, title
        Planet of X̄_sp; figure title (default: the gallery's own).
    fixed
        The deprecated spelling of ``params`` (a :class:`DeprecationWarning`; both at once are
        refused).
    **values_and_settings
        Parameters by name and settings by name, as above: the vocabulary of every front door
        (:func:`~gearchaos.integrate.settings.split_keywords`). Any other name is refused with
        the closest valid one.

    Returns
    -------
    (figure, rows)
        The :func:`~gearchaos.plot.gallery.poincare_gallery` figure and one dictionary per value
        with the keys :data:`ROW_KEYS`: ``value``, ``motion`` (``failed`` when the integration
        failed), ``lle`` (per unit τ; None when not computable), ``k01`` (0–1 test),
        ``indicators_agree``, ``distinct_section_points``, ``status`` and ``motion_note``.

    Raises
    ------
    ParameterError
        An unknown or invalid parameter name, value or setting (checked for every value before
        anything runs), ``param`` also among the fixed parameters, a parameter given twice, no
        Ω, or invalid ``with_``.
    """
    from ..dynamics.verdict.point import analyse_point
    from ..model.target import resolve
    from ..plot import axis_symbol
    from ..plot.gallery import parse_extras, poincare_gallery

    if with_ is not None and not isinstance(with_, str | Iterable):
        raise ParameterError(f"with_ must be 'phase', 'spectrum' or both: got {with_!r}")
    extras = parse_extras(with_)
    if fixed is not None:  # the spelling before the one vocabulary
        params = renamed_keyword(
            "run_gallery", "fixed", "params", check_params("fixed", fixed), params
        )
    fixed_values, base = split_keywords(
        values_and_settings, settings, params, GALLERY_SETTINGS, door=run_gallery, target=gs
    )
    settings = base.replace(samples_per_period=64 if extras else 1)
    if not isinstance(param, str):
        raise ParameterError(f"param must be a dotted parameter name: got {param!r}")
    if param in fixed_values:
        raise ParameterError(f"{param} is both varied and fixed; choose one", name=param)
    vals = _gallery_values(param, values)
    progress = check_bool("progress", progress)
    planet = check_int("planet", planet, lo=1)
    if title is not None and not isinstance(title, str):
        raise ParameterError(f"title must be text or None: got {type(title).__name__}")
    # resolve every point first: a bad name or value fails before anything runs
    systems = [resolve(gs, {**fixed_values, param: v}) for v in vals]
    n_planets = systems[0].group_size
    if n_planets and planet > n_planets:
        raise ParameterError(f"planet must be one of 1..{n_planets}: got {planet}")
    results: list[Any] = []
    summaries: list[dict[str, Any]] = []
    rows: list[dict[str, Any]] = []
    sym = display_symbol(param)
    with _progress(progress, len(vals)) as bar:
        task = bar.add_task("Poincaré gallery", total=len(vals))
        for v, system in zip(vals, systems, strict=True):
            bar.update(task, description=f"{sym} = {v:g}")
            point = analyse_point(system, None, settings)
            summary = point.summary
            results.append(point.result)
            summaries.append(summary)
            rows.append(
                {
                    "value": v,
                    "motion": summary["motion"],
                    "lle": _finite(summary.get("lle")),
                    "lle_error": _finite(summary.get("lle_error")),
                    "evidence": summary.get("evidence", "record"),
                    "max_multiplier": _finite(summary.get("max_multiplier")),
                    "k01": _finite(summary.get("k01")),
                    "indicators_agree": bool(summary.get("indicators_agree", True)),
                    "distinct_section_points": int(summary["distinct_section_points"]),
                    "status": summary["status"],
                    "motion_note": summary.get("motion_note", ""),
                }
            )
            bar.advance(task)
    if title is None:
        from ..plot._common import given as given_text, variable

        given = [given_text(k, fv) for k, fv in fixed_values.items() if _is_number(fv)]

        info = variable(results[0], None, planet) if results else None
        symbol, dot = (info.symbol, info.dot_symbol) if info else (rf"\bar{{X}}_{{sp{planet}}}", "")
        title = f"Poincaré maps of ${symbol}$ versus ${dot}$"
        title += f" at different {axis_symbol(param)}"
        if given:
            title += "\nat " + ", ".join(given)
        title += (
            f"\n{settings.transient_periods:g} transient + {settings.periods} recorded periods, "
            f"{start_text(settings)}; labels and λ₁ from the motion verdict"
        )
    fig = poincare_gallery(
        results, summaries, param=param, values=vals, with_=extras, planet=planet, title=title
    )
    return fig, rows


#: Most panels a gallery draws (the seed's galleries have 8 or 9).
MAX_GALLERY_VALUES = 64


def _gallery_values(param: str, values: Any) -> list[float]:
    """The values of a gallery's path: 1 to :data:`MAX_GALLERY_VALUES` finite numbers."""
    if isinstance(values, str | bytes) or not isinstance(values, Iterable):
        raise ParameterError(
            f"values must be a sequence of numbers (the values of {param}): "
            f"got {type(values).__name__}"
        )
    vals = []
    for i, v in enumerate(values):
        if i >= MAX_GALLERY_VALUES:
            raise ParameterError(
                f"values: a gallery draws at most {MAX_GALLERY_VALUES} panels: got more "
                f"values of {param}"
            )
        vals.append(check_real(f"values[{i}] ({param})", v))
    if not vals:
        raise ParameterError(f"values must hold at least one value of {param}: got none")
    return vals


def _fmt(v: Any) -> str:
    """A value inside a mathtext title (where "-" is typeset as a minus)."""
    return f"{float(v):g}"


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


# --------------------------------------------------------------------------- recipes
@dataclass(frozen=True)
class Gallery:
    """One Poincaré gallery of the seed paper.

    Attributes
    ----------
    name
        ``fig5``, ``fig7`` or ``fig10``.
    caption
        The seed's caption in plain text.
    param, values
        The varied parameter and the values drawn, in panel order.
    named
        The values among ``values`` that the seed's text names (the others fill its range).
    fixed
        Fixed parameters by dotted name (read-only mapping).
    notes
        Where the values come from.
    """

    name: str
    caption: str
    param: str
    values: tuple[float, ...]
    named: tuple[float, ...]
    fixed: Mapping[str, float] = field(hash=False)
    notes: str = ""
    transient_periods: int = FULL_PERIODS[0]
    periods: int = FULL_PERIODS[1]

    def __post_init__(self) -> None:
        object.__setattr__(self, "fixed", MappingProxyType(dict(self.fixed)))
        missing = [v for v in self.named if v not in self.values]
        if missing:
            raise ParameterError(f"{self.name}: named values must be drawn: missing {missing}")

    def title(self, quick: bool = False) -> str:
        """Figure title in mathtext, built from the recipe's own numbers."""
        number = self.name.removeprefix("fig")
        given = ", ".join(f"${tex(k)} = {_fmt(v)}$" for k, v in self.fixed.items())
        tr, rec = QUICK_PERIODS if quick else (self.transient_periods, self.periods)
        text = (
            f"Fig. {number}: Poincaré maps of $\\bar{{X}}_{{sp1}}$ versus "
            f"$\\bar{{X}}'_{{sp1}}$ at {given} and different ${tex(self.param)}$\n"
            f"{tr} transient + {rec} recorded mesh periods, "
            f"{start_text(GALLERY_SETTINGS)}; labels and λ₁ from the motion verdict"
        )
        return text + (" (quick)" if quick else "")


def _galleries() -> dict[str, Gallery]:
    items = [
        Gallery(
            name=d["name"],
            caption=d["caption"],
            param=d["param"],
            values=tuple(d["values"]),
            named=tuple(d["named"]),
            fixed=d["fixed"],
            notes=d["notes"],
        )
        for d in load_figures()["gallery"]
    ]
    return {g.name: g for g in items}


#: The seed's Poincaré galleries by name (``fig5``, ``fig7``, ``fig10``).
GALLERIES: dict[str, Gallery] = _galleries()


def get_gallery(name: str) -> Gallery:
    """The gallery called ``name`` (``fig5``, ``Fig5`` and ``5`` alike)."""
    return lookup_figure(GALLERIES, name, "gallery")


def _write_json(path: Path, obj: Any) -> None:
    text = json.dumps(obj, indent=2, ensure_ascii=False, allow_nan=False) + "\n"
    write_file(str(path), text.encode("utf-8"), what="gallery table")


def _write_csv(path: Path, rows: Sequence[Mapping[str, Any]]) -> None:
    with staged_file(str(path), what="gallery table") as tmp:
        with open(tmp, "w", newline="", encoding="utf-8") as fh:
            writer = csv.DictWriter(fh, fieldnames=list(ROW_KEYS))
            writer.writeheader()
            for row in rows:
                writer.writerow({k: "" if row.get(k) is None else row.get(k) for k in ROW_KEYS})


def reproduce_gallery(
    name: str,
    outdir: str | os.PathLike[str] = ".",
    *,
    quick: bool = False,
    progress: bool = True,
    gearset: GearSet | None = None,
) -> dict[str, Any]:
    """Draw the seed's Poincaré gallery ``name`` with the default gear set (or ``gearset``).

    Writes ``outdir/<name>.png`` (the grid), ``outdir/<name>.json`` (settings, gear set and the
    rows of :func:`run_gallery`) and ``outdir/<name>.csv`` (the rows); with ``quick`` the stem
    is ``<name>-quick`` (so a quick run never replaces a full one) and every value runs
    50 transient + 100 recorded periods instead of 100 + 500.

    Returns
    -------
    dict
        ``{"figure", "json", "table" (the CSV), "points", "failed", "seconds", "rows"}``.
    """
    from .._version import __version__
    from ..plot import savefig

    g = get_gallery(name)
    t0 = time.perf_counter()
    out = Path(os.fspath(outdir))
    out.mkdir(parents=True, exist_ok=True)
    stem = g.name + ("-quick" if quick else "")
    tr, rec = QUICK_PERIODS if quick else (g.transient_periods, g.periods)
    gs = seed_gearset(gearset)
    fig, rows = run_gallery(
        gs,
        g.param,
        g.values,
        params=dict(g.fixed),
        transient_periods=tr,
        periods=rec,
        progress=progress,
        title=g.title(quick),
    )
    png = out / f"{stem}.png"
    try:
        savefig(fig, png)
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)
    table = out / f"{stem}.csv"
    _write_csv(table, rows)
    meta = out / f"{stem}.json"
    _write_json(
        meta,
        {
            "figure": g.name,
            "caption": g.caption,
            "param": g.param,
            "values": list(g.values),
            "named_values": list(g.named),
            "fixed": dict(g.fixed),
            "gearset": gs.name,
            "gearset_toml": gs.to_toml(),
            "transient_periods": tr,
            "periods": rec,
            "quick": quick,
            "notes": g.notes,
            "version": __version__,
            "rows": rows,
        },
    )
    return {
        "figure": str(png),
        "json": str(meta),
        "table": str(table),
        "points": len(rows),
        "failed": sum(r["status"] != "ok" for r in rows),
        "seconds": time.perf_counter() - t0,
        "rows": rows,
    }
