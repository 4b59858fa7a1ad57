"""Linear modal analysis of the planetary gear model (MODEL.md §10.3).

The physical 4+N-DOF model of MODEL.md §5 is linearised by removing every dead zone and
freezing each mesh stiffness at its mean value; loads, transmission and eccentricity errors and
damping are dropped. With the coordinates

    q = (x_s, y_s, u_s, u_1, …, u_N, u_c)      [m]

(u_s = r_bs θ_s, u_i = r_bp θ_pi, u_c = r_c θ_c) the mesh deflections are

    δ_spi = u_s + u_i − u_c cos α_s − x_s sin(ψ_i − α_s) + y_s cos(ψ_i − α_s) = a_iᵀ q,
    δ_rpi = −u_i − u_c cos α_r = r_iᵀ q,

and the energies

    T = ½ m_s (ẋ_s² + ẏ_s²) + ½ m_s* u̇_s² + ½ m_p* Σ_i u̇_i² + ½ m_c* u̇_c²,
    V = ½ k_m,sp Σ_i δ_spi² + ½ k_m,rp Σ_i δ_rpi² + ½ k_s (x_s² + y_s²),

give M q̈ + K q = 0 with

    M = diag(m_s, m_s, m_s*, m_p*, …, m_p*, m_c*),   m_c* = J_c/r_c² + N m_p,
    K = k_m,sp Σ_i a_i a_iᵀ + k_m,rp Σ_i r_i r_iᵀ + k_s (e_x e_xᵀ + e_y e_yᵀ).

Since −∂V/∂q reproduces the right-hand sides of MODEL.md §5 term by term, these are exactly its
equations of motion with b = 0, k = k_m, c = 0 and no excitation. The natural frequencies solve
the generalised symmetric eigenproblem K φ = ω² M φ (:func:`scipy.linalg.eigh`); they do not
depend on the mesh phasing, the clearances, the errors or the load.

Mode families (Lin & Parker 1999; rigid pins and a fixed ring), for N ≥ 3 equally spaced planets:

- rotational: x_s = y_s = 0, all u_i equal; three simple modes, one of them the rigid-body
  rotation u_s = u_c (cos α_s + cos α_r), u_i = −u_c cos α_r with ω = 0;
- translational: u_s = u_c = 0, u_i ∝ sin(ψ_i − α_s) or cos(ψ_i − α_s); two pairs of equal
  frequency (sun motion along x and along y);
- planet: x_s = y_s = u_s = u_c = 0 with Σ u_i = Σ u_i sin(ψ_i − α_s) = Σ u_i cos(ψ_i − α_s) = 0;
  one frequency ω² = (k_m,sp + k_m,rp)/m_p* of multiplicity N − 3 (N ≥ 4).

For N = 2 the three non-rotational modes all move the sun and are simple; for N = 1 every
elastic mode moves the sun. Both are reported as ``translational``.

References
----------
Lin, J. & Parker, R. G. (1999). Analytical characterization of the unique properties of planetary
gear free vibration. J. Vib. Acoust. 121, 316–321.
Kahraman, A. (1994). Natural modes of planetary gear trains. J. Sound Vib. 173(1), 125–130.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg

from .._checks import check_real
from ..gearset import GearSet

__all__ = [
    "KINDS",
    "Mode",
    "coordinate_names",
    "mass_stiffness",
    "modes_table",
    "natural_frequencies",
]

#: Mode families, in the order used to split accidental degeneracies.
KINDS: tuple[str, ...] = ("rotational", "translational", "planet")

# A vector lies in a family's subspace when its M-norm projection exceeds 1 − _IN_SUBSPACE.
_IN_SUBSPACE = 1e-6


@dataclass(frozen=True)
class Mode:
    """One natural frequency of the linear planetary model and its mode shapes.

    Attributes
    ----------
    omega_rad_s : float
        Natural frequency ω [rad/s] (exactly 0.0 for the rigid-body rotation).
    hz : float
        ω / 2π [Hz].
    ratio : float
        ω / ω_n with ω_n = √(k_m,sp / m_e) (:attr:`GearSet.omega_n`): the dimensionless mesh
        frequency Ω at which the first mesh harmonic meets this mode.
    kind : str
        ``"rotational"``, ``"translational"`` or ``"planet"``.
    multiplicity : int
        Dimension of the eigenspace (2 for translational pairs, N − 3 for planet modes).
    shape : numpy.ndarray
        (4 + N, multiplicity) read-only array of mass-normalised eigenvectors in the physical
        coordinates ``names`` (Φᵀ M Φ = I, units kg^−½). Translational pairs are rotated so that
        the first column moves the sun along +x (y_s = 0) and the second along +y (x_s = 0);
        in every other column the largest component is positive.
    names : tuple of str
        Coordinate names ``("x_s", "y_s", "u_s", "u_1", …, "u_N", "u_c")``.
    """

    omega_rad_s: float
    hz: float
    ratio: float
    kind: str
    multiplicity: int
    shape: np.ndarray = field(repr=False, compare=False)
    names: tuple[str, ...] = field(repr=False)

    def as_dict(self) -> dict[str, Any]:
        """The ``gearchaos info --json`` row: ``{"hz", "ratio", "kind", "multiplicity"}``."""
        return {
            "hz": float(self.hz),
            "ratio": float(self.ratio),
            "kind": str(self.kind),
            "multiplicity": int(self.multiplicity),
        }


def coordinate_names(n_planets: int) -> tuple[str, ...]:
    """Physical coordinate names ``("x_s", "y_s", "u_s", "u_1", …, "u_N", "u_c")``."""
    return ("x_s", "y_s", "u_s", *(f"u_{i + 1}" for i in range(n_planets)), "u_c")


def mass_stiffness(gs: GearSet) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """Mass and mean stiffness matrices of the physical 4+N-DOF model (SI).

    Parameters
    ----------
    gs : GearSet
        The gear set. Clearances, errors, damping, torque and mesh phasing are ignored.

    Returns
    -------
    M : numpy.ndarray
        (4+N, 4+N) diagonal mass matrix diag(m_s, m_s, m_s*, m_p*, …, m_p*, m_c*) [kg].
    K : numpy.ndarray
        (4+N, 4+N) symmetric positive semi-definite stiffness matrix [N/m],
        K = k_m,sp Σ a_i a_iᵀ + k_m,rp Σ r_i r_iᵀ + k_s (e_x e_xᵀ + e_y e_yᵀ), where δ_spi = a_iᵀ q
        and δ_rpi = r_iᵀ q (MODEL.md §3 with e = 0).
    names : tuple of str
        Coordinate names, see :func:`coordinate_names`.

    Notes
    -----
    Row by row, −K q equals the elastic forces of MODEL.md §5:
    Σ F_spi sin(ψ_i − α_s) − F_sx, −Σ F_spi cos(ψ_i − α_s) − F_sy, −Σ F_spi, −F_spi + F_rpi and
    Σ (F_spi cos α_s + F_rpi cos α_r), with F = k_m δ and F_s = k_s x_s. K has the null vector of
    the rigid rotation u_s = u_c (cos α_s + cos α_r), u_i = −u_c cos α_r, x_s = y_s = 0.
    """
    n = gs.n_planets
    dof = 4 + n
    ix, iy, ius, iuc = 0, 1, 2, 3 + n
    a_s, a_r = gs.alpha_s, gs.alpha_r
    st = gs.stiffness
    psi = np.asarray(gs.planet_angles)

    M = np.diag(
        [
            gs.mass.sun,
            gs.mass.sun,
            gs.equivalent_mass_sun,
            *([gs.equivalent_mass_planet] * n),
            gs.equivalent_mass_carrier,
        ]
    ).astype(float)

    K = np.zeros((dof, dof))
    for i in range(n):
        a = np.zeros(dof)
        a[ix] = -math.sin(psi[i] - a_s)
        a[iy] = math.cos(psi[i] - a_s)
        a[ius] = 1.0
        a[3 + i] = 1.0
        a[iuc] = -math.cos(a_s)
        r = np.zeros(dof)
        r[3 + i] = -1.0
        r[iuc] = -math.cos(a_r)
        K += st.sun_planet_mean * np.outer(a, a) + st.planet_ring_mean * np.outer(r, r)
    K[ix, ix] += st.sun_bearing
    K[iy, iy] += st.sun_bearing
    return M, K, coordinate_names(n)


def _family_bases(gs: GearSet, M: np.ndarray) -> dict[str, np.ndarray]:
    """M-orthonormal bases of the rotational, planet and translational subspaces.

    rotational = {x_s = y_s = 0, u_1 = … = u_N}; planet = {x_s = y_s = u_s = u_c = 0,
    Σu_i = Σu_i sin(ψ_i − α_s) = Σu_i cos(ψ_i − α_s) = 0}; translational = the M-orthogonal
    complement of both. For N ≥ 2 all three are invariant under M⁻¹K.
    """
    n = gs.n_planets
    dof = 4 + n
    d = np.sqrt(np.diag(M))
    planets = slice(3, 3 + n)

    rot = np.zeros((dof, 3))
    rot[2, 0] = 1.0
    rot[planets, 1] = 1.0
    rot[3 + n, 2] = 1.0

    psi = np.asarray(gs.planet_angles)
    constraints = np.vstack([np.ones(n), np.sin(psi - gs.alpha_s), np.cos(psi - gs.alpha_s)])
    null = scipy.linalg.null_space(constraints)  # orthonormal (n, n - rank)
    planet = np.zeros((dof, null.shape[1]))
    planet[planets, :] = null

    def orthonormal_in_m(b: np.ndarray) -> np.ndarray:
        if b.shape[1] == 0:
            return b
        q, _ = np.linalg.qr(d[:, None] * b)  # Euclidean-orthonormal in M^{1/2} coordinates
        return np.asarray(q / d[:, None])

    rot_m = orthonormal_in_m(rot)
    planet_m = orthonormal_in_m(planet)
    taken = d[:, None] * np.hstack([rot_m, planet_m])
    trans_m = scipy.linalg.null_space(taken.T) / d[:, None]
    return {"rotational": rot_m, "translational": trans_m, "planet": planet_m}


def _tidy(phi: np.ndarray, kind: str, names: tuple[str, ...]) -> np.ndarray:
    """Deterministic gauge of an eigenspace basis (columns M-orthonormal on entry and exit)."""
    phi = phi.copy()
    if kind == "translational" and phi.shape[1] == 2:
        ry = phi[names.index("y_s"), :]
        norm = float(np.hypot(ry[0], ry[1]))
        if norm > 0.0:
            rot = np.array([[ry[1], ry[0]], [-ry[0], ry[1]]]) / norm  # orthogonal 2×2
            phi = phi @ rot  # column 0: y_s = 0, column 1: x_s = 0
            for j, name in enumerate(("x_s", "y_s")):
                if phi[names.index(name), j] < 0.0:
                    phi[:, j] = -phi[:, j]
            return phi
    for j in range(phi.shape[1]):
        k = int(np.argmax(np.abs(phi[:, j])))
        if phi[k, j] < 0.0:
            phi[:, j] = -phi[:, j]
    return phi


def _split_group(
    phi: np.ndarray, bases: dict[str, np.ndarray], M: np.ndarray, names: tuple[str, ...]
) -> list[tuple[str, np.ndarray]]:
    """Split one eigenspace into its parts in each mode family.

    If the eigenspace is the direct sum of its intersections with the families (always true for
    N ≥ 2, where the families are invariant), each part is returned with its own basis; an
    accidental degeneracy of two families thus yields two modes at the same frequency.
    Otherwise (N = 1) the whole space is ``translational`` if it moves the sun, else
    ``rotational``.
    """
    m = phi.shape[1]
    parts: list[tuple[str, np.ndarray]] = []
    for kind in KINDS:
        b = bases[kind]
        if b.shape[1] == 0:
            continue
        c = b.T @ M @ phi  # coefficients of the M-orthogonal projection
        _, s, vt = np.linalg.svd(c, full_matrices=False)
        r = int(np.sum(s > 1.0 - _IN_SUBSPACE))
        if r:
            parts.append((kind, phi @ vt[:r].T))
    if sum(p.shape[1] for _, p in parts) == m:
        return parts
    moves_sun = bool(np.max(np.abs(phi[:2, :]) * np.sqrt(M[0, 0])) > math.sqrt(_IN_SUBSPACE))
    return [("translational" if moves_sun else "rotational", phi)]


def natural_frequencies(gs: GearSet, *, rtol: float = 1e-8) -> list[Mode]:
    """Natural frequencies and mode shapes of the linear planetary model.

    Solves K φ = ω² M φ for the physical 4+N-DOF model at mean mesh stiffness without clearances
    (:func:`mass_stiffness`; MODEL.md §5 and §10.3).

    Parameters
    ----------
    gs : GearSet
        The gear set (SI). Mesh phasing, clearances, errors and load do not enter.
    rtol : float, optional
        Relative tolerance on ω² under which neighbouring eigenvalues form one degenerate mode.

    Returns
    -------
    list of Mode
        Sorted by frequency; the multiplicities add up to 4 + N. The rigid-body rotation is
        the first entry, ``rotational`` with ``ratio == 0.0``.

    Notes
    -----
    The problem is solved in the dimensionless form K̄ = K/k_m,sp, M̄ = M/m_e, whose eigenvalues
    are λ̄ = (ω/ω_n)². Eigenvalues with |λ̄| ≤ 1000 ε (4+N) max λ̄ (ε the machine epsilon) are
    round-off of the rigid-body zero and are set to exactly 0. Modes are classified by
    projecting each eigenspace on the rotational, translational and planet subspaces (see the
    module docstring). For N ≥ 3, equally spaced planets and α_s = α_r = α the rotational
    roots solve Kahraman's quadratic in λ = ω² with m_c⁺ = m_c*/cos²α,

        λ² m_p* m_c⁺ m_s*
        − λ [N k_sp m_p* m_c⁺ + (k_rp + k_sp) m_c⁺ m_s* + N (k_rp + k_sp) m_p* m_s*]
        + N k_rp k_sp (N m_p* + m_c⁺ + 4 m_s*) = 0,

    the translational pairs solve

        m_s m_p* λ² − [m_p* (k_s + N k_sp/2) + m_s (k_sp + k_rp)] λ
        + (k_s + N k_sp/2)(k_sp + k_rp) − N k_sp²/2 = 0,

    and the planet modes sit at λ = (k_sp + k_rp)/m_p* (MODEL.md §10.3).
    """
    check_real("rtol", rtol, lo=0.0, hi=1.0, lo_open=True, hi_open=True)
    M, K, names = mass_stiffness(gs)
    me = gs.equivalent_mass_mesh
    ksp = gs.stiffness.sun_planet_mean
    lam, vec = scipy.linalg.eigh(K / ksp, M / me)
    vec = vec / math.sqrt(me)  # M-normalised in SI: Φᵀ M Φ = I
    dof = len(names)
    zero_tol = 1000.0 * np.finfo(float).eps * dof * float(np.max(np.abs(lam)))
    lam = np.where(np.abs(lam) <= zero_tol, 0.0, lam)

    groups: list[list[int]] = []
    for j in range(dof):
        if groups:
            prev = lam[groups[-1][-1]]
            if abs(lam[j] - prev) <= rtol * max(abs(lam[j]), abs(prev)) + zero_tol:
                groups[-1].append(j)
                continue
        groups.append([j])

    bases = _family_bases(gs, M)
    wn = gs.omega_n
    modes: list[Mode] = []
    for g in groups:
        lam_g = float(np.mean(lam[g]))
        ratio = math.sqrt(lam_g) if lam_g > 0.0 else 0.0
        omega = ratio * wn
        for kind, phi in _split_group(vec[:, g], bases, M, names):
            shape = _tidy(phi, kind, names)
            shape.flags.writeable = False
            modes.append(
                Mode(
                    omega_rad_s=omega,
                    hz=omega / (2.0 * math.pi),
                    ratio=ratio,
                    kind=kind,
                    multiplicity=int(shape.shape[1]),
                    shape=shape,
                    names=names,
                )
            )
    modes.sort(key=lambda md: (md.omega_rad_s, KINDS.index(md.kind)))
    return modes


def modes_table(gs: GearSet) -> list[dict[str, Any]]:
    """Natural frequencies as JSON-ready rows (the ``gearchaos info --json`` contract).

    Returns
    -------
    list of dict
        One ``{"hz": float, "ratio": float (ω/ω_n), "kind": "rotational" | "translational" |
        "planet", "multiplicity": int}`` per :class:`Mode` of :func:`natural_frequencies`,
        sorted by frequency, the rigid-body zero mode included.
    """
    return [mode.as_dict() for mode in natural_frequencies(gs)]
