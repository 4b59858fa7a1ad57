"""Contact regimes along a 1-D sweep: the ranges of the swept parameter in which each mesh
keeps, loses or reverses its drive-flank contact.

Every sweep store of a gear set holds, per point, mesh and planet, the contact regime over the
recorded window (``contact_sp``, ``contact_rp``; MODEL.md §8, :mod:`gearchaos.analysis.contact`:
``none`` — the drive flanks never part, ``single_sided`` — the teeth separate and meet again
on the drive flank (rattle), ``double_sided`` — they also hit the back flank), and a response
store (:func:`gearchaos.response`) the peak contact force of every mesh and planet
(``force_peak_sp``, ``force_peak_rp``, in k_m,sp b_c). :func:`contact_ranges` cuts the swept
axis, per mesh and sweep direction, into maximal runs of neighbouring points whose planets are
in the same regimes, with the largest peak contact force of each run: the table that answers
"from which speed does this gearbox rattle, and how hard?".
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..analysis.contact import REGIMES
from ..errors import ParameterError
from .result import SweepResult

__all__ = ["CONTACT_MESHES", "ContactRange", "contact_ranges", "contact_variable", "regime_words"]

#: The meshes of a gear-set store: key of its variables → name.
CONTACT_MESHES: Mapping[str, str] = {"sp": "sun_planet", "rp": "planet_ring"}
#: Regime of each stored code (−1: the point failed, so no regime is known).
CODE_REGIME: Mapping[int, str] = {-1: "unknown", 0: REGIMES[0], 1: REGIMES[1], 2: REGIMES[2]}
_EXPECTED_MEANINGS = ["unknown", *REGIMES]


@dataclass(frozen=True)
class ContactRange:
    """A maximal run of neighbouring swept values over which every planet of one mesh stays in
    one contact regime.

    Attributes
    ----------
    mesh
        ``sun_planet`` or ``planet_ring``.
    direction
        ``up`` or ``down`` for a continuation sweep in both directions, else ``None``.
    regimes
        The regime of each planet (``planets`` order): ``none``, ``single_sided``,
        ``double_sided`` or ``unknown`` (a failed point).
    planets
        The planet numbers.
    start, stop
        The first and the last swept value of the run (in increasing order).
    points
        How many swept values the run holds.
    peak_force
        The largest peak contact force of the mesh over the run's points and planets, in
        k_m,sp b_c; ``None`` where the store holds no forces (a sweep that is not a response).
    """

    mesh: str
    direction: str | None
    regimes: tuple[str, ...]
    planets: tuple[int, ...]
    start: float
    stop: float
    points: int
    peak_force: float | None = None

    @property
    def regime(self) -> str:
        """The most severe regime of the planets (``unknown`` only when every one is)."""
        known = [r for r in self.regimes if r in REGIMES]
        return max(known, key=REGIMES.index) if known else "unknown"

    @property
    def uniform(self) -> bool:
        """Whether every planet is in the same regime."""
        return len(set(self.regimes)) == 1

    def describe(self) -> str:
        """The regime in words: ``single-sided``, or per planet where they differ
        (``single-sided: planets 1, 3; none: 2, 4``, ``double-sided: planet 2; none: 1, 3``)."""
        if self.uniform:
            return regime_words(self.regimes[0])
        parts: list[str] = []
        for regime in sorted(set(self.regimes), key=_severity, reverse=True):
            who = [str(p) for p, r in zip(self.planets, self.regimes, strict=True) if r == regime]
            prefix = ("planet " if len(who) == 1 else "planets ") if not parts else ""
            parts.append(f"{regime_words(regime)}: {prefix}{', '.join(who)}")
        return "; ".join(parts)


def _severity(regime: str) -> int:
    return REGIMES.index(regime) if regime in REGIMES else -1


def regime_words(regime: str) -> str:
    """``single_sided`` → ``single-sided``, ``none`` → ``none`` …"""
    return regime.replace("_", "-")


def contact_variable(res: SweepResult, key: str) -> Any:
    """The stored contact codes of mesh ``key`` (``sp`` or ``rp``), checked: a DataArray over
    the swept dimensions and ``planet_all``."""
    name = f"contact_{key}"
    ds = res.ds
    if name not in ds.data_vars:
        raise ParameterError(
            f"the store has no contact regimes ({name}): contact ranges need a classified sweep "
            "of a gear set (gearchaos bifurcation or response; older stores after gearchaos "
            "classify STORE)"
        )
    meanings = str(ds[name].attrs.get("flag_meanings", "")).split()
    values = [int(v) for v in np.ravel(ds[name].attrs.get("flag_values", []))]
    if meanings and (meanings != _EXPECTED_MEANINGS or values != [-1, 0, 1, 2]):
        raise ParameterError(
            f"{name} must have flag_values [-1, 0, 1, 2] meaning {' '.join(_EXPECTED_MEANINGS)}:"
            f" got {values} meaning {' '.join(meanings)}"
        )
    return ds[name]


def _runs(rows: list[tuple[str, ...]]) -> list[tuple[int, int]]:
    """Maximal runs [i, j) of equal neighbours."""
    out, start = [], 0
    for i in range(1, len(rows) + 1):
        if i == len(rows) or rows[i] != rows[start]:
            out.append((start, i))
            start = i
    return out


def contact_ranges(ds: Any, *, select: Mapping[str, Any] | None = None) -> list[ContactRange]:
    """The contact regime of every mesh along a 1-D sweep, as ranges of the swept parameter.

    Parameters
    ----------
    ds
        A sweep store or dataset of a gear set with one swept parameter left after ``select``
        (:func:`gearchaos.bifurcation`, :func:`gearchaos.response`), or its
        :class:`~gearchaos.sweep.SweepResult`. A ``direction`` dimension (continuation up and
        down) gives the ranges of each direction.
    select
        Values of the other swept dimensions (a family value), as for
        :func:`~gearchaos.plot.bifurcation`.

    Returns
    -------
    list of ContactRange
        Sun–planet meshes first, then planet–ring; per mesh the directions in store order
        (``up``, ``down``), each cut into maximal runs of neighbouring swept values (in
        increasing order) whose planets keep their regimes; with the run's largest peak
        contact force where the store holds forces (``force_peak_sp``/``_rp``).
    """
    res = SweepResult.of(ds).select(select)
    sub = res.ds
    x_name = res.line_axis("contact ranges", "contact_sp" if "contact_sp" in sub else None)
    x = np.asarray(sub[x_name].values, dtype=np.float64)
    order = np.argsort(x, kind="stable")
    directions = res.layout().directions
    out: list[ContactRange] = []
    for key, mesh in CONTACT_MESHES.items():
        codes = contact_variable(res, key)
        planets = tuple(int(p) for p in np.asarray(sub["planet_all"].values))
        force = sub.get(f"force_peak_{key}")
        for direction in directions or (None,):
            pick = {} if direction is None else {"direction": direction}
            c = np.asarray(codes.sel(pick).transpose(x_name, "planet_all").values)[order]
            rows = [tuple(CODE_REGIME.get(int(v), "unknown") for v in row) for row in c]
            f = None
            if force is not None:
                fa = force.sel(pick)
                dims = (x_name, "planet_all") if "planet_all" in fa.dims else (x_name,)
                f = np.asarray(fa.transpose(*dims).values, dtype=np.float64)[order]
                f = f.reshape(len(x), -1)
            for i, j in _runs(rows):
                peak = None
                if f is not None:
                    chunk = f[i:j]
                    peak = float(np.nanmax(chunk)) if np.isfinite(chunk).any() else None
                out.append(
                    ContactRange(
                        mesh=mesh,
                        direction=direction,
                        regimes=rows[i],
                        planets=planets,
                        start=float(x[order][i]),
                        stop=float(x[order][j - 1]),
                        points=j - i,
                        peak_force=peak,
                    )
                )
    if not out:
        raise ParameterError(f"contact ranges need swept values: {x_name} has none")
    return out
