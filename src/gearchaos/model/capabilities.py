"""The record of the model contract: :class:`Capabilities`, one field per member of the
contract with its meaning and default, read from a model by :meth:`Capabilities.of`, and the
:class:`Contact` s it lists (:mod:`gearchaos.model.contract` describes the contract and
re-exports both)."""

from __future__ import annotations

import dataclasses
import math
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np

from ..errors import ParameterError

__all__ = ["CONTACT_KINDS", "QUANTITIES", "Capabilities", "Contact"]

#: The physical quantities a variable may measure (``Capabilities.quantities``): name → SI
#: unit. A model's ``scales`` has an attribute of each name it uses, the factor from the
#: dimensionless value to SI.
QUANTITIES: Mapping[str, str] = MappingProxyType({"length": "m", "velocity": "m/s", "force": "N"})
#: Kinds of contact (:class:`Contact`).
CONTACT_KINDS = ("mesh", "bearing")


@dataclass(frozen=True)
class Contact:
    """A contact whose regime analyses report: ``name``, the index ``column`` of the tracked
    observable (a deflection) it is judged on, its half clearance b̄ and its ``kind``
    (``mesh``: teeth meet at δ = ±b̄, regime from min δ; ``bearing``: a journal touches the
    bearing at ±b̄, regime from both extrema)."""

    name: str
    column: int
    clearance: float
    kind: str = "mesh"


def _doc(doc: str, otherwise: str | None = None, *, shown: str | None = None) -> dict[str, Any]:
    """The metadata of a field of :class:`Capabilities`: ``doc`` says what the member is
    (markdown), ``otherwise`` what a model that does not give it gets, in words (``None``: a
    required member), ``shown`` how the tables write the member (a method with its
    arguments)."""
    return {"doc": doc, "otherwise": otherwise, "shown": shown}


#: The default of a member derived from others (:meth:`Capabilities.__post_init__`).
_DERIVED: Any = None


def _empty() -> Mapping[str, Any]:
    return MappingProxyType({})


@dataclass(frozen=True, eq=False)
class Capabilities:
    """What a model gives gearchaos: the model contract, one field per member.

    Each field holds a member of the model (read by :meth:`of` from the model's attribute,
    property or method of the same name); its ``metadata`` says what the member is
    (``doc``) and, in words, what a model that does not give it gets (``otherwise``: the
    field's default; ``None`` for the required members). ``Capabilities.of(model)`` is the
    one place where a model's members are looked up: the layers above read
    :attr:`~gearchaos.model.System.capabilities`.
    """

    # -- required ------------------------------------------------------------------
    name: str = field(metadata=_doc("a short name for titles and stores"))
    state_names: tuple[str, ...] = field(metadata=_doc("the state y, in order"))
    obs_names: tuple[str, ...] = field(
        metadata=_doc(
            "the observables `rhs` writes: first `n_track` *tracked* ones (the integrator "
            "records their extrema over every run and lands steps on their switches), then their "
            "τ-derivatives, then any extras (forces, stiffness)"
        )
    )
    n_track: int = field(metadata=_doc("how many of the observables are tracked (see `obs_names`)"))
    n_state: int = field(
        metadata=_doc("the length of the state (a `UserModel` gives `len(state_names)`)")
    )
    kind: int = field(
        metadata=_doc(
            "the integer that selects the compiled right-hand side: built-in models have fixed "
            "kinds; a `UserModel` registers its `rhs` and derives its kind from the model's "
            "source"
        )
    )
    pack: Callable[[float], np.ndarray] = field(
        repr=False,
        metadata=_doc(
            "the float64 parameter vector `p` that `rhs` reads, at Ω", shown="pack(self, omega)"
        ),
    )
    # -- optional ------------------------------------------------------------------
    rhs: Any = field(
        default=None,
        repr=False,
        metadata=_doc(
            "the compiled right-hand side, a `numba.njit(cache=True)` function `rhs(t, y, p, "
            "dydt, obs, level)` writing dy/dτ into `dydt[:n_state]` and the observables into "
            "`obs` (at least the first `2 n_track`; `level` says whether all are needed, "
            "`OBS_ALL`)",
            "required of a `UserModel`; a built-in model's `kind` selects its own",
        ),
    )
    tangent: Any = field(
        default=None,
        repr=False,
        metadata=_doc(
            "`tangent(t, y, p, obs, dydt, n, k)`: the Jacobian J(τ, y[:n]) applied to the `k` "
            "tangent vectors stored after the state in `y`, written into `dydt[n:]`",
            "central finite differences of `rhs`",
        ),
    )
    switch_widths: np.ndarray = field(
        default=_DERIVED,
        metadata=_doc(
            "the half clearance b_k of the dead zone on each tracked observable (`inf`: smooth): "
            "the integrator lands a step where a tracked observable crosses ±b_k, where the "
            "vector field has a kink",
            "`inf` for each tracked observable (no switches)",
        ),
    )
    contacts: tuple[Contact, ...] = field(
        default=(),
        metadata=_doc(
            "`Contact(name, column, clearance, kind)` for each mesh and bearing whose contact "
            "regime (no impact, single-sided, double-sided) analyses report; a sweep stores a "
            "mesh's as `contact_NAME` (the meshes of a force group as `contact_LABEL`)",
            "none",
        ),
    )
    clearances: Mapping[str, float] = field(
        default=_DERIVED,
        metadata=_doc(
            "half clearances by name: store attributes `clearance_NAME`, clearance lines in "
            "figures (`symbols` name them)",
            "the contacts' half clearances by their names",
        ),
    )
    n_contact_forces: int = field(
        default=0,
        metadata=_doc(
            "how many tracked observables, at the end of the tracked ones, are contact forces "
            "(their extrema give peak forces; they have no switch)",
            "0",
        ),
    )
    force_groups: tuple[tuple[str, str, str], ...] = field(
        default=(),
        metadata=_doc(
            "(label, contact-force variable, deflection variable) of each kind of mesh whose "
            "contact forces are tracked: what `gearchaos response` and load factors read",
            "none",
        ),
    )
    static_mesh_force: Callable[[float], float] | None = field(
        default=None,
        repr=False,
        metadata=_doc(
            "the static load of one mesh at Ω, the reference of the dynamic load factor",
            "no load factors",
            shown="static_mesh_force(self, omega)",
        ),
    )
    default_observables: tuple[str, str] = field(
        default=_DERIVED,
        metadata=_doc(
            "the pair (variable, derivative) that sections, diagrams and labels show; a group "
            "name (`delta_sp`) stands for its first member",
            "the first tracked observable and its derivative, else the first two states",
        ),
    )
    scales: Any = field(
        default=None,
        metadata=_doc(
            "physical scales: `omega_n` (ω_n in rad/s, time τ = ω_n t), `length` (m) and an "
            "attribute for each quantity of `quantities` (`velocity`, `force`), for axes in SI "
            "units",
            "none: dimensionless axes only",
        ),
    )
    quantities: Mapping[str, str] = field(
        default_factory=_empty,
        metadata=_doc(
            "the physical quantity of each variable or group: name → `length`, `velocity` or "
            "`force` (`QUANTITIES`), converted to SI by the attribute of `scales` of that name",
            "none",
        ),
    )
    symbols: Mapping[str, tuple[str, str | None, str | None, str | None]] = field(
        default_factory=_empty,
        metadata=_doc(
            "figure symbols of its variables: variable (or group, `%d` standing for the member's "
            "number) → (mathtext symbol without `$`, its definition or None, the name of its "
            "clearance in `clearances` or None, the clearance's symbol or None)",
            "variables drawn by their names",
        ),
    )
    parameter_symbols: Mapping[str, str] = field(
        default_factory=_empty,
        metadata=_doc(
            "figure symbols of its parameters: field → mathtext symbol without `$`, for the axis "
            "of a swept or continued parameter and the *at …* line of figure titles; "
            "`check_model` refuses a key that is no field",
            "parameters named by their fields",
        ),
    )
    period_factor: float = field(
        default=1.0,
        metadata=_doc(
            "the forcing period T in units of 2π/Ω: T = `period_factor`·2π/Ω, the period of a "
            "forcing with several frequencies (mesh frequencies Ω and 3Ω/5: 5); sections, "
            "protocols (transient and recorded periods) and labels (period n) count T",
            "1: T = 2π/Ω",
        ),
    )
    period_name: str = field(
        default="forcing",
        metadata=_doc(
            "what one forcing period is called in axes, labels and tables (`mesh`: mesh periods, "
            "harmonics of the mesh frequency f_m)",
            "`forcing`",
        ),
    )
    member_name: str = field(
        default="member",
        metadata=_doc(
            "what one member of a variable group is called (`planet`: `delta_sp_1 … delta_sp_N` "
            "are the planets' deflections)",
            "`member`",
        ),
    )
    contact_words: Mapping[str, str] = field(
        default_factory=_empty,
        metadata=_doc(
            "how figures and tables write a contact or a group of contacts in words: name → "
            "words (`sun_planet`, the group of `sun_planet_1 … sun_planet_N`, → `sun–planet`)",
            "contacts and groups written by their names",
        ),
    )
    gearset: Any = field(
        default=None,
        repr=False,
        metadata=_doc(
            "the gear set the model was built from: speeds in rpm and Hz, eccentricity warnings, "
            "the gear set's TOML in stores",
            "none",
        ),
    )
    result_dataset: Callable[..., Any] | None = field(
        default=None,
        repr=False,
        metadata=_doc(
            "the dataset of a simulation result in the model's own layout (variables per group "
            "member, with long names and units)",
            "one variable per state and observable",
            shown="result_dataset(self, result, attrs, series)",
        ),
    )
    warn_for: Callable[[str], None] | None = field(
        default=None,
        repr=False,
        metadata=_doc(
            "warn when `analysis` (`Poincaré section`) is questionable for this model (a "
            "planetary model with eccentricities has no 1T-periodic section)",
            "no warnings",
            shown="warn_for(self, analysis)",
        ),
    )

    #: The names of the required members.
    REQUIRED: ClassVar[tuple[str, ...]]

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "name", str(self.name))
        for attr in ("state_names", "obs_names"):
            set_(self, attr, tuple(getattr(self, attr)))
        for attr in ("n_track", "n_state", "kind", "n_contact_forces"):
            set_(self, attr, _count(self, attr))
        set_(self, "contacts", tuple(self.contacts))
        set_(self, "force_groups", tuple(tuple(map(str, g)) for g in self.force_groups))
        widths = (
            np.full(self.n_track, np.inf)
            if self.switch_widths is None
            else np.array(self.switch_widths, dtype=np.float64)
        )
        widths.setflags(write=False)
        set_(self, "switch_widths", widths)
        if self.clearances is None:
            set_(self, "clearances", {c.name: c.clearance for c in self.contacts})
        for attr in _MAPS:
            value = getattr(self, attr)
            if not isinstance(value, Mapping):
                raise ParameterError(f"{attr} must map {_MAPS[attr]}: got {type(value).__name__}")
            set_(self, attr, MappingProxyType(dict(value)))
        pair = self.default_observables
        set_(self, "default_observables", _default_pair(self) if pair is None else _pair(pair))
        factor = self.period_factor
        if isinstance(factor, bool) or not isinstance(factor, int | float | np.floating):
            raise ParameterError(f"period_factor must be a number > 0: got {factor!r}")
        if not (math.isfinite(float(factor)) and float(factor) > 0):
            raise ParameterError(f"period_factor must be a finite number > 0: got {factor!r}")
        set_(self, "period_factor", float(factor))
        set_(self, "period_name", str(self.period_name))
        set_(self, "member_name", str(self.member_name))

    @classmethod
    def of(cls, model: Any) -> Capabilities:
        """The record of ``model``: each field from the model's member of the same name (an
        attribute, property or method), a member it does not give (or gives as ``None``)
        taking the field's default. A missing required member is refused with
        :class:`~gearchaos.errors.ParameterError` naming it and what it is.

        A model is frozen, so its record is read once: the records of the last
        :data:`RECENT_MODELS` models are kept (by identity, with the model)."""
        key = id(model)
        with _LOCK:
            hit = _RECENT.get(key)
        if hit is not None and hit[0] is model:
            return hit[1]
        caps = cls._read(model)
        with _LOCK:
            if len(_RECENT) >= RECENT_MODELS:
                _RECENT.pop(next(iter(_RECENT)))
            _RECENT[key] = (model, caps)
        return caps

    @classmethod
    def _read(cls, model: Any) -> Capabilities:
        what = type(model).__name__
        values: dict[str, Any] = {}
        for f in _FIELDS:
            value = getattr(model, f.name, None)
            if value is None:
                if f.name in cls.REQUIRED:
                    raise ParameterError(
                        f"{what} must define {f.name}, {f.metadata['doc']} (the model "
                        "contract: gearchaos.model.contract.Capabilities)"
                    )
                continue
            values[f.name] = value
        try:
            return cls(**values)
        except ParameterError as exc:
            raise ParameterError(f"{what}.{exc}") from None

    def in_words(self, name: str) -> str:
        """A contact or group of contacts as figures and tables write it: its
        :attr:`contact_words`, a member of a group by the group's words and its number
        (``sun_planet_1`` → ``sun–planet_1``), else ``name`` itself."""
        words = self.contact_words
        if name in words:
            return words[name]
        head, _, tail = name.rpartition("_")
        return f"{words[head]}_{tail}" if tail.isdigit() and head in words else name

    @property
    def has_scales(self) -> bool:
        """Whether the model converts to SI units (it gives ``scales``)."""
        return self.scales is not None


#: The members that are mappings, and what they map (for the refusal of anything else).
_MAPS = {
    "clearances": "contact names to half clearances",
    "quantities": "variable names to quantities",
    "symbols": "variable names to figure symbols",
    "parameter_symbols": "field names to mathtext symbols",
    "contact_words": "contact or group names to words",
}
#: How many models' records :meth:`Capabilities.of` keeps.
RECENT_MODELS = 256
_RECENT: dict[int, tuple[Any, Capabilities]] = {}
_LOCK = threading.Lock()
#: The fields of :class:`Capabilities`, in order.
_FIELDS = dataclasses.fields(Capabilities)
Capabilities.REQUIRED = tuple(f.name for f in _FIELDS if f.metadata["otherwise"] is None)


def _count(caps: Capabilities, attr: str) -> int:
    value = getattr(caps, attr)
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise ParameterError(f"{attr} must be an integer: got {value!r}")
    return int(value)


def _pair(pair: Any) -> tuple[str, str]:
    first, second = pair
    return (str(first), str(second))


def _default_pair(caps: Capabilities) -> tuple[str, str]:
    """The first tracked observable and its derivative, else the first two states."""
    names, n_track = caps.obs_names, caps.n_track
    if n_track >= 1 and len(names) >= 2 * n_track:
        return (names[0], names[n_track])
    states = caps.state_names or ("",)  # no states: check_model refuses the model
    return (states[0], states[1] if len(states) > 1 else states[0])
