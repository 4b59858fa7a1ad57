"""Command-line interface: ``gearchaos simulate | bifurcation | classify | plot | poincare |
reproduce | info | presets | init-gearset``.

Every command takes the gear set the same way: ``--preset NAME`` (default ``sheng2016``) or
``--gearset FILE.toml`` (one of the two), then any number of ``--set NAME=VALUE`` changes by
the dotted parameter names of :func:`gearchaos.gearset.io.field_names` (``backlash.sun_planet``,
``teeth.sun``, the alias ``xi`` for the three damping ratios). ``omega`` (the dimensionless mesh
frequency Ω = ω/ω_n) is a simulation setting, not a gear-set field, but is given with
``--set omega=1.5`` as well, so that a command line reads like a point of a sweep.

Exit codes: 0 success; 2 invalid input (unknown or invalid parameter, conflicting options,
missing gear-set file, a sweep store made with other settings) — the message names the
parameter, the rule and the value and suggests the closest valid name; 1 the integration failed
or a file could not be written; 130 a sweep interrupted with Ctrl-C (its store keeps every
finished chunk). Errors are reported on stderr as one line, never as a traceback.
"""

from __future__ import annotations

import contextlib
import difflib
import json
import math
import sys
import warnings
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, NoReturn

import numpy as np
import typer
from rich.columns import Columns
from rich.console import Console
from rich.markup import escape
from rich.table import Table
from rich.text import Text

from . import __version__
from .errors import IntegrationError, ParameterError, Status, StoreError

if TYPE_CHECKING:
    from .gearset import GearSet

__all__ = ["DEFAULT_OMEGA", "DEFAULT_PRESET", "app", "parse_sets"]

#: Ω used by ``gearchaos simulate`` when no ``--set omega=...`` is given.
DEFAULT_OMEGA = 1.5
#: Gear set used when neither ``--preset`` nor ``--gearset`` is given.
DEFAULT_PRESET = "sheng2016"

EXIT_FAILURE = 1
EXIT_INVALID = 2
EXIT_INTERRUPTED = 130

#: Figures of the seed paper that ``gearchaos reproduce`` knows: bifurcation diagrams
#: (:mod:`gearchaos.paper.recipes`) and Poincaré galleries (:data:`GALLERY_FIGURES`).
PAPER_FIGURES = ("fig4", "fig5", "fig6", "fig7", "fig8", "fig9", "fig10", "fig11", "fig12")
#: The Poincaré galleries among them (:mod:`gearchaos.paper.galleries`).
GALLERY_FIGURES = ("fig5", "fig7", "fig10")
INTERRUPTED_MESSAGE = (
    "interrupted: the store keeps every finished chunk; run the same command again to resume"
)

app = typer.Typer(
    name="gearchaos",
    help=(
        "Nonlinear dynamics of planetary gear trains with backlash and bearing clearance: "
        "simulate a gear set at a mesh frequency, sweep any parameter into bifurcation "
        "diagrams and maps, reproduce the seed paper's figures, inspect linear properties, "
        "manage gear-set files. Parameters are addressed by dotted names "
        "(backlash.sun_planet, teeth.sun, xi, ...), the same as in Python and in result files."
    ),
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode="markdown",
    context_settings={"help_option_names": ["-h", "--help"]},
)


# --------------------------------------------------------------------------- consoles, errors
def _stdout() -> Console:
    return Console(highlight=False)


def _stderr() -> Console:
    return Console(stderr=True, highlight=False)


def _fail(message: str, code: int) -> NoReturn:
    _stderr().print(Text("error: ", style="bold red") + Text(message), soft_wrap=True)
    raise typer.Exit(code)


@contextlib.contextmanager
def _reported_errors() -> Iterator[None]:
    """Turn the package's exceptions into one line on stderr and an exit code."""
    try:
        yield
    except (ParameterError, StoreError) as exc:
        _fail(str(exc), EXIT_INVALID)
    except FileNotFoundError as exc:
        _fail(str(exc), EXIT_INVALID)
    except IntegrationError as exc:
        _fail(str(exc), EXIT_FAILURE)
    except OSError as exc:
        where = f": '{exc.filename}'" if getattr(exc, "filename", None) else ""
        _fail(f"{exc.strerror or exc}{where}", EXIT_FAILURE)


def _jsonable(obj: Any) -> Any:
    """A JSON-ready copy: numpy scalars and arrays to Python, non-finite floats to null."""
    if isinstance(obj, Mapping):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.generic):
        return _jsonable(obj.item())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, Path):
        return str(obj)
    return obj


def _print_json(obj: Any) -> None:
    typer.echo(json.dumps(_jsonable(obj), indent=2, ensure_ascii=False, allow_nan=False))


# --------------------------------------------------------------------------- --set parsing
def _parse_float(name: str, raw: str) -> float:
    try:
        return float(raw)
    except ValueError:
        raise ParameterError(f"{name} must be a number: got {raw!r}") from None


def _parse_int(name: str, raw: str) -> int:
    try:
        return int(raw)
    except ValueError:
        pass
    try:
        value = float(raw)
    except ValueError:
        value = math.nan
    if value.is_integer():
        return int(value)
    raise ParameterError(f"{name} must be an integer: got {raw!r}")


def _parse_floats(name: str, raw: str) -> tuple[float, ...]:
    text = raw.strip()
    if text.startswith("[") and text.endswith("]"):
        text = text[1:-1]
    items = [item.strip() for item in text.split(",") if item.strip()]
    return tuple(_parse_float(f"{name}[{i}]", item) for i, item in enumerate(items))


def _unquote(raw: str) -> str:
    if len(raw) >= 2 and raw[0] == raw[-1] and raw[0] in "'\"":
        return raw[1:-1]
    return raw


def _parse_value(key: str, raw: str) -> object:
    """Convert the text of ``--set key=raw`` to the Python type of the field ``key``."""
    from .gearset.io import ALIASES
    from .gearset.validation import FIELD_KINDS, RECORD_CLASSES

    kind = FIELD_KINDS.get(key)
    if key in ALIASES:
        kind = "float"
    elif key in ("name", "description"):
        kind = "str"
    if kind == "int":
        return _parse_int(key, raw)
    if kind == "float":
        return _parse_float(key, raw)
    if kind == "floats":
        return _parse_floats(key, raw)
    if kind == "str":
        return _unquote(raw)
    if key in RECORD_CLASSES:
        names = [n for n in FIELD_KINDS if n.startswith(key + ".")]
        raise ParameterError(
            f"{key} is a table, not a parameter; set one of its fields: {', '.join(names)}"
        )
    close = difflib.get_close_matches(key.lower(), [*FIELD_KINDS, *ALIASES, "omega"], n=1)
    if close == ["omega"]:
        raise ParameterError(f"unknown parameter {key!r}; did you mean 'omega'?")
    return raw  # GearSet.evolve reports the unknown name with its own suggestion


def parse_sets(items: Sequence[str]) -> tuple[float | None, dict[str, object]]:
    """Split ``--set NAME=VALUE`` options into Ω and gear-set changes.

    Parameters
    ----------
    items : sequence of str
        The option values, e.g. ``["omega=1.5", "xi=0.05", "backlash.sun_planet=3"]``.
        Values are parsed by the kind of the field: integers for tooth and planet numbers,
        numbers for physical values, comma-separated numbers (optionally in brackets) for the
        stiffness harmonics, text for ``torque.mode``, ``*.units``, ``mesh_phasing.model``,
        ``name`` and ``description``. A name given twice keeps its last value.

    Returns
    -------
    omega : float or None
        The value of ``omega`` if given.
    changes : dict
        The other names and their parsed values, for :meth:`GearSet.evolve`, which rejects
        unknown names with a suggestion.

    Raises
    ------
    ParameterError
        For an item without ``=``, a value that does not parse as its field's kind, or
        ``omega`` not a finite number > 0.
    """
    omega: float | None = None
    changes: dict[str, object] = {}
    for item in items:
        key, sep, raw = item.partition("=")
        key, raw = key.strip(), raw.strip()
        if not sep or not key:
            raise ParameterError(f"--set expects NAME=VALUE (e.g. omega=1.5): got {item!r}")
        if key == "omega":
            omega = _parse_float("omega", raw)
            if not (math.isfinite(omega) and omega > 0):
                raise ParameterError(f"omega must be a finite number > 0: got {raw!r}")
        else:
            changes[key] = _parse_value(key, raw)
    return omega, changes


def _gearset(
    preset: str | None, gearset_file: Path | None, changes: Mapping[str, object]
) -> GearSet:
    from .gearset import GearSet
    from .gearset import preset as load_preset

    if preset is not None and gearset_file is not None:
        raise ParameterError(
            f"--preset and --gearset are mutually exclusive: got --preset {preset} and "
            f"--gearset {gearset_file}; give one (default: --preset {DEFAULT_PRESET})"
        )
    if gearset_file is not None:
        gs = GearSet.from_toml(gearset_file)
    else:
        gs = load_preset(preset if preset is not None else DEFAULT_PRESET)
    return gs.evolve(dict(changes)) if changes else gs


# --------------------------------------------------------------------------- shared options
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
SetOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--set",
        "-s",
        help=(
            "NAME=VALUE, repeatable: omega=1.5 (the dimensionless mesh frequency Ω), "
            "xi=0.05 (all damping ratios), or any dotted gear-set parameter such as "
            "backlash.sun_planet=3, clearance.sun_bearing=2, torque.input=1500."
        ),
        show_default=False,
    ),
]
JsonOpt = Annotated[
    bool, typer.Option("--json", help="Print the result as JSON on stdout, and nothing else.")
]


def _version_callback(value: bool) -> None:
    if value:
        typer.echo(f"gearchaos {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: Annotated[
        bool,
        typer.Option(
            "--version",
            "-V",
            callback=_version_callback,
            is_eager=True,
            help="Print the version and exit.",
        ),
    ] = False,
) -> None:
    """gearchaos: nonlinear dynamics of planetary gear trains with clearances."""


# --------------------------------------------------------------------------- simulate
@app.command()
def simulate(
    preset: PresetOpt = None,
    gearset: GearsetOpt = None,
    set_: SetOpt = None,
    transient: Annotated[
        float, typer.Option("--transient", help="Mesh periods discarded before recording.")
    ] = 100.0,
    periods: Annotated[
        int, typer.Option("--periods", help="Mesh periods recorded (one Poincaré point each).")
    ] = 200,
    samples_per_period: Annotated[
        int,
        typer.Option(
            "--samples-per-period",
            help="Samples per mesh period of the time history (figure, spectra).",
        ),
    ] = 64,
    rtol: Annotated[
        float, typer.Option("--rtol", help="Relative tolerance (Dormand–Prince 5(4)).")
    ] = 1e-8,
    atol: Annotated[float, typer.Option("--atol", help="Absolute tolerance.")] = 1e-10,
    output: Annotated[
        Path | None,
        typer.Option(
            "--output",
            "-o",
            help=(
                "Directory for simulation.nc (netCDF, all samples and the gear set) and "
                "simulation.png (summary figure); created if missing. "
                "Without -o nothing is written."
            ),
            file_okay=False,
            show_default=False,
        ),
    ] = None,
    json_out: JsonOpt = False,
    plot: Annotated[
        bool, typer.Option("--plot/--no-plot", help="Write the summary figure (with -o).")
    ] = True,
    lyapunov: Annotated[
        bool,
        typer.Option(
            "--lyapunov",
            help=(
                "Also compute the largest Lyapunov exponent (same transient, periods and "
                "tolerances); it decides quasi-periodic vs chaotic motion."
            ),
        ),
    ] = False,
) -> None:
    """Simulate a gear set at one mesh frequency and summarise the steady response.

    Runs the seed paper's protocol (MODEL.md §8): zero initial state, adaptive Dormand–Prince
    5(4), TRANSIENT mesh periods discarded, then PERIODS recorded with a Poincaré point
    X̄_sp1 = δ_sp1/b_c at each τ_k = 2πk/Ω. Ω is set with **--set omega=...**
    (default **1.5**). Prints the motion label (1T … nT, QP, chaos or unresolved, with the
    0–1 test K and, with **--lyapunov**, the largest Lyapunov exponent λ₁ that decides it), the
    section range of X̄_sp1 and the contact regime of every mesh.

    Example: **gearchaos simulate --preset sheng2016 --set omega=1.5 --set xi=0.05 -o out/**
    """
    with _reported_errors():
        omega, changes = parse_sets(set_ or [])
        gs = _gearset(preset, gearset, changes)
        omega = DEFAULT_OMEGA if omega is None else omega
        if output is not None:
            output.mkdir(parents=True, exist_ok=True)
        result, caught = _run_simulation(
            gs,
            omega,
            quiet=json_out,
            transient_periods=transient,
            periods=periods,
            samples_per_period=samples_per_period,
            rtol=rtol,
            atol=atol,
        )
        for w in caught:
            _stderr().print(
                Text("warning: ", style="bold yellow") + Text(str(w.message)), soft_wrap=True
            )

        from .analysis.summary import summarize

        lle = (
            _largest_exponent(result, transient=transient, periods=periods, rtol=rtol, atol=atol)
            if lyapunov
            else None
        )
        summary = summarize(result, lle=lle)
        written: list[Path] = []
        if output is not None:
            nc = output / "simulation.nc"
            result.save(nc)
            written.append(nc)
            if plot:
                written.append(_save_figure(result, output / "simulation.png"))

    if json_out:
        _print_json(summary)
        for path in written:
            _stderr().print(f"wrote {path}")
        return
    from .analysis.summary import format_summary

    out = _stdout()
    table = format_summary(summary, title=f"gearchaos simulation of {gs.name} at Ω = {omega:g}")
    _add_motion_rows(table, summary)
    out.print(table)
    out.print(
        Text(
            f"{transient:g} transient + {periods} recorded mesh periods, "
            f"rtol {rtol:g}, atol {atol:g}",
            style="dim",
        )
    )
    for path in written:
        out.print(Text.assemble(("wrote ", "dim"), (str(path), "bold")), soft_wrap=True)


def _largest_exponent(
    result: Any, *, transient: float, periods: int, rtol: float, atol: float
) -> float | None:
    """λ₁ of a simulated system at the run's settings (None, with a warning, if it fails)."""
    from .analysis.lyapunov import lyapunov_spectrum

    if not result.status.ok:
        return None
    err = _stderr()
    spinner: contextlib.AbstractContextManager[Any] = contextlib.nullcontext()
    if err.is_terminal:
        spinner = err.status("largest Lyapunov exponent…")
    with spinner:
        lr = lyapunov_spectrum(
            result.system,
            n_exponents=1,
            transient_periods=transient,
            periods=periods,
            rtol=rtol,
            atol=atol,
        )
    value = float(lr.largest)
    if not (lr.status.ok and math.isfinite(value)):
        err.print(
            Text("warning: ", style="bold yellow")
            + Text(f"the Lyapunov exponent could not be computed: {lr.status.message}"),
            soft_wrap=True,
        )
        return None
    return value


def _add_motion_rows(table: Table, summary: Mapping[str, Any]) -> None:
    """The motion indicators of a summary as rows of its table."""
    lle = summary.get("lle")
    k01 = summary.get("k01")
    table.add_row("largest Lyapunov exponent λ₁", "—" if lle is None else f"{lle:.4g}")
    table.add_row("0–1 test K", "—" if k01 is None else f"{k01:.3f}")
    agree = summary.get("indicators_agree")
    if agree is not None:
        table.add_row(
            "indicators agree", Text("yes" if agree else "no", style="" if agree else "bold red")
        )
    note = summary.get("motion_note")
    if note:
        table.add_row("motion note", escape(str(note)))


def _run_simulation(
    gs: GearSet, omega: float, *, quiet: bool, **settings: Any
) -> tuple[Any, list[warnings.WarningMessage]]:
    """``gearchaos.simulate`` under a spinner on stderr, collecting warnings."""
    from .integrate import simulate as run

    err = _stderr()
    spinner: contextlib.AbstractContextManager[Any] = contextlib.nullcontext()
    if not quiet and err.is_terminal:
        total = settings["transient_periods"] + settings["periods"]
        spinner = err.status(f"integrating {gs.name} at Ω = {omega:g}, {total:g} mesh periods…")
    with spinner, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = run(gs, omega=omega, **settings)
    return result, list(caught)


def _save_figure(result: Any, path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .plot import savefig, summary_figure

    fig = summary_figure(result)
    try:
        savefig(fig, path)
    finally:
        plt.close(fig)
    return path


# --------------------------------------------------------------------------- info
@app.command()
def info(
    preset: PresetOpt = None,
    gearset: GearsetOpt = None,
    set_: SetOpt = None,
    json_out: JsonOpt = False,
) -> None:
    """Linear properties of a gear set: radii, equivalent masses, ω_n, damping coefficients,
    dimensionless groups, mesh phasing and natural frequencies with their mode classes.

    With **--set omega=...** the operating point (mesh frequency, sun speed) is added.
    """
    with _reported_errors():
        omega, changes = parse_sets(set_ or [])
        gs = _gearset(preset, gearset, changes)
        from .analysis.derived import gearset_info

        data = dict(gearset_info(gs))
        if omega is not None:
            data["operating_point"] = {
                "omega": omega,
                "mesh_frequency_rad_s": omega * gs.omega_n,
                "mesh_frequency_hz": omega * gs.omega_n / (2.0 * math.pi),
                "sun_speed_rpm": gs.sun_speed_rpm(omega),
            }
    if json_out:
        _print_json(data)
        return
    out = _stdout()
    out.print(Text.assemble(("gear set ", "dim"), (gs.name, "bold")))
    if gs.description:
        out.print(Text(gs.description, style="dim"))
    out.print()
    for renderable in _info_renderables(data):
        out.print(renderable)


# Labels of the gearset_info() entries (symbols of MODEL.md); unknown keys get a label
# made from the key, so new entries show up without a change here.
_LABELS: dict[str, str] = {
    "planets": "planets N",
    "teeth.sun": "sun teeth z_s",
    "teeth.planet": "planet teeth z_p",
    "teeth.ring": "ring teeth z_r",
    "omega_n_rad_s": "ω_n = √(k_m,sp/m_e) [rad/s]",
    "omega_n_hz": "ω_n/2π [Hz]",
    "output_torque_N_m": "output torque T_L [N m]",
    "torque_ratio": "torque ratio T_L/T_D",
    "load_mode": "load mode",
    "reference_omega": "Ω_ref (constant power)",
    "static_mesh_force_N": "static mesh force T_D/(N r_bs) [N]",
    "mesh_phasing.model": "mesh phasing model",
    "mesh_phasing.class": "phasing class",
    "mesh_phasing.k": "k = z_r mod N",
    "radii_m.sun": "r_s sun pitch",
    "radii_m.planet": "r_p planet pitch",
    "radii_m.ring": "r_r ring pitch",
    "radii_m.carrier": "r_c = r_s + r_p",
    "radii_m.base_sun": "r_bs = r_s cos α_s",
    "radii_m.base_planet": "r_bp = r_p cos α_s",
    "equivalent_masses_kg.sun": "m_s* = J_s/r_bs²",
    "equivalent_masses_kg.planet": "m_p* = J_p/r_bp²",
    "equivalent_masses_kg.carrier": "m_c* = J_c/r_c² + N m_p",
    "equivalent_masses_kg.mesh": "m_e = m_s* m_p*/(m_s* + m_p*)",
    "damping_coefficients_N_s_per_m.sun_planet": "c_sp = 2ξ_sp √(k_m,sp m_e)",
    "damping_coefficients_N_s_per_m.planet_ring": "c_rp = 2ξ_rp √(k_m,rp m_p*)",
    "damping_coefficients_N_s_per_m.sun_bearing": "c_s = 2ξ_s √(k_s m_s)",
    "dimensionless.mu_s": "μ_s = m_s/m_e",
    "dimensionless.mu_s_star": "μ_s* = m_s*/m_e",
    "dimensionless.mu_p_star": "μ_p* = m_p*/m_e",
    "dimensionless.mu_c_star": "μ_c* = m_c*/m_e",
    "dimensionless.eps_sp": "ε_sp = k_a,sp/k_m,sp",
    "dimensionless.kappa_rp_mean": "κ_rp mean = k_m,rp/k_m,sp",
    "dimensionless.kappa_rp_alt": "κ_rp alternating = k_a,rp/k_m,sp",
    "dimensionless.kappa_b": "κ_b = k_s/k_m,sp",
    "dimensionless.damping_sun_planet": "c̄_sp = c_sp/(m_e ω_n)",
    "dimensionless.damping_planet_ring": "c̄_rp = c_rp/(m_e ω_n)",
    "dimensionless.damping_sun_bearing": "c̄_s = c_s/(m_e ω_n)",
    "dimensionless.b_sp": "b̄_sp",
    "dimensionless.b_rp": "b̄_rp",
    "dimensionless.b_s": "b̄_s",
    "dimensionless.torque_input": "T̄_D",
    "dimensionless.torque_output": "T̄_L",
    "dimensionless.te_sp": "Ā_sp",
    "dimensionless.te_rp": "Ā_rp",
    "dimensionless.harmonics_sp": "stiffness harmonics sp",
    "dimensionless.harmonics_rp": "stiffness harmonics rp",
    "static_deflection.sun_planet_m": "sun–planet F/k_m,sp [m]",
    "static_deflection.sun_planet_bar": "sun–planet F/(k_m,sp b_c)",
    "static_deflection.planet_ring_m": "planet–ring F/k_m,rp [m]",
    "static_deflection.planet_ring_bar": "planet–ring F/(k_m,rp b_c)",
    "natural_frequencies.hz": "f [Hz]",
    "natural_frequencies.ratio": "ω/ω_n",
    "natural_frequencies.kind": "mode class",
    "natural_frequencies.multiplicity": "multiplicity",
    "omega_at_resonances.mode_ratio": "mode ω/ω_n",
    "omega_at_resonances.kind": "mode class",
    "omega_at_resonances.harmonic": "harmonic h",
    "omega_at_resonances.omega": "Ω = (ω/ω_n)/h",
    "operating_point.omega": "Ω = ω/ω_n",
    "operating_point.mesh_frequency_rad_s": "mesh frequency ω [rad/s]",
    "operating_point.mesh_frequency_hz": "mesh frequency [Hz]",
    "operating_point.sun_speed_rpm": "sun speed [rpm]",
}
_TITLES: dict[str, str] = {
    "radii_m": "Radii [m]",
    "equivalent_masses_kg": "Equivalent masses [kg]",
    "damping_coefficients_N_s_per_m": "Damping [N s/m]",
    "dimensionless": "Dimensionless groups (MODEL.md §7)",
    "static_deflection": "Static mesh deflection",
    "natural_frequencies": "Natural frequencies (mean stiffness, no clearance)",
    "omega_at_resonances": "Resonances: mesh harmonic h·Ω meets a mode",
    "operating_point": "Operating point",
}
#: Groups shown as rows of the overview table rather than as tables of their own.
_OVERVIEW_GROUPS = ("teeth", "mesh_phasing")
_UNIT_SUFFIXES = (
    ("_N_s_per_m", "N s/m"),
    ("_rad_s", "rad/s"),
    ("_N_m", "N m"),
    ("_rpm", "rpm"),
    ("_hz", "Hz"),
    ("_kg", "kg"),
    ("_m", "m"),
    ("_N", "N"),
)


def _label(path: str) -> str:
    """The label of an info entry: from :data:`_LABELS`, else made from the key."""
    if path in _LABELS:
        return _LABELS[path]
    key = path.rsplit(".", 1)[-1]
    for suffix, unit in _UNIT_SUFFIXES:
        if key.endswith(suffix) and len(key) > len(suffix):
            return f"{key[: -len(suffix)].replace('_', ' ')} [{unit}]"
    return key.replace("_", " ")


def _fmt(value: Any) -> str:
    if isinstance(value, bool) or value is None:
        return "—" if value is None else str(value)
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.6g}"
    if isinstance(value, (list, tuple)):
        return ", ".join(_fmt(v) for v in value) or "—"
    return str(value)


def _flatten(prefix: str, value: Mapping[str, Any]) -> Iterator[tuple[str, Any]]:
    for k, v in value.items():
        path = f"{prefix}.{k}" if prefix else str(k)
        if isinstance(v, Mapping):
            yield from _flatten(path, v)
        else:
            yield path, v


def _pairs_table(title: str | None) -> Table:
    table = Table(title=escape(title) if title else None, title_justify="left", show_header=False)
    table.add_column("quantity", style="cyan")
    table.add_column("value", justify="right")
    return table


def _info_renderables(data: Mapping[str, Any]) -> list[Any]:
    """Rich tables of a :func:`gearset_info` dictionary: an overview of the scalars, the
    groups of numbers side by side, then the mode and resonance lists."""
    overview = _pairs_table(None)
    groups: list[Table] = []
    lists: list[Table] = []
    for key, value in data.items():
        if key in ("name", "description"):
            continue
        if isinstance(value, Mapping):
            target = overview if key in _OVERVIEW_GROUPS else _pairs_table(_TITLES.get(key, key))
            for path, v in _flatten(key, value):
                target.add_row(escape(_label(path)), escape(_fmt(v)))
            if target is not overview:
                groups.append(target)
        elif (
            isinstance(value, (list, tuple))
            and value
            and all(isinstance(v, Mapping) for v in value)
        ):
            columns: list[str] = []
            for row in value:
                columns.extend(k for k in row if k not in columns)
            table = Table(title=escape(_TITLES.get(key, key)), title_justify="left")
            for col in columns:
                table.add_column(
                    escape(_label(f"{key}.{col}")), justify="left" if col == "kind" else "right"
                )
            for row in value:
                table.add_row(*(escape(_fmt(row.get(col))) for col in columns))
            lists.append(table)
        else:
            overview.add_row(escape(_label(key)), escape(_fmt(value)))
    out: list[Any] = [overview]
    if groups:
        out.append(Columns(groups, padding=(0, 2)))
    return [*out, *lists]


# --------------------------------------------------------------------------- bifurcation
QuietOpt = Annotated[
    bool, typer.Option("--quiet", "-q", help="No progress bar and no summary (errors only).")
]


def _parse_planets(raw: str | None) -> tuple[int, ...]:
    if raw is None:
        return (1,)
    items = [item.strip() for item in raw.split(",") if item.strip()]
    if not items:
        raise ParameterError(f"--planets must be planet numbers such as 1,2: got {raw!r}")
    planets = tuple(_parse_int("--planets", item) for item in items)
    bad = [p for p in planets if p < 1]
    if bad:
        raise ParameterError(f"--planets must be planet numbers >= 1: got {raw!r}")
    return planets


def _axis_name(item: str) -> str:
    return item.partition("=")[0].strip()


@contextlib.contextmanager
def _interruptible() -> Iterator[None]:
    """Ctrl-C (and SIGTERM, which the sweep engine turns into it) → one line and exit 130."""
    try:
        yield
    except KeyboardInterrupt:
        _fail(INTERRUPTED_MESSAGE, EXIT_INTERRUPTED)


def _sweep_counts(ds: Any) -> tuple[int, int]:
    """(points, failed) of a sweep dataset: every grid point, and those with status 1–3."""
    status = np.asarray(ds["status"].values)
    failed = int(np.sum((status != Status.OK) & (status != Status.NOT_RUN)))
    return int(status.size), failed


@app.command()
def bifurcation(
    output: Annotated[
        Path,
        typer.Option(
            "--output",
            "-o",
            help=(
                "Zarr store to write (a directory, e.g. run.zarr). Written chunk by chunk; run "
                "the same command again after an interruption to resume."
            ),
            show_default=False,
        ),
    ],
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
    preset: PresetOpt = None,
    gearset: GearsetOpt = None,
    set_: SetOpt = None,
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
    ic: Annotated[
        str,
        typer.Option(
            "--ic",
            help=(
                "Initial conditions: fresh (zero state at every point, the seed's protocol) or "
                "continuation (each point starts from the previous point's final state)."
            ),
        ),
    ] = "fresh",
    direction: Annotated[
        str,
        typer.Option(
            "--direction",
            help="up, down or both (continuation only; both overlays the branches).",
        ),
    ] = "up",
    transient: Annotated[
        float, typer.Option("--transient", help="Mesh periods discarded at every point.")
    ] = 100.0,
    periods: Annotated[
        int,
        typer.Option("--periods", help="Mesh periods recorded at every point (section points)."),
    ] = 100,
    rtol: Annotated[
        float, typer.Option("--rtol", help="Relative tolerance (Dormand–Prince 5(4)).")
    ] = 1e-8,
    atol: Annotated[float, typer.Option("--atol", help="Absolute tolerance.")] = 1e-10,
    workers: Annotated[
        int | None,
        typer.Option(
            "--workers",
            "-w",
            help="Local worker processes (default: in-process on all cores).",
            show_default=False,
        ),
    ] = None,
    scheduler: Annotated[
        str | None,
        typer.Option(
            "--scheduler",
            help="Address of a running dask.distributed scheduler, e.g. tcp://HOST:8786.",
            show_default=False,
        ),
    ] = None,
    dask_local: Annotated[
        int | None,
        typer.Option(
            "--dask-local",
            help="Start a local Dask cluster with N workers on this machine.",
            show_default=False,
        ),
    ] = None,
    overwrite: Annotated[
        bool,
        typer.Option("--overwrite", help="Replace an existing store made with other settings."),
    ] = False,
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
    quiet: QuietOpt = False,
    json_out: JsonOpt = False,
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
    with _reported_errors(), _interruptible():
        if not vary:
            raise ParameterError(
                "--vary is required: give NAME=VALUES once (e.g. --vary omega=0.1:4:800) "
                "or twice for a 2-D map"
            )
        if len(vary) > 2:
            raise ParameterError(
                f"--vary may be given once or twice (two make a 2-D map): got {len(vary)}"
            )
        if ic not in ("fresh", "continuation"):
            raise ParameterError(f"--ic must be fresh or continuation: got {ic!r}")
        if direction not in ("up", "down", "both"):
            raise ParameterError(f"--direction must be up, down or both: got {direction!r}")
        if direction != "up" and ic != "continuation":
            raise ParameterError(
                f"--direction {direction} needs --ic continuation "
                "(fresh starts do not depend on the sweep direction)"
            )
        omega, changes = parse_sets(set_ or [])
        gs = _gearset(preset, gearset, {})
        swept = {_axis_name(v) for v in vary} | ({_axis_name(family)} if family else set())
        fixed: dict[str, Any] = dict(changes)
        for name in swept & set(fixed):
            raise ParameterError(f"{name} is both swept and set with --set; choose one")
        if "omega" not in swept:
            if omega is None:
                omega = DEFAULT_OMEGA
                if not (quiet or json_out):
                    _stderr().print(
                        Text(
                            f"Ω = {DEFAULT_OMEGA:g} (not swept; change it with --set omega=...)",
                            style="dim",
                        )
                    )
            fixed["omega"] = omega
        elif omega is not None:
            raise ParameterError("omega is both swept and set with --set; choose one")

        import time

        from .sweep import bifurcation as run_bifurcation

        t0 = time.perf_counter()
        ds = run_bifurcation(
            gs,
            list(vary),
            family=family,
            fixed=fixed,
            observe=tuple(observe) if observe else ("delta_sp", "delta_sp_dot"),
            planets=_parse_planets(planets),
            initial_conditions=ic,
            direction=direction,
            transient_periods=transient,
            periods=periods,
            rtol=rtol,
            atol=atol,
            lyapunov=lyapunov,
            store=output,
            overwrite=overwrite,
            workers=workers,
            scheduler=scheduler,
            dask_local=dask_local,
            progress=not quiet,
        )
        seconds = time.perf_counter() - t0
        points, failed = _sweep_counts(ds)

    result = {"store": str(output), "points": points, "failed": failed, "seconds": seconds}
    if json_out:
        _print_json(result)
        return
    if quiet:
        return
    table = _pairs_table(f"gearchaos bifurcation of {gs.name}")
    dims = [d for d in ds["status"].dims]
    table.add_row("grid", escape(" × ".join(f"{d} ({ds.sizes[d]})" for d in dims)))
    table.add_row("points", str(points))
    table.add_row("failed", Text(str(failed), style="bold red" if failed else ""))
    table.add_row("seconds", f"{seconds:.3g}")
    if seconds > 0:
        table.add_row("points/s", f"{points / seconds:.3g}")
    table.add_row("store", escape(str(output)))
    out = _stdout()
    out.print(table)
    out.print(
        Text(
            f"{transient:g} transient + {periods} recorded mesh periods, {ic} initial "
            f"conditions, rtol {rtol:g}, atol {atol:g}"
            + (", largest Lyapunov exponents" if lyapunov else ""),
            style="dim",
        )
    )
    regimes = _stored_regime_table(ds)
    if regimes:
        out.print(_regime_table(regimes, title="motion regimes (fraction of the swept points)"))
    out.print(Text(f"next: gearchaos plot {output} -o {output.stem}.png", style="dim"))


# --------------------------------------------------------------------------- regime tables
def _stored_regime_table(ds: Any) -> dict[str, dict[str, float]]:
    """The ``regime_table`` attribute of a sweep store (empty when it has none)."""
    raw = ds.attrs.get("regime_table")
    if not raw:
        return {}
    try:
        table = json.loads(raw) if isinstance(raw, str) else dict(raw)
    except (TypeError, ValueError):
        return {}
    return {str(k): {str(r): float(f) for r, f in v.items()} for k, v in table.items()}


_SYMBOLS = {
    "omega": "Ω",
    "xi": "ξ",
    "backlash.sun_planet": "b̄_sp",
    "backlash.planet_ring": "b̄_rp",
    "clearance.sun_bearing": "b̄_s",
}


def _column_title(key: str) -> str:
    """``xi=0.03`` → ``ξ = 0.03``; ``all`` → ``all points``."""
    if key == "all":
        return "all points"
    name, sep, value = key.partition("=")
    if not sep:
        return key
    return f"{_SYMBOLS.get(name, name)} = {value}"


def _regime_table(table: Mapping[str, Mapping[str, float]], *, title: str | None) -> Table:
    """A rich table of a regime table: one row per regime (with its palette colour), one
    column per family value, fractions in %."""
    from .analysis.classify import sort_labels
    from .plot.regimes import regime_colour

    labels = sort_labels(label for column in table.values() for label in column)
    out = Table(title=escape(title) if title else None, title_justify="left")
    out.add_column("regime", no_wrap=True)
    for key in table:
        out.add_column(escape(_column_title(key)), justify="right")
    for label in labels:
        cells = []
        for column in table.values():
            f = column.get(label)
            cells.append("—" if f is None else f"{100.0 * f:.1f} %")
        swatch = Text("■ ", style=regime_colour(label)) + Text(label)
        out.add_row(swatch, *cells)
    return out


# --------------------------------------------------------------------------- plot
@app.command()
def plot(
    store: Annotated[
        Path,
        typer.Argument(help="Sweep store written by `gearchaos bifurcation`.", show_default=False),
    ],
    output: Annotated[
        Path,
        typer.Option("--output", "-o", help="Figure file: .png, .pdf or .svg.", show_default=False),
    ],
    var: Annotated[
        str,
        typer.Option(
            "--var", help="Section variable: delta_sp (X̄_sp), delta_sp_dot, delta_rp, x_s, ..."
        ),
    ] = "delta_sp",
    planet: Annotated[int, typer.Option("--planet", help="Planet of per-planet variables.")] = 1,
    clearance: Annotated[
        bool,
        typer.Option("--clearance-lines", help="Dashed lines at ±b̄ of the variable's clearance."),
    ] = False,
    resonances: Annotated[
        bool,
        typer.Option(
            "--resonances",
            help="Vertical lines where the 1st–3rd mesh harmonic meets a natural frequency "
            "(Ω sweeps).",
        ),
    ] = False,
) -> None:
    """Draw a sweep store: bifurcation diagrams (one panel per family value) for a 1-D sweep,
    maps coloured by the number of distinct section points (1T, 2T, …, many) for a 2-D sweep.

    Example: **gearchaos plot fig4.zarr -o fig4.png --clearance-lines**
    """
    from .plot.figure import SAVE_FORMATS

    with _reported_errors():
        if output.suffix.lower() not in SAVE_FORMATS:
            raise ParameterError(
                f"--output must end in one of {', '.join(SAVE_FORMATS)}: got {str(output)!r}"
            )
        ds = _open_store(store)
        import matplotlib

        matplotlib.use("Agg")
        from .plot import savefig, sweep_figure

        fig = sweep_figure(
            ds, var=var, planet=planet, clearance_lines=clearance, resonances=resonances
        )
        if output.parent != Path(""):
            output.parent.mkdir(parents=True, exist_ok=True)
        savefig(fig, output)
    _stdout().print(Text.assemble(("wrote ", "dim"), (str(output), "bold")), soft_wrap=True)


def _open_store(path: Path) -> Any:
    """Open a sweep store; a missing or unreadable one is invalid input (exit 2)."""
    if not path.exists():
        raise ParameterError(f"store not found: {str(path)!r}")
    from .sweep import open_sweep

    try:
        ds = open_sweep(path)
    except Exception as exc:  # zarr raises several types for a directory that is no store
        raise ParameterError(f"{str(path)!r} is not a readable sweep store: {exc}") from None
    if "status" not in ds.data_vars:
        raise ParameterError(f"{str(path)!r} is not a gearchaos sweep store (no 'status')")
    return ds


# --------------------------------------------------------------------------- classify
@app.command()
def classify(
    store: Annotated[
        Path,
        typer.Argument(help="Sweep store written by `gearchaos bifurcation`.", show_default=False),
    ],
    rtol: Annotated[
        float,
        typer.Option(
            "--rtol",
            help=(
                "Tolerance of period detection, relative to the attractor's size: section "
                "points closer than this repeat."
            ),
        ),
    ] = 1e-3,
    max_period: Annotated[
        int, typer.Option("--max-period", help="Longest period n recognised as nT.")
    ] = 64,
    json_out: JsonOpt = False,
) -> None:
    """(Re)label every point of a sweep store without re-simulating: 1T … nT (period of the
    stored section sequence), QP or chaos (by the stored largest Lyapunov exponent when the
    sweep ran with --lyapunov, confirmed by the 0–1 test and the spectrum), unresolved, failed.

    Rewrites the store's motion, period, k01 and indicators_agree variables and its
    regime_table attribute, and prints the regime table: the fraction of the swept points in
    each regime, per family value. **--json** prints that table as a dictionary
    (family value → regime → fraction).

    Example: **gearchaos classify fig4.zarr --rtol 1e-4**
    """
    with _reported_errors():
        if not (math.isfinite(rtol) and 0.0 < rtol < 1.0):
            raise ParameterError(f"--rtol must be a number in (0, 1): got {rtol!r}")
        if max_period < 1:
            raise ParameterError(f"--max-period must be an integer >= 1: got {max_period!r}")
        _open_store(store)
        from .sweep import classify_store

        table = classify_store(store, period_rtol=rtol, max_period=max_period)
    if json_out:
        _print_json(table)
        return
    out = _stdout()
    out.print(_regime_table(table, title=f"motion regimes of {store} (fraction of the points)"))
    out.print(
        Text(
            f"period tolerance {rtol:g} of the attractor size, periods up to {max_period}",
            style="dim",
        )
    )


# --------------------------------------------------------------------------- poincare
@app.command()
def poincare(
    vary: Annotated[
        str | None,
        typer.Option(
            "--vary",
            "-v",
            help=(
                "NAME=VALUES: one panel per value, VALUES a,b,c or start:stop:count; NAME is "
                "omega, xi or a dotted gear-set parameter, e.g. "
                "omega=1.2,1.35,1.5,1.7,1.875,1.926,2.02,2.3 or backlash.sun_planet=1:6:12."
            ),
            show_default=False,
        ),
    ] = None,
    output: Annotated[
        Path | None,
        typer.Option("--output", "-o", help="Figure file: .png, .pdf or .svg.", show_default=False),
    ] = None,
    preset: PresetOpt = None,
    gearset: GearsetOpt = None,
    set_: SetOpt = None,
    transient: Annotated[
        float, typer.Option("--transient", help="Mesh periods discarded for every value.")
    ] = 100.0,
    periods: Annotated[
        int, typer.Option("--periods", help="Mesh periods recorded (Poincaré points) per value.")
    ] = 300,
    with_: Annotated[
        str | None,
        typer.Option(
            "--with",
            help="Extra rows under each map: phase, spectrum or phase,spectrum.",
            show_default=False,
        ),
    ] = None,
    planet: Annotated[int, typer.Option("--planet", help="Planet of X̄_sp.")] = 1,
    rtol: Annotated[
        float, typer.Option("--rtol", help="Relative tolerance (Dormand–Prince 5(4)).")
    ] = 1e-8,
    atol: Annotated[float, typer.Option("--atol", help="Absolute tolerance.")] = 1e-10,
    quiet: QuietOpt = False,
    json_out: JsonOpt = False,
) -> None:
    """A gallery of Poincaré maps (X̄_sp1 against X̄'_sp1) along a parameter path, each panel
    titled with the value, its motion label and its largest Lyapunov exponent λ₁.

    Every value is one simulation with the seed's protocol (TRANSIENT mesh periods discarded,
    PERIODS recorded) plus a Lyapunov run at the same settings; the label (1T … nT, QP, chaos,
    unresolved) uses that λ₁. Prints a table of the values (value, motion, λ₁, K of the 0–1
    test, distinct points); **--json** prints them as rows.

    Example: **gearchaos poincare --vary omega=1.2,1.35,1.5,1.7,1.875,1.926,2.02,2.3
    --with phase -o gallery.png**
    """
    from .plot.figure import SAVE_FORMATS

    with _reported_errors():
        if not vary:
            raise ParameterError(
                "--vary is required: give NAME=VALUES, e.g. --vary omega=1.2,1.5,1.875"
            )
        if output is None:
            raise ParameterError("--output is required: the figure file, e.g. -o gallery.png")
        if output.suffix.lower() not in SAVE_FORMATS:
            raise ParameterError(
                f"--output must end in one of {', '.join(SAVE_FORMATS)}: got {str(output)!r}"
            )
        from .plot.gallery import parse_extras
        from .sweep.spec import parse_axis

        try:
            extras = parse_extras(with_)
        except ParameterError:
            raise ParameterError(
                f"--with must be phase, spectrum or phase,spectrum: got {with_!r}"
            ) from None
        axis = parse_axis(vary)
        omega, changes = parse_sets(set_ or [])
        fixed: dict[str, Any] = dict(changes)
        if axis.name in fixed or (axis.name == "omega" and omega is not None):
            raise ParameterError(f"{axis.name} is both varied and set with --set; choose one")
        if axis.name != "omega":
            if omega is None:
                omega = DEFAULT_OMEGA
                if not (quiet or json_out):
                    _stderr().print(
                        Text(
                            f"Ω = {DEFAULT_OMEGA:g} (not varied; change it with --set omega=...)",
                            style="dim",
                        )
                    )
            fixed["omega"] = omega
        gs = _gearset(preset, gearset, {})

        import time

        import matplotlib

        matplotlib.use("Agg")
        from .paper.galleries import run_gallery
        from .plot import savefig

        t0 = time.perf_counter()
        fig, rows = run_gallery(
            gs,
            axis.name,
            axis.values,
            fixed=fixed,
            transient=transient,
            periods=periods,
            with_=extras,
            progress=not (quiet or json_out),
            rtol=rtol,
            atol=atol,
            planet=planet,
        )
        if output.parent != Path(""):
            output.parent.mkdir(parents=True, exist_ok=True)
        try:
            savefig(fig, output)
        finally:
            import matplotlib.pyplot as plt

            plt.close(fig)
        seconds = time.perf_counter() - t0
    if json_out:
        _print_json(
            {
                "figure": str(output),
                "param": axis.name,
                "fixed": fixed,
                "transient_periods": transient,
                "periods": periods,
                "seconds": seconds,
                "rows": rows,
            }
        )
        return
    if quiet:
        return
    out = _stdout()
    out.print(_gallery_rows_table(rows, axis.name, title=f"Poincaré gallery of {gs.name}"))
    out.print(Text.assemble(("wrote ", "dim"), (str(output), "bold")), soft_wrap=True)


def _gallery_rows_table(rows: Sequence[Mapping[str, Any]], param: str, *, title: str) -> Table:
    """One row per value: value, motion (in its palette colour), λ₁, K, agree, points."""
    from .plot.regimes import regime_colour

    table = Table(title=escape(title), title_justify="left")
    table.add_column(escape(_SYMBOLS.get(param, param)), justify="right")
    table.add_column("motion", no_wrap=True)
    table.add_column("λ₁", justify="right")
    table.add_column("0–1 K", justify="right")
    table.add_column("agree", justify="center")
    table.add_column("distinct points", justify="right")
    for r in rows:
        motion = str(r["motion"])
        lle, k01 = r.get("lle"), r.get("k01")
        agree = bool(r.get("indicators_agree", True))
        table.add_row(
            f"{float(r['value']):g}",
            Text("■ ", style=regime_colour(motion)) + Text(motion),
            "—" if lle is None else f"{lle:.3g}",
            "—" if k01 is None else f"{k01:.3f}",
            Text("yes" if agree else "no", style="" if agree else "bold red"),
            str(r.get("distinct_section_points", "—")),
        )
    return table


# --------------------------------------------------------------------------- reproduce
@app.command()
def reproduce(
    figure: Annotated[
        str | None,
        typer.Argument(
            help=f"Figure of the seed paper: {', '.join(PAPER_FIGURES)} (or --all).",
            show_default=False,
        ),
    ] = None,
    all_figures: Annotated[
        bool,
        typer.Option(
            "--all",
            help=(
                "Run every figure, check the paper's conclusions and landmarks and write "
                "OUTPUT/index.html (the reproduction report)."
            ),
        ),
    ] = False,
    output: Annotated[
        Path,
        typer.Option(
            "--output",
            "-o",
            help=(
                "Directory for FIG.png and the sweep store FIG.zarr (galleries: FIG.json and "
                "FIG.csv); created if missing."
            ),
            file_okay=False,
        ),
    ] = Path("."),
    quick: Annotated[
        bool, typer.Option("--quick", help="A coarse version (fewer points and periods), for CI.")
    ] = False,
    workers: Annotated[
        int | None,
        typer.Option(
            "--workers",
            "-w",
            help="Local worker processes (default: in-process on all cores).",
            show_default=False,
        ),
    ] = None,
    overwrite: Annotated[
        bool,
        typer.Option("--overwrite", help="Replace an existing store made with other settings."),
    ] = False,
    preset: PresetOpt = None,
    gearset: GearsetOpt = None,
    quiet: QuietOpt = False,
    json_out: JsonOpt = False,
) -> None:
    """Run the exact sweep of one of the seed paper's bifurcation figures with the default gear
    set (or --preset / --gearset) and draw it in the paper's layout (resumable like
    `gearchaos bifurcation`), or draw one of its Poincaré galleries.

    Bifurcation diagrams — fig4: Ω sweep, ξ = 0.03, 0.05, 0.07, 0.09; fig6: b̄_sp at Ω = 1.5 for
    four ξ; fig8: b̄_sp at ξ = 0.11 for Ω = 1, 1.5, 2, 2.5; fig9: b̄_rp at Ω = 1.5 for four ξ;
    fig11: b̄_rp at ξ = 0.11 for four Ω; fig12: b̄_s at ξ = 0.05, Ω = 1.5.

    Poincaré galleries (FIG.png, FIG.json and FIG.csv with value, motion, λ₁, K, distinct
    points) — fig5: Ω path at ξ = 0.03; fig7: b̄_sp ∈ [1, 6] at Ω = 1.5, ξ = 0.05; fig10:
    b̄_rp ∈ [1, 9] at Ω = 1.5, ξ = 0.05, at the values the seed's text names.

    --all runs every figure into OUTPUT, checks the conclusions of the seed's Section 4 and its
    landmarks against the runs and writes the report OUTPUT/index.html (resumable; 4–8 minutes
    on 2 cores, --quick about a minute).

    Example: **gearchaos reproduce fig4 -o paper/ --quick**;
    **gearchaos reproduce --all -o report/**
    """
    gs = None
    label = None
    if preset is not None or gearset is not None:
        with _reported_errors():
            gs = _gearset(preset, gearset, {})
        label = f"preset {preset}" if preset is not None else f"file {gearset} ({gs.name})"
    if all_figures:
        if figure is not None:
            _fail("give either FIG or --all, not both", EXIT_INVALID)
        with _reported_errors(), _interruptible():
            from .paper.report import build_report

            index = build_report(
                output,
                quick=quick,
                progress=not (quiet or json_out),
                workers=workers,
                gearset=gs,
                gearset_label=label,
            )
        if json_out:
            _print_json({"report": str(index)})
        elif not quiet:
            _stdout().print(escape(str(index)))
        return
    if figure is None:
        _fail("give a figure (FIG) or --all", EXIT_INVALID)
    with _reported_errors(), _interruptible():
        name = figure.strip().lower()
        if name not in PAPER_FIGURES:
            close = difflib.get_close_matches(name, PAPER_FIGURES, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ParameterError(
                f"FIG must be one of {', '.join(PAPER_FIGURES)}: got {figure!r}{hint}"
            )
        if name in GALLERY_FIGURES:
            if workers is not None and not (quiet or json_out):
                _stderr().print(
                    Text(
                        f"--workers does not apply to {name} (a gallery runs its "
                        f"{name} values one after the other)",
                        style="dim",
                    )
                )
            import matplotlib

            matplotlib.use("Agg")
            from .paper.galleries import reproduce_gallery

            output.mkdir(parents=True, exist_ok=True)
            result = dict(
                reproduce_gallery(
                    name, output, quick=quick, progress=not (quiet or json_out), gearset=gs
                )
            )
        else:
            try:
                from .paper.recipes import reproduce as run_recipe
            except ImportError as exc:
                _fail(
                    f"the paper recipes are not available in this installation: {exc}",
                    EXIT_FAILURE,
                )
            output.mkdir(parents=True, exist_ok=True)
            result = dict(
                run_recipe(
                    name,
                    output,
                    quick=quick,
                    progress=not quiet,
                    workers=workers,
                    overwrite=overwrite,
                    gearset=gs,
                )
            )
    if json_out:
        _print_json(result)
        return
    if quiet:
        return
    rows = result.pop("rows", None)
    if rows is not None:
        from .paper.galleries import get_gallery

        _stdout().print(
            _gallery_rows_table(rows, get_gallery(name).param, title=f"Poincaré gallery {name}")
        )
    table = _pairs_table(f"gearchaos reproduce {name}" + (" (quick)" if quick else ""))
    for key in ("figure", "store", "points", "failed", "seconds"):
        if key in result:
            value = result[key]
            text = f"{value:.3g}" if key == "seconds" and isinstance(value, float) else str(value)
            table.add_row(key, escape(text))
    for key, value in result.items():
        if key not in ("figure", "store", "points", "failed", "seconds"):
            table.add_row(escape(str(key)), escape(_fmt(value)))
    _stdout().print(table)


# --------------------------------------------------------------------------- presets, init-gearset
@app.command()
def presets() -> None:
    """List the built-in gear sets (use one with --preset NAME)."""
    from .gearset import list_presets

    table = Table(title="Built-in gear sets", title_justify="left")
    table.add_column("name", style="bold cyan", no_wrap=True)
    table.add_column("description")
    for name, description in list_presets():
        table.add_row(name, description)
    _stdout().print(table)


@app.command("init-gearset")
def init_gearset(
    file: Annotated[
        Path, typer.Argument(help="TOML file to write.", dir_okay=False, show_default=False)
    ],
    force: Annotated[
        bool, typer.Option("--force", "-f", help="Overwrite an existing file.")
    ] = False,
) -> None:
    """Write a commented gear-set file to start from (the sheng2016 values, every line
    explained); edit it, then run **gearchaos simulate --gearset FILE**."""
    from .gearset import template_toml

    if file.exists() and not force:
        _fail(f"{file} already exists; pass --force to overwrite it", EXIT_FAILURE)
    with _reported_errors():
        file.write_text(template_toml(), encoding="utf-8")
    out = _stdout()
    out.print(Text.assemble(("wrote ", "dim"), (str(file), "bold")), soft_wrap=True)
    out.print(
        Text(f"next: gearchaos simulate --gearset {file} --set omega=1.5 -o out/", style="dim")
    )


# --------------------------------------------------------------------------- calibrate
@app.command()
def calibrate(
    landmarks: Annotated[
        Path | None,
        typer.Option(
            "--landmarks",
            help="Landmarks file (default: the packaged paper/landmarks.toml).",
            dir_okay=False,
            show_default=False,
        ),
    ] = None,
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            help=(
                "JSON-lines file, one line per evaluated candidate; re-used on restart. "
                "best.toml is written beside it."
            ),
            dir_okay=False,
        ),
    ] = Path("calibration.jsonl"),
    budget_minutes: Annotated[
        float, typer.Option("--budget-minutes", help="Stop evaluating after this many minutes.")
    ] = 110.0,
    max_candidates: Annotated[
        int | None,
        typer.Option(
            "--max-candidates",
            help="Stop when the candidate sequence (resumed ones included) reaches N.",
            show_default=False,
        ),
    ] = None,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the candidate sequence.")] = 0,
    quick: Annotated[
        bool, typer.Option("--quick", help="3 candidates on tiny sweeps, for CI.")
    ] = False,
    quiet: QuietOpt = False,
    json_out: JsonOpt = False,
) -> None:
    """Search the quantities of the seed's lost Table 1 (N and tooth numbers, input torque,
    transmission-error amplitude, stiffness ratios, mass ratios, b_c, load mode) for the gear set
    whose coarse sweeps reproduce the most landmarks of the seed's text. Resumable: candidates
    already in --out are not evaluated again. See docs/reproduction.md.

    Example: **gearchaos calibrate --landmarks paper/landmarks.toml --budget-minutes 110**
    """
    from .paper.calibrate import calibrate as run_calibration

    show = not (quiet or json_out)
    err = _stderr()

    def on_record(rec: Mapping[str, Any], now: bool) -> None:
        if show:
            what = f"{rec['seconds']:.0f} s" if now else "resumed"
            err.print(
                Text(
                    f"candidate {rec['index']} ({rec['origin']}): score {rec['score']:.2f} "
                    f"[{what}]",
                    style="dim",
                )
            )

    with _reported_errors():
        if landmarks is not None and not landmarks.exists():
            raise FileNotFoundError(f"landmarks file not found: '{landmarks}'")
        if out.parent and not out.parent.exists():
            out.parent.mkdir(parents=True, exist_ok=True)
        result = run_calibration(
            landmarks,
            out,
            budget_minutes=budget_minutes,
            max_candidates=max_candidates,
            seed=seed,
            quick=quick,
            on_record=on_record,
        )
    summary = {
        "out": str(out),
        "best_toml": str(result.best_toml) if result.best_toml else None,
        "evaluated": result.evaluated,
        "resumed": result.reused,
        "stopped": result.stopped,
        "plausible": result.plausible,
        "problems": result.problems,
        "best": result.best,
        "top": result.top(3),
    }
    if json_out:
        _print_json(summary)
    elif not quiet:
        table = _pairs_table("gearchaos calibrate: best candidate" + (" (quick)" if quick else ""))
        best = result.best or {}
        table.add_row("score", escape(_fmt(best.get("score"))))
        for key, value in (best.get("variables") or {}).items():
            table.add_row(escape(str(key)), escape(_fmt(value)))
        table.add_row("evaluated / resumed", f"{result.evaluated} / {result.reused}")
        table.add_row("stopped", escape(result.stopped))
        table.add_row("best.toml", escape(str(result.best_toml)))
        verdict = (
            "yes: inside every range, no validation warnings"
            if result.plausible
            else "no: " + "; ".join(result.problems)
        )
        table.add_row("physically plausible", escape(verdict))
        _stdout().print(table)
    if result.stopped == "interrupted":
        _fail(
            f"interrupted: every finished candidate is in {out}; run the same command again "
            "to resume",
            EXIT_INTERRUPTED,
        )


if __name__ == "__main__":  # pragma: no cover
    sys.exit(app())
