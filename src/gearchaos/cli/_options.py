"""The options many commands share, each declared once, in groups passed on as one object.

A group is a frozen record whose fields are the options (``typer.Option`` in ``Annotated``):
:class:`Target` (``--preset``, ``--gearset``, ``--model``, ``--set``), :class:`Protocol`
(``--transient``, ``--settle``, ``--perturbation``, ``--periods``, ``--samples-per-period``),
:class:`Solver` (``--rtol``, ``--atol``), :class:`Execution` (``--workers``, ``--scheduler``,
``--dask-local``), :class:`Output` (``-o``, ``--overwrite``, ``--quiet``, ``--json``),
:class:`Verdict` (``--verdict/--no-verdict``) and :class:`Confirm` (``--confirm-periods``, the
attractor tools'). A command names a group as one parameter::

    @c.command()
    def simulate(
        target: c.Target = c.Target(),
        protocol: c.Protocol = c.Protocol.of(SIMULATION).offering(...),
        ...
    ) -> None:

and :func:`~gearchaos.cli._common.command` spreads it into its options on the command line (in
the group's panel of ``--help``) and gathers them back into one record before the command
runs. The default record gives the command's defaults (:meth:`Protocol.of` takes them from the
library's :class:`~gearchaos.integrate.settings.SolverSettings`), :meth:`OptionGroup.offering`
the subset of the group's options it takes, its own help for some and which are required.

Choices are enumerations built from the library's own tuples (:data:`Direction` from
:data:`gearchaos.sweep.spec.DIRECTIONS`, …): ``--help`` lists them and the command line refuses
others by name, so no command checks them again. A library refusal of a keyword reaches the
user under the option's name (:func:`named_options`).
"""

from __future__ import annotations

import contextlib
import copy
import enum
import functools
import inspect
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import (
    TYPE_CHECKING,
    Annotated,
    Any,
    ClassVar,
    TypeVar,
    cast,
    get_args,
    get_type_hints,
)

import typer

from ..dynamics.curves.boundary import ASSESS
from ..dynamics.verdict.settings import CONFIRM_PERIODS
from ..errors import ParameterError
from ..integrate.settings import SETTLE_CHOICES, SolverSettings
from ..plot.amplitude import QUANTITIES
from ..sweep.exports import FORMATS
from ..sweep.spec import DIRECTIONS, INITIAL_CONDITIONS

#: Gear set used when neither ``--preset`` nor ``--gearset`` is given.
DEFAULT_PRESET = "sheng2016"


# --------------------------------------------------------------------------- choices
def choices(name: str, values: Iterable[str]) -> type[enum.StrEnum]:
    """An enumeration of the library's own tuple of choices (each member's name and value is
    the text): an option annotated with it lists them in ``--help`` and refuses others by
    name. Commands pass ``member.value`` on to the library."""
    return cast(type[enum.StrEnum], enum.StrEnum(name, [(v, v) for v in values]))


if TYPE_CHECKING:  # for the type checker a choice is a str enumeration; its members: below
    Direction = enum.StrEnum
    InitialConditions = enum.StrEnum
    Settle = enum.StrEnum
    Assess = enum.StrEnum
    ExportFormat = enum.StrEnum
    Quantity = enum.StrEnum
else:
    #: ``--direction``: :data:`gearchaos.sweep.spec.DIRECTIONS`.
    Direction = choices("Direction", DIRECTIONS)
    #: ``--initial-conditions``: :data:`gearchaos.sweep.spec.INITIAL_CONDITIONS`.
    InitialConditions = choices("InitialConditions", INITIAL_CONDITIONS)
    #: ``--settle``: :data:`gearchaos.integrate.settings.SETTLE_CHOICES`.
    Settle = choices("Settle", SETTLE_CHOICES)
    #: ``boundary --assess``: :data:`gearchaos.dynamics.curves.boundary.ASSESS`.
    Assess = choices("Assess", ASSESS)
    #: ``export --to``: :data:`gearchaos.sweep.exports.FORMATS`.
    ExportFormat = choices("ExportFormat", FORMATS)
    #: ``plot --quantity``: :data:`gearchaos.plot.amplitude.QUANTITIES`.
    Quantity = choices("Quantity", QUANTITIES)


#: The default of ``--settle``: the transient always runs its full length.
SETTLE_OFF = Settle("off")


def choice_value(member: enum.StrEnum | None) -> str | None:
    """The text of a choice (``None`` stays ``None``)."""
    return None if member is None else str(member.value)


# --------------------------------------------------------------------------- groups
@dataclass(frozen=True)
class Offer:
    """Which options of a group a command takes (``names``; all when ``None``), its own help
    for some of them (``help``: name → text) and which of them are required."""

    names: tuple[str, ...] | None = None
    help: tuple[tuple[str, str], ...] = ()
    required: tuple[str, ...] = ()


G = TypeVar("G", bound="OptionGroup")


@dataclass(frozen=True)
class OptionGroup:
    """Base of a group of options: a frozen record whose fields (but ``offered``) are options,
    each ``Annotated[TYPE, typer.Option(...)]`` with its default."""

    #: Title of the group's panel in ``--help`` (None: the command's own "Options").
    panel: ClassVar[str | None] = None
    #: The options a command offers (:meth:`offering`); not an option itself.
    offered: Offer = field(default=Offer(), repr=False, compare=False, kw_only=True)

    @classmethod
    def declarations(cls) -> dict[str, Any]:
        """Field name → its ``Annotated`` option declaration, in field order."""
        hints = get_type_hints(cls, include_extras=True)
        return {f.name: hints[f.name] for f in fields(cls) if f.name != "offered"}

    def offering(
        self: G,
        *names: str,
        help: Mapping[str, str] | None = None,
        required: Iterable[str] = (),
    ) -> G:
        """This group as a command takes it: only the options ``names`` (all when none are
        given), with the command's own ``help`` for some and the ``required`` ones without a
        default."""
        known = self.declarations()
        help = dict(help or {})
        required = tuple(required)
        chosen = names or tuple(known)
        for name in (*chosen, *help, *required):
            if name not in known:
                raise TypeError(f"{type(self).__name__} has no option {name!r}")
        return replace(self, offered=Offer(tuple(chosen), tuple(help.items()), required))

    def offered_values(self) -> dict[str, Any]:
        """Field name → value of the options a command offers."""
        return {name: getattr(self, name) for name in self.offered.names or self.declarations()}

    def options(self) -> list[tuple[str, Any, Any]]:
        """(field name, ``Annotated`` declaration, default) of every offered option, the
        command's help and this group's ``--help`` panel put into the declaration; the default
        is ``...`` (required) for a required option."""
        declared = self.declarations()
        names = self.offered.names or tuple(declared)
        helps = dict(self.offered.help)
        out = []
        for name in names:
            base, info, *rest = get_args(declared[name])
            info = copy.copy(info)
            if self.panel is not None:
                info.rich_help_panel = self.panel
            if name in helps:
                info.help = helps[name]
            default = ... if name in self.offered.required else getattr(self, name)
            out.append((name, Annotated[(base, info, *rest)], default))
        return out


@dataclass(frozen=True)
class Target(OptionGroup):
    """What a command computes with: a built-in gear set (``--preset``), a gear-set file
    (``--gearset``) or your own model (``--model``), changed by ``--set NAME=VALUE``."""

    panel: ClassVar[str | None] = "Gear set or model"

    preset: Annotated[
        str | None,
        typer.Option(
            "--preset",
            "-p",
            help=f"Built-in gear set (see `gearchaos presets`). Default: {DEFAULT_PRESET}.",
            show_default=False,
        ),
    ] = None
    gearset_file: Annotated[
        Path | None,
        typer.Option(
            "--gearset",
            "-g",
            help="Gear-set TOML file (start from `gearchaos init-gearset`). Excludes --preset.",
            dir_okay=False,
            show_default=False,
        ),
    ] = None
    model: Annotated[
        str | None,
        typer.Option(
            "--model",
            "-m",
            help="Your own model instead of a gear set: FILE.py:CLASS, MODULE:CLASS or an "
            "installed name (see docs/howto/own-model.md); --set NAME=VALUE sets its "
            "parameters. Excludes --preset and --gearset. With --from, the model the file "
            "records: naming it is your consent to run its code, which a file alone never "
            "gets.",
            show_default=False,
        ),
    ] = None
    sets: Annotated[
        list[str] | None,
        typer.Option(
            "--set",
            "-s",
            help=(
                "NAME=VALUE, repeatable: omega=1.5 (the dimensionless mesh frequency Ω), "
                "xi=0.05 (all damping ratios), or any dotted gear-set parameter such as "
                "backlash.sun_planet=3, clearance.sun_bearing=2, torque.input=1500; with "
                "--model, omega and the model's own parameters (its field names)."
            ),
            show_default=False,
        ),
    ] = None

    @property
    def names_gear_set(self) -> bool:
        """Whether ``--preset`` or ``--gearset`` is given."""
        return self.preset is not None or self.gearset_file is not None


#: ``--model`` of a command that reads a file recording the model (plot, explore, boundary).
RECORDED_MODEL = Target().offering(
    "model",
    help={
        "model": "The model a file records, when it is your own (FILE.py:CLASS, MODULE:CLASS "
        "or an installed name; see docs/howto/own-model.md): naming it is your consent to run "
        "its code, which a file alone never gets."
    },
)


@dataclass(frozen=True)
class Protocol(OptionGroup):
    """How long a run is and what it records: transient and recorded forcing periods, samples
    per period, early end of the transient and the perturbation of the start from rest."""

    panel: ClassVar[str | None] = "Protocol and solver"

    transient: Annotated[
        float, typer.Option("--transient", help="Mesh periods discarded before recording.")
    ] = 100.0
    settle: Annotated[
        Settle,
        typer.Option(
            "--settle",
            help=(
                "off: always --transient periods of transient; auto: end it early once the "
                "Poincaré sections repeat (period ≤ 64), never later than --transient."
            ),
        ),
    ] = SETTLE_OFF
    perturbation: Annotated[
        float | None,
        typer.Option(
            "--perturbation",
            help=(
                "Size of the reproducible perturbation of the start from rest that breaks the "
                "planets' symmetry as in any real gearbox (default 1e-6; 0: the exact "
                "symmetric start)."
            ),
            show_default=False,
        ),
    ] = None
    periods: Annotated[
        int, typer.Option("--periods", help="Mesh periods recorded (one Poincaré point each).")
    ] = 200
    samples_per_period: Annotated[
        int,
        typer.Option(
            "--samples-per-period",
            help="Samples per mesh period of the recorded time history (figure, spectra, RMS "
            "values).",
        ),
    ] = 1

    @classmethod
    def of(cls, settings: SolverSettings, **values: Any) -> Protocol:
        """The protocol of ``settings`` (a library default such as
        :data:`~gearchaos.integrate.settings.SIMULATION`) with ``values`` changed; the
        perturbation is the settings' own unless ``--perturbation`` is given."""
        return replace(
            cls(
                transient=settings.transient_periods,
                settle=Settle(settings.settle),
                periods=settings.periods,
                samples_per_period=settings.samples_per_period,
            ),
            **values,
        )


@dataclass(frozen=True)
class Solver(OptionGroup):
    """The integrator's tolerances (adaptive Dormand–Prince 5(4))."""

    panel: ClassVar[str | None] = "Protocol and solver"

    rtol: Annotated[
        float,
        typer.Option("--rtol", help="Relative tolerance of the integrator (Dormand–Prince 5(4))."),
    ] = 1e-8
    atol: Annotated[float, typer.Option("--atol", help="Absolute tolerance of the integrator.")] = (
        1e-10
    )

    @classmethod
    def of(cls, settings: SolverSettings) -> Solver:
        """The tolerances of ``settings``."""
        return cls(rtol=settings.rtol, atol=settings.atol)


@dataclass(frozen=True)
class Execution(OptionGroup):
    """Where the points of a sweep run: local worker processes or a Dask cluster."""

    panel: ClassVar[str | None] = "Execution"

    workers: Annotated[
        int | None,
        typer.Option(
            "--workers",
            "-w",
            help="Local worker processes (default: in-process on all cores).",
            show_default=False,
        ),
    ] = None
    scheduler: Annotated[
        str | None,
        typer.Option(
            "--scheduler",
            help=(
                "Address of a running dask.distributed scheduler, e.g. tcp://HOST:8786 — one "
                "you trust: Dask exchanges pickles, which run code when read."
            ),
            show_default=False,
        ),
    ] = None
    dask_local: Annotated[
        int | None,
        typer.Option(
            "--dask-local",
            help="Start a local Dask cluster with N workers on this machine.",
            show_default=False,
        ),
    ] = None


@dataclass(frozen=True)
class Output(OptionGroup):
    """What a command writes and prints: the file or directory ``-o`` (each command says which
    in its own help), whether it replaces one, and what it prints."""

    panel: ClassVar[str | None] = "Output"

    file: Annotated[
        str | None,
        typer.Option(
            "--output",
            "-o",
            metavar="<path>",
            help="Where to write the result.",
            show_default=False,
        ),
    ] = None
    overwrite: Annotated[
        bool,
        typer.Option("--overwrite", help="Replace an existing store made with other settings."),
    ] = False
    quiet: Annotated[
        bool, typer.Option("--quiet", "-q", help="No progress bar and no summary (errors only).")
    ] = False
    json: Annotated[
        bool, typer.Option("--json", help="Print the result as JSON on stdout, and nothing else.")
    ] = False

    def path(self) -> Path | None:
        """The path of ``-o``; an empty one is refused (it would mean the current directory by
        accident)."""
        if self.file is None:
            return None
        if not self.file.strip():
            raise ParameterError("--output must be a path: got an empty string")
        return Path(self.file)

    def required_path(self) -> Path:
        """The path of a required ``-o``."""
        path = self.path()
        if path is None:  # a command that requires -o never runs without it
            raise ParameterError("--output is required")
        return path

    def figure(self) -> Path | None:
        """The path of ``-o`` naming a figure file: its suffix one the figures are saved as
        (:data:`gearchaos.plot.figure.SAVE_FORMATS`)."""
        from ..plot.figure import SAVE_FORMATS

        path = self.path()
        if path is not None and path.suffix.lower() not in SAVE_FORMATS:
            raise ParameterError(
                f"--output must end in one of {', '.join(SAVE_FORMATS)}: got {str(path)!r}"
            )
        return path

    def directory(self) -> Path | None:
        """The path of ``-o`` naming a directory: an existing file is refused."""
        path = self.path()
        if path is not None and path.exists() and not path.is_dir():
            raise ParameterError(f"--output must be a directory: {str(path)!r} is a file")
        return path

    @property
    def silent(self) -> bool:
        """Nothing but the result on stdout: ``--quiet`` or ``--json`` (no progress, no notes)."""
        return self.quiet or self.json


@dataclass(frozen=True)
class Verdict(OptionGroup):
    """Whether the motion is decided by the verdict (orbits confirmed by shooting, chaos and
    QP by λ₁ with its error) or labelled from the record alone. One spelling on every
    command, ``--verdict/--no-verdict``; ``--verdicts/--no-verdicts`` (the old spelling of
    ``bifurcation``) still works, hidden."""

    verdict: Annotated[
        bool | None,
        typer.Option(
            "--verdict/--no-verdict",
            help="Decide the motion with the verdict (default), or label it from the record alone.",
            show_default=False,
        ),
    ] = None
    verdicts: Annotated[
        bool | None,
        typer.Option(
            "--verdicts/--no-verdicts",
            hidden=True,
            help="Old spelling of --verdict/--no-verdict.",
            show_default=False,
        ),
    ] = None

    def decided(self) -> bool:
        """Whether the verdict decides the motion (the default); both spellings at once are
        refused."""
        if self.verdict is not None and self.verdicts is not None:
            raise ParameterError(
                "give --verdict or --no-verdict only (--verdicts/--no-verdicts is its old "
                "spelling): got both spellings"
            )
        chosen = self.verdict if self.verdict is not None else self.verdicts
        return True if chosen is None else chosen


@dataclass(frozen=True)
class Confirm(OptionGroup):
    """How the attractor tools (``attractors``, ``basins``, ``basin-fractions``) confirm a
    chaotic or quasi-periodic attractor: by a last window of at least ``--confirm-periods``
    periods (:func:`~gearchaos.dynamics.verdict.decide.confirmed_settings`)."""

    confirm_periods: Annotated[
        int,
        typer.Option(
            "--confirm-periods",
            help="A chaotic or quasi-periodic attractor is listed only after a last window of "
            "this many periods confirms it (a chaotic transient that ends on an orbit within "
            "it is that orbit's run).",
        ),
    ] = CONFIRM_PERIODS


# --------------------------------------------------------------------------- commands
F = TypeVar("F", bound=Callable[..., Any])


def spread_groups(fn: F) -> F:
    """``fn`` as Typer sees a command: every parameter typed by an :class:`OptionGroup` is
    replaced by that group's offered options (default record: the parameter's default), and
    the returned function gathers them back into one record before calling ``fn``. Its
    ``option_groups`` attribute maps each group parameter to its record and option names."""
    sig = inspect.signature(fn)
    hints = get_type_hints(fn, include_extras=True)
    params: list[inspect.Parameter] = []
    groups: dict[str, tuple[OptionGroup, tuple[str, ...]]] = {}
    for p in sig.parameters.values():
        hint = hints.get(p.name, p.annotation)
        if isinstance(hint, type) and issubclass(hint, OptionGroup):
            record = p.default if isinstance(p.default, hint) else hint()
            names = []
            for name, declaration, default in record.options():
                params.append(
                    inspect.Parameter(name, p.KEYWORD_ONLY, default=default, annotation=declaration)
                )
                names.append(name)
            groups[p.name] = (record, tuple(names))
        else:
            params.append(p.replace(kind=p.KEYWORD_ONLY, annotation=hint))
    taken = [p.name for p in params]
    twice = sorted({n for n in taken if taken.count(n) > 1})
    if twice:
        raise TypeError(f"{fn.__name__}: parameters {twice} are declared twice")

    @functools.wraps(fn)
    def run(**values: Any) -> Any:
        for group, (record, names) in groups.items():
            values[group] = replace(record, **{n: values.pop(n) for n in names})
        return fn(**values)

    run.__signature__ = sig.replace(parameters=params)  # type: ignore[attr-defined]
    run.__annotations__ = {p.name: p.annotation for p in params}
    run.option_groups = groups  # type: ignore[attr-defined]
    return run  # type: ignore[return-value]


@contextlib.contextmanager
def named_options(**options: str) -> Iterator[None]:
    """A library refusal of one of the keywords ``options`` (keyword → option, by the
    error's ``name``) is reported under the option: the keyword that starts its message
    replaced by the option (``period_rtol must be …`` → ``--period-rtol must be …``), else the
    option put before it (``--x: …``)."""
    try:
        yield
    except ParameterError as exc:
        option = options.get(exc.name or "")
        if option is None:
            raise
        text = str(exc)
        if text.startswith(f"{exc.name} "):
            raise ParameterError(option + text[len(exc.name or "") :], name=exc.name) from None
        raise ParameterError(f"{option}: {text}", name=exc.name) from None
