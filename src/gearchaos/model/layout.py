"""Index layout of the packed float64 parameter vectors that the compiled kernels read.

Each built-in system has an integer *kind* and a flat parameter vector ``p``. The positions are
module-level integer constants so that numba folds them into the machine code. Nothing outside
:mod:`gearchaos.model` should index ``p`` directly; use the records and ``pack`` functions.
"""

from __future__ import annotations

# ---------- system kinds
KIND_PLANETARY = 0
KIND_BACKLASH_OSCILLATOR = 1
KIND_LINEAR = 2
KIND_DUFFING = 3
KIND_LORENZ = 4
#: Planet counts whose planetary right-hand side is compiled for that count, as kind
#: KIND_PLANETARY_FIXED + N (fixed loop trip counts and parameter offsets: a step about 11 %
#: cheaper, issue 13); other counts use the general KIND_PLANETARY kernel. Each kind is compiled
#: (once, on first use, into numba's disk cache) only when a gear set with that count runs.
PLANETARY_FIXED_N = (3, 4, 5, 6)
KIND_PLANETARY_FIXED = 100


def planetary_kind(n_planets: int) -> int:
    """The kernel kind of a planetary model with ``n_planets`` planets."""
    n = int(n_planets)
    return KIND_PLANETARY_FIXED + n if n in PLANETARY_FIXED_N else KIND_PLANETARY


# ---------- planetary (kind 0)
P_N = 0  # number of planets N
P_OMEGA = 1  # Ω, dimensionless mesh frequency
P_INV_MU_S = 2  # 1/μ_s   (sun translational mass)
P_INV_MUS = 3  # 1/μ_s*  (sun equivalent torsional mass)
P_INV_MUP = 4  # 1/μ_p*
P_INV_MUC = 5  # 1/μ_c*
P_CS = 6  # c̄_s = 2ζ_b, sun bearing damping
P_KB = 7  # κ_b = k_s/k_m,sp
P_BS = 8  # b̄_s
P_CSP = 9  # c̄_sp
P_CRP = 10  # c̄_rp
P_BSP = 11  # b̄_sp
P_BRP = 12  # b̄_rp
P_EPS_SP = 13  # ε_sp = k_a,sp/k_m,sp
P_KRP_M = 14  # k_m,rp/k_m,sp
P_KRP_A = 15  # k_a,rp/k_m,sp
P_TD = 16  # T̄_D at this Ω (constant power already applied)
P_TL = 17  # T̄_L at this Ω
P_COS_AS = 18  # cos α_s
P_COS_AR = 19  # cos α_r
P_ASP = 20  # Ā_sp
P_ARP = 21  # Ā_rp
P_ES = 22  # Ē_s
P_EP = 23  # Ē_p
P_ER = 24  # Ē_r
P_ZS = 25  # z_s
P_ZP = 26  # z_p
P_ZR = 27  # z_r
P_ECC = 28  # 1.0 if any eccentricity is non-zero
P_NH_SP = 29  # number of extra stiffness harmonics (h = 2, 3, …) of the sun–planet mesh
P_NH_RP = 30  # … of the planet–ring mesh
P_HEADER = 32  # per-planet blocks start here

# per-planet blocks, each N long, in this order after the header
B_S = 0  # sin(ψ_i − α_s)
B_C = 1  # cos(ψ_i − α_s)
B_CK_SP = 2  # cos φ_spi   (stiffness phase)
B_SK_SP = 3  # sin φ_spi
B_CK_RP = 4  # cos φ_rpi
B_SK_RP = 5  # sin φ_rpi
B_CE_SP = 6  # cos(φ_spi + φ_te,sp)   (transmission-error phase)
B_SE_SP = 7  # sin(φ_spi + φ_te,sp)
B_CE_RP = 8  # cos(φ_rpi + φ_te,rp)
B_SE_RP = 9  # sin(φ_rpi + φ_te,rp)
B_C_ES = 10  # cos(β_s − ψ_i + α_s)   (sun eccentricity in the sun–planet mesh)
B_S_ES = 11
B_C_EPS = 12  # cos(β_p + α_s)        (planet eccentricity in the sun–planet mesh)
B_S_EPS = 13
B_C_EPR = 14  # cos(β_p − α_r)        (planet eccentricity in the planet–ring mesh)
B_S_EPR = 15
B_C_ER = 16  # cos(β_r − ψ_i − α_r)   (ring eccentricity)
B_S_ER = 17
N_BLOCKS = 18
# then NH_SP harmonic amplitudes (relative to k_m,sp) and NH_RP harmonic amplitudes

# planetary observables: groups of one value per planet (True) or a single value (False), in
# the order the kernel writes them. The tracked groups come first — the arguments of the dead
# zones (δ̄_sp, δ̄_rp, x̄_s, ȳ_s: contact switches), then the contact forces F̄ᶜ_sp, F̄ᶜ_rp —, then
# their τ-derivatives (``<group>_dot``), then the extras (mesh forces and stiffnesses). The
# kernel's offsets and the names of the observables are both generated from this table.
PLANETARY_TRACKED = (
    ("delta_sp", True),
    ("delta_rp", True),
    ("x_s", False),
    ("y_s", False),
    ("contact_force_sp", True),
    ("contact_force_rp", True),
)
PLANETARY_EXTRAS = (
    ("force_sp", True),
    ("force_rp", True),
    ("stiffness_sp", True),
    ("stiffness_rp", True),
)
PLANETARY_GROUPS = (
    *PLANETARY_TRACKED,
    *((f"{name}_dot", per_planet) for name, per_planet in PLANETARY_TRACKED),
    *PLANETARY_EXTRAS,
)


def _offsets(groups: tuple[tuple[str, bool], ...]) -> dict[str, tuple[int, int]]:
    """(a, b) for each group (and ``"size"`` after the last): it starts at index a N + b."""
    out, a, b = {}, 0, 0
    for name, per_planet in groups:
        out[name] = (a, b)
        a, b = (a + 1, b) if per_planet else (a, b + 1)
    out["size"] = (a, b)
    return out


#: where each planetary observable group starts, as (a, b): index a N + b for N planets (global
#: tuples of ints, which numba folds into the kernels as constants)
PLANETARY_OBS = _offsets(PLANETARY_GROUPS)
O_DELTA_SP = PLANETARY_OBS["delta_sp"]
O_DELTA_RP = PLANETARY_OBS["delta_rp"]
O_X_S = PLANETARY_OBS["x_s"]
O_Y_S = PLANETARY_OBS["y_s"]
O_CONTACT_SP = PLANETARY_OBS["contact_force_sp"]
O_CONTACT_RP = PLANETARY_OBS["contact_force_rp"]
O_DOT = PLANETARY_OBS["delta_sp_dot"]  # the derivatives: each group's offset plus this one's
O_FORCE_SP = PLANETARY_OBS["force_sp"]
O_FORCE_RP = PLANETARY_OBS["force_rp"]
O_STIFFNESS_SP = PLANETARY_OBS["stiffness_sp"]
O_STIFFNESS_RP = PLANETARY_OBS["stiffness_rp"]


def planetary_offset(group: tuple[int, int], n_planets: int) -> int:
    """Index of the first observable of a group (``PLANETARY_OBS``) for ``n_planets`` planets."""
    return group[0] * n_planets + group[1]


def planetary_obs_names(n_planets: int) -> tuple[str, ...]:
    """Names of the planetary observables for ``n_planets`` planets, in the kernel's order:
    ``<group>_<i>`` (planets from 1) for a group with one value per planet, else ``<group>``."""
    planets = range(1, int(n_planets) + 1)
    return tuple(
        name_i
        for name, per_planet in PLANETARY_GROUPS
        for name_i in ((f"{name}_{i}" for i in planets) if per_planet else (name,))
    )


def planetary_n_track(n_planets: int) -> int:
    """Number of tracked planetary observables (their derivatives follow them)."""
    return planetary_offset(O_DOT, n_planets)


# ---------- backlash oscillator (kind 1)
BO_OMEGA = 0
BO_ZETA = 1
BO_EPS = 2
BO_B = 3
BO_FM = 4
BO_FA = 5  # effective amplitude: F_a Ω^q (q = 2 for transmission-error forcing, 0 for force)
BO_SIZE = 6

# ---------- linear system (kind 2)
LIN_OMEGA = 0
LIN_N = 1
LIN_HEADER = 2  # then A (n×n, row-major), f (n: cos forcing), g (n: sin forcing)

# ---------- Duffing (kind 3)
DU_OMEGA = 0
DU_DELTA = 1
DU_ALPHA = 2
DU_BETA = 3
DU_GAMMA = 4

# ---------- Lorenz (kind 4)
LZ_SIGMA = 0
LZ_RHO = 1
LZ_BETA = 2

# ---------- the finite-difference tangent of a model without its own (work arrays on the stack)
FD_MAX_STATE = 256  # most states
FD_MAX_OBS = 1024  # most observables
