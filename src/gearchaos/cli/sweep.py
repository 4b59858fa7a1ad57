"""Sweep commands: ``gearchaos bifurcation`` and ``classify`` (``plot`` is :mod:`.plot`)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape
from rich.text import Text

from .._text import escape_path
from ..errors import ParameterError
from ..gearset.parsing import parse_int
from ..model.contract import Capabilities
from ..model.target import model_for
from ..sweep.classify import MAX_PERIOD, PERIOD_RTOL
from ..sweep.spec import SWEEP_SOLVER
from . import _common as c
from ._render import regime_table, sweep_summary


def _initial_conditions(value: c.InitialConditions | None, old: str | None) -> tuple[str, str]:
    """(value, option) of ``--initial-conditions`` (the name of the Python keyword
    ``initial_conditions=`` and of the store attribute), or of its deprecated spelling ``--ic``
    with a warning (its value is checked by the library, under its name); both refused."""
    if old is not None:
        if value is not None:
            raise ParameterError(
                "give --initial-conditions only (--ic is its deprecated spelling): got both"
            )
        c.warn(
            "--ic is deprecated and will be removed in the next release; use "
            "--initial-conditions (the spelling of the Python keyword initial_conditions=)"
        )
        return old, "--ic"
    return c.choice_value(value) or "fresh", "--initial-conditions"


def _parse_planets(raw: str | None) -> tuple[int, ...]:
    if raw is None:
        return (1,)
    items = [item.strip() for item in raw.split(",")]
    if not all(items):
        raise ParameterError(f"--planets must be planet numbers such as 1,2: got {raw!r}")
    return tuple(parse_int("--planets", item) for item in items)  # >= 1: the library's rule


def _axis_name(item: str) -> str:
    return item.partition("=")[0].strip()


def open_store(path: Path) -> Any:
    """A sweep store as a :class:`~gearchaos.sweep.SweepResult`; a missing, unreadable or
    foreign one is invalid input (exit 2; :func:`gearchaos.sweep.result.open_result`)."""
    from ..sweep.result import open_result

    return open_result(path)


StoreArg = Annotated[
    Path,
    typer.Argument(help="Sweep store written by `gearchaos bifurcation`.", show_default=False),
]


@c.command()
def bifurcation(
    vary: Annotated[
        list[str] | None,
        typer.Option(
            "--vary",
            "-v",
            help=(
                "NAME=VALUES, once (bifurcation diagram) or twice (2-D map): VALUES is "
                "start:stop:count, log:start:stop:count or a,b,c; NAME is omega, xi or a "
                "dotted gear-set parameter, e.g. omega=0.05:4:800, backlash.planet_ring=1:16:300."
            ),
            show_default=False,
        ),
    ] = None,
    family: Annotated[
        str | None,
        typer.Option(
            "--family",
            "-f",
            help="NAME=VALUES: one diagram per value, e.g. xi=0.03,0.05,0.07,0.09.",
            show_default=False,
        ),
    ] = None,
    target: c.Target = c.Target(),
    observe: Annotated[
        list[str] | None,
        typer.Option(
            "--observe",
            help=(
                "Variable stored at every section point, repeatable: delta_sp, delta_sp_dot, "
                "delta_rp, delta_rp_dot, x_s, y_s, ... Default: delta_sp and delta_sp_dot."
            ),
            show_default=False,
        ),
    ] = None,
    planets: Annotated[
        str | None,
        typer.Option(
            "--planets", help="Observed planets, comma-separated (default 1).", show_default=False
        ),
    ] = None,
    initial_conditions: Annotated[
        c.InitialConditions | None,
        typer.Option(
            "--initial-conditions",
            help=(
                "Initial conditions: fresh (zero state at every point, the seed's protocol) or "
                "continuation (each point starts from the previous point's final state). "
                "Default: fresh."
            ),
            show_default=False,
        ),
    ] = None,
    ic: Annotated[
        str | None,
        typer.Option("--ic", hidden=True, help="Deprecated spelling of --initial-conditions."),
    ] = None,
    direction: Annotated[
        c.Direction,
        typer.Option(
            "--direction",
            help="Continuation only: up, down or both (both overlays the branches).",
        ),
    ] = c.Direction("up"),
    protocol: c.Protocol = c.Protocol.of(SWEEP_SOLVER).offering(
        "transient", "settle", "perturbation", "periods"
    ),
    solver: c.Solver = c.Solver.of(SWEEP_SOLVER),
    execution: c.Execution = c.Execution(),
    lyapunov: Annotated[
        bool,
        typer.Option(
            "--lyapunov",
            help=(
                "Also store the largest Lyapunov exponent lle of every point; the motion "
                "labels then tell quasi-periodic from chaotic motion by it."
            ),
        ),
    ] = False,
    verdict: c.Verdict = c.Verdict().offering(
        help={
            "verdict": "Decide every point's motion with the verdict: nT confirmed by shooting "
            "(Floquet multipliers), chaos and QP by λ₁ ± its error, transients finished "
            "(default). --no-verdict labels from the records alone (faster)."
        }
    ),
    orbits: Annotated[
        bool,
        typer.Option(
            "--orbits",
            help=(
                "Confirm every label nT (n ≤ 8) by shooting a period-n orbit from the point's "
                "final state; store orbit_residual, orbit_max_multiplier (largest |μ|) and "
                "orbit_status (confirmed, unstable, shorter_period, not_converged, ...)."
            ),
        ),
    ] = False,
    output: c.Output = c.Output().offering(
        help={
            "file": "Zarr store to write (a directory, e.g. run.zarr). Written chunk by chunk; "
            "run the same command again after an interruption to resume."
        },
        required=("file",),
    ),
) -> None:
    """Sweep one or two parameters and store the Poincaré section values of every point.

    Every grid point is one simulation with the seed's protocol (MODEL.md §8): TRANSIENT mesh
    periods discarded, PERIODS recorded with one section point each. The store (Zarr, opened
    by xarray.open_zarr or gearchaos.open_sweep) holds the section values, status and step
    counts per point and the full gear set and settings, and labels every point (motion 1T …
    nT, QP, chaos, unresolved, failed; the regime table is printed at the end). Ω is a
    parameter like any other: sweep it with **--vary omega=...**, or fix it with
    **--set omega=...**; when it is neither swept nor set, Ω = **1.5**. Draw the result with
    **gearchaos plot STORE -o fig.png**.

    Example (the seed's Fig. 4): **gearchaos bifurcation --vary omega=0.05:4:800
    --family xi=0.03,0.05,0.07,0.09 -o fig4.zarr**
    """

    with c.reported_errors(), c.interruptible():
        if not vary:
            raise ParameterError(
                "--vary is required: give NAME=VALUES once (e.g. --vary omega=0.1:4:800) "
                "or twice for a 2-D map"
            )
        if len(vary) > 2:
            raise ParameterError(
                f"--vary may be given once or twice (two make a 2-D map): got {len(vary)}"
            )
        ic, ic_option = _initial_conditions(initial_conditions, ic)
        way = str(direction.value)
        if way != "up" and ic == "fresh":  # the library's rule, in the options' words
            raise ParameterError(
                f"--direction {way} needs {ic_option} continuation "
                "(fresh starts do not depend on the sweep direction)"
            )
        settings = c.settings(protocol, solver)
        swept = {_axis_name(v) for v in vary} | ({_axis_name(family)} if family else set())
        gs, fixed = c.sweep_target(target, swept, output.silent)

        from .. import sweep

        with c.named_options(
            initial_conditions=ic_option, direction="--direction", planets="--planets"
        ):
            res, seconds = c.run_sweep(
                sweep.bifurcation,
                gs,
                list(vary),
                settings=settings,
                output=output,
                execution=execution,
                family=family,
                params=fixed,
                observe=tuple(observe) if observe else None,
                planets=_parse_planets(planets),
                initial_conditions=ic,
                direction=way,
                lyapunov=lyapunov,
                orbits=orbits,
                verdicts=verdict.decided(),
            )

    path = output.required_path()
    result: dict[str, Any] = sweep_summary(res, path, seconds)
    if orbits:
        import numpy as np

        from ..sweep.variables import ORBIT_STATUS

        codes = np.asarray(res.ds["orbit_status"].values).ravel()
        result["orbits"] = {
            k: int(np.sum(codes == v)) for k, v in ORBIT_STATUS.items() if np.any(codes == v)
        }
    title = f"gearchaos bifurcation of {gs.name}"
    table = c.sweep_report(title, res, result, output)
    if table is None:
        return
    table.add_row("seconds", f"{seconds:.3g}")
    if seconds > 0:
        table.add_row("points/s", f"{result['points'] / seconds:.3g}")
    table.add_row("store", escape(str(path)))
    out = c.stdout()
    out.print(table)
    period = Capabilities.of(model_for(gs, {})).period_name  # mesh: a gear set's
    out.print(
        Text(
            f"{protocol.transient:g} transient + {protocol.periods} recorded {period} periods, "
            f"{ic} initial conditions, rtol {solver.rtol:g}, atol {solver.atol:g}"
            + (", largest Lyapunov exponents" if lyapunov else "")
            + (", nT labels checked by periodic orbits" if orbits else ""),
            style="dim",
        )
    )
    if orbits:
        table2 = ", ".join(f"{k.replace('_', ' ')} {n}" for k, n in result["orbits"].items())
        out.print(Text(f"periodic orbits behind the nT labels: {table2}", style="dim"))
    regimes = res.regime_table()
    if regimes:
        out.print(regime_table(regimes, title="motion regimes (fraction of the swept points)"))
    shown, stem = escape_path(path), escape_path(path.stem)
    out.print(Text(f"next: gearchaos plot {shown} -o {stem}.png", style="dim"))


@c.command()
def classify(
    store: StoreArg,
    period_rtol: Annotated[
        float | None,
        typer.Option(
            "--period-rtol",
            help=(
                "Tolerance of period detection, relative to the attractor's size: section "
                f"points closer than this repeat. [default: {PERIOD_RTOL:g}]"
            ),
            show_default=False,
        ),
    ] = None,
    rtol: Annotated[
        float | None,
        typer.Option("--rtol", hidden=True, help="Deprecated name of --period-rtol."),
    ] = None,
    max_period: Annotated[
        int, typer.Option("--max-period", help="Longest period n recognised as nT.")
    ] = MAX_PERIOD,
    output: c.Output = c.Output().offering("json"),
) -> None:
    """(Re)label every point of a sweep store without re-simulating: 1T … nT (period of the
    stored section sequence), QP or chaos (by the stored largest Lyapunov exponent when the
    sweep ran with --lyapunov, confirmed by the 0–1 test and the spectrum), unresolved, failed.

    Rewrites the period and indicators_agree variables and the regime_table attribute, and
    the motion and k01 of a store labelled from its record (--no-verdict: evidence record,
    decided again with these tolerances; a store's confirmed verdicts are never rewritten),
    and prints the regime table: the fraction of the swept points in each regime, per family
    value. **--json** prints that table as a dictionary
    (family value → regime → fraction).

    Example: **gearchaos classify fig4.zarr --period-rtol 1e-4**
    """
    with c.reported_errors():
        option, tol = "--period-rtol", period_rtol
        if rtol is not None:
            if period_rtol is not None:
                raise ParameterError("give --period-rtol only (--rtol is its deprecated name)")
            c.warn(
                "classify --rtol is deprecated: it is the period tolerance, not the "
                "integrator's rtol; use --period-rtol"
            )
            option, tol = "--rtol", rtol
        tol = PERIOD_RTOL if tol is None else tol
        open_store(store)
        from ..sweep import classify_store

        with c.named_options(period_rtol=option, max_period="--max-period"):
            table = classify_store(store, period_rtol=tol, max_period=max_period)
    if output.json:
        c.print_json(table)
        return
    out = c.stdout()
    out.print(regime_table(table, title=f"motion regimes of {store} (fraction of the points)"))
    out.print(
        Text(
            f"period tolerance {tol:g} of the attractor size, periods up to {max_period}",
            style="dim",
        )
    )
