"""Rendering of results for people: rich tables of summaries, gear-set information, regime
tables and gallery rows. Symbols come from the parameter registry
(:mod:`gearchaos.gearset.schema`)."""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from rich.columns import Columns
from rich.markup import escape as escape_markup
from rich.table import Table
from rich.text import Text

from .._text import escape_text
from ..analysis.motion import Motion
from ..analysis.summary import format_exponent
from ..gearset.mapping import flatten
from ..gearset.schema import display_symbol as symbol
from ..model.response import mesh_contacts

if TYPE_CHECKING:
    from ..model.system import System

__all__ = [
    "add_motion_rows",
    "column_title",
    "fmt",
    "gallery_rows_table",
    "info_renderables",
    "pairs_table",
    "plain_symbol",
    "regime_table",
    "section_symbol",
    "summary_labels",
    "sweep_summary",
    "sweep_table",
]


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
    "mesh_phasing.model": "mesh phasing used by the model",
    "mesh_phasing.class": "Parker–Lin phasing class of the teeth (if model = parker)",
    "mesh_phasing.k": "k = z_r mod N (decides the class)",
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
    "omega_at_resonances.sun_speed_rpm": "sun speed [rpm]",
    "clearances_um.sun_planet": "b_sp = b̄_sp b_c (sun–planet backlash)",
    "clearances_um.planet_ring": "b_rp = b̄_rp b_c (planet–ring backlash)",
    "clearances_um.sun_bearing": "b_s = b̄_s b_c (sun bearing)",
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
    "clearances_um": "Half clearances [µm]",
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


def escape(text: str) -> str:
    """Text for a table: control characters (of names and titles read from files) shown as
    escapes (:func:`~gearchaos._text.escape_text`), rich markup characters escaped."""
    return escape_markup(escape_text(text))


def label(path: str) -> str:
    """The label of an info entry: from :data:`_LABELS`, else made from the key."""
    if path in _LABELS:
        return _LABELS[path]
    key = path.rsplit(".", 1)[-1]
    for suffix, unit in _UNIT_SUFFIXES:
        if key.endswith(suffix) and len(key) > len(suffix):
            return f"{key[: -len(suffix)].replace('_', ' ')} [{unit}]"
    return key.replace("_", " ")


def fmt(value: Any) -> str:
    if isinstance(value, bool) or value is None:
        return "—" if value is None else str(value)
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.6g}"
    if isinstance(value, (list, tuple)):
        return ", ".join(fmt(v) for v in value) or "—"
    return str(value)


def pairs_table(title: str | None) -> Table:
    table = Table(title=escape(title) if title else None, title_justify="left", show_header=False)
    table.add_column("quantity", style="cyan")
    table.add_column("value", justify="right")
    return table


def info_renderables(data: Mapping[str, Any]) -> list[Any]:
    """Rich tables of a :func:`gearset_info` dictionary: an overview of the scalars, the
    groups of numbers side by side, then the mode and resonance lists."""
    overview = pairs_table(None)
    groups: list[Table] = []
    lists: list[Table] = []
    for key, value in data.items():
        if key in ("name", "description"):
            continue
        if isinstance(value, Mapping):
            target = overview if key in _OVERVIEW_GROUPS else pairs_table(_TITLES.get(key, key))
            for path, v in flatten(value, f"{key}.").items():
                target.add_row(escape(label(path)), escape(fmt(v)))
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
                    escape(label(f"{key}.{col}")), justify="left" if col == "kind" else "right"
                )
            for row in value:
                table.add_row(*(escape(fmt(row.get(col))) for col in columns))
            lists.append(table)
        else:
            overview.add_row(escape(label(key)), escape(fmt(value)))
    out: list[Any] = [overview]
    if groups:
        out.append(Columns(groups, padding=(0, 2)))
    return [*out, *lists]


def column_title(key: str) -> str:
    """``xi=0.03`` → ``ξ = 0.03``; ``all`` → ``all points``."""
    if key == "all":
        return "all points"
    name, sep, value = key.partition("=")
    if not sep:
        return key
    return f"{symbol(name)} = {value}"


def regime_table(table: Mapping[str, Mapping[str, float]], *, title: str | None) -> Table:
    """A rich table of a regime table: one row per regime (with its palette colour), one
    column per family value, fractions in %."""
    from ..analysis.classify import sort_labels
    from ..plot.regimes import regime_colour

    labels = sort_labels(label for column in table.values() for label in column)
    out = Table(title=escape(title) if title else None, title_justify="left")
    out.add_column("regime", no_wrap=True)
    for key in table:
        out.add_column(escape(column_title(key)), justify="right")
    for label in labels:
        cells = []
        for column in table.values():
            f = column.get(label)
            cells.append("—" if f is None else f"{100.0 * f:.1f} %")
        swatch = Text("■ ", style=regime_colour(label)) + Text(label)
        out.add_row(swatch, *cells)
    return out


def add_motion_rows(table: Table, summary: Mapping[str, Any]) -> None:
    """The evidence behind a summary's motion label as rows of its table (λ₁ and the
    multiplier are rows of :func:`format_summary`)."""
    lle = summary.get("lle")
    k01 = summary.get("k01")
    if summary.get("evidence", "record") == "record":
        table.add_row("largest Lyapunov exponent λ₁", "—" if lle is None else f"{lle:.4g}")
    table.add_row("0–1 test K", "—" if k01 is None else f"{k01:.3f}")
    agree = summary.get("indicators_agree")
    if agree is not None:
        table.add_row(
            "indicators agree", Text("yes" if agree else "no", style="" if agree else "bold red")
        )
    if summary.get("motion") is None and summary.get("record_label"):
        table.add_row("record label (no verdict)", escape(str(summary["record_label"])))
    if summary.get("window_periods"):
        start = int(summary.get("window_start", 0))
        end = start + int(summary["window_periods"])
        table.add_row("λ₁ measured over", f"periods {start}–{end} after the record")
    for orb in summary.get("coexisting") or []:
        mu = orb.get("max_multiplier")
        orbit = Motion.periodic(int(orb["period"]))
        table.add_row(
            "coexisting stable orbit",
            f"{orbit}, max |μ| = {mu:.6g} (not the recorded motion)"
            if mu is not None
            else f"{orbit} (not the recorded motion)",
        )
    note = summary.get("motion_note")
    if note:
        table.add_row("motion note", escape(str(note)))


def gallery_rows_table(rows: Sequence[Mapping[str, Any]], param: str, *, title: str) -> Table:
    """One row per value: value, motion (in its palette colour), what decided it, max |μ|,
    λ₁ ± its error, K, agree, points."""
    from ..dynamics.verdict.evidence import evidence_words
    from ..plot.regimes import regime_colour

    table = Table(title=escape(title), title_justify="left")
    table.add_column(escape(symbol(param)), justify="right")
    table.add_column("motion", no_wrap=True)
    table.add_column("decided by", no_wrap=True)
    table.add_column("max |μ|", justify="right")
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
            evidence_words(str(r.get("evidence", "record"))),
            "—" if r.get("max_multiplier") is None else f"{r['max_multiplier']:.4g}",
            format_exponent(lle, r.get("lle_error")),
            "—" if k01 is None else f"{k01:.3f}",
            Text("yes" if agree else "no", style="" if agree else "bold red"),
            str(r.get("distinct_section_points", "—")),
        )
    return table


def sweep_summary(res: Any, output: Any, seconds: float) -> dict[str, Any]:
    """What a sweep command reports (``--json``): store, points, failed points and seconds."""
    return {
        "store": str(output),
        "points": int(res.status().size),
        "failed": res.n_failed,
        "seconds": seconds,
    }


def sweep_table(title: str, res: Any, summary: Mapping[str, Any]) -> Table:
    """The summary table of a sweep command, headed by its grid (Ω with the sun speed the
    store records beside it), points and failed points."""
    table = pairs_table(title)
    table.add_row("grid", escape(" × ".join(f"{d} ({res.ds.sizes[d]})" for d in res.lead_dims)))
    from ..plot.units import PhysicalScales

    rpm = PhysicalScales.of_sweep(res).rpm_per_omega  # None: no gear set, or ω_n swept
    om = res.ds["omega"].values if "omega" in res.lead_dims else res.fixed_value("omega")
    if rpm is not None and om is not None:
        lo, hi = float(np.min(om)), float(np.max(om))
        span = f"{lo:.6g}" if lo == hi else f"{lo:.6g} … {hi:.6g}"
        speeds = f"{lo * rpm:.5g}" if lo == hi else f"{lo * rpm:.5g} … {hi * rpm:.5g}"
        table.add_row("Ω (sun speed)", f"{span} ({speeds} rpm)")
    table.add_row("points", str(summary["points"]))
    failed = summary["failed"]
    table.add_row("failed", Text(str(failed), style="bold red" if failed else ""))
    return table


def _fmt(v: Any) -> str:
    if v is None:
        return "—"
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


#: Greek letters of mathtext symbols, as text.
_GREEK = {
    name: chr(code)
    for name, code in (
        ("alpha", 0x3B1), ("beta", 0x3B2), ("gamma", 0x3B3), ("delta", 0x3B4),
        ("epsilon", 0x3B5), ("varepsilon", 0x3B5), ("zeta", 0x3B6), ("eta", 0x3B7),
        ("theta", 0x3B8), ("kappa", 0x3BA), ("lambda", 0x3BB), ("mu", 0x3BC), ("nu", 0x3BD),
        ("xi", 0x3BE), ("pi", 0x3C0), ("rho", 0x3C1), ("sigma", 0x3C3), ("tau", 0x3C4),
        ("phi", 0x3C6), ("varphi", 0x3C6), ("chi", 0x3C7), ("psi", 0x3C8), ("omega", 0x3C9),
        ("Gamma", 0x393), ("Delta", 0x394), ("Theta", 0x398), ("Lambda", 0x39B),
        ("Xi", 0x39E), ("Pi", 0x3A0), ("Sigma", 0x3A3), ("Phi", 0x3A6), ("Psi", 0x3A8),
        ("Omega", 0x3A9),
    )
}  # fmt: skip
_ACCENTS = {"bar": "\u0304", "dot": "\u0307", "ddot": "\u0308", "hat": "\u0302", "tilde": "\u0303"}
_MATH_COMMAND = re.compile(r"\\([A-Za-z]+)")


def plain_symbol(mathtext: str) -> str | None:
    r"""A model's mathtext symbol as plain text for a terminal: ``\bar{X}_{sp1}`` → ``X̄_sp1``,
    ``\bar{\sigma}`` → ``σ̄``, ``\mathrm{x\_1}`` → ``x_1``; None for a symbol with a command
    this does not know (the caller writes the variable's name instead)."""
    text = mathtext.strip().strip("$")
    text = re.sub(r"\\mathrm\{([^{}]*)\}", r"\1", text).replace(r"\_", "_")
    text = re.sub(r"\\[,;:! ]", " ", text)

    def accent(m: re.Match[str]) -> str:
        inner = m.group(2)
        inner = _GREEK.get(inner[1:], inner) if inner.startswith("\\") else inner
        return inner + _ACCENTS[m.group(1)]

    accents = "|".join(_ACCENTS)
    text = re.sub(rf"\\({accents})\{{(\\?[A-Za-z]+|.)\}}", accent, text)
    text = re.sub(rf"\\({accents})\s*(\\[A-Za-z]+|[A-Za-z])", accent, text)
    text = _MATH_COMMAND.sub(lambda m: _GREEK.get(m.group(1), m.group(0)), text)
    if "\\" in text:
        return None
    return text.replace("{", "").replace("}", "")


def _group_name(label: str, contacts: Sequence[str]) -> str:
    """A mesh type by its contacts: the stem they share before the member's number
    (``sun_planet_1 … sun_planet_5`` → ``sun_planet``), a lone contact's name, else the
    type's own label."""
    if len(contacts) == 1:
        return contacts[0]
    parts = [c.rpartition("_") for c in contacts]
    stems = {head for head, _, _ in parts}
    numbered = all(head and tail.isdigit() for head, _, tail in parts)
    return stems.pop() if numbered and len(stems) == 1 else label


def section_symbol(system: System | None, name: str) -> str:
    """The section variable ``name`` of ``system`` as tables write it: its symbol from the
    model's capabilities as plain text when it is the model's section variable
    (:meth:`~gearchaos.model.System.section_pair`: the planetary model's ``delta_sp_1`` is
    X̄_sp1, the two-stage train's ``x_1`` is q̄_1), else ``name`` itself."""
    if system is None:
        return name
    caps = system.capabilities
    entry = caps.symbols.get(caps.default_observables[0])
    if entry is None or system.section_pair(1)[0] != name:
        return name
    sym = entry[0] % 1 if "%d" in entry[0] else entry[0]  # its first member's
    return plain_symbol(sym) or name


def summary_labels(summary: Mapping[str, Any], system: System | None = None) -> dict[str, str]:
    """The row label of each key of ``summary`` that its table shows, in the table's order,
    in the words of the model of ``system`` (a :class:`~gearchaos.model.System`: its
    capabilities name the section variable by its symbol, the mesh types by their contacts
    and the frequency by its period); without one, the summary's own names."""
    section = str(summary.get("section_variable") or "section variable")
    frequency = "Ω ω_n/2π [Hz]"
    groups: dict[str, tuple[str, ...]] = {}
    if system is not None:
        caps = system.capabilities
        section = section_symbol(system, section)
        if caps.period_factor == 1.0:  # Ω is the frequency of its period
            frequency = f"{caps.period_name} frequency [Hz]"
        groups = mesh_contacts(system)
    loads = [k for k in summary if k.startswith("load_factor_") and k.endswith("_max")]
    labels = {
        "omega": "Ω = ω/ω_n",
        "omega_n_rad_s": "ω_n [rad/s]",
        "omega_hz": frequency,
        "sun_speed_rpm": "sun speed [rpm]",
        "distinct_section_points": "distinct section points",
        "motion": "motion",
        "evidence": "decided by",
        "max_multiplier": "max |μ| (Floquet)",
        "lle": "λ₁ [1/τ]",
        "extra_periods": "periods added to finish the transient",
        "section_min": f"{section} section min",
        "section_max": f"{section} section max",
    }
    for key in loads:
        mesh = key[len("load_factor_") : -len("_max")]
        labels[key] = f"load factor {_group_name(mesh, groups.get(mesh, ()))} (max)"
    labels["dte_rms"] = f"DTE RMS {summary.get('dte_contact') or ''}".rstrip()
    labels.update(status="status", steps_accepted="steps accepted", steps_rejected="steps rejected")
    return labels


def format_summary(
    summary: dict[str, Any], system: System | None = None, *, title: str | None = None
) -> Any:
    """A :class:`rich.table.Table` of a summary from
    :func:`~gearchaos.analysis.summary.summarize`, its rows labelled by
    :func:`summary_labels` in the words of the model of ``system`` (the
    :class:`~gearchaos.model.System` that ran)."""
    if title is None:
        gs = summary.get("gearset")
        # gear-set switch: a summary (analysis.summary) carries its gear set's name, no model
        title = f"gearchaos simulation{f' of {gs}' if gs else ''}"
    table = Table(title=escape(title), show_header=True, header_style="bold")
    table.add_column("quantity")
    table.add_column("value", justify="right")
    # None: the model has no scales (ω_n, Hz) or no mesh types (DTE)
    optional = {"omega_n_rad_s", "omega_hz", "dte_rms"}
    for key, label in summary_labels(summary, system).items():
        if key in summary:
            value = summary[key]
            if value is None and key in optional:
                continue
            recorded = summary.get("recorded_section_points")
            if key == "distinct_section_points" and recorded:
                value = f"{int(value)} of {int(recorded)}"
            if key == "lle" and value is not None:
                value = format_exponent(value, summary.get("lle_error"))
            if key in ("max_multiplier", "extra_periods") and not value:
                continue
            if key in ("evidence", "lle") and summary.get("evidence", "record") == "record":
                continue
            table.add_row(escape(label), escape(_fmt(value)))
    style = {"none": "green", "single_sided": "yellow", "double_sided": "red"}
    for c in summary.get("contact", []):
        regime = c["regime"]
        table.add_row(
            escape(f"contact {c['mesh']}"), f"[{style.get(regime, 'white')}]{escape(regime)}[/]"
        )
    return table
