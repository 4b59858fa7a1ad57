"""The seed paper's bifurcation figures as data, and the one call that redraws each of them.

Sheng et al. (2016) show six bifurcation studies of the sun–planet mesh deflection X̄_sp1 at
the Poincaré section τ = kT (T = 2π/Ω), each a sweep of one parameter with one panel per value
of a second one:

======  ==============================  ===========================  ==============================
figure  swept (x axis)                  panels (family)              fixed
======  ==============================  ===========================  ==============================
Fig. 4  Ω ∈ [0, 4]                      ξ = 0.03, 0.05, 0.07, 0.09   b̄_sp = 3, b̄_rp = 3.5, b̄_s = 2
Fig. 6  b̄_sp ∈ [1, 10]                  ξ = 0.03, 0.05, 0.07, 0.09   Ω = 1.5, b̄_rp = 3.5, b̄_s = 2
Fig. 8  b̄_sp ∈ [1, 10]                  Ω = 1, 1.5, 2, 2.5           ξ = 0.11, b̄_rp = 3.5, b̄_s = 2
Fig. 9  b̄_rp ∈ [1, 16]                  ξ = 0.03, 0.05, 0.07, 0.09   Ω = 1.5, b̄_sp = 3, b̄_s = 2
Fig. 11 b̄_rp ∈ [1, 11]                  Ω = 1, 1.5, 2, 2.5           ξ = 0.11, b̄_sp = 3, b̄_s = 2
Fig. 12 b̄_s ∈ [1, 10]                   Ω = 1.5 (one panel)          ξ = 0.05, b̄_sp = 3, b̄_rp = 3.5
======  ==============================  ===========================  ==============================

Every sweep starts each point from rest perturbed by 10⁻⁶ along a fixed seeded direction,
integrates 100 transient mesh periods and records 100 section points, on the default gear set
(``gearchaos.preset("sheng2016")``), and decides every label by the motion verdict;
``paper_protocol`` runs the seed's own protocol instead (the exact zero start, labels from the
record alone). Dotted parameter names: ``omega``, ``xi`` (all three
damping ratios), ``backlash.sun_planet``, ``backlash.planet_ring``, ``clearance.sun_bearing``.

:func:`reproduce` runs one recipe into a resumable Zarr store and draws it as a PNG; ``quick``
runs a coarse version (12 points per panel, 20 + 16 periods) for CI.

Limits: the seed's Table 1 was lost and ``sheng2016`` is a stand-in — the MODEL.md §9 set
(preset ``hindawi2021``) calibrated against the landmarks of the seed's text
(docs/reproduction.md) — so the diagrams reproduce the seed's protocol and layout, not its exact
bifurcation points.
"""

from __future__ import annotations

import math
import os
import time
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, TypeVar

import numpy as np

from ..errors import ParameterError
from ..gearset import GearSet
from ..gearset.schema import tex

__all__ = [
    "PAPER_PROTOCOL",
    "PRESET",
    "QUICK_PERIODS",
    "RECIPES",
    "FamilyAxis",
    "Recipe",
    "VaryAxis",
    "reproduce",
    "seed_gearset",
]

#: Gear set every recipe runs on.
PRESET = "sheng2016"


def seed_gearset(gearset: GearSet | None = None) -> GearSet:
    """The gear set a figure of the paper is made for: ``gearset``, by default the
    :data:`PRESET` preset."""
    from ..gearset import preset

    if gearset is None:  # gear-set switch: the paper's figures are of the seed's gear set
        return preset(PRESET)
    return gearset


#: (transient, recorded) mesh periods of the full sweeps: the seed's protocol.
FULL_PERIODS = (100, 100)
#: (transient, recorded) mesh periods of the ``quick`` sweeps.
QUICK_PERIODS = (20, 16)
#: Points per panel of the ``quick`` sweeps.
QUICK_POINTS = 12
#: The seed's own protocol, beside the report's verdicts (``paper_protocol``): every point
#: from the exact zero state (no perturbation: the planets stay in their symmetric subspace),
#: labelled from its 100 + 100-period record alone (no verdict, no λ₁), as the seed did.
PAPER_PROTOCOL: Mapping[str, Any] = MappingProxyType(
    {"verdicts": False, "lyapunov": False, "perturbation": 0.0}
)

_CLEARANCES = ("backlash.sun_planet", "backlash.planet_ring", "clearance.sun_bearing")


def _num(v: float) -> str:
    return f"{v:g}"


@dataclass(frozen=True)
class VaryAxis:
    """The swept parameter: ``count`` (full) or ``quick_count`` linearly spaced values from
    ``start`` to ``stop``, both included."""

    name: str
    start: float
    stop: float
    count: int
    quick_count: int = QUICK_POINTS

    def __post_init__(self) -> None:
        if not (math.isfinite(self.start) and math.isfinite(self.stop) and self.start < self.stop):
            raise ParameterError(
                f"{self.name}: start must be finite and below stop: got {self.start}, {self.stop}"
            )
        for what, n in (("count", self.count), ("quick_count", self.quick_count)):
            if n < 2:
                raise ParameterError(f"{self.name}: {what} must be >= 2: got {n}")

    def values(self, quick: bool = False) -> np.ndarray:
        return np.linspace(self.start, self.stop, self.quick_count if quick else self.count)


@dataclass(frozen=True)
class FamilyAxis:
    """The panel parameter: one bifurcation diagram per value, like the seed's panels (a)–(d)."""

    name: str
    values: tuple[float, ...]


@dataclass(frozen=True)
class Recipe:
    """One bifurcation figure of the seed paper.

    Attributes
    ----------
    name
        ``fig4`` … ``fig12``.
    caption
        The seed's caption, shortened (panel list left out), in plain text.
    vary
        The swept parameter and its range.
    family
        The panel parameter and its values.
    fixed
        Fixed overrides by dotted name (read-only mapping).
    notes
        Where and why the recipe departs from, or interprets, the seed.
    """

    name: str
    caption: str
    vary: VaryAxis
    family: FamilyAxis
    fixed: Mapping[str, float] = field(hash=False)
    notes: str = ""
    transient_periods: int = FULL_PERIODS[0]
    periods: int = FULL_PERIODS[1]
    observe: tuple[str, ...] = field(default=("delta_sp", "delta_sp_dot"))

    def __post_init__(self) -> None:
        object.__setattr__(self, "fixed", MappingProxyType(dict(self.fixed)))

    @property
    def clearance_sweep(self) -> bool:
        """Whether the swept parameter is a backlash or clearance (draw ±b̄ lines)."""
        return self.vary.name in _CLEARANCES

    @property
    def frequency_sweep(self) -> bool:
        """Whether the swept parameter is Ω (mark resonances)."""
        return self.vary.name == "omega"

    def sweep_kwargs(self, quick: bool = False, paper_protocol: bool = False) -> dict[str, Any]:
        """Keyword arguments of :func:`gearchaos.bifurcation` (all but target and store); with
        ``paper_protocol`` the seed's own protocol (:data:`PAPER_PROTOCOL`)."""
        tr, rec = QUICK_PERIODS if quick else (self.transient_periods, self.periods)
        own = dict(PAPER_PROTOCOL) if paper_protocol else {}
        return {
            "vary": {self.vary.name: self.vary.values(quick)},
            "family": {self.family.name: list(self.family.values)},
            "params": dict(self.fixed),
            "observe": self.observe,
            "planets": (1,),
            "initial_conditions": "fresh",
            "transient_periods": tr,
            "periods": rec,
            # the largest Lyapunov exponent decides QP vs chaos in the motion labels that the
            # regime bands, landmarks and conclusions read (about 1.3x the cost)
            "lyapunov": True,
            **own,
        }

    def title(self, quick: bool = False, paper_protocol: bool = False) -> str:
        """Figure title in matplotlib mathtext, built from the recipe's own numbers."""
        number = self.name.removeprefix("fig")
        given = ", ".join(f"${tex(k)} = {_num(v)}$" for k, v in self.fixed.items())
        fam = tex(self.family.name)
        values = ", ".join(_num(v) for v in self.family.values)
        plural = "s" if len(self.family.values) > 1 else ""
        text = (
            f"Fig. {number}: bifurcation diagram{plural} of $\\bar{{X}}_{{sp1}}$ versus "
            f"${tex(self.vary.name)}$\nat {given}, ${fam} = {values}$"
        )
        if quick:
            text += (
                f"\n(quick: {self.vary.quick_count} points per panel, "
                f"{QUICK_PERIODS[0]} + {QUICK_PERIODS[1]} periods)"
            )
        if paper_protocol:
            text += "\n(the seed's protocol: exact zero start, labels from the record alone)"
        return text


def load_figures() -> dict[str, Any]:
    """The seed's figures as data (``figures.toml`` in this package): ``recipe`` and
    ``gallery`` entries, each entry's notes with its section's stand-in note appended."""
    from importlib import resources

    text = resources.files(__package__).joinpath("figures.toml").read_text(encoding="utf-8")
    data = tomllib.loads(text)
    for section, entries in (("recipes", "recipe"), ("galleries", "gallery")):
        stand_in = data[section]["stand_in"]
        for entry in data[entries]:
            own = entry.get("notes", "")
            entry["notes"] = f"{own} {stand_in}" if own else stand_in
    return data


def _recipes() -> dict[str, Recipe]:
    items = [
        Recipe(
            name=d["name"],
            caption=d["caption"],
            vary=VaryAxis(**d["vary"]),
            family=FamilyAxis(d["family"]["name"], tuple(d["family"]["values"])),
            fixed=d["fixed"],
            notes=d["notes"],
        )
        for d in load_figures()["recipe"]
    ]
    return {r.name: r for r in items}


#: The seed's bifurcation figures by name (``fig4``, ``fig6``, ``fig8``, ``fig9``, ``fig11``,
#: ``fig12``).
RECIPES: dict[str, Recipe] = _recipes()


T = TypeVar("T")


def lookup_figure(table: Mapping[str, T], name: Any, what: str) -> T:
    """The entry of ``table`` for a figure name (``fig4``, ``Fig4`` and ``4`` alike)."""
    key = str(name).strip().lower()
    if key.isdigit():
        key = "fig" + key
    try:
        return table[key]
    except KeyError:
        raise ParameterError(f"{what} must be one of {', '.join(table)}: got {name!r}") from None


def get_recipe(name: str) -> Recipe:
    """The recipe called ``name`` (``fig4``, ``Fig4`` and ``4`` alike)."""
    return lookup_figure(RECIPES, name, "figure")


def reproduce(
    name: str,
    outdir: str | os.PathLike[str] = ".",
    *,
    quick: bool = False,
    progress: bool = True,
    workers: int | None = None,
    overwrite: bool = False,
    gearset: GearSet | None = None,
    paper_protocol: bool = False,
) -> dict[str, Any]:
    """Run the sweep of the seed's figure ``name`` and draw it in the seed's layout.

    The sweep goes into ``outdir/<name>.zarr`` (``<name>-quick.zarr`` with ``quick``) through
    :func:`gearchaos.bifurcation`: running again with the same arguments resumes an
    interrupted sweep (nothing already written is recomputed) and a finished one is only
    redrawn. The figure — one panel per family value, ±b̄ clearance lines when a clearance is
    swept, resonance markers when Ω is swept, the caption as title — is written to
    ``outdir/<name>.png`` (``<name>-quick.png``), so a quick run never replaces a full one.

    Parameters
    ----------
    name
        One of :data:`RECIPES` (``fig4``, ``fig6``, ``fig8``, ``fig9``, ``fig11``, ``fig12``).
    outdir
        Directory of the store and the figure (created if missing).
    quick
        Coarse version for CI: 12 points per panel, 20 transient + 16 recorded periods.
    progress
        Show a progress bar.
    workers
        Worker count of the sweep (default: all cores).
    overwrite
        Replace an existing store made with other settings (otherwise refused with a
        :class:`~gearchaos.errors.StoreError`).
    gearset
        The gear set (default: the :data:`PRESET` preset). Its fixed parameters are replaced by
        the recipe's (Ω or ξ and the clearances as the figure sets them).
    paper_protocol
        Run the seed's own protocol instead (:data:`PAPER_PROTOCOL`: exact zero start,
        labels from the record alone, no verdict and no λ₁) into ``<name>-paper.zarr`` and
        ``<name>-paper.png`` (``-quick-paper`` with ``quick``): what the seed's method says,
        beside the verdicts.

    Returns
    -------
    dict
        ``{"figure": PNG path, "store": Zarr path, "points": grid points, "failed": points
        whose status is not OK, "seconds": wall time of the call}``.

    Raises
    ------
    ParameterError
        ``name`` is not a recipe.
    """
    recipe = get_recipe(name)
    from ..plot import savefig
    from ..plot.bifurcation import bifurcation_figure
    from ..sweep import bifurcation

    t0 = time.perf_counter()
    out = Path(os.fspath(outdir))
    out.mkdir(parents=True, exist_ok=True)
    stem = recipe.name + ("-quick" if quick else "") + ("-paper" if paper_protocol else "")
    store = out / f"{stem}.zarr"
    png = out / f"{stem}.png"
    ds = bifurcation(
        seed_gearset(gearset),
        **recipe.sweep_kwargs(quick, paper_protocol),
        store=str(store),
        overwrite=overwrite,
        workers=workers,
        progress=progress,
    )
    fig = bifurcation_figure(
        ds,
        var="delta_sp",
        planet=1,
        clearance_lines=recipe.clearance_sweep,
        resonances=recipe.frequency_sweep,
    )
    fig.suptitle(recipe.title(quick, paper_protocol), fontsize="medium")
    try:
        savefig(fig, png)
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)
    status = np.asarray(ds["status"].values)
    return {
        "figure": str(png),
        "store": str(store),
        "points": int(status.size),
        "failed": int(np.count_nonzero(status != 0)),
        "seconds": time.perf_counter() - t0,
    }
