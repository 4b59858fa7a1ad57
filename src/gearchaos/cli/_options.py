"""The options many commands share, declared once: the target (``--preset``, ``--gearset``,
``--model``, ``--set``), the protocol and solver (``--transient``, ``--periods``, ``--settle``,
``--perturbation``, ``--rtol``, ``--atol``), execution (``--workers``) and output (``--json``,
``--quiet``, ``--overwrite``). :mod:`._common` re-exports them (``c.PresetOpt``)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

#: Gear set used when neither ``--preset`` nor ``--gearset`` is given.
DEFAULT_PRESET = "sheng2016"

PresetOpt = Annotated[
    str | None,
    typer.Option(
        "--preset",
        "-p",
        help=f"Built-in gear set (see `gearchaos presets`). Default: {DEFAULT_PRESET}.",
        show_default=False,
    ),
]
GearsetOpt = Annotated[
    Path | None,
    typer.Option(
        "--gearset",
        "-g",
        help="Gear-set TOML file (start from `gearchaos init-gearset`). Excludes --preset.",
        dir_okay=False,
        show_default=False,
    ),
]
ModelOpt = Annotated[
    str | None,
    typer.Option(
        "--model",
        "-m",
        help="Your own model instead of a gear set: FILE.py:CLASS, MODULE:CLASS or an installed "
        "name (see docs/howto/own-model.md); --set NAME=VALUE sets its parameters. Excludes "
        "--preset and --gearset. With --from, the model the file records: naming it is your "
        "consent to run its code, which a file alone never gets.",
        show_default=False,
    ),
]
FromModelOpt = Annotated[
    str | None,
    typer.Option(
        "--model",
        "-m",
        help="The model a file records, when it is your own (FILE.py:CLASS, MODULE:CLASS or an "
        "installed name; see docs/howto/own-model.md): naming it is your consent to run its "
        "code, which a file alone never gets.",
        show_default=False,
    ),
]
SetOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--set",
        "-s",
        help=(
            "NAME=VALUE, repeatable: omega=1.5 (the dimensionless mesh frequency Ω), "
            "xi=0.05 (all damping ratios), or any dotted gear-set parameter such as "
            "backlash.sun_planet=3, clearance.sun_bearing=2, torque.input=1500; with --model, "
            "omega and the model's own parameters (its field names)."
        ),
        show_default=False,
    ),
]
JsonOpt = Annotated[
    bool, typer.Option("--json", help="Print the result as JSON on stdout, and nothing else.")
]
QuietOpt = Annotated[
    bool, typer.Option("--quiet", "-q", help="No progress bar and no summary (errors only).")
]
TransientOpt = Annotated[
    float, typer.Option("--transient", help="Mesh periods discarded before recording.")
]
SettleOpt = Annotated[
    str,
    typer.Option(
        "--settle",
        help=(
            "off: always --transient periods of transient; auto: end it early once the Poincaré "
            "sections repeat (period ≤ 64), never later than --transient."
        ),
    ),
]
PerturbationOpt = Annotated[
    float | None,
    typer.Option(
        "--perturbation",
        help=(
            "Size of the reproducible perturbation of the start from rest that breaks the "
            "planets' symmetry as in any real gearbox (default 1e-6; 0: the exact symmetric "
            "start)."
        ),
        show_default=False,
    ),
]
PeriodsOpt = Annotated[
    int, typer.Option("--periods", help="Mesh periods recorded (one Poincaré point each).")
]
RtolOpt = Annotated[
    float,
    typer.Option("--rtol", help="Relative tolerance of the integrator (Dormand–Prince 5(4))."),
]
AtolOpt = Annotated[float, typer.Option("--atol", help="Absolute tolerance of the integrator.")]
WorkersOpt = Annotated[
    int | None,
    typer.Option(
        "--workers",
        "-w",
        help="Local worker processes (default: in-process on all cores).",
        show_default=False,
    ),
]
OverwriteOpt = Annotated[
    bool,
    typer.Option("--overwrite", help="Replace an existing store made with other settings."),
]
