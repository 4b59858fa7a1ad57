"""Spectral indicator of chaos: are the lines of a spectrum discrete, or is it broadband?

:func:`spectral_broadband` is one of the independent indicators that
:func:`~gearchaos.analysis.classify.classify_motion` uses to confirm a motion label.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import ParameterError

__all__ = ["spectral_broadband"]


def spectral_broadband(
    x: Any,
    *,
    prominence: float = 100.0,
    half_width: int = 3,
    threshold: float = 0.99,
) -> tuple[bool, float]:
    """Discrete spectral lines or a broadband spectrum? Returns ``(broadband, peak_fraction)``.

    Parameters
    ----------
    x
        A Poincaré section sequence or a uniformly sampled time history, shape (N,) or (N, d),
        N ≥ 16, finite. The section sequence is the better input: it removes the lines of the
        forcing and its harmonics, which dominate a time history even when the motion is
        chaotic.
    prominence
        A local maximum of the power spectrum is a line when its power exceeds ``prominence``
        times the median power (the spectral floor). Default 100 (20 dB): the periodogram of a
        broadband signal fluctuates exponentially about its mean, so a bin of white noise
        exceeds 100 × its median with probability e^{−100 ln 2} ≈ 10⁻³⁰.
    half_width
        Each line owns its bin ± ``half_width`` bins (the Hann window's main lobe is ± 2 bins
        about the true frequency, which lies within half a bin of the peak bin).
    threshold
        ``broadband`` is True when ``peak_fraction < threshold``, i.e. when more than
        1 − threshold (default 1 %) of the power lies outside the lines. A quasi-periodic
        sequence has all its power in the lines mα mod 1 of its rotation number α and their
        harmonics (the Hann window leaks < 10⁻³ of a line's power outside ± 3 bins); a
        chaotic one keeps a broadband part even when it is made of thin bands whose band
        structure puts 95–99 % of the power into a few lines.

    Returns
    -------
    broadband : bool
        True for a broadband (chaotic) spectrum, False for discrete lines (periodic or
        quasi-periodic). False for a constant signal.
    peak_fraction : float
        Fraction of the fluctuating power (mean removed, DC bin excluded) inside the lines;
        NaN for a constant signal.

    Notes
    -----
    Each column is demeaned, multiplied by a Hann window and transformed (``rfft``); the
    power spectra of the columns, each normalised to unit total, are summed so that every
    observable weighs the same. Noise in a regular signal (integration error at 10⁻⁶ of the
    amplitude) adds a broadband part of order 10⁻¹² of the power, far below the threshold.
    Resolution limits: two incommensurate lines closer than ~4 bins merge (harmless), and a
    chaotic attractor of very thin bands (broadband part < 1 %) reads as lines.
    """
    a = np.asarray(x, dtype=np.float64)
    if a.ndim == 1:
        a = a[:, None]
    elif a.ndim != 2:
        raise ParameterError(f"x must have shape (N,) or (N, d): got shape {a.shape}")
    if a.shape[0] < 16 or a.shape[1] == 0:
        raise ParameterError(f"x must have at least 16 samples and 1 column: got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ParameterError("x must be finite: got NaN or inf values")
    if not (math.isfinite(prominence) and prominence >= 1):
        raise ParameterError(f"prominence must be a finite number >= 1: got {prominence!r}")
    if not (isinstance(half_width, int | np.integer) and half_width >= 0):
        raise ParameterError(f"half_width must be an integer >= 0: got {half_width!r}")
    if not (math.isfinite(threshold) and 0 < threshold <= 1):
        raise ParameterError(f"threshold must be a number in (0, 1]: got {threshold!r}")
    scale = np.max(np.abs(a), axis=0)
    a = a - a.mean(axis=0)
    window = np.hanning(a.shape[0])[:, None]
    power = np.abs(np.fft.rfft(a * window, axis=0)[1:]) ** 2
    totals = power.sum(axis=0)
    # a column constant to round-off (fluctuation ≲ 1e-12 of its magnitude) carries no spectrum
    live = totals > (1e-24 * a.shape[0]) * np.maximum(scale, np.finfo(np.float64).tiny) ** 2
    if not np.any(live):
        return False, math.nan
    P = np.sum(power[:, live] / totals[live], axis=1)
    floor = float(np.median(P))
    left = np.concatenate([[-np.inf], P[:-1]])
    right = np.concatenate([P[1:], [-np.inf]])
    lines = np.flatnonzero((P >= left) & (P >= right) & (P > prominence * floor))
    mask = np.zeros(P.size, dtype=bool)
    for i in lines:
        mask[max(0, i - half_width) : i + half_width + 1] = True
    fraction = float(P[mask].sum() / P.sum())
    return bool(fraction < threshold), fraction
