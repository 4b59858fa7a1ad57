"""Gear sets of the kernel tests: hindawi2021 with n equally spaced planets, optionally with
the rare terms (eccentricities, stiffness harmonics) the default gear sets do not have."""

from __future__ import annotations

import math

import gearchaos as gc

RARE = {
    "eccentricity.sun": 3e-6,
    "eccentricity.planet": 2e-6,
    "eccentricity.ring": 5e-6,
    "stiffness.sun_planet_harmonics": (0.05, -0.02),
    "stiffness.planet_ring_harmonics": (0.03,),
}


def variant_gearset(n: int, rare: bool) -> gc.GearSet:
    """hindawi2021 with n planets (and the rare terms when ``rare``)."""
    base = gc.preset("hindawi2021")
    changes: dict[str, object] = {}
    if n != base.n_planets:
        # the smallest sun from 35 teeth around which n planets of 31 are equally spaced
        # ((z_s + z_r)/N whole) and clear each other ((z_s + z_p)·sin(π/N) > z_p + 2)
        zs = 35
        while (2 * (zs + 31)) % n or (zs + 31) * math.sin(math.pi / n) <= 33:
            zs += 1
        changes = {"geometry.planets": n, "teeth.sun": zs, "teeth.ring": zs + 62}
    if rare:
        changes.update(RARE)
    return base.evolve(changes) if changes else base
