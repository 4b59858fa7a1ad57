"""Orbits with a known answer, shared by the chaos-indicator tests: the logistic map at r = 4
and the Hénon map (chaotic), an irrational rotation (quasi-periodic)."""

from __future__ import annotations

import math

import numpy as np

GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def logistic(n: int, r: float = 4.0, x: float = 0.1234, skip: int = 100) -> np.ndarray:
    out = np.empty(n)
    for i in range(n + skip):
        x = r * x * (1.0 - x)
        if i >= skip:
            out[i - skip] = x
    return out


def henon(n: int, a: float = 1.4, b: float = 0.3, skip: int = 100) -> np.ndarray:
    x, y = 0.1, 0.1
    out = np.empty((n, 2))
    for i in range(n + skip):
        x, y = 1.0 - a * x * x + y, b * x
        if i >= skip:
            out[i - skip] = (x, y)
    return out


def rotation(n: int, alpha: float = GOLDEN) -> np.ndarray:
    k = np.arange(n)
    return np.column_stack([np.cos(2 * math.pi * k * alpha), np.sin(2 * math.pi * k * alpha)])
