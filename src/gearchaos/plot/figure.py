"""One-page summary figure of a simulation and a format-aware :func:`savefig`."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from .._files import check_output_file
from .._marks import mark_file, placeholder
from .._output import check_replaceable, file_has_mark, staged_file
from .._version import __version__
from ..analysis.summary import motion_text
from ..errors import ParameterError
from ..model.record import model_title
from ..model.response import mesh_contacts
from ._common import message, variable
from .phase import phase_portrait, poincare_map, sun_orbit
from .timeseries import mesh_force_history, spectrum, time_history

__all__ = ["SAVE_FORMATS", "point_figure", "savefig", "summary_figure"]

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


def _contact_groups(names: list[str]) -> list[str]:
    """The group of each contact, by its name: ``sun_planet_2`` → ``sun_planet`` where
    another contact shares the stem before the member's number, else the name itself
    (``stage_1`` alone, ``c1``, ``mesh``)."""
    stems = [n.rpartition("_")[0] if n.rpartition("_")[2].isdigit() else "" for n in names]
    return [s if s and stems.count(s) > 1 else n for s, n in zip(stems, names, strict=True)]


def _text_lines(result: Any, summary: dict[str, Any]) -> list[str]:
    what, name = model_title(result.system.model)
    owner = f"{what}: {name}"
    n = summary["distinct_section_points"]
    motion = motion_text(summary)
    recorded = summary.get("recorded_section_points")
    points = f"{n} of {recorded}" if recorded else str(n)
    lines = [
        owner,
        rf"$\Omega = \omega/\omega_n$ = {_fmt(summary['omega'])}",
    ]
    if variable(result).definition is None:  # the panels do not say what the variables are
        shown = [n for n in result.system.state_names if not n.endswith("_dot")]
        names = ", ".join(f"${variable(result, n).symbol}$" for n in shown[:6])
        lines.append(f"variables: {names}" + (" …" if len(shown) > 6 else "") + " (and rates)")
    if summary.get("omega_n_rad_s") is not None:
        lines.append(rf"$\omega_n$ = {_fmt(summary['omega_n_rad_s'], '.5g')} rad/s")
    caps = result.system.capabilities
    if summary.get("omega_hz") is not None:
        hz = _fmt(summary["omega_hz"], ".5g")
        if caps.period_factor == 1.0:  # Ω is the frequency of the model's period
            name = caps.period_name
            symbol = "f_m" if name == "mesh" else "f"
            lines.append(f"{name} frequency ${symbol}$ = {hz} Hz")
        else:
            lines.append(rf"$\Omega\omega_n/2\pi$ = {hz} Hz")
    if summary.get("sun_speed_rpm") is not None:
        lines.append(f"sun speed = {_fmt(summary['sun_speed_rpm'], '.5g')} rpm")
    lines.append(f"distinct section points: {points} (motion: {motion})")
    lo, hi = summary.get("section_min"), summary.get("section_max")
    if lo is not None:
        sym = f"${variable(result).symbol}$"
        lines.append(f"{sym} on the section: {_fmt(lo)} … {_fmt(hi)}")
    meshes = mesh_contacts(result.system)
    loads = {m: summary.get(f"load_factor_{m}_max") for m in meshes}
    if any(v is not None for v in loads.values()):
        every = [c.name for c in caps.contacts]
        group_of = dict(zip(every, _contact_groups(every), strict=True))
        parts = []
        for m, value in loads.items():  # a mesh type by the group of its contacts
            found = {group_of.get(n, m) for n in meshes[m]}
            group = found.pop() if len(found) == 1 else m
            parts.append(f"{caps.in_words(group)} {_fmt(value, '.3g')}")
        lines.append(f"max load factor: {', '.join(parts)}")
    contact = summary.get("contact", [])
    if contact:
        member = caps.member_name
        per = f" ({member}s 1…N)" if result.system.group_size else ""
        lines.append(f"contact regimes{per}:")
        regimes_of: dict[str, list[str]] = {}
        for group, c in zip(_contact_groups([c["mesh"] for c in contact]), contact, strict=True):
            regimes_of.setdefault(group, []).append(_REGIME_SHORT.get(c["regime"], c["regime"]))
        for group, regimes in regimes_of.items():
            lines.append(f"   {caps.in_words(group)}: {', '.join(regimes)}")
    lines.append(
        f"status: {summary['status']}  (steps {summary['steps_accepted']} accepted, "
        f"{summary['steps_rejected']} rejected)"
    )
    s = result.solver
    lines.append(
        f"transient {s.transient_periods:g} + recorded {s.periods} periods, "
        f"{s.samples_per_period} samples/period"
    )
    added = int(summary.get("extra_periods") or 0)
    if added:
        lines.append(f"periods added by the verdict to finish the transient: {added}")
    return lines


def summary_figure(
    result: Any,
    summary: dict[str, Any] | None = None,
    *,
    planet: int = 1,
    history_periods: float = 10,
    figsize: tuple[float, float] | None = None,
) -> Any:
    """A one-page figure of one simulation: 2×3 panels over a full-width force panel.

    Panels: time history of X̄_sp (last ``history_periods`` periods), phase portrait,
    Poincaré map, amplitude spectrum (a message when ``samples_per_period < 4``), sun-centre
    orbit, a text panel, and under them the mesh contact forces of ``planet`` over the same
    periods with the separations shaded (:func:`~gearchaos.plot.timeseries.mesh_force_history`);
    the text panel lists Ω, ω_n, sun speed, distinct section points, contact regimes,
    status and the gear set name. Works for reference systems and models of one's own too
    (their default observable is shown, and the text names their variables by the model's
    symbols); a panel that does not apply is left out rather than drawn empty: without sun
    coordinates the text takes the sun orbit's place, without tracked mesh contact forces
    (``force_groups``) there is no force panel and the figure is shorter (16 × 9 inches
    instead of 16 × 13, unless ``figsize`` is given).

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
    var = None  # the model's default observable
    sun = {"x_s", "y_s"} <= set(result.system.state_names)
    forces = bool(result.system.force_groups)  # what mesh_force_history draws
    rows: list[Any] = [["00", "01", "02"], ["10", "11" if sun else "12", "12"]]
    if forces:
        rows.append(["force", "force", "force"])
    if figsize is None:
        figsize = (16.0, 13.0) if forces else (16.0, 9.0)
    fig = Figure(figsize=figsize, layout="constrained")
    mosaic = fig.subplot_mosaic(rows, height_ratios=[1.0, 1.0, 0.8][: len(rows)])
    axs = np.array([[mosaic.get(f"{r}{c}") for c in range(3)] for r in range(2)], dtype=object)
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

    if sun:
        sun_periods = min(5.0 * periods, float(result.solver.periods))
        ax = sun_orbit(result, ax=axs[1, 1], periods=sun_periods)
        ax.set_title(f"sun centre orbit (last {sun_periods:g} periods)")
        ax.legend(loc="upper right", fontsize="small")

    if forces:
        ax = mesh_force_history(result, planet, ax=mosaic["force"], periods=periods)
        ax.set_title(f"mesh contact forces (last {periods:g} periods; shaded: teeth apart)")
        ax.legend(loc="center left", bbox_to_anchor=(1.06, 0.5), fontsize="small")

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

    name = model_title(result.system.model)[1]
    rpm = summary.get("sun_speed_rpm")
    title = f"{name}: Ω = {result.system.omega:g}"
    if rpm is not None:
        title += f" (sun {rpm:.0f} rpm)"
    title += f" — motion {motion_text(summary)}, status {summary['status']}"
    fig.suptitle(title, fontsize=14)
    return fig


def point_figure(result: Any, var: str | None, planet: int = 1, periods: float = 10.0) -> Any:
    """The explorer's figure of one point: phase portrait, the variable and its mesh's
    contact force against time (a note where the model tracks no contact forces), and the
    amplitude spectrum (harmonics of the model's forcing period labelled), 2×2. Warnings of
    the plots are silenced (the explorer shows the figure, not a log)."""
    import warnings

    from matplotlib.figure import Figure

    groups = result.system.force_groups
    force = next((f for _, f, d in groups if d == var), groups[0][1] if groups else "")
    fig = Figure(figsize=(11.0, 7.2), dpi=90, layout="constrained")
    axs = fig.subplots(2, 2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        phase_portrait(result, var, planet, ax=axs[0, 0], periods=periods)
        axs[0, 0].set_title("phase portrait")
        time_history(result, var, planet, ax=axs[0, 1], periods=periods)
        axs[0, 1].set_title("time history")
        if force:
            time_history(result, force, planet, ax=axs[1, 0], periods=periods)
            axs[1, 0].set_title("contact force of the mesh")
        else:
            axs[1, 0].set_axis_off()
            axs[1, 0].text(
                0.5, 0.5, f"{result.system.name} tracks no contact forces", ha="center",
                va="center", transform=axs[1, 0].transAxes, color="0.4",
            )  # fmt: skip
        spectrum(result, var, planet, ax=axs[1, 1])
        name = result.system.capabilities.period_name  # mesh: a gear train's
        axs[1, 1].set_title(f"amplitude spectrum ({name} harmonics labelled)")
    return fig


def savefig(fig: Any, path: str | os.PathLike[str], *, dpi: float = 150) -> str:
    """Write ``fig`` as PNG, PDF or SVG, chosen by the suffix of ``path``; returns the path.

    Raises :class:`~gearchaos.errors.ParameterError` for any other suffix. The file carries
    gearchaos's mark (:mod:`gearchaos._marks`: a PNG text chunk, or the PDF's and SVG's
    creator, holding the digest of the file); an existing file without a valid one — another
    program's, or one that merely mentions gearchaos — is never replaced
    (:class:`~gearchaos.errors.StoreError`), and the figure is written under a unique
    temporary name and renamed, so a failed write never leaves a partial file at ``path``.
    """
    p = Path(check_output_file(path, what="figure file"))  # never replaces /dev/null or a FIFO
    suffix = p.suffix.lower()
    if suffix not in SAVE_FORMATS:
        raise ParameterError(
            f"path must end in one of {', '.join(SAVE_FORMATS)}: got {os.fspath(path)!r}"
        )
    # an existing file is replaced only if gearchaos drew it (the mark in its metadata)
    check_replaceable(str(p), what="figure", ours=file_has_mark)
    creator = f"gearchaos {__version__}"
    if suffix == ".png":  # the mark is a chunk of its own (mark_file)
        metadata = {"Software": creator}
    else:
        metadata = {"Creator": f"{creator} {placeholder()}"}
    with staged_file(str(p), what="figure") as tmp:
        fig.savefig(tmp, format=suffix[1:], dpi=dpi, metadata=metadata)
        mark_file(tmp)
    return str(p)
