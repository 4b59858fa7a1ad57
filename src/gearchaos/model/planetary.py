"""The transverse–torsional 2K-H planetary gear model in minimal relative coordinates.

:func:`nondimensionalise` turns a :class:`~gearchaos.gearset.GearSet` (SI) into frozen
:class:`PlanetaryParameters` (MODEL.md §7) and :class:`Scales` to convert back;
:class:`PlanetaryModel` packs them for the compiled right-hand side
(:func:`gearchaos.model.kernels.planetary_rhs`); :func:`planetary_system` is the usual entry.

Coordinates (MODEL.md §6): q = (x̄_s, ȳ_s, p̄_1..p̄_N, σ̄), state = (q, q'), with
p_i = u_s + u_i − u_c cos α_s and σ = u_s − u_c (cos α_s + cos α_r); the rigid-body rotation is
removed, so the zero state is a consistent start.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np

from ..errors import ParameterError
from ..gearset import GearSet
from ..gearset.validation import warn_if_eccentric
from . import layout as L
from .contract import Contact
from .system import System

__all__ = [
    "PlanetaryModel",
    "PlanetaryParameters",
    "Scales",
    "nondimensionalise",
    "planetary_system",
]


@dataclass(frozen=True)
class Scales:
    """Scales that turn dimensionless quantities back into SI.

    x = b_c x̄ [m]; t = τ/ω_n [s]; ẋ = b_c ω_n x̄' [m/s]; F = k_m,sp b_c F̄ [N];
    ω = ω_n Ω [rad/s].
    """

    length: float  # b_c [m]
    omega_n: float  # [rad/s]
    mass: float  # m_e [kg]
    stiffness: float  # k_m,sp [N/m]

    @property
    def time(self) -> float:
        """1/ω_n [s]."""
        return 1.0 / self.omega_n

    @property
    def velocity(self) -> float:
        """b_c ω_n [m/s]."""
        return self.length * self.omega_n

    @property
    def force(self) -> float:
        """k_m,sp b_c [N]."""
        return self.stiffness * self.length


@dataclass(frozen=True)
class PlanetaryParameters:
    """Dimensionless parameters of MODEL.md §7 (symbols in comments).

    Angles in radians. ``load_mode`` is ``constant_torque`` or ``constant_power``; for the
    latter ``torque_input`` is T̄_D at Ω = ``omega_ref`` and T̄_D(Ω) = T̄_D Ω_ref/Ω.
    """

    n_planets: int  # N
    teeth_sun: int  # z_s
    teeth_planet: int  # z_p
    teeth_ring: int  # z_r
    alpha_s: float  # α_s
    alpha_r: float  # α_r
    mu_s: float  # μ_s = m_s/m_e (sun translational)
    mu_s_star: float  # μ_s* = m_s*/m_e
    mu_p_star: float  # μ_p* = m_p*/m_e
    mu_c_star: float  # μ_c* = m_c*/m_e
    damping_sun_planet: float  # c̄_sp = c_sp/(m_e ω_n) = 2ξ_sp
    damping_planet_ring: float  # c̄_rp
    damping_sun_bearing: float  # c̄_s
    kappa_b: float  # κ_b = k_s/k_m,sp
    eps_sp: float  # ε_sp = k_a,sp/k_m,sp
    kappa_rp_mean: float  # k_m,rp/k_m,sp
    kappa_rp_alt: float  # k_a,rp/k_m,sp
    harmonics_sp: tuple[float, ...]  # k_h,sp/k_m,sp, h = 2, 3, …
    harmonics_rp: tuple[float, ...]  # k_h,rp/k_m,sp
    b_sp: float  # b̄_sp
    b_rp: float  # b̄_rp
    b_s: float  # b̄_s
    torque_input: float  # T̄_D = T_D/(r_bs k_m,sp b_c)
    torque_output: float  # T̄_L = T_L/(r_c k_m,sp b_c)
    load_mode: str
    omega_ref: float  # Ω_ref of constant power
    te_sp: float  # Ā_sp
    te_rp: float  # Ā_rp
    te_sp_phase: float  # phase offset of e_sp relative to φ_spi
    te_rp_phase: float
    ecc_sun: float  # Ē_s
    ecc_planet: float  # Ē_p
    ecc_ring: float  # Ē_r
    beta_s: float
    beta_p: float
    beta_r: float
    psi: tuple[float, ...]  # ψ_i
    phi_sp: tuple[float, ...]  # φ_spi
    phi_rp: tuple[float, ...]  # φ_rpi

    def loads(self, omega: float) -> tuple[float, float]:
        """(T̄_D, T̄_L) at Ω, with the load mode applied."""
        if self.load_mode == "constant_power":
            s = self.omega_ref / omega
            return self.torque_input * s, self.torque_output * s
        return self.torque_input, self.torque_output


def nondimensionalise(gs: GearSet) -> tuple[PlanetaryParameters, Scales]:
    """Dimensionless parameters (MODEL.md §7) and scales of a gear set."""
    if not isinstance(gs, GearSet):
        raise ParameterError(f"gs must be a GearSet: got {type(gs).__name__}")
    st = gs.stiffness
    me = gs.equivalent_mass_mesh
    k = st.sun_planet_mean
    wn = math.sqrt(k / me)
    bc = gs.clearance.characteristic_length
    msx, mpx, mcx = gs.equivalent_mass_sun, gs.equivalent_mass_planet, gs.equivalent_mass_carrier
    b_sp, b_rp = gs.backlash_bar()
    phi_sp, phi_rp = gs.mesh_phases()
    te, ec = gs.transmission_error, gs.eccentricity
    par = PlanetaryParameters(
        n_planets=gs.n_planets,
        teeth_sun=gs.teeth.sun,
        teeth_planet=gs.teeth.planet,
        teeth_ring=gs.teeth.ring,
        alpha_s=gs.alpha_s,
        alpha_r=gs.alpha_r,
        mu_s=gs.mass.sun / me,
        mu_s_star=msx / me,
        mu_p_star=mpx / me,
        mu_c_star=mcx / me,
        damping_sun_planet=gs.damping_sun_planet / (me * wn),
        damping_planet_ring=gs.damping_planet_ring / (me * wn),
        damping_sun_bearing=gs.damping_sun_bearing / (me * wn),
        kappa_b=st.sun_bearing / k,
        eps_sp=st.sun_planet_alternating / k,
        kappa_rp_mean=st.planet_ring_mean / k,
        kappa_rp_alt=st.planet_ring_alternating / k,
        harmonics_sp=tuple(h / k for h in st.sun_planet_harmonics),
        harmonics_rp=tuple(h / k for h in st.planet_ring_harmonics),
        b_sp=b_sp,
        b_rp=b_rp,
        b_s=gs.sun_bearing_clearance_bar(),
        torque_input=gs.torque.input / (gs.base_radius_sun * k * bc),
        torque_output=gs.output_torque / (gs.radius_carrier * k * bc),
        load_mode=gs.torque.mode,
        omega_ref=gs.torque.reference_omega,
        te_sp=te.sun_planet / bc,
        te_rp=te.planet_ring / bc,
        te_sp_phase=math.radians(te.sun_planet_phase),
        te_rp_phase=math.radians(te.planet_ring_phase),
        ecc_sun=ec.sun / bc,
        ecc_planet=ec.planet / bc,
        ecc_ring=ec.ring / bc,
        beta_s=math.radians(ec.sun_phase),
        beta_p=math.radians(ec.planet_phase),
        beta_r=math.radians(ec.ring_phase),
        psi=gs.planet_angles,
        phi_sp=phi_sp,
        phi_rp=phi_rp,
    )
    return par, Scales(length=bc, omega_n=wn, mass=me, stiffness=k)


# Header slots of the packed vector filled straight from PlanetaryParameters (slot, field).
_HEADER = {
    L.P_CS: "damping_sun_bearing",
    L.P_KB: "kappa_b",
    L.P_BS: "b_s",
    L.P_CSP: "damping_sun_planet",
    L.P_CRP: "damping_planet_ring",
    L.P_BSP: "b_sp",
    L.P_BRP: "b_rp",
    L.P_EPS_SP: "eps_sp",
    L.P_KRP_M: "kappa_rp_mean",
    L.P_KRP_A: "kappa_rp_alt",
    L.P_ASP: "te_sp",
    L.P_ARP: "te_rp",
    L.P_ES: "ecc_sun",
    L.P_EP: "ecc_planet",
    L.P_ER: "ecc_ring",
    L.P_ZS: "teeth_sun",
    L.P_ZP: "teeth_planet",
    L.P_ZR: "teeth_ring",
}
# Slots holding reciprocals of equivalent masses (slot, field).
_INVERSES = {
    L.P_INV_MU_S: "mu_s",
    L.P_INV_MUS: "mu_s_star",
    L.P_INV_MUP: "mu_p_star",
    L.P_INV_MUC: "mu_c_star",
}


def pack_planetary(par: PlanetaryParameters, omega: float) -> np.ndarray:
    """Packed parameter vector for :func:`~gearchaos.model.kernels.planetary_rhs` at Ω."""
    N = par.n_planets
    nh_sp, nh_rp = len(par.harmonics_sp), len(par.harmonics_rp)
    p = np.zeros(L.P_HEADER + L.N_BLOCKS * N + nh_sp + nh_rp)
    td, tl = par.loads(omega)
    p[L.P_N] = N
    p[L.P_OMEGA] = omega
    for slot, name in _INVERSES.items():
        p[slot] = 1.0 / getattr(par, name)
    for slot, name in _HEADER.items():
        p[slot] = getattr(par, name)
    p[L.P_TD] = td
    p[L.P_TL] = tl
    p[L.P_COS_AS] = math.cos(par.alpha_s)
    p[L.P_COS_AR] = math.cos(par.alpha_r)
    p[L.P_ECC] = 1.0 if (par.ecc_sun or par.ecc_planet or par.ecc_ring) else 0.0
    p[L.P_NH_SP] = nh_sp
    p[L.P_NH_RP] = nh_rp

    psi = np.asarray(par.psi)
    phs = np.asarray(par.phi_sp)
    phr = np.asarray(par.phi_rp)
    a_s, a_r = par.alpha_s, par.alpha_r
    blocks = {
        L.B_S: np.sin(psi - a_s),
        L.B_C: np.cos(psi - a_s),
        L.B_CK_SP: np.cos(phs),
        L.B_SK_SP: np.sin(phs),
        L.B_CK_RP: np.cos(phr),
        L.B_SK_RP: np.sin(phr),
        L.B_CE_SP: np.cos(phs + par.te_sp_phase),
        L.B_SE_SP: np.sin(phs + par.te_sp_phase),
        L.B_CE_RP: np.cos(phr + par.te_rp_phase),
        L.B_SE_RP: np.sin(phr + par.te_rp_phase),
        L.B_C_ES: np.cos(par.beta_s - psi + a_s),
        L.B_S_ES: np.sin(par.beta_s - psi + a_s),
        L.B_C_EPS: np.full(N, math.cos(par.beta_p + a_s)),
        L.B_S_EPS: np.full(N, math.sin(par.beta_p + a_s)),
        L.B_C_EPR: np.full(N, math.cos(par.beta_p - a_r)),
        L.B_S_EPR: np.full(N, math.sin(par.beta_p - a_r)),
        L.B_C_ER: np.cos(par.beta_r - psi - a_r),
        L.B_S_ER: np.sin(par.beta_r - psi - a_r),
    }
    for b, values in blocks.items():
        p[L.P_HEADER + b * N : L.P_HEADER + (b + 1) * N] = values
    h0 = L.P_HEADER + L.N_BLOCKS * N
    p[h0 : h0 + nh_sp] = par.harmonics_sp
    p[h0 + nh_sp : h0 + nh_sp + nh_rp] = par.harmonics_rp
    return p


#: The variables and groups of the planetary model that are lengths (in units of b_c).
_LENGTHS = ("delta_sp", "delta_rp", "x_s", "y_s", "p", "sigma")


@dataclass(frozen=True)
class PlanetaryModel:
    """The planetary gear model: dimensionless parameters, scales and the source gear set."""

    parameters: PlanetaryParameters
    scales: Scales
    gearset: GearSet | None = None
    name: str = "planetary"

    @property
    def kind(self) -> int:
        """Kind of the compiled kernel: the one for this planet count where there is one."""
        return L.planetary_kind(self.parameters.n_planets)

    @classmethod
    def from_gearset(cls, gs: GearSet) -> PlanetaryModel:
        par, sc = nondimensionalise(gs)
        return cls(par, sc, gs, name=f"planetary[{gs.name}]")

    @property
    def n_planets(self) -> int:
        return self.parameters.n_planets

    @property
    def n_dof(self) -> int:
        """N + 3 elastic coordinates."""
        return self.parameters.n_planets + 3

    @property
    def n_state(self) -> int:
        return 2 * self.n_dof

    @property
    def state_names(self) -> tuple[str, ...]:
        N = self.n_planets
        q = ("x_s", "y_s", *(f"p_{i + 1}" for i in range(N)), "sigma")
        return q + tuple(f"{s}_dot" for s in q)

    @property
    def obs_names(self) -> tuple[str, ...]:
        """From the layout table the kernel's offsets come from
        (:data:`~gearchaos.model.layout.PLANETARY_GROUPS`)."""
        return L.planetary_obs_names(self.n_planets)

    @property
    def n_track(self) -> int:
        """Extrema are tracked for the 2N mesh deflections, the two sun-bearing displacements
        (dead-zone switches located) and the 2N mesh contact forces (no switch of their own)."""
        return L.planetary_n_track(self.n_planets)

    @property
    def n_contact_forces(self) -> int:
        """The last 2N tracked observables are the mesh contact forces F̄ᶜ_sp, F̄ᶜ_rp."""
        return 2 * self.n_planets

    @property
    def switch_widths(self) -> np.ndarray:
        """Half clearances b of the dead zones f(·; b) of the tracked observables (``inf``
        for the contact forces)."""
        par, N = self.parameters, self.n_planets
        return np.array([par.b_sp] * N + [par.b_rp] * N + [par.b_s, par.b_s] + [np.inf] * (2 * N))

    @property
    def clearances(self) -> dict[str, float]:
        """Half clearances of each contact, dimensionless."""
        par = self.parameters
        return {"sun_planet": par.b_sp, "planet_ring": par.b_rp, "sun_bearing": par.b_s}

    @property
    def contacts(self) -> tuple[Contact, ...]:
        """The 2N meshes (judged on δ̄_spi, δ̄_rpi) and the sun bearing in x and y (judged on
        x̄_s, ȳ_s), in the order of the tracked observables."""
        par, N = self.parameters, self.n_planets
        out = [Contact(f"sun_planet_{i + 1}", i, par.b_sp) for i in range(N)]
        out += [Contact(f"planet_ring_{i + 1}", N + i, par.b_rp) for i in range(N)]
        out += [
            Contact("sun_bearing_x", 2 * N, par.b_s, "bearing"),
            Contact("sun_bearing_y", 2 * N + 1, par.b_s, "bearing"),
        ]
        return tuple(out)

    #: The seed's section variables: the sun–planet mesh deflection X̄_spi and its derivative.
    default_observables = ("delta_sp", "delta_sp_dot")
    #: Figure symbols: variable → (mathtext symbol, definition, clearance name, clearance
    #: symbol); ``%d`` marks a per-planet group (its member's number goes there).
    symbols: ClassVar[Mapping[str, tuple[str, str | None, str | None, str | None]]] = (
        MappingProxyType(
            {
                "delta_sp": (
                    r"\bar{X}_{sp%d}",
                    r"\delta_{sp%d}/b_c",
                    "sun_planet",
                    r"\bar{b}_{sp}",
                ),
                "delta_rp": (
                    r"\bar{X}_{rp%d}",
                    r"\delta_{rp%d}/b_c",
                    "planet_ring",
                    r"\bar{b}_{rp}",
                ),
                "force_sp": (r"\bar{F}_{sp%d}", r"F_{sp%d}/(k_{m,sp}\,b_c)", None, None),
                "force_rp": (r"\bar{F}_{rp%d}", r"F_{rp%d}/(k_{m,sp}\,b_c)", None, None),
                "contact_force_sp": (
                    r"\bar{F}^c_{sp%d}",
                    r"F^c_{sp%d}/(k_{m,sp}\,b_c)",
                    None,
                    None,
                ),
                "contact_force_rp": (
                    r"\bar{F}^c_{rp%d}",
                    r"F^c_{rp%d}/(k_{m,sp}\,b_c)",
                    None,
                    None,
                ),
                "p": (r"\bar{p}_{%d}", r"p_{%d}/b_c", None, None),
                "x_s": (r"\bar{x}_s", r"x_s/b_c", "sun_bearing", r"\bar{b}_s"),
                "y_s": (r"\bar{y}_s", r"y_s/b_c", "sun_bearing", r"\bar{b}_s"),
                "sigma": (r"\bar{\sigma}", r"\sigma/b_c", None, None),
            }
        )
    )
    #: The physical quantity of each variable and group (converted by :class:`Scales`): the
    #: displacements and deflections are lengths, their τ-derivatives velocities.
    quantities: ClassVar[Mapping[str, str]] = MappingProxyType(
        {
            **{f"{v}{d}": q for v in _LENGTHS for d, q in (("", "length"), ("_dot", "velocity"))},
            **dict.fromkeys(
                ("force_sp", "force_rp", "contact_force_sp", "contact_force_rp"), "force"
            ),
        }
    )
    #: What one forcing period is called (axes: "mesh periods", ω/ω_m) and a group member.
    period_name = "mesh"
    member_name = "planet"
    #: The meshes' contact groups in words (the summary figure's load factors and regimes).
    contact_words: ClassVar[Mapping[str, str]] = MappingProxyType(
        {"sun_planet": "sun–planet", "planet_ring": "planet–ring"}
    )
    #: Mesh types whose contact forces are tracked: (label, force group, deflection group).
    force_groups = (("sp", "contact_force_sp", "delta_sp"), ("rp", "contact_force_rp", "delta_rp"))

    def result_dataset(self, result: Any, attrs: dict[str, Any], series: Any) -> Any:
        """The dataset of a simulation result of this model, per planet
        (:func:`~gearchaos.model.planetary_dataset.planetary_dataset`)."""
        from .planetary_dataset import planetary_dataset

        return planetary_dataset(self, result, attrs, series)

    def static_mesh_force(self, omega: float) -> float:
        """F̄_static = T̄_D/N at Ω (MODEL.md §10.1), the load factor's reference."""
        td, _ = self.parameters.loads(omega)
        return float(td) / int(self.n_planets)

    def pack(self, omega: float) -> np.ndarray:
        return pack_planetary(self.parameters, omega)

    def warn_for(self, analysis: str) -> None:
        """Warn when a Poincaré-section analysis meets eccentricities (see
        :func:`~gearchaos.gearset.validation.warn_if_eccentric`)."""
        if self.gearset is not None and self.gearset.has_eccentricity:
            warn_if_eccentric(self.gearset, analysis)


def planetary_system(gs: GearSet, omega: float) -> System:
    """The planetary model of ``gs`` at dimensionless mesh frequency Ω = ω/ω_n."""
    if not isinstance(gs, GearSet):
        raise ParameterError(f"gs must be a GearSet: got {type(gs).__name__}")
    return System(PlanetaryModel.from_gearset(gs), omega)
