"""The seed paper (Sheng et al. 2016) as code: one recipe per bifurcation figure.

>>> from gearchaos.paper import RECIPES, reproduce
>>> sorted(RECIPES)
['fig11', 'fig12', 'fig4', 'fig6', 'fig8', 'fig9']
>>> reproduce("fig4", "out", quick=True)   # doctest: +SKIP
"""

from .recipes import RECIPES, FamilyAxis, Recipe, VaryAxis, get_recipe, reproduce

__all__ = ["RECIPES", "FamilyAxis", "Recipe", "VaryAxis", "get_recipe", "reproduce"]
