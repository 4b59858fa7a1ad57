"""Explore a sweep store in the browser: ``gearchaos explore RUN.zarr`` or, in a notebook,
``gearchaos.explore(store)``.

A local web app (Panel on Bokeh) shows the store's bifurcation diagram with its band of motion
labels (or the regime map of a 2-D sweep). A click, or the slider along the swept axis, selects
the nearest swept point and shows its stored Poincaré section, motion label and λ₁ at once;
its phase portrait, time histories of X̄ and of the contact force, spectrum with the mesh
harmonics h f_m labelled, recomputed λ₁ and, for an nT orbit, Floquet multipliers are computed
in a worker process, cached per point, while a spinner turns. A box zoom and *Finer sweep*
run a resumable sweep of the shown range into a sibling store ``<RUN>.zoom/…zarr``, which the
page then shows.

The module is callable: ``gearchaos.explore(store)`` is :func:`explore`.
"""

import sys
import types
from typing import Any

from .app import Explorer, Workers, explore
from .compute import compute_point, run_zoom, zoom_path
from .model import ExploreModel, Point
from .server import serve

__all__ = [
    "ExploreModel",
    "Explorer",
    "Point",
    "Workers",
    "compute_point",
    "explore",
    "run_zoom",
    "serve",
    "zoom_path",
]


class _CallableModule(types.ModuleType):
    """``gearchaos.explore`` is this package and, called, :func:`explore` (a package and a
    function cannot otherwise share the name ``gearchaos.explore``)."""

    def __call__(self, store: Any, **kwargs: Any) -> Explorer:
        return explore(store, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
