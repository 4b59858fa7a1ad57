"""Attractors and their basins: :mod:`.coexistence` (coexisting attractors at one operating
point, from several starts) and :mod:`.basins` (which attractor each start of a grid reaches).
"""

from .coexistence import Attractor, attractors

__all__ = ["Attractor", "attractors"]
