"""Time histories and amplitude spectra of simulation results."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import ParameterError
from ._common import (
    clearance_lines,
    frequency_axis,
    get_ax,
    has_physical_scales,
    omega_times,
    period_axis_label,
    period_name,
    sample_window,
    to_periods,
    variable,
)
from .units import (
    PhysicalScales,
    clearance_notes,
    fit_to_data,
    linear_axis,
    secondary_axis,
    section_points,
)

#: ``gid`` of the mesh-harmonic labels and sideband lines of a spectrum.
HARMONIC_GID = "mesh-harmonic"

__all__ = ["amplitude_spectrum", "mesh_force_history", "spectrum", "time_history"]


def time_history(
    result: Any,
    var: str | None = None,
    planet: int = 1,
    ax: Any = None,
    periods: float | None = None,
    *,
    physical: bool = True,
) -> Any:
    """Plot a variable against time in mesh (forcing) periods, t/T_m = τΩ/2π.

    Parameters
    ----------
    result
        A :class:`~gearchaos.SimulationResult`; use ``samples_per_period`` ≫ 1 for a smooth
        curve (with one sample per period only the section points are drawn).
    var, planet
        The variable: for planetary results ``delta_sp`` (default, X̄_spi), ``delta_rp``,
        ``force_sp``, ``force_rp``, ``p`` of ``planet``, or ``x_s``, ``y_s``, ``sigma``; for
        other systems a state or observable name (default: the first state, e.g. ``x``).
    ax
        Axes to draw on (default: a new figure).
    periods
        Show only the last ``periods`` recorded periods (default: all).

    physical
        Physical axes opposite the dimensionless ones (time in ms; µm, mm/s or N), for gear
        sets.

    Returns
    -------
    matplotlib.axes.Axes
        Limits follow the data; dashed lines at ±b̄ for variables with a clearance where they
        fall inside (an edge note where not), dots at the Poincaré section times.
    """
    info = variable(result, var, planet)
    ax = get_ax(ax)
    sl = sample_window(result, periods)
    s = result.samples_per_period
    t = to_periods(result, result.tau)
    y = np.asarray(result.series(info.name))
    if s > 1:
        ax.plot(t[sl], y[sl], lw=0.8, color="C0", label=f"${info.symbol}$")
    idx = np.arange(result.tau.size)[sl]
    sec = idx[idx % s == 0]
    section_points(ax, t[sec], y[sec])
    clearance_lines(ax, info)
    ax.set_xlabel(period_axis_label(result))
    ax.set_ylabel(info.label)
    fit_to_data(ax, None, y[sl])
    if info.clearance is not None:
        clearance_notes(ax, "y", (-info.clearance, info.clearance), info.clearance_symbol or "b")
    if physical:
        scales = PhysicalScales.of_result(result)
        secondary_axis(ax, "y", scales.quantity(info.name), scales)
        ms = scales.period_ms(result.system.omega)
        if ms is not None:
            linear_axis(ax, "x", ms, "t [ms]")
    return ax


def _spans(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) indices of the runs of True in ``mask``."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    d = np.diff(m.astype(np.int8))
    return list(zip(np.nonzero(d == 1)[0], np.nonzero(d == -1)[0] - 1, strict=True))


def mesh_force_history(
    result: Any,
    planet: int = 1,
    ax: Any = None,
    periods: float | None = None,
    *,
    physical: bool = True,
) -> Any:
    """Plot the mesh contact forces of one planet against time in mesh periods, with the
    separations shaded.

    The contact force is the mesh force κ(τ) f(δ̄; b̄) + c̄ δ̄' of MODEL.md §4 while the teeth
    touch (|δ̄| > b̄) and it presses them together, and exactly 0 while they are apart (the
    damping term alone is not a contact force) or where the damping would pull them just
    before release (flanks cannot; :func:`gearchaos.model.response.compressive_contact_forces`).
    For planetary results both meshes of ``planet`` are drawn (sun–planet F̄ᶜ_spi and
    planet–ring F̄ᶜ_rpi) with the static mesh force T̄_D/N dotted; for the backlash oscillator
    its single mesh (static force F_m). Intervals where a mesh is separated are shaded in its
    colour.

    Parameters
    ----------
    result
        A :class:`~gearchaos.SimulationResult` with ``samples_per_period`` ≫ 1.
    planet
        The planet (1-based) of a planetary result.
    ax, periods, physical
        As for :func:`time_history` (the physical axis is the force in N, the time in ms).

    Returns
    -------
    matplotlib.axes.Axes
    """
    from ..model.response import mesh_groups, static_mesh_force

    groups = mesh_groups(result.system)
    if not groups:
        raise ParameterError(
            "mesh_force_history needs a model that tracks mesh contact forces (its "
            f"force_groups): {result.system.name} tracks none"
        )
    ax = get_ax(ax)
    sl = sample_window(result, periods)
    t = to_periods(result, result.tau)[sl]
    colours = {"sp": "C0", "rp": "C3", "mesh": "C0"}
    names = {"sp": "sun–planet", "rp": "planet–ring", "mesh": "mesh"}
    ys = []
    for g in groups:
        obs = result.system.observable(g.force.name, [planet] if g.force.per_planet else None)
        y = np.asarray(obs.take(result.states, result.observables))
        y = (y[:, 0] if y.ndim > 1 else y)[sl]
        ys.append(y)
        sub = f"{g.mesh}{planet}" if g.force.per_planet else ""
        label = rf"$\bar F^c_{{{sub}}}$ {names[g.mesh]}" if sub else r"$\bar F^c$"
        ax.plot(t, y, lw=0.9, color=colours[g.mesh], label=label)
        # apart: inside the clearance (the force is also 0 where the damping would pull)
        dcol = g.deflection.columns[planet - 1 if g.force.per_planet else 0]
        delta = result.observables[sl, dcol]
        apart = np.abs(delta) <= result.system.switch_widths[dcol]
        first = True
        for a, b in _spans(apart):
            lo = t[max(a - 1, 0)] if a > 0 else t[a]
            hi = t[min(b + 1, t.size - 1)]
            ax.axvspan(
                lo,
                hi,
                color=colours[g.mesh],
                alpha=0.12,
                lw=0,
                gid="separation",
                label=f"{names[g.mesh]} teeth apart" if first else None,
            )
            first = False
    static = static_mesh_force(result.system)
    if math.isfinite(static):
        ax.axhline(static, ls=":", lw=0.8, color="0.3", label="static mesh force")
    ax.axhline(0.0, lw=0.5, color="0.5")
    ax.set_xlabel(period_axis_label(result))
    ax.set_ylabel(
        r"contact force $\bar F^c = F^c/(k_{m,sp}\,b_c)$"
        if has_physical_scales(result)
        else r"contact force $F^c$"
    )
    fit_to_data(ax, t, np.concatenate(ys))
    if physical:
        scales = PhysicalScales.of_result(result)
        secondary_axis(ax, "y", "force", scales, symbol="$F^c$")
        ms = scales.period_ms(result.system.omega)
        if ms is not None:
            linear_axis(ax, "x", ms, "t [ms]")
    return ax


def amplitude_spectrum(
    result: Any,
    var: str | None = None,
    planet: int = 1,
    *,
    window: str = "boxcar",
) -> tuple[np.ndarray, np.ndarray]:
    """One-sided amplitude spectrum of the recorded (steady) response.

    The recorded window spans an integer number P of forcing periods sampled uniformly with
    ``s = samples_per_period`` samples each, so with the default rectangular window the FFT
    bins fall exactly on multiples 1/P of the forcing frequency 2π/T and a periodic response
    has leakage-free lines at its harmonics: for x_j = a cos(2πkτ_j/T + φ) the bin at
    ωT/2π = k holds amplitude ``a``. For a period T = 2π/Ω (the planetary model's mesh period)
    that is ω/Ω = k; a model whose forcing period is T = f·2π/Ω (``period_factor`` f) has its
    line at Ω at k = f (the two-frequency train's lines at Ω and 3Ω/5 at 5 and 3). The mean is
    removed first. ``window="hann"`` applies
    a Hann window (amplitudes divided by the window's mean, so lines keep their height) for
    non-periodic motion.

    Returns
    -------
    (ratio, amplitude)
        ``ratio = ωT/2π``, in multiples of the frequency of the model's forcing period (ω/Ω,
        multiples of the mesh frequency, for the planetary model), for bins 1 … Ps/2 and the
        amplitudes, in the units of the variable.
    """
    info = variable(result, var, planet)
    s = result.samples_per_period
    if s < 4:
        raise ParameterError(
            f"spectrum needs samples_per_period >= 4 (a Nyquist limit of at least twice the "
            f"forcing frequency): got {s}; simulate with samples_per_period=32 or more"
        )
    x = np.asarray(result.series(info.name), dtype=np.float64)
    bad = np.flatnonzero(~np.isfinite(x))
    n_periods = (bad[0] if bad.size else x.size) // s
    if n_periods < 1:
        raise ParameterError(
            f"spectrum needs at least one whole recorded period of finite samples: got "
            f"{bad[0] if bad.size else x.size} samples at {s} per period"
        )
    x = x[: n_periods * s]
    x = x - x.mean()
    if window == "boxcar":
        w = np.ones(x.size)
    elif window == "hann":
        w = np.hanning(x.size + 1)[:-1]  # periodic Hann
    else:
        raise ParameterError(f"window must be 'boxcar' or 'hann': got {window!r}")
    amp = 2.0 * np.abs(np.fft.rfft(x * w)) / w.sum()
    k = np.arange(amp.size)
    ratio = k / n_periods  # multiples of the period's frequency 2π/T
    if x.size % 2 == 0:
        amp[-1] /= 2.0  # the Nyquist bin is not doubled
    return ratio[1:], amp[1:]


def spectrum(
    result: Any,
    var: str | None = None,
    planet: int = 1,
    ax: Any = None,
    *,
    max_harmonic: float | None = 5.0,
    window: str = "boxcar",
) -> Any:
    """Plot the amplitude spectrum of a variable on a log scale (see :func:`amplitude_spectrum`).

    The frequency axis is in multiples of the frequency 2π/T of the model's forcing period T
    (:func:`~gearchaos.plot._common.frequency_axis`: ω/ω_m, multiples of the mesh frequency,
    for the planetary model; ωT/2π for a period T = 5·2π/Ω, whose line at Ω lies at 5), shown
    up to ``max_harmonic`` of them (or the Nyquist limit s/2); each whole multiple is marked
    and labelled (``3Ω/5``, in Hz too for a model with scales). Raises
    :class:`~gearchaos.errors.ParameterError` unless ``samples_per_period >= 4``.
    """
    info = variable(result, var, planet)
    ratio, amp = amplitude_spectrum(result, var, planet, window=window)
    ax = get_ax(ax)
    top = float(np.max(amp)) if amp.size else 0.0
    floor = top * 1e-12 if top > 0 else 1e-300
    ax.plot(ratio, np.maximum(amp, floor), lw=0.8, color="C0")
    ax.set_yscale("log")
    hi = ratio[-1] if max_harmonic is None else min(float(max_harmonic), float(ratio[-1]))
    ax.set_xlim(0.0, hi)
    if top > 0:
        shown = amp[ratio <= hi]
        lo = max(float(np.min(shown[shown > 0])) if np.any(shown > 0) else floor, top * 1e-9)
        ax.set_ylim(lo / 2.0, top * 3.0)
    scales = PhysicalScales.of_result(result) if has_physical_scales(result) else PhysicalScales()
    factor = result.system.capabilities.period_factor  # T = factor·2π/Ω
    # 2π/T in Hz: the frequency of one multiple on the axis
    f_t = None
    if scales.omega_n:
        f_t = float(result.omega) * scales.omega_n / (2.0 * math.pi * factor)
    for h in range(1, math.floor(hi) + 1):
        ax.axvline(h, color="0.8", lw=0.6, zorder=0)
        if period_name(result) == "mesh":
            base = f"{h}$f_m$"
        else:  # h·2π/T as a multiple of Ω (3Ω/5 for T = 5·2π/Ω)
            base = f"${omega_times(h / factor)}$"
        label = base if f_t is None else f"{base} = {h * f_t:.0f} Hz"
        ax.text(
            h,
            0.98,
            label,
            transform=ax.get_xaxis_transform(),
            rotation=90,
            ha="right",
            va="top",
            fontsize="x-small",
            color="0.35",
            gid=HARMONIC_GID,
        )
    from ..model.record import sidebands

    for side in sidebands(result.system.model):  # h ± side, in multiples of the frequency
        for h in range(1, math.floor(hi) + 1):
            for r in (h - side, h + side):
                if 0.0 < r <= hi:
                    ax.axvline(r, color="0.85", lw=0.5, ls=":", zorder=0, gid=HARMONIC_GID)
    symbol, words = frequency_axis(result)
    ax.set_xlabel(f"${symbol}$ ({words})")
    if f_t is not None:  # a model with scales: the frequency in Hz opposite
        linear_axis(ax, "x", f_t, "frequency [Hz]")
    ax.set_ylabel(f"amplitude of ${info.symbol}$")
    return ax
