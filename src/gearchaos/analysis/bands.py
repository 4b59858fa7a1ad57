"""Bands and invariant circles of a section sequence: pure functions of recorded arrays.

A chaotic attractor of the Poincaré map often splits into n *bands*, separate sets that the
section visits in turn (x_k, x_{k+n}, … stay in one band): over the whole sequence the 0–1
test for chaos then sees the regular alternation, not the chaos inside each band, and gives
K ≈ 0. A torus (quasi-periodic motion) meets the section in n closed curves, visited in turn,
on each of which Pⁿ acts as an orientation-preserving circle homeomorphism.

* :func:`band_count` — the number of bands: the largest n ≤ ``max_bands`` such that the
  sequence's subsequences x_{j::n} are separate sets (every point's nearest neighbour lies in its
  own subsequence, and the subsequences' bounding boxes are disjoint in some coordinate or
  their nearest-neighbour test holds for every point).
* :func:`circle_order` — the rotation test of one band: on an invariant circle Pⁿ preserves
  the cyclic order of the points, so the rank of x_{k+1} among the band's points, minus that
  of x_k (mod m), takes (almost) one value — the rotation number times m — whereas on a
  chaotic band the rank shifts spread over all values. The points are ordered by their angle
  about the band's centroid in its two principal directions; a curve that is not star-shaped
  about its centroid fails the test (a false negative: the torus is then not confirmed by this
  test, never a false positive).
* :func:`uniform_return` — the recurrence test, whatever the shape: on an invariant circle
  (conjugate to a rotation by ρ) some shift q brings *every* point back close to itself,
  ‖x_{k+q} − x_k‖ ≤ |h′|·‖qρ‖ for all k, and the best such distance falls like 1/q as the record
  grows; on a chaotic set no shift brings all points back at once (mixing), so the best
  uniform return stays of the order of the set's size.
* :func:`band_tests` — both per band, with the 0–1 test K of every band's subsequence.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .chaos01 import MIN_LENGTH as MIN_LENGTH_01, chaos01

__all__ = ["BandTests", "band_count", "band_tests", "circle_order", "uniform_return"]

#: Fewest points of a band for the rotation test.
MIN_BAND_POINTS = 32


def _standardised(x: np.ndarray) -> np.ndarray:
    """The sequence shifted to its minimum and divided by its largest coordinate range (one
    scale for every column: a component that barely moves, such as a sun centre held by
    symmetry, must not be blown up to the size of the motion)."""
    x = np.asarray(x, dtype=np.float64)
    if x.size == 0:
        return np.zeros((x.shape[0], 1))
    span = float(np.max(np.ptp(x, axis=0)))
    if span <= 1e-12 * max(1.0, float(np.max(np.abs(x)))):
        return np.zeros((x.shape[0], 1))
    return (x - x.min(axis=0)) / span


def _nearest_in_own(z: np.ndarray, n: int) -> float:
    """Fraction of points whose nearest neighbour (another point) has the same index mod n."""
    m = z.shape[0]
    d2 = np.sum((z[:, None, :] - z[None, :, :]) ** 2, axis=-1)
    np.fill_diagonal(d2, np.inf)
    nn = np.argmin(d2, axis=1)
    idx = np.arange(m)
    return float(np.mean((nn % n) == (idx % n)))


def _principal(x: np.ndarray, k: int = 2) -> np.ndarray:
    """The sequence's coordinates along its k principal directions (one scale for all
    columns): the observables that carry its motion, whichever state components they are."""
    z = _standardised(x)
    c = z - z.mean(axis=0)
    if c.shape[1] <= 1:
        return c
    # the eigenvectors of the small d × d scatter matrix (cheaper than an SVD of the m × d
    # sequence), largest eigenvalues first
    _, vecs = np.linalg.eigh(c.T @ c)
    return c @ vecs[:, ::-1][:, : min(k, vecs.shape[1])]


def band_count(x: np.ndarray, max_bands: int = 8, *, max_points: int = 1200) -> int:
    """The number of bands of the section sequence ``x`` (m, d): the largest n ≤
    ``max_bands`` dividing into subsequences x_{j::n} whose points all have their nearest
    neighbour in their own subsequence (at least 16 points each); 1 when none. Only the last
    ``max_points`` points are used (a multiple of every n is not needed: the test is per
    point)."""
    z = _standardised(np.asarray(x)[-max_points:])
    m = z.shape[0]
    best = 1
    for n in range(2, max_bands + 1):
        if m // n < 16:
            break
        if _nearest_in_own(z, n) >= 1.0:
            best = n
    return best


def circle_order(x: np.ndarray) -> float:
    """The rotation test of one band's sequence x (m, d): the largest fraction of rank shifts
    (rank(x_{k+1}) − rank(x_k) mod m, ranks by angle about the centroid in the two principal
    directions) that fall within a window of ±max(1, m/100) around one value. 1 on an
    invariant circle that is star-shaped about its centroid (up to the one point the window
    gains or loses), about 2·max(1, m/100)/m on a set without order. NaN for fewer than
    :data:`MIN_BAND_POINTS` points."""
    z = _standardised(x)
    m = z.shape[0]
    if m < MIN_BAND_POINTS:
        return math.nan
    p = _principal(x)
    if p.shape[1] < 2:
        return math.nan
    ang = np.arctan2(p[:, 1], p[:, 0])
    rank = np.empty(m, dtype=np.int64)
    rank[np.argsort(ang, kind="stable")] = np.arange(m)
    shift = (rank[1:] - rank[:-1]) % m
    w = max(1, m // 100)
    counts = np.bincount(shift, minlength=m).astype(np.float64)
    # circular window sums of width 2w + 1
    ext = np.concatenate([counts[-w:], counts, counts[:w]])
    win = np.convolve(ext, np.ones(2 * w + 1), mode="valid")
    return float(np.max(win) / shift.size)


def uniform_return(x: np.ndarray, max_shift: int | None = None) -> tuple[float, int]:
    """(r, q): the smallest over shifts q ≤ ``max_shift`` (default m/3) of
    max_k ‖x_{k+q} − x_k‖_∞ relative to the set's largest coordinate range, and the shift
    that gives it (see the module docstring: small on an invariant circle, of order one on a
    chaotic set).
    (inf, 0) for fewer than :data:`MIN_BAND_POINTS` points."""
    z = _standardised(x)
    m = z.shape[0]
    if m < MIN_BAND_POINTS:
        return math.inf, 0
    top = max(1, min(m - 1, m // 3 if max_shift is None else int(max_shift)))
    best, arg = math.inf, 0
    for q in range(1, top + 1):
        r = float(np.max(np.abs(z[q:] - z[:-q])))
        if r < best:
            best, arg = r, q
    return best, arg


@dataclass(frozen=True)
class BandTests:
    """The band structure of a section sequence and the tests of each band.

    Attributes
    ----------
    bands
        n, the number of bands (1: one set).
    k01
        The 0–1 test K of each band's subsequence (NaN where too short).
    order
        :func:`circle_order` of each band (NaN where too short).
    """

    bands: int
    k01: tuple[float, ...]
    order: tuple[float, ...]

    def chaotic(self, k_chaos: float) -> bool:
        """Every band's K above ``k_chaos``."""
        return bool(self.k01) and all(math.isfinite(k) and k > k_chaos for k in self.k01)

    def torus(self, k_regular: float, min_order: float) -> bool:
        """Every band an invariant circle: its points in cyclic order (the rotation test at
        ``min_order``) or its 0–1 test below ``k_regular``."""
        return bool(self.k01) and all(
            (math.isfinite(o) and o >= min_order) or (math.isfinite(k) and k < k_regular)
            for k, o in zip(self.k01, self.order, strict=True)
        )

    def text(self) -> str:
        def fmt(v: tuple[float, ...]) -> str:
            return ", ".join(f"{a:.2f}" if math.isfinite(a) else "—" for a in v)

        head = "one band" if self.bands == 1 else f"{self.bands} bands"
        return f"{head}: 0–1 K = {fmt(self.k01)}, rotation order {fmt(self.order)}"


def band_tests(x: np.ndarray, max_bands: int = 8) -> BandTests:
    """:class:`BandTests` of the section sequence x (m, d): its bands (:func:`band_count`),
    and for each band the 0–1 test on its first two columns and the rotation test."""
    x = np.asarray(x, dtype=np.float64)
    n = band_count(x, max_bands)
    ks, orders = [], []
    for j in range(n):
        sub = x[j::n]
        ks.append(chaos01(_principal(sub)) if sub.shape[0] >= MIN_LENGTH_01 else math.nan)
        orders.append(circle_order(sub))
    return BandTests(n, tuple(ks), tuple(orders))
