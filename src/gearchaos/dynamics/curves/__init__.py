"""Two-parameter boundary curves of a branch's events (stability charts).

:mod:`.boundary` (the front door, :func:`boundary_curve`), :mod:`.tracing` (the method),
:mod:`.defining` (defining test functions and codimension-2 points) and :mod:`.file` (curve
files).
"""

from .boundary import boundary_curve
from .file import open_curve

__all__ = ["boundary_curve", "open_curve"]
