"""Basins of attraction: ``gearchaos basins`` and ``gearchaos basin-fractions``."""

from __future__ import annotations

import json
import time
from typing import Annotated, Any

import typer
from rich.markup import escape
from rich.table import Table
from rich.text import Text

from .._text import escape_path
from ..errors import ParameterError
from ..sweep.basins import BASIN_SETTINGS
from . import _common as c

#: -o and the rest of the output options of basins and basin-fractions.
OUTPUT = c.Output().offering(
    help={
        "file": "Zarr store to write (a directory, e.g. basins.zarr); run the same command "
        "again after an interruption to resume."
    },
    required=("file",),
)
SampleOpt = Annotated[
    int,
    typer.Option(
        "--sample",
        help="Starts from which the attractor catalogue is built first (decided by the motion "
        "verdict); the others are matched against it.",
    ),
]
SeedOpt = Annotated[int, typer.Option("--seed", help="Seed of the sample (and random starts).")]
PROTOCOL = c.Protocol.of(BASIN_SETTINGS).offering("transient", "periods")
BaseOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--base",
        help="STATE=VALUE, repeatable: the value of a state coordinate that is not varied "
        "(default 0).",
        show_default=False,
    ),
]


def _pairs(items: list[str] | None, option: str) -> dict[str, str]:
    out: dict[str, str] = {}
    for item in items or []:
        name, sep, value = item.partition("=")
        if not sep or not name.strip() or not value.strip():
            raise ParameterError(f"{option} must be STATE=VALUE: got {item!r}")
        out[name.strip()] = value.strip()
    return out


def _base(items: list[str] | None) -> dict[str, float] | None:
    from ..gearset.parsing import parse_float

    pairs = _pairs(items, "--base")
    return {k: parse_float(f"--base {k}", v) for k, v in pairs.items()} or None


def _box(items: list[str] | None) -> dict[str, tuple[float, float]] | None:
    from ..gearset.parsing import parse_float

    out: dict[str, tuple[float, float]] = {}
    for name, text in _pairs(items, "--box").items():
        lo, sep, hi = text.partition(":")
        if not sep:
            raise ParameterError(f"--box must be STATE=LOW:HIGH: got {name}={text!r}")
        out[name] = (parse_float(f"--box {name}", lo), parse_float(f"--box {name}", hi))
    return out or None


#: The options of the keywords of basins() and basin_fractions() that refusals name.
_OPTIONS = {
    "x": "--x",
    "y": "--y",
    "base_state": "--base",
    "starts": "--starts",
    "box": "--box",
    "confirm_periods": "--confirm-periods",
}


def _legend_table(
    title: str, entries: list[dict[str, Any]], codes: Any, xname: str, column: int
) -> Table:
    import numpy as np

    from ..dynamics.attractors.basins import BasinAttractor

    table = Table(title=title, title_justify="left")
    for col in ("code", "attractor", "evidence", "share of starts"):
        table.add_column(col)
    n = max(1, int(np.sum(codes != -1)))
    for k, e in enumerate(entries):
        a = BasinAttractor.from_record(e)
        table.add_row(
            str(k),
            escape(a.legend(xname, column)),
            escape(a.evidence),
            f"{100 * np.sum(codes == k) / n:.3g} %",
        )
    failed = int(np.sum(codes == -2))
    if failed:
        table.add_row("-2", "failed", "integration failed", f"{100 * failed / n:.3g} %")
    return table


@c.command()
def basins(
    x: Annotated[
        str,
        typer.Option("--x", help="STATE=start:stop:count, the horizontal state coordinate."),
    ],
    y: Annotated[
        str, typer.Option("--y", help="STATE=start:stop:count, the vertical state coordinate.")
    ],
    base: BaseOpt = None,
    target: c.Target = c.Target(),
    sample: SampleOpt = 32,
    seed: SeedOpt = 0,
    confirm: c.Confirm = c.Confirm(),
    protocol: c.Protocol = PROTOCOL,
    solver: c.Solver = c.Solver.of(BASIN_SETTINGS),
    execution: c.Execution = c.Execution(),
    output: c.Output = OUTPUT,
) -> None:
    """Basin image at one operating point: which attractor each start of a 2-D slice of
    initial states reaches.

    The attractors are found first from --sample starts (each decided by the motion verdict:
    orbits confirmed by shooting with their multipliers, chaos and QP by λ₁ over a last window
    of at least CONFIRM_PERIODS periods (2000)), then every start's record is matched against
    them (unmatched starts get the verdict). Draw it with
    **gearchaos plot STORE -o basins.png**.

    Example (twin-well Duffing): **gearchaos basins --model gearchaos.model.library:Duffing
    --set alpha=-1 --set gamma=0.1 --set delta=0.25 --set omega=1.2 --x x=-2:2:200
    --y x_dot=-2:2:200 -o basins.zarr**
    """
    from ..sweep.basins import basins as run

    with c.reported_errors(), c.interruptible():
        built, omega = c.point_target(target, output.silent)
        settings = c.settings(protocol, solver)
        t0 = time.perf_counter()
        with c.warnings_to_stderr(), c.named_options(**_OPTIONS):
            ds = run(
                built,
                x,
                y,
                base_state=_base(base),
                omega=omega,
                settings=settings,
                store=output.required_path(),
                overwrite=output.overwrite,
                progress=not output.silent,
                sample=sample,
                seed=seed,
                confirm_periods=confirm.confirm_periods,
                **execution.offered_values(),
            )
        seconds = time.perf_counter() - t0
    path = output.required_path()
    import numpy as np

    entries = json.loads(ds.attrs["attractors"])["0"]["entries"]
    codes = np.asarray(ds["attractor"].values)
    if output.json:
        c.print_json(
            {
                "store": str(path),
                "starts": int(codes.size),
                "seconds": seconds,
                "attractors": [
                    {**e, "share": float(np.mean(codes == k)), "section_states": None}
                    for k, e in enumerate(entries)
                ],
                "failed": int(np.sum(codes == -2)),
            }
        )
        return
    if output.quiet:
        return
    xname = ds.attrs["dims"][1]
    column = [str(s) for s in ds["state"].values].index(xname)
    out = c.stdout()
    title = f"{codes.size} starts at Ω = {omega:g}"
    out.print(_legend_table(title, entries, codes, xname, column))
    out.print(
        Text(
            f"{seconds:.3g} s; next: gearchaos plot {escape_path(path)} -o "
            f"{escape_path(path.stem)}.png",
            style="dim",
        )
    )


@c.command("basin-fractions")
def basin_fractions(
    vary: Annotated[
        str, typer.Option("--vary", "-v", help="NAME=VALUES, the parameter, e.g. omega=1:2:40.")
    ],
    starts: Annotated[
        int, typer.Option("--starts", "-k", help="Random starts per parameter value.")
    ] = 200,
    box: Annotated[
        list[str] | None,
        typer.Option(
            "--box",
            help="STATE=LOW:HIGH, repeatable: the box the starts are drawn in (uniform); the "
            "other states at --base. Default: every state in mid ± 2·range of the motion from "
            "rest at each value.",
            show_default=False,
        ),
    ] = None,
    base: BaseOpt = None,
    target: c.Target = c.Target(),
    sample: SampleOpt = 16,
    seed: SeedOpt = 0,
    confirm: c.Confirm = c.Confirm(),
    protocol: c.Protocol = PROTOCOL,
    solver: c.Solver = c.Solver.of(BASIN_SETTINGS),
    execution: c.Execution = c.Execution(),
    output: c.Output = OUTPUT,
) -> None:
    """Across a parameter, the fraction of random starts ending on each attractor, with 95 %
    Wilson confidence intervals ("how likely is rattle at this speed"). Each start is labelled
    as by **gearchaos basins** (chaos and QP confirmed over --confirm-periods).

    Example: **gearchaos basin-fractions --vary omega=1:2:21 --starts 200 -o fractions.zarr**
    """
    from ..sweep.basin_fractions import basin_fractions as run

    with c.reported_errors(), c.interruptible():
        omega, changes = c.parse_sets(target.sets or [])
        built = c.load_target(target, changes)
        omega = c.point_omega(built, omega, changes)  # --set sun_rpm / mesh_hz: through it
        name = vary.partition("=")[0].strip()
        values = c.sweep_fixed({name}, omega, {}, output.silent, "varied", "swept or set")
        settings = c.settings(protocol, solver)
        t0 = time.perf_counter()
        with c.warnings_to_stderr(), c.named_options(**_OPTIONS):
            ds = run(
                built,
                vary,
                starts=starts,
                box=_box(box),
                base_state=_base(base),
                seed=seed,
                params=values,
                settings=settings,
                store=output.required_path(),
                overwrite=output.overwrite,
                progress=not output.silent,
                sample=sample,
                confirm_periods=confirm.confirm_periods,
                **execution.offered_values(),
            )
        seconds = time.perf_counter() - t0
    path = output.required_path()
    from ..dynamics.attractors.basins import BasinAttractor

    param = ds.attrs["dims"][0]
    cats, tracks = json.loads(ds.attrs["attractors"]), json.loads(ds.attrs["tracks"])
    first = str(ds["state"].values[0])
    track_ids = [int(t) for t in ds["track"].values]
    rows = []
    for i, p in enumerate(ds[param].values):
        own = {  # this value's own attractor of each track (its own |μ| or λ₁)
            t: BasinAttractor.from_record(cats[str(i)]["entries"][k]).legend(first)
            for k, t in enumerate(tracks[i])
        }
        for j, t in enumerate(track_ids):
            if bool(ds["present"].values[i, j]):
                rows.append(
                    {
                        param: float(p),
                        "track": t,
                        "attractor": own.get(t, "failed"),
                        "fraction": float(ds["fraction"].values[i, j]),
                        "low": float(ds["fraction_low"].values[i, j]),
                        "high": float(ds["fraction_high"].values[i, j]),
                    }
                )
    if output.json:
        c.print_json({"store": str(path), "seconds": seconds, "fractions": rows})
        return
    if output.quiet:
        return
    table = Table(title=f"basin fractions of {starts} starts (95 % Wilson interval)")
    for col in (param, "track", "attractor", "fraction", "interval"):
        table.add_column(col)
    for r in rows:
        table.add_row(
            f"{r[param]:.4g}",
            str(r["track"]),
            escape(str(r["attractor"])),
            f"{r['fraction']:.3f}",
            f"[{r['low']:.3f}, {r['high']:.3f}]",
        )
    out = c.stdout()
    out.print(table)
    out.print(
        Text(
            f"{seconds:.3g} s; next: gearchaos plot {escape_path(path)} -o "
            f"{escape_path(path.stem)}.png",
            style="dim",
        )
    )
