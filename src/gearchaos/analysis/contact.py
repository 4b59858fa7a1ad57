"""Contact (impact) regimes of the meshes with backlash (MODEL.md §8).

With half clearance b the mesh deflection δ decides the state of a tooth pair: drive flanks in
contact (δ > b), teeth apart in the gap (|δ| ≤ b), back flanks in contact (δ < −b). Over the
steady (recorded) window each mesh is in one of three regimes, decided by the minimum of δ:

=================  ====================  =================================================
regime             condition             meaning
=================  ====================  =================================================
``none``           δ_min > b             no separation: the drive flanks never part
``single_sided``   −b ≤ δ_min ≤ b        the teeth separate but never reach the back flank
``double_sided``   δ_min < −b            back-flank contact (double-sided impact)
=================  ====================  =================================================

The minimum is the one the integrator tracks inside every accepted step (refined by cubic
Hermite interpolation), so it does not depend on ``samples_per_period``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import ParameterError

__all__ = [
    "REGIMES",
    "contact_fractions",
    "contact_regime",
    "contact_regimes",
    "mesh_deflections",
    "separation_fraction",
]

#: The contact regimes, from mildest to strongest.
REGIMES = ("none", "single_sided", "double_sided")


def contact_regime(delta_min: float, b: float) -> str:
    """Contact regime of one mesh from the minimum deflection δ_min and half clearance b.

    Returns ``none`` (δ_min > b), ``single_sided`` (−b ≤ δ_min ≤ b) or ``double_sided``
    (δ_min < −b); ``unknown`` when δ_min is NaN (the integration failed before recording).
    """
    b = float(b)
    if not (math.isfinite(b) and b >= 0):
        raise ParameterError(f"b (half clearance) must be a finite number >= 0: got {b!r}")
    d = float(delta_min)
    if math.isnan(d):
        return "unknown"
    if d > b:
        return "none"
    if d >= -b:
        return "single_sided"
    return "double_sided"


def mesh_deflections(result: Any) -> dict[str, tuple[str, int, float]]:
    """Meshes of a result: name → (deflection variable, tracked index, half clearance).

    The model's mesh :attr:`~gearchaos.model.System.contacts`: planetary results give
    ``sun_planet_1..N`` then ``planet_ring_1..N``; the single-mesh backlash oscillator gives
    ``mesh``. Systems without a mesh raise :class:`~gearchaos.errors.ParameterError`.
    """
    system = result.system
    names = system.obs_names
    out = {
        c.name: (names[c.column], c.column, float(c.clearance))
        for c in system.contacts
        if c.kind == "mesh"
    }
    if not out:
        raise ParameterError(
            f"contact regimes need a model with gear meshes (its contacts): got {system.name}"
        )
    return out


def contact_regimes(result: Any) -> dict[str, str]:
    """Contact regime of every mesh over the recorded window (see the module docstring).

    Keys ``sun_planet_1..N``, ``planet_ring_1..N`` in that order for planetary results,
    ``mesh`` for the backlash oscillator; values from :data:`REGIMES` (or ``unknown``).
    """
    return {
        mesh: contact_regime(result.obs_min[k], b)
        for mesh, (_, k, b) in mesh_deflections(result).items()
    }


def contact_fractions(result: Any) -> dict[str, dict[str, float]]:
    """Fraction of the recorded samples spent in each contact state, per mesh.

    For every mesh a dict with ``drive`` (δ > b, drive flanks in contact), ``gap``
    (|δ| ≤ b, teeth apart) and ``back`` (δ < −b, back flanks in contact), counted over the
    finite samples at ``tau`` (``samples_per_period`` per period); NaN when no sample is
    finite. Being sampled, these fractions can miss short impacts that
    :func:`contact_regimes` (exact extrema) sees.
    """
    out: dict[str, dict[str, float]] = {}
    for mesh, (name, _, b) in mesh_deflections(result).items():
        d = np.asarray(result.series(name), dtype=np.float64)
        d = d[np.isfinite(d)]
        if d.size == 0:
            out[mesh] = {"drive": math.nan, "gap": math.nan, "back": math.nan}
            continue
        back = float(np.mean(d < -b))
        drive = float(np.mean(d > b))
        out[mesh] = {"drive": drive, "gap": 1.0 - drive - back, "back": back}
    return out


def separation_fraction(result: Any) -> dict[str, float]:
    """Fraction of the recorded samples in which each mesh has lost drive-flank contact.

    Separation means δ ≤ b: the drive flanks are apart, whether the teeth float in the gap
    (|δ| ≤ b) or have crossed it to the back flank (δ < −b). Equals
    ``gap + back`` of :func:`contact_fractions`; sampled, so use ``samples_per_period`` ≫ 1.
    """
    return {mesh: f["gap"] + f["back"] for mesh, f in contact_fractions(result).items()}
