"""The package version and the provenance attributes every result file carries.

A leaf module (no imports from the package), so that any layer can stamp its results without
importing the package top.
"""

from __future__ import annotations

__version__ = "0.1.0"

__all__ = ["__version__", "provenance"]


def provenance() -> dict[str, str]:
    """Versions of gearchaos and of the numerical libraries, for result attributes."""
    import numba
    import numpy
    import scipy

    return {
        "version": __version__,
        "numba_version": numba.__version__,
        "numpy_version": numpy.__version__,
        "scipy_version": scipy.__version__,
    }
