"""The 0–1 test for chaos (Gottwald & Melbourne) on a scalar or vector sequence.

The test needs no phase-space reconstruction and no Lyapunov exponent: it drives a planar
"translation" by the observable and asks whether it wanders like a Brownian motion (chaos,
K ≈ 1) or stays bounded (regular motion, periodic or quasi-periodic, K ≈ 0). Applied here to
the Poincaré section sequence of an orbit, it is the independent confirmation of the largest
Lyapunov exponent that :mod:`gearchaos.analysis.classify` uses to tell quasi-periodic from
chaotic motion.

References
----------
G. A. Gottwald and I. Melbourne, "A new test for chaos in deterministic systems",
Proc. R. Soc. Lond. A 460 (2004) 603–611.

G. A. Gottwald and I. Melbourne, "On the implementation of the 0–1 test for chaos",
SIAM J. Appl. Dyn. Syst. 8 (2009) 129–145.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np
import scipy.fft as sp_fft

from ..errors import ParameterError

__all__ = ["MIN_LENGTH", "chaos01", "chaos01_components"]

#: Shortest series the test accepts (with ``ncut = N/10`` this leaves 10 lags to correlate).
MIN_LENGTH = 100

#: Interval of the random frequencies c, away from the resonances c = 0 and c = π.
C_RANGE = (math.pi / 5.0, 4.0 * math.pi / 5.0)


def _validate(series: Any, n_c: Any, ncut: Any) -> tuple[np.ndarray, int]:
    phi = np.asarray(series, dtype=np.float64)
    if phi.ndim == 1:
        phi = phi[:, None]
    elif phi.ndim != 2:
        raise ParameterError(f"series must have shape (N,) or (N, d): got shape {phi.shape}")
    N = phi.shape[0]
    if N < MIN_LENGTH:
        raise ParameterError(
            f"series must have at least {MIN_LENGTH} samples for the 0–1 test: got {N}"
        )
    if phi.shape[1] == 0:
        raise ParameterError(f"series must have at least one column: got shape {phi.shape}")
    if not np.all(np.isfinite(phi)):
        raise ParameterError("series must be finite: got NaN or inf values")
    if not (isinstance(n_c, int | np.integer) and not isinstance(n_c, bool) and n_c >= 1):
        raise ParameterError(f"n_c must be an integer >= 1: got {n_c!r}")
    if ncut is None:
        ncut = N // 10
    if not (
        isinstance(ncut, int | np.integer) and not isinstance(ncut, bool) and 2 <= ncut <= N - 1
    ):
        raise ParameterError(f"ncut must be an integer in 2..{N - 1} (N − 1): got {ncut!r}")
    return phi, int(ncut)


#: Largest N·ncut for which M_c is summed directly (compiled, O(N ncut) per c and column);
#: longer series use the FFT autocorrelation (O(N log N)). A sweep's 100 sections with
#: ncut = 10 take the direct path, about ten times faster than the FFT one with its numpy
#: call overheads (the 0–1 test was 85 % of a sweep's classification, issue 13).
DIRECT_MAX_WORK = 100_000


def _k_values(phi: np.ndarray, c: np.ndarray, ncut: int) -> np.ndarray:
    """K_c for observables φ (shape (N, d)) and every frequency in ``c``: shape (n_c, d)."""
    if phi.shape[0] * ncut <= DIRECT_MAX_WORK:
        return np.asarray(_k_values_direct(np.ascontiguousarray(phi), c, ncut))
    return _k_values_fft(phi, c, ncut)


@numba.njit(cache=True)
def _k_values_direct(phi, c, ncut):  # pragma: no cover - compiled
    """:func:`_k_values` from the sums of the definition (the docstring of :func:`chaos01`)."""
    N, d = phi.shape
    K = np.zeros((c.size, d))
    cs = np.empty(N)
    sn = np.empty(N)
    zr = np.empty(N)
    zi = np.empty(N)
    D = np.empty(ncut)
    nbar = 0.5 * (ncut + 1)
    sxx = 0.0
    for m in range(1, ncut + 1):
        sxx += (m - nbar) ** 2
    for a in range(c.size):
        # e^{ijc} by repeated rotation (drift ~ j·1e-16, negligible for N ≤ DIRECT_MAX_WORK)
        c1 = math.cos(c[a])
        s1 = math.sin(c[a])
        cs[0] = c1
        sn[0] = s1
        for j in range(1, N):
            cs[j] = cs[j - 1] * c1 - sn[j - 1] * s1
            sn[j] = sn[j - 1] * c1 + cs[j - 1] * s1
        for col in range(d):
            mean = 0.0
            for j in range(N):
                mean += phi[j, col]
            mean /= N
            # z(n) = Σ_{j≤n} φ(j) e^{ijc}, shifted by its mean (M_c is invariant to a shift)
            pr = 0.0
            pi = 0.0
            for j in range(N):
                pr += phi[j, col] * cs[j]
                pi += phi[j, col] * sn[j]
                zr[j] = pr
                zi[j] = pi
            mr = 0.0
            mi = 0.0
            for j in range(N):
                mr += zr[j]
                mi += zi[j]
            mr /= N
            mi /= N
            for j in range(N):
                zr[j] -= mr
                zi[j] -= mi
            dbar = 0.0
            for m in range(1, ncut + 1):
                acc = 0.0
                for j in range(N - m):
                    dr = zr[j + m] - zr[j]
                    di = zi[j + m] - zi[j]
                    acc += dr * dr + di * di
                vosc = mean * mean * (1.0 - math.cos(m * c[a])) / (1.0 - math.cos(c[a]))
                D[m - 1] = acc / (N - m) - vosc
                dbar += D[m - 1]
            dbar /= ncut
            sxy = 0.0
            syy = 0.0
            for m in range(1, ncut + 1):
                sxy += (m - nbar) * (D[m - 1] - dbar)
                syy += (D[m - 1] - dbar) ** 2
            den = math.sqrt(sxx * syy)
            K[a, col] = sxy / den if den > 0.0 else 0.0
    return K


def _k_values_fft(phi: np.ndarray, c: np.ndarray, ncut: int) -> np.ndarray:
    """:func:`_k_values` by FFT autocorrelation, for long series."""
    N = phi.shape[0]
    j = np.arange(1, N + 1, dtype=np.float64)
    rot = np.exp(1j * c[:, None] * j[None, :])  # e^{i j c}, shape (n_c, N)
    # translation variables z_c(n) = p_c(n) + i q_c(n) = Σ_{j≤n} φ(j) e^{i j c}: (n_c, d, N)
    z = np.cumsum(rot[:, None, :] * phi.T[None, :, :], axis=2)
    z -= z.mean(axis=2, keepdims=True)  # M_c is invariant to a shift of z; this limits round-off
    # Σ_{j=1}^{N-n} |z(j+n) − z(j)|² = Σ_{j>n}|z_j|² + Σ_{j≤N-n}|z_j|² − 2 Re Σ_j z(j+n) z̄(j)
    cs = np.cumsum(z.real**2 + z.imag**2, axis=2)
    n = np.arange(1, ncut + 1)
    head = cs[..., N - 1 - n]  # Σ_{j=1}^{N-n} |z_j|²
    tail = cs[..., -1:] - cs[..., n - 1]  # Σ_{j=n+1}^{N} |z_j|²
    F = sp_fft.fft(z, sp_fft.next_fast_len(2 * N - 1), axis=2)
    corr = sp_fft.ifft(F.real**2 + F.imag**2, axis=2)[..., 1 : ncut + 1].real
    M = (head + tail - 2.0 * corr) / (N - n)
    # oscillatory term of the mean, V_osc(c, n) = (Eφ)² (1 − cos nc)/(1 − cos c)
    mean = phi.mean(axis=0)
    shape = (1.0 - np.cos(np.outer(c, n))) / (1.0 - np.cos(c))[:, None]  # (n_c, ncut)
    D = M - (mean**2)[None, :, None] * shape[:, None, :]
    # K_c = corr(n, D_c(n)), n = 1 … ncut
    nc = n - n.mean()
    Dc = D - D.mean(axis=2, keepdims=True)
    den = np.sqrt(np.sum(nc * nc) * np.sum(Dc * Dc, axis=2))
    with np.errstate(invalid="ignore", divide="ignore"):
        k = (Dc @ nc) / den
    return np.where(den > 0, k, 0.0)


def chaos01_components(
    series: Any, *, n_c: int = 100, seed: int = 0, ncut: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The frequencies c and the values K_c behind :func:`chaos01`.

    Returns ``(c, K)``: ``c`` of shape (n_c,), ``K`` of shape (n_c, d) (one column per column
    of the series). Useful to look for resonant c (isolated large K_c in a regular series).
    """
    phi, ncut = _validate(series, n_c, ncut)
    rng = np.random.default_rng(seed)
    c = rng.uniform(C_RANGE[0], C_RANGE[1], int(n_c))
    # a constant observable (to round-off) is a fixed point: regular, K_c = 0
    const = np.ptp(phi, axis=0) <= 8.0 * np.finfo(np.float64).eps * np.max(np.abs(phi), axis=0)
    K = np.zeros((c.size, phi.shape[1]))
    if not np.all(const):
        K[:, ~const] = _k_values(phi[:, ~const], c, ncut)
    return c, K


def chaos01(series: Any, *, n_c: int = 100, seed: int = 0, ncut: int | None = None) -> float:
    """0–1 test for chaos: K ≈ 0 for regular, K ≈ 1 for chaotic dynamics.

    Parameters
    ----------
    series
        Observable φ(j), j = 1 … N, sampled once per forcing period (a Poincaré section
        sequence), shape (N,); or (N, d) for d observables (e.g. X̄_sp1 and X̄'_sp1), whose
        K_c values are pooled before the median. N ≥ 100 (:data:`MIN_LENGTH`), all finite.
    n_c
        Number of random frequencies c drawn uniformly from (π/5, 4π/5).
    seed
        Seed of the random frequencies (:func:`numpy.random.default_rng`); the result is
        deterministic for a given seed.
    ncut
        Largest lag n of the mean-square displacement; default N/10 (integer part), as
        recommended by Gottwald & Melbourne (2009).

    Returns
    -------
    float
        K = median over c (and over the columns) of K_c, in [−1, 1]; values near 1 mean chaos,
        near 0 regular motion.

    Notes
    -----
    For each c the observable drives the translation variables

        p_c(n) = Σ_{j=1}^{n} φ(j) cos(jc),   q_c(n) = Σ_{j=1}^{n} φ(j) sin(jc),

    whose mean-square displacement, averaged over the N − n available starting points,

        M_c(n) = 1/(N−n) Σ_{j=1}^{N−n} [p_c(j+n) − p_c(j)]² + [q_c(j+n) − q_c(j)]²,

    stays bounded for regular dynamics and grows linearly in n for chaotic dynamics. The
    modified mean-square displacement removes the bounded oscillation that a non-zero mean of
    φ contributes and that slows convergence (Gottwald & Melbourne 2009, eq. 2.5):

        D_c(n) = M_c(n) − V_osc(c, n),   V_osc(c, n) = (Eφ)² (1 − cos nc)/(1 − cos c),

    with Eφ the mean of φ. The growth rate is measured by the correlation method,
    K_c = corr(ξ, Δ) with ξ = (1, …, ncut) and Δ = (D_c(1), …, D_c(ncut)), and
    K = median_c K_c; the median discards the few c that resonate with a frequency of a
    regular orbit (where p_c, q_c grow linearly and K_c ≈ 1). M_c is summed directly for short
    series (N·ncut ≤ :data:`DIRECT_MAX_WORK`, compiled) and by FFT autocorrelation for long
    ones, O(n_c d N log N).

    Limits: the test measures the growth of D_c, so a regular sequence contaminated by noise
    tends to K ≈ 1 as N grows (the noise drives a random walk); detect periodicity first
    (:func:`~gearchaos.analysis.periodicity.detect_period`), as the classifier does. A
    constant column (a fixed point) gives K_c = 0. A transient that has not decayed biases K
    upward. Sample once per forcing period: an oversampled flow gives K ≈ 0 whatever the
    dynamics (Gottwald & Melbourne 2009, §4).
    """
    _, K = chaos01_components(series, n_c=n_c, seed=seed, ncut=ncut)
    return float(np.median(K))
