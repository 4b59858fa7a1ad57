"""gearchaos — nonlinear dynamics of geared transmissions with clearances."""

__version__ = "0.1.0"
