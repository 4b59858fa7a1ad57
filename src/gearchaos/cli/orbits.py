"""Periodic orbits and their branches: ``gearchaos orbit`` and ``gearchaos continue``."""

from __future__ import annotations

import contextlib
import json
import math
import time
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape
from rich.table import Table
from rich.text import Text

from ..dynamics.attractors.coexistence import ATTRACTOR_SETTINGS
from ..dynamics.orbits.orbit import ORBIT_SETTINGS
from ..dynamics.orbits.stability import STABILITY_MARGIN
from ..errors import IntegrationError, ParameterError
from ..gearset.schema import OMEGA, SPEEDS
from . import _common as c
from ._render import pairs_table, section_symbol
from ._speeds import speed_note, speed_range, speeds_per_omega

PeriodOpt = Annotated[
    int | None,
    typer.Option(
        "--period",
        "-n",
        help="Period n of the orbit, in forcing periods (a gear set's mesh periods; default: the "
        "period --from knows, else 1).",
        show_default=False,
    ),
]

FromOpt = Annotated[
    str | None,
    typer.Option(
        "--from",
        help="Start from a file instead of from rest: a sweep store (the state a point ended "
        "in; pick it with --at), a branch file (its point at --at NAME=VALUE) or an orbit file "
        "(gearchaos orbit -o ORBIT.nc). The gear set and the point's values come with it.",
        show_default=False,
    ),
]

AtOpt = Annotated[
    str | None,
    typer.Option(
        "--at",
        help="The point of --from: NAME=VALUE[,NAME=VALUE…], e.g. --at omega=1.5 (a store "
        "point's swept values; a branch's parameter).",
        show_default=False,
    ),
]


#: The protocol of orbit and continue: --transient simulates the first guess; one period.
GUESS = c.Protocol.of(ORBIT_SETTINGS, periods=1).offering(
    "transient",
    help={
        "transient": "Mesh periods simulated from rest for the first guess of the (starting) "
        "orbit; while the shooting then finds no orbit (or, for orbit, an unstable one), the "
        "guess settles longer, up to 16 times as long."
    },
)


def _period(period: int | None, start: Any) -> int:
    """--period, else the period the start knows, else 1."""
    if period is not None:
        return period
    return (start.period if start is not None else None) or 1


def _start_values(
    from_: str | None, at: str | None, target: c.Target
) -> tuple[Any, dict[str, Any], Any]:
    """(gear set, parameter values, start or None) of ``orbit`` and ``continue``: from
    ``--from``/``--at`` when given (its gear set and values, ``--set`` on top), else the gear
    set of ``--preset``/``--gearset`` changed by ``--set`` and Ω alone as a value."""
    from ._start import load_start

    if from_ is None:
        if at is not None:
            raise ParameterError(f"--at picks a point of --from, which is missing: got --at {at}")
        built, omega = c.point_target(target)
        values: dict[str, Any] = {} if omega is None else {OMEGA: omega}
        return built, values, None
    omega, changes = c.parse_sets(target.sets or [])
    if target.names_gear_set:
        raise ParameterError(
            "--from brings the gear set it was computed for: drop --preset/--gearset (change "
            "values with --set)"
        )
    start = load_start(from_, at, target.model)
    values = {**start.values, **c.without_speeds(changes)}
    omega = c.point_omega(start.gearset, omega, changes, values)
    if omega is not None:
        values[OMEGA] = omega
    return start.gearset, values, start


def _spinner(text: str, quiet: bool) -> contextlib.AbstractContextManager[Any]:
    err = c.stderr()
    return err.status(text) if (not quiet and err.is_terminal) else contextlib.nullcontext()


@c.command()
def orbit(
    target: c.Target = c.Target(),
    period: PeriodOpt = None,
    protocol: c.Protocol = GUESS,
    from_: FromOpt = None,
    at: AtOpt = None,
    solver: c.Solver = c.Solver.of(ORBIT_SETTINGS),
    output: c.Output = c.Output().offering(
        "file",
        "json",
        help={
            "file": "Also write the orbit to ORBIT.nc (state, multipliers, monodromy, gear set, "
            "values, settings): a start for gearchaos continue --from ORBIT.nc."
        },
    ),
) -> None:
    """Find the period-n orbit at one operating point by shooting (Newton on Pⁿ(y) − y = 0,
    the Jacobian from the variational equations) and print its Floquet multipliers, stability
    and contact regimes.

    The multipliers μ are the eigenvalues of the monodromy matrix; the orbit is stable when
    every |μ| < 1 − 10⁻⁴ (the motion verdict's criterion; a multiplier equal to 1 for a
    structural reason, a free direction, is set aside). **--json** prints exactly {period,
    minimal_period, converged, residual, stable, stability_margin, max_multiplier,
    multipliers: [{re, im, abs}], section_variable, section: [...], contact: [...],
    message}, section being the orbit's values of the model's section variable (the planetary
    model's delta_sp_1, X̄_sp1); a period-2 shooting that converges on a 1T orbit says
    minimal_period 1.

    The guess is a simulation from rest of --transient forcing periods, settled longer (up to
    16 times) while the shooting lands on no orbit or an unstable one; or the state of a
    sweep point, branch point or orbit file (**--from FILE --at NAME=VALUE**).

    Example: **gearchaos orbit --set omega=1.5 --period 1**
    """
    from ..dynamics.orbits.orbit import periodic_orbit

    with c.reported_errors():
        gs, values, start = _start_values(from_, at, target)
        values.setdefault("omega", c.DEFAULT_OMEGA)
        omega = values["omega"]
        settings = c.settings(protocol, solver)
        period = _period(period, start)
        if period < 1 or period > 64:
            raise ParameterError(f"--period must be an integer in [1, 64]: got {period}")
        path = output.path()
        if path is not None and path.suffix.lower() != ".nc":
            raise ParameterError(f"--output must end in .nc (an orbit file): got {output.file!r}")
        guess = None
        if start is not None:
            settings = settings.replace(**start.section)
            guess = start.state
        with _spinner(f"shooting the period-{period} orbit at Ω = {omega:g}…", output.json):
            with c.warnings_to_stderr():
                orb = periodic_orbit(
                    gs, period=period, guess=guess, settings=settings, params=values
                )
        summary = orb.summary()
        if path is not None:
            orb.save(path)
    if output.json:
        c.print_json(summary)  # exactly the keys of PeriodicOrbit.summary()
        return
    out = c.stdout()
    title = f"period-{period} orbit of {gs.name} at Ω = {omega:g}{speed_note(gs, omega, values)}"
    table = pairs_table(title + ("" if start is None else f", from {start.source}"))
    table.add_row(
        "converged",
        Text("yes" if orb.converged else "no", style="" if orb.converged else "bold red"),
    )
    table.add_row("residual ‖Pⁿ(y) − y‖", f"{orb.residual:.3g}")
    table.add_row(f"stable (|μ| < 1 − {STABILITY_MARGIN:g})", "yes" if orb.stable else "no")
    table.add_row("largest |μ|", f"{orb.max_multiplier:.6g}")
    table.add_row("minimal period", str(orb.minimal_period))
    xs = summary["section"]
    table.add_row(
        f"{section_symbol(orb.system, summary['section_variable'])} at the section",
        escape(", ".join(f"{x:.6g}" for x in xs)),
    )
    for item in summary["contact"]:
        table.add_row(f"contact {item['contact']}", escape(str(item["regime"])))
    out.print(table)
    mult = Table(title="Floquet multipliers μ (by modulus)", title_justify="left")
    for col in ("re", "im", "|μ|"):
        mult.add_column(col, justify="right")
    for m in summary["multipliers"]:
        mult.add_row(f"{m['re']:.6g}", f"{m['im']:.6g}", f"{m['abs']:.6g}")
    out.print(mult)
    if not orb.converged:
        out.print(Text(f"not converged: {orb.message}", style="bold red"))
    elif orb.message != "converged":
        out.print(Text(orb.message, style="dim"))
    if path is not None:
        c.wrote(path)


@c.command("continue")
def continue_(
    vary: Annotated[
        str | None,
        typer.Option(
            "--vary",
            "-v",
            help="NAME=START:STOP: the continued parameter and its range, e.g. omega=0.2:4 or "
            "backlash.sun_planet=1:6 (the branch starts at START).",
            show_default=False,
        ),
    ] = None,
    target: c.Target = c.Target(),
    period: PeriodOpt = None,
    protocol: c.Protocol = GUESS,
    from_: FromOpt = None,
    at: AtOpt = None,
    solver: c.Solver = c.Solver.of(ORBIT_SETTINGS),
    max_points: Annotated[
        int, typer.Option("--max-points", help="Most points of the branch.")
    ] = 2000,
    cascade: Annotated[
        int | None,
        typer.Option(
            "--cascade",
            help="Follow the period-doubling cascade K doublings deep: at every period "
            "doubling of the branch (stable on one side) the period-2n branch born there, "
            "then at theirs, ...; every branch goes into the one .nc file.",
            show_default=False,
        ),
    ] = None,
    cascade_all: Annotated[
        bool,
        typer.Option(
            "--cascade-all",
            help="With --cascade: switch also at period doublings of branches unstable on "
            "both sides.",
        ),
    ] = False,
    output: c.Output = c.Output().offering(
        help={"file": "Branch file: BRANCH.nc (netCDF) or BRANCH.zarr."}, required=("file",)
    ),
) -> None:
    """Continue a branch of period-n orbits in one parameter (pseudo-arclength, so folds are
    passed) and locate its events: folds (μ through +1), period doublings (μ through −1),
    Neimark–Sacker bifurcations (a complex pair through the unit circle, the seed's "Hopf")
    and grazings (a contact regime changes along the orbit).

    Writes the branch (parameter, section state, X̄ values, multipliers, stability per point;
    the events table) and prints its stable and unstable segments and events. Overlay it on a
    sweep with **gearchaos plot STORE --branch BRANCH.nc**.

    With **--cascade K** the period-2n branches born at its period doublings follow (K
    doublings deep), each with its own events, all in BRANCH.nc (drawn together by
    **gearchaos plot BRANCH.nc**).

    Example: **gearchaos continue --vary omega=0.2:4 --set xi=0.03 -o branch.nc**
    """
    from ..dynamics.continuation.arclength import continuation
    from ..dynamics.continuation.branch import branch_summary

    with c.reported_errors():
        if not vary or "=" not in vary:
            raise ParameterError(
                f"--vary is required: NAME=START:STOP, e.g. --vary omega=0.2:4: got {vary!r}"
            )
        path = output.required_path()
        if path.suffix.lower() not in (".nc", ".zarr"):
            raise ParameterError(f"--output must end in .nc or .zarr: got {output.file!r}")
        if cascade is not None and path.suffix.lower() != ".nc":
            raise ParameterError(
                f"--cascade writes every branch into one netCDF file: --output must end in "
                f".nc: got {output.file!r}"
            )
        if cascade_all and cascade is None:
            raise ParameterError("--cascade-all needs --cascade K: got no --cascade")
        name = vary.partition("=")[0].strip()
        set_names = {item.partition("=")[0].strip() for item in target.sets or []}
        if name in set_names:
            raise ParameterError(f"{name} is both continued and set with --set; choose one")
        if from_ is None:
            gs, values = c.sweep_target(target, {name}, output.silent, "continued")
            start = None
        else:
            gs, values, start = _start_values(from_, at, target)
        if name in SPEEDS:  # a branch in Ω: the speed's range converted through the gear set
            vary, name = speed_range(gs, vary, values), OMEGA
        settings = c.settings(protocol, solver)
        period = _period(period, start)
        first = None
        if start is not None:  # the orbit at the file's point: the branch starts there
            from ..dynamics.orbits.orbit import periodic_orbit
            from ..model.record import parameter_value

            if name not in values:  # the start's own value of the continued parameter
                values[name] = parameter_value(gs, name)
            settings = settings.replace(**start.section)
            with c.warnings_to_stderr():
                first = periodic_orbit(
                    gs, period=period, guess=start.state, settings=settings, params=values
                )
            if not first.converged:
                raise IntegrationError(
                    f"no period-{period} orbit near the start, {start.source} ({first.message}, "
                    f"residual {first.residual:.3g}): pick a point whose motion is periodic"
                )
            values.pop(name)
        t0 = time.perf_counter()
        with _spinner(f"continuing the period-{period} branch in {name}…", output.silent):
            with c.warnings_to_stderr():
                ds = continuation(
                    gs,
                    vary,
                    period=period,
                    start=first,
                    settings=settings,
                    params=values,
                    max_points=max_points,
                    store=path,
                    overwrite=output.overwrite,
                    cascade=cascade,
                    cascade_every=cascade_all,
                )
        branches = ds if isinstance(ds, list) else [ds]
        summary = branch_summary(branches[0])
        summary["seconds"] = time.perf_counter() - t0
        summary["branch"] = str(path)
        if cascade is not None:
            summary["cascade"] = [_cascade_entry(b) for b in branches[1:]]
            summary["cascade_skipped"] = json.loads(branches[0].attrs["cascade_skipped"])
    if output.json:
        c.print_json(summary)
        return
    if output.quiet:
        return
    out = c.stdout()
    rpm = speeds_per_omega(gs, values).get("sun_rpm") if name == OMEGA else None
    _print_branch(out, summary, f"period-{period} branch of {gs.name} in {name}", name, rpm)
    for entry in summary.get("cascade", []):
        title = (
            f"{entry['branch']}: period-{entry['period']} branch from the period doubling at "
            f"{name}={entry['parent_value']:.6g} of {entry['parent']}"
        )
        _print_branch(out, entry, title, name, rpm)
    for skip in summary.get("cascade_skipped", []):
        out.print(
            Text(
                f"no branch from the period doubling at {name}={skip['value']:.6g} of "
                f"{skip['parent']}: {skip['reason']}",
                style="dim",
            )
        )
    if any(e["events"] for e in [summary, *summary.get("cascade", [])]):
        out.print(
            Text(
                "± is half the final bracket of the location plus the integrator's error of "
                "the event's test function (checked at rtol/100); a smaller --rtol locates "
                "the events more precisely",
                style="dim",
            )
        )
    c.wrote(Path(path))


def _cascade_entry(branch: Any) -> dict[str, Any]:
    """The summary of one period-2n branch of a cascade, naming where it was born."""
    from ..dynamics.continuation.branch import branch_summary

    a = branch.attrs
    return {
        "branch": str(a["branch"]),
        "parent": str(a["parent"]),
        "parent_event": int(a["parent_event"]),
        "parent_value": float(a["parent_value"]),
        **branch_summary(branch),
    }


def _print_branch(
    out: Any, summary: dict[str, Any], title: str, name: str, rpm: float | None = None
) -> None:
    """The points, stop reason, segments and events table of one branch; with ``rpm`` (the
    sun speed per unit Ω of a branch in Ω) the segments and events also in rpm."""
    table = pairs_table(title)
    table.add_row("points", str(summary["points"]))
    table.add_row("stopped", escape(str(summary["stop_reason"])))
    if "seconds" in summary:
        table.add_row("seconds", f"{summary['seconds']:.3g}")
    for seg in summary["segments"]:
        what = "stable" if seg["stable"] else "unstable"
        speed = "" if rpm is None else f" ({seg['from'] * rpm:.5g} … {seg['to'] * rpm:.5g} rpm)"
        table.add_row(
            escape(f"{what} {seg['from']:.6g} … {seg['to']:.6g}{speed}"),
            f"{seg['points']} points",
        )
    out.print(table)
    events = Table(title="events along the branch", title_justify="left")
    speed_cols = () if rpm is None else ("sun speed [rpm]",)
    for col in ("kind", f"{name} ± uncertainty", *speed_cols, "multiplier", "detail"):
        events.add_column(escape(col), overflow="fold")  # wrapped, never cut off with …
    for e in summary["events"]:
        mu = e.get("multiplier")
        mu_text = "—" if mu is None else f"{mu['re']:.4g}{mu['im']:+.4g}i (|μ| {mu['abs']:.4g})"
        events.add_row(
            escape(e["kind"]),
            _with_uncertainty(e["value"], e.get("uncertainty")),
            *(() if rpm is None else (f"{e['value'] * rpm:.5g}",)),
            escape(mu_text),
            escape(str(e.get("detail", "")).replace(",", ", ")),  # wraps between the meshes
        )
    out.print(events)


def _with_uncertainty(value: float, u: float | None) -> str:
    """``value ± u``: the value to the decimal of the uncertainty's first significant digit
    (six significant digits without an uncertainty)."""
    if u is None or not math.isfinite(u) or u <= 0:
        return f"{value:.6g}"
    digits = max(0, -math.floor(math.log10(u)))
    return f"{value:.{digits}f} ± {u:.1g}" if digits <= 15 else f"{value:.15g} ± {u:.1g}"


@c.command()
def attractors(
    target: c.Target = c.Target(),
    starts: Annotated[
        int,
        typer.Option(
            "--starts",
            "-k",
            help="Initial conditions: the state at rest and K − 1 seeded random states around "
            "its motion.",
        ),
    ] = 8,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the random starts.")] = 0,
    confirm: c.Confirm = c.Confirm(),
    protocol: c.Protocol = c.Protocol.of(ATTRACTOR_SETTINGS).offering("transient", "periods"),
    solver: c.Solver = c.Solver.of(ATTRACTOR_SETTINGS),
    output: c.Output = c.Output().offering("json"),
) -> None:
    """List the distinct attractors at one operating point, from several initial conditions.

    Each start is simulated (TRANSIENT + PERIODS forcing periods, with the largest Lyapunov
    exponent λ₁) and labelled as a sweep labels its points; runs that end on the same
    attractor are grouped. A periodic attractor is confirmed by shooting its orbit, whose
    Floquet multipliers say how stable it is; a chaotic or quasi-periodic one by a last window
    of at least CONFIRM_PERIODS periods (2000). **--json** prints a list of {label, lle,
    lle_error, evidence, starts, section_variable, section, orbit: {period, converged, residual,
    max_multiplier, stable} or null}, section being the distinct values of the model's section
    variable (the planetary model's delta_sp_1, X̄_sp1) on the attractor, or their range.

    Example (a stable 1T orbit beside a chaotic attractor): **gearchaos attractors --set
    omega=1.5**
    """
    from ..dynamics.attractors.coexistence import attractors as find

    with c.reported_errors():
        gs, omega = c.point_target(target, output.json)
        settings = c.settings(protocol, solver)
        with _spinner(f"simulating {starts} starts at Ω = {omega:g}…", output.json):
            with c.warnings_to_stderr():
                found = find(
                    gs,
                    starts=starts,
                    seed=seed,
                    settings=settings,
                    omega=omega,
                    confirm_periods=confirm.confirm_periods,
                )
    items = [a.summary() for a in found]
    if output.json:
        c.print_json(items)
        return
    out = c.stdout()
    table = Table(
        title=f"{len(found)} attractor(s) of {gs.name} at Ω = {omega:g}"
        f"{speed_note(gs, omega)} from {starts} starts",
        title_justify="left",
    )
    symbol = (
        section_symbol(found[0].system, items[0]["section_variable"]) if found else "section"
    )  # every attractor is of the same system: its section variable
    section = f"{symbol} at the section"
    for col in ("motion", "λ₁", "starts (0: at rest)", section, "orbit"):
        table.add_column(escape(col))
    for a, item in zip(found, items, strict=True):
        xs = item["section"]
        xs_text = ", ".join(f"{x:.5g}" for x in xs) if a.period else f"{xs[0]:.5g} … {xs[-1]:.5g}"
        orb = item["orbit"]
        orbit_text = (
            "—"
            if orb is None
            else (
                f"max |μ| = {orb['max_multiplier']:.4g}, "
                + ("stable" if orb["stable"] else "unstable")
                + ("" if orb["converged"] else " (not converged)")
            )
        )
        table.add_row(
            escape(a.label),
            f"{a.lle:+.4g}",
            escape(", ".join(str(s) for s in a.starts)),
            escape(xs_text),
            escape(orbit_text),
        )
    out.print(table)
    if len(found) > 1:
        out.print(
            Text(
                "several attractors coexist: which one a simulation or sweep shows depends on "
                "where it starts",
                style="dim",
            )
        )
