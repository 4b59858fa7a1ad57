"""The seed paper (Sheng et al. 2016) as code: one recipe per bifurcation figure
(:mod:`.recipes`) and per Poincaré gallery (:mod:`.galleries`).

>>> from gearchaos.paper import RECIPES, reproduce
>>> sorted(RECIPES)
['fig11', 'fig12', 'fig4', 'fig6', 'fig8', 'fig9']
>>> reproduce("fig4", "out", quick=True)   # doctest: +SKIP
"""

from .galleries import GALLERIES, Gallery, get_gallery, reproduce_gallery, run_gallery
from .recipes import RECIPES, FamilyAxis, Recipe, VaryAxis, get_recipe, reproduce

__all__ = [
    "GALLERIES",
    "RECIPES",
    "FamilyAxis",
    "Gallery",
    "Recipe",
    "VaryAxis",
    "get_gallery",
    "get_recipe",
    "reproduce",
    "reproduce_gallery",
    "run_gallery",
]
