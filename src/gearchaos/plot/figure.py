"""One-page summary figure of a simulation and a format-aware :func:`savefig`."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from ..errors import ParameterError
from ._common import is_planetary, message
from .phase import phase_portrait, poincare_map, sun_orbit
from .timeseries import spectrum, time_history

__all__ = ["SAVE_FORMATS", "savefig", "summary_figure"]

#: File suffixes :func:`savefig` writes.
SAVE_FORMATS = (".png", ".pdf", ".svg")

_REGIME_SHORT = {
    "none": "none",
    "single_sided": "single",
    "double_sided": "double",
    "unknown": "?",
}


def _fmt(v: Any, spec: str = ".4g") -> str:
    return "—" if v is None else format(v, spec)


def _text_lines(result: Any, summary: dict[str, Any]) -> list[str]:
    gs = summary.get("gearset") or result.system.name
    n = summary["distinct_section_points"]
    motion = summary["motion"]
    recorded = summary.get("recorded_section_points")
    points = f"{n} of {recorded}" if recorded else str(n)
    lines = [
        f"gear set: {gs}",
        rf"$\Omega = \omega/\omega_n$ = {_fmt(summary['omega'])}",
    ]
    if summary.get("omega_n_rad_s") is not None:
        lines.append(rf"$\omega_n$ = {_fmt(summary['omega_n_rad_s'], '.5g')} rad/s")
    if summary.get("mesh_frequency_hz") is not None:
        lines.append(rf"mesh frequency $f_m$ = {_fmt(summary['mesh_frequency_hz'], '.5g')} Hz")
    if summary.get("sun_speed_rpm") is not None:
        lines.append(f"sun speed = {_fmt(summary['sun_speed_rpm'], '.5g')} rpm")
    lines.append(f"distinct section points: {points} (motion: {motion})")
    lo, hi = summary.get("x_sp1_section_min"), summary.get("x_sp1_section_max")
    if lo is not None:
        sym = r"$\bar{X}_{sp1}$" if is_planetary(result) else f"${result.system.state_names[0]}$"
        lines.append(f"{sym} on the section: {_fmt(lo)} … {_fmt(hi)}")
    if summary.get("load_factor_sp_max") is not None:
        lines.append(
            "max load factor: sun–planet "
            f"{_fmt(summary['load_factor_sp_max'], '.3g')}, planet–ring "
            f"{_fmt(summary.get('load_factor_rp_max'), '.3g')}"
        )
    contact = summary.get("contact", [])
    if contact:
        per = " (planets 1…N)" if is_planetary(result) else ""
        lines.append(f"contact regimes{per}:")
        groups: dict[str, list[str]] = {}
        for c in contact:
            mesh = c["mesh"]
            group = mesh.rpartition("_")[0] if mesh[-1].isdigit() else mesh
            groups.setdefault(group, []).append(_REGIME_SHORT.get(c["regime"], c["regime"]))
        for group, regimes in groups.items():
            name = group.replace("sun_planet", "sun–planet").replace("planet_ring", "planet–ring")
            lines.append(f"   {name}: {', '.join(regimes)}")
    lines.append(
        f"status: {summary['status']}  (steps {summary['steps_accepted']} accepted, "
        f"{summary['steps_rejected']} rejected)"
    )
    s = result.solver
    lines.append(
        f"transient {s.transient_periods} + recorded {s.periods} periods, "
        f"{s.samples_per_period} samples/period"
    )
    return lines


def summary_figure(
    result: Any,
    summary: dict[str, Any] | None = None,
    *,
    planet: int = 1,
    history_periods: float = 10,
    figsize: tuple[float, float] = (16.0, 9.5),
) -> Any:
    """A one-page 2×3 figure of one simulation.

    Panels: time history of X̄_sp (last ``history_periods`` periods), phase portrait,
    Poincaré map, amplitude spectrum (a message when ``samples_per_period < 4``), sun-centre
    orbit, and a text panel with Ω, ω_n, sun speed, distinct section points, contact regimes,
    status and the gear set name. Works for reference systems too (their first state is
    shown; the sun-orbit panel then says why it is empty).

    Parameters
    ----------
    result
        A :class:`~gearchaos.SimulationResult`; the figure never simulates.
    summary
        The result of :func:`gearchaos.analysis.summarize` (computed when not given).
    planet
        The planet whose sun–planet mesh is shown.

    Returns
    -------
    matplotlib.figure.Figure
        Not registered with pyplot (no GUI state); save it with :func:`savefig`.
    """
    from matplotlib.figure import Figure

    from ..analysis.summary import summarize

    if summary is None:
        summary = summarize(result)
    fig = Figure(figsize=figsize, layout="constrained")
    axs = fig.subplots(2, 3)
    planetary = is_planetary(result)
    var = "delta_sp" if planetary else None
    periods = min(float(history_periods), float(result.solver.periods))

    ax = time_history(result, var, planet, ax=axs[0, 0], periods=periods)
    ax.set_title(f"time history (last {periods:g} periods)")
    ax.legend(loc="best", fontsize="small", framealpha=0.9)

    try:
        orbit_periods = min(5.0 * periods, float(result.solver.periods))
        ax = phase_portrait(result, var, planet, ax=axs[0, 1], periods=orbit_periods)
        if result.samples_per_period > 1:
            ax.set_title(f"phase portrait (orbit: last {orbit_periods:g} periods)")
        else:
            ax.set_title("phase portrait (section points only)")
    except ParameterError as e:
        message(axs[0, 1], str(e))

    try:
        ax = poincare_map(result, planet, ax=axs[0, 2], var=var)
        n_pts = summary["distinct_section_points"]
        ax.set_title(f"Poincaré map ({n_pts} distinct of {len(result.section_tau)} points)")
    except ParameterError as e:
        message(axs[0, 2], str(e))

    if result.samples_per_period >= 4:
        ax = spectrum(result, var, planet, ax=axs[1, 0])
        ax.set_title("amplitude spectrum (recorded window)")
    else:
        message(
            axs[1, 0],
            "no spectrum: needs samples_per_period ≥ 4\n"
            f"(this run has {result.samples_per_period})",
        )
        axs[1, 0].set_title("amplitude spectrum")

    if planetary:
        sun_periods = min(5.0 * periods, float(result.solver.periods))
        ax = sun_orbit(result, ax=axs[1, 1], periods=sun_periods)
        ax.set_title(f"sun centre orbit (last {sun_periods:g} periods)")
        ax.legend(loc="upper right", fontsize="small")
    else:
        message(axs[1, 1], f"no sun orbit: {result.system.name} is not a planetary model")

    tx = axs[1, 2]
    tx.set_axis_off()
    tx.text(
        0.0,
        1.0,
        "\n".join(_text_lines(result, summary)),
        va="top",
        ha="left",
        transform=tx.transAxes,
        fontsize=10,
        linespacing=1.6,
    )
    tx.set_title("summary")

    gs = summary.get("gearset") or result.system.name
    rpm = summary.get("sun_speed_rpm")
    title = f"{gs}: Ω = {result.system.omega:g}"
    if rpm is not None:
        title += f" (sun {rpm:.0f} rpm)"
    title += f" — motion {summary['motion']}, status {summary['status']}"
    fig.suptitle(title, fontsize=14)
    return fig


def savefig(fig: Any, path: str | os.PathLike[str], *, dpi: float = 150) -> str:
    """Write ``fig`` as PNG, PDF or SVG, chosen by the suffix of ``path``; returns the path.

    Raises :class:`~gearchaos.errors.ParameterError` for any other suffix, and writes under a
    temporary name first so that a failed write never leaves a partial file at ``path``.
    """
    p = Path(os.fspath(path))
    suffix = p.suffix.lower()
    if suffix not in SAVE_FORMATS:
        raise ParameterError(
            f"path must end in one of {', '.join(SAVE_FORMATS)}: got {os.fspath(path)!r}"
        )
    tmp = p.with_name(p.name + ".partial")
    try:
        fig.savefig(tmp, format=suffix[1:], dpi=dpi)
        os.replace(tmp, p)
    finally:
        if tmp.exists():
            tmp.unlink()
    return str(p)
