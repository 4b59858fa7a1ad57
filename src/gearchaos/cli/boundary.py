"""``gearchaos boundary``: continue an event of a branch in a second parameter (stability
charts), and the ``plot --boundaries`` figure."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.text import Text

from .._text import escape_path
from ..errors import ParameterError
from . import _common as c

#: Short names of the event kinds for --event (``pd1``: the first period doubling).
EVENT_SHORT = {
    "fold": "fold",
    "pd": "period_doubling",
    "period_doubling": "period_doubling",
    "ns": "neimark_sacker",
    "neimark_sacker": "neimark_sacker",
    "grazing": "grazing",
    "graze": "grazing",
}


def pick_event(found: list[Any], spec: str) -> Any:
    """The event ``spec`` of a branch: KIND[N] (``pd1``, ``fold2``, ``grazing``: the N-th,
    default first, of that kind in arclength order) or #K (the K-th event, from 0)."""
    spec = spec.strip()
    if spec.startswith("#") and spec[1:].isdigit():
        k = int(spec[1:])
        if not 0 <= k < len(found):
            raise ParameterError(f"--event #{k}: the branch has {len(found)} events (#0 …)")
        return found[k]
    m = re.fullmatch(r"([a-z_]+?)(\d*)", spec)
    kind = EVENT_SHORT.get(m.group(1)) if m else None
    if m is None or kind is None:
        raise ParameterError(
            "--event must be KIND[N] (fold1, pd1, ns1, grazing1) or #K (the K-th event): "
            f"got {spec!r}"
        )
    n = int(m.group(2) or 1)
    same = [e for e in found if e.kind == kind]
    if not 1 <= n <= len(same):
        have = ", ".join(f"{e.kind} at {e.parameter}={e.value:.6g}" for e in found) or "none"
        raise ParameterError(
            f"--event {spec}: the branch has {len(same)} {kind} events (its events: {have})"
        )
    return same[n - 1]


@c.command()
def boundary(
    from_: Annotated[
        Path,
        typer.Option(
            "--from",
            help="Branch file of `gearchaos continue` holding the event.",
            show_default=False,
        ),
    ],
    vary: Annotated[
        str,
        typer.Option(
            "--vary",
            "-v",
            help="NAME=LO:HI: the second parameter and its range, e.g. "
            "xi=0.01:0.05 (the event's value of it must lie inside).",
            show_default=False,
        ),
    ],
    event: Annotated[
        str,
        typer.Option(
            "--event",
            "-e",
            help="Which event: fold1, pd1, ns1, grazing1 (KIND and its number "
            "along the branch) or #K (the K-th event).",
        ),
    ] = "pd1",
    within: Annotated[
        str | None,
        typer.Option(
            "--within",
            help="NAME=LO:HI: range of the branch's parameter [default: the branch's range].",
            show_default=False,
        ),
    ] = None,
    at: Annotated[
        str | None,
        typer.Option(
            "--at",
            help="Values of the second parameter to land on exactly, comma-separated.",
            show_default=False,
        ),
    ] = None,
    assess: Annotated[
        c.Assess,
        typer.Option(
            "--assess",
            help="Which points state their uncertainty (corrected again 100 times tighter): "
            "landed (the --at points), all (every point, about twice the cost) or none.",
        ),
    ] = c.Assess("landed"),
    max_points: Annotated[
        int, typer.Option("--max-points", help="Most new points per direction.")
    ] = 200,
    max_step: Annotated[
        float, typer.Option("--max-step", help="Largest step (1 = a whole range).")
    ] = 0.02,
    resume: Annotated[
        bool,
        typer.Option("--resume", help="Extend the unfinished ends of an existing CURVE.nc."),
    ] = False,
    target: c.Target = c.RECORDED_MODEL,
    output: c.Output = c.Output().offering(
        help={"file": "Curve file: CURVE.nc."}, required=("file",)
    ),
) -> None:
    """Continue a fold, period doubling, Neimark–Sacker or grazing event of a branch in a
    second parameter: the boundary curve of a stability chart, with its orbit and
    multipliers at every point and the codimension-2 points met (cusps, fold–flip,
    resonances), written in the branch-file format. Draw it over a 2-D regime map of the same
    parameters with **gearchaos plot MAP.zarr --boundaries CURVE.nc**.

    Example: **gearchaos boundary --from branch.nc --event pd1 --vary xi=0.01:0.05 -o pd.nc**
    """
    from ..dynamics.continuation.branch import open_branch
    from ..dynamics.continuation.events import events
    from ..dynamics.curves.boundary import boundary_curve
    from ..integrate.settings import SolverSettings
    from ._start import _gearset, name_model

    with c.reported_errors():
        path = output.required_path()
        if path.suffix.lower() not in (".nc", ".zarr"):
            raise ParameterError(f"--output must end in .nc or .zarr: got {output.file!r}")
        quiet, json_out = output.quiet, output.json
        name_model(target.model)  # the consent to build the branch's own model again
        branch = open_branch(from_)
        if branch.attrs.get("kind") == "boundary_curve":
            raise ParameterError(f"--from {from_} is a boundary curve, not a one-parameter branch")
        built = _gearset(branch.attrs, str(from_))  # its model, before anything else
        chosen = pick_event(events(branch), event)
        cfg = SolverSettings.from_record(branch.attrs)
        name = str(branch.attrs["parameter"])
        if within is None:
            within = (
                f"{name}={float(branch.attrs['range_start']):.10g}:"
                f"{float(branch.attrs['range_stop']):.10g}"
            )
        values = None
        if at:
            try:
                values = [float(v) for v in at.split(",") if v.strip()]
            except ValueError:
                raise ParameterError(
                    f"--at must be numbers separated by commas: got {at!r}"
                ) from None
        err = c.stderr()

        def progress(k: int, q: Any) -> None:
            if not quiet and not json_out and k % 10 == 0:
                err.print(
                    Text(f"  {k} points, at {name}={q.z[-2]:.6g}, {vary.partition('=')[0]}="
                         f"{q.z[-1]:.6g}", style="dim")
                )  # fmt: skip

        if not quiet and not json_out:
            err.print(Text(f"continuing {chosen!r} in {vary}", style="dim"))
        with c.named_options(vary="--vary", within="--within", at="--at"):
            curve = boundary_curve(
                built, chosen, vary, within=within, settings=cfg, at=values,
                assess=str(assess.value), max_points=max_points, max_step=max_step, store=path,
                resume=resume, overwrite=output.overwrite, progress=progress,
            )  # fmt: skip
        summary = curve_summary(curve)
        if json_out:
            c.print_json(summary)
            return
        if not quiet:
            out = c.stdout()
            out.print(
                f"{summary['kind']} curve: {summary['points']} points, "
                f"{summary['parameter']} {summary['range'][0]:.6g} … {summary['range'][1]:.6g}, "
                f"{summary['parameter2']} {summary['range2'][0]:.6g} … "
                f"{summary['range2'][1]:.6g}"
            )
            out.print(f"ends: {summary['stop_reason']}")
            u = summary["uncertainty"]
            if u["assessed"]:
                out.print(
                    f"uncertainty ({u['assessed']} points corrected again 100 times tighter): "
                    f"{summary['parameter']} ± {u['max']:.2g}, {summary['parameter2']} ± "
                    f"{u['max2']:.2g} at most"
                )
            for e in summary["codim2"]:
                out.print(
                    f"  {e['kind']} at {summary['parameter']}={e['value']:.8g}, "
                    f"{summary['parameter2']}={e['value2']:.8g}"
                )
            shown = escape_path(path)
            out.print(Text(f"next: gearchaos plot MAP.zarr --boundaries {shown} -o chart.png",
                           style="dim"))  # fmt: skip
    c.wrote(path)


def curve_summary(ds: Any) -> dict[str, Any]:
    """A JSON-serialisable summary of a curve: kind, parameters, ranges, points, stop reason
    and codimension-2 points."""
    n1, n2 = str(ds.attrs["parameter"]), str(ds.attrs["parameter2"])
    return {
        "kind": str(ds.attrs["curve_kind"]),
        "parameter": n1,
        "parameter2": n2,
        "points": int(ds.sizes["point"]),
        "range": [float(ds[n1].min()), float(ds[n1].max())],
        "range2": [float(ds[n2].min()), float(ds[n2].max())],
        "stop_reason": str(ds.attrs["stop_reason"]),
        "uncertainty": _uncertainty(ds),
        "codim2": [
            {
                "kind": str(ds.event_kind.values[k]),
                "value": float(ds.event_value.values[k]),
                "value2": float(ds.event_value2.values[k]),
                "uncertainty": float(ds.event_uncertainty.values[k]),
                "uncertainty2": float(ds.event_uncertainty2.values[k]),
            }
            for k in range(ds.sizes.get("event", 0))
        ],
    }


def _uncertainty(ds: Any) -> dict[str, Any]:
    """How many points state their uncertainty, and the largest of each parameter."""
    import numpy as np

    u = np.asarray(ds.uncertainty.values) if "uncertainty" in ds else np.zeros(0)
    u2 = np.asarray(ds.uncertainty2.values) if "uncertainty2" in ds else np.full(u.shape, np.nan)
    done = ~np.isnan(u)
    return {
        "assessed": int(done.sum()),
        "max": float(u[done].max()) if done.any() else None,
        "max2": float(np.nan_to_num(u2[done], nan=0.0).max()) if done.any() else None,
    }


def is_curve_file(path: Path) -> bool:
    """Whether ``path`` is a boundary-curve file (a branch file of two parameters)."""
    from ..dynamics.continuation.branch import open_branch

    try:
        return bool(open_branch(path).attrs.get("kind") == "boundary_curve")
    except Exception:  # not a branch file at all: the plot command reports it
        return False


def boundaries_figure(curves: list[Path], res: Any) -> Any:
    """The stability chart of ``plot MAP --boundaries CURVE.nc`` (``res`` the map's
    :class:`~gearchaos.sweep.SweepResult`) or of ``plot CURVE.nc`` alone (``res`` None)."""
    from ..dynamics.curves.file import open_curve
    from ..plot import figure_for

    opened = [open_curve(p) for p in curves]
    return figure_for(opened) if res is None else figure_for(res, boundaries=opened)
