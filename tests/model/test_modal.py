"""Linear modal analysis against the closed forms of MODEL.md §10.3 (Lin & Parker 1999,
Kahraman 1994).

Every reference value is recomputed here from the raw gear-set fields with the formulas of
MODEL.md (§1 equivalent masses, §5 equations of motion, §10.3 frequency equations); none is
copied from the code under test.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import gearchaos as gc
from gearchaos.model.modal import Mode, mass_stiffness, modes_table, natural_frequencies

RTOL = 1e-9

# Valid standard tooth numbers: z_r = z_s + 2 z_p, (z_s + z_r)/N an integer, and N planets
# that clear each other, (z_s + z_p)·sin(π/N) > z_p + 2.
TEETH = {
    1: (34, 31, 96),  # 130/1
    2: (34, 31, 96),  # 130/2 = 65
    3: (30, 33, 96),  # 126/3 = 42
    4: (34, 30, 94),  # 128/4 = 32
    5: (34, 31, 96),  # 130/5 = 26 (the hindawi2021 preset, MODEL.md §9)
    6: (42, 27, 96),  # 138/6 = 23; (42 + 27)·sin(π/6) = 34.5 > 29
}


def gearset(n: int, **changes: object) -> gc.GearSet:
    zs, zp, zr = TEETH[n]
    base: dict[str, object] = {
        "geometry.planets": n,
        "teeth.sun": zs,
        "teeth.planet": zp,
        "teeth.ring": zr,
    }
    base.update({k.replace("__", "."): v for k, v in changes.items()})
    return gc.preset("hindawi2021").evolve(base)


class Ref:
    """Independent physical quantities of a gear set, straight from MODEL.md §1 and §4."""

    def __init__(self, gs: gc.GearSet) -> None:
        g, z = gs.geometry, gs.teeth
        self.n = g.planets
        self.a_s = math.radians(g.pressure_angle_sun)
        self.a_r = math.radians(g.pressure_angle_ring)
        r_s, r_p = g.module * z.sun / 2, g.module * z.planet / 2
        r_bs, r_bp, r_c = r_s * math.cos(self.a_s), r_p * math.cos(self.a_s), r_s + r_p
        self.ms = gs.mass.sun
        self.ms_star = gs.inertia.sun / r_bs**2
        self.mp_star = gs.inertia.planet / r_bp**2
        self.mc_star = gs.inertia.carrier / r_c**2 + self.n * gs.mass.planet
        self.me = self.ms_star * self.mp_star / (self.ms_star + self.mp_star)
        self.ksp = gs.stiffness.sun_planet_mean
        self.krp = gs.stiffness.planet_ring_mean
        self.kb = gs.stiffness.sun_bearing
        self.omega_n = math.sqrt(self.ksp / self.me)

    def rotational(self) -> list[float]:
        """Kahraman's quadratic in λ = ω² (α_s = α_r = α), m_c⁺ = m_c*/cos²α."""
        n, ks, kr = self.n, self.ksp, self.krp
        ms, mp = self.ms_star, self.mp_star
        mc = self.mc_star / math.cos(self.a_s) ** 2
        a = mp * mc * ms
        b = -(n * ks * mp * mc + (kr + ks) * mc * ms + n * (kr + ks) * mp * ms)
        c = n * kr * ks * (n * mp + mc + 4 * ms)
        return quadratic_roots(a, b, c)

    def translational(self) -> list[float]:
        n, ks, kr, kb = self.n, self.ksp, self.krp, self.kb
        a = self.ms * self.mp_star
        b = -(self.mp_star * (kb + n * ks / 2) + self.ms * (ks + kr))
        c = (kb + n * ks / 2) * (ks + kr) - n * ks**2 / 2
        return quadratic_roots(a, b, c)

    def planet(self) -> float:
        return (self.ksp + self.krp) / self.mp_star


def quadratic_roots(a: float, b: float, c: float) -> list[float]:
    """Both real roots, each computed without cancellation."""
    disc = b * b - 4 * a * c
    assert disc > 0
    q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
    return sorted([q / a, c / q])


def omega2(modes: list[Mode], kind: str) -> list[float]:
    return [m.omega_rad_s**2 for m in modes if m.kind == kind]


# ---------------------------------------------------------------- closed forms, N = 3, 4, 5


@pytest.mark.parametrize("n", [3, 4, 5])
def test_rotational_modes_match_kahraman_quadratic(n: int) -> None:
    gs = gearset(n)
    ref = Ref(gs)
    modes = natural_frequencies(gs)
    rot = [m for m in modes if m.kind == "rotational"]
    assert [m.multiplicity for m in rot] == [1, 1, 1]
    assert rot[0].omega_rad_s == 0.0 and rot[0].ratio == 0.0 and rot[0].hz == 0.0
    np.testing.assert_allclose(omega2(rot[1:], "rotational"), ref.rotational(), rtol=RTOL)


@pytest.mark.parametrize("n", [3, 4, 5])
def test_translational_pairs_match_closed_form(n: int) -> None:
    gs = gearset(n)
    ref = Ref(gs)
    modes = natural_frequencies(gs)
    trans = [m for m in modes if m.kind == "translational"]
    assert [m.multiplicity for m in trans] == [2, 2]
    np.testing.assert_allclose(omega2(modes, "translational"), ref.translational(), rtol=RTOL)


@pytest.mark.parametrize("n", [3, 4, 5, 6])
def test_planet_modes(n: int) -> None:
    gs = gearset(n)
    ref = Ref(gs)
    planet = [m for m in natural_frequencies(gs) if m.kind == "planet"]
    if n == 3:
        assert planet == []
        return
    assert len(planet) == 1
    assert planet[0].multiplicity == n - 3
    assert planet[0].omega_rad_s ** 2 == pytest.approx(ref.planet(), rel=RTOL)


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 6])
def test_count_and_single_zero_mode(n: int) -> None:
    modes = natural_frequencies(gearset(n))
    assert sum(m.multiplicity for m in modes) == 4 + n
    zero = [m for m in modes if m.ratio == 0.0]
    assert len(zero) == 1 and zero[0] is modes[0]
    assert zero[0].kind == "rotational" and zero[0].multiplicity == 1
    assert all(m.ratio > 1e-3 for m in modes[1:])
    ratios = [m.ratio for m in modes]
    assert ratios == sorted(ratios)
    assert {m.kind for m in modes} <= {"rotational", "translational", "planet"}


@pytest.mark.parametrize("n", [3, 4, 5])
def test_units_and_ratio(n: int) -> None:
    gs = gearset(n)
    ref = Ref(gs)
    for m in natural_frequencies(gs):
        assert m.ratio == pytest.approx(m.omega_rad_s / ref.omega_n, rel=1e-12, abs=0.0)
        assert m.hz == pytest.approx(m.omega_rad_s / (2 * math.pi), rel=1e-12, abs=0.0)


# ---------------------------------------------------------------- matrices and shapes


def model_forces(gs: gc.GearSet, q: np.ndarray) -> np.ndarray:
    """Right-hand sides of MODEL.md §5 (b = 0, k = k_m, c = 0, no load, no errors)."""
    ref = Ref(gs)
    n = ref.n
    x, y, us, u, uc = q[0], q[1], q[2], q[3 : 3 + n], q[3 + n]
    psi = 2 * np.pi * np.arange(n) / n
    d_sp = us + u - uc * math.cos(ref.a_s) - x * np.sin(psi - ref.a_s) + y * np.cos(psi - ref.a_s)
    d_rp = -u - uc * math.cos(ref.a_r)
    f_sp, f_rp = ref.ksp * d_sp, ref.krp * d_rp
    return np.concatenate(
        [
            [np.sum(f_sp * np.sin(psi - ref.a_s)) - ref.kb * x],
            [-np.sum(f_sp * np.cos(psi - ref.a_s)) - ref.kb * y],
            [-np.sum(f_sp)],
            -f_sp + f_rp,
            [np.sum(f_sp * math.cos(ref.a_s) + f_rp * math.cos(ref.a_r))],
        ]
    )


@pytest.mark.parametrize("n", [1, 2, 3, 5])
@pytest.mark.parametrize("alpha_r", [22.5, 20.0])
def test_stiffness_reproduces_equations_of_motion(n: int, alpha_r: float) -> None:
    gs = gearset(n, geometry__pressure_angle_ring=alpha_r)
    ref = Ref(gs)
    M, K, names = mass_stiffness(gs)
    assert names == ("x_s", "y_s", "u_s", *(f"u_{i}" for i in range(1, n + 1)), "u_c")
    np.testing.assert_array_equal(
        M, np.diag([ref.ms, ref.ms, ref.ms_star, *[ref.mp_star] * n, ref.mc_star])
    )
    assert np.array_equal(K, K.T)
    rng = np.random.default_rng(n)
    for _ in range(5):
        q = rng.normal(size=4 + n) * 1e-5
        np.testing.assert_allclose(-K @ q, model_forces(gs, q), rtol=1e-12, atol=1e-12 * ref.ksp)


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 6])
def test_mode_shapes_mass_orthonormal(n: int) -> None:
    gs = gearset(n)
    M, K, _ = mass_stiffness(gs)
    modes = natural_frequencies(gs)
    phi = np.hstack([m.shape for m in modes])
    assert phi.shape == (4 + n, 4 + n)
    np.testing.assert_allclose(phi.T @ M @ phi, np.eye(4 + n), atol=1e-10)
    lam = np.concatenate([[m.omega_rad_s**2] * m.multiplicity for m in modes])
    scale = float(np.max(lam))
    np.testing.assert_allclose(phi.T @ K @ phi, np.diag(lam), atol=1e-10 * scale)
    assert not modes[0].shape.flags.writeable


@pytest.mark.parametrize("n", [4, 5])
def test_mode_shape_families(n: int) -> None:
    gs = gearset(n)
    modes = natural_frequencies(gs)
    ix, iy, ius, iuc = 0, 1, 2, 3 + n
    planets = slice(3, 3 + n)
    for m in modes:
        s = m.shape / np.max(np.abs(m.shape))
        if m.kind == "rotational":
            np.testing.assert_allclose(s[[ix, iy]], 0.0, atol=1e-10)
            np.testing.assert_allclose(s[planets] - s[3], 0.0, atol=1e-10)
        elif m.kind == "translational":
            np.testing.assert_allclose(s[[ius, iuc]], 0.0, atol=1e-10)
            assert abs(s[iy, 0]) < 1e-10 and s[ix, 0] > 0  # sun moves along x
            assert abs(s[ix, 1]) < 1e-10 and s[iy, 1] > 0  # sun moves along y
        else:
            np.testing.assert_allclose(s[[ix, iy, ius, iuc]], 0.0, atol=1e-10)
            np.testing.assert_allclose(s[planets].sum(axis=0), 0.0, atol=1e-10)


@pytest.mark.parametrize("alpha_r", [22.5, 20.0])
def test_zero_mode_is_rigid_rotation(alpha_r: float) -> None:
    gs = gearset(5, geometry__pressure_angle_ring=alpha_r)
    ref = Ref(gs)
    v = natural_frequencies(gs)[0].shape[:, 0]
    uc = v[-1]
    expected = np.array(
        [0.0, 0.0, uc * (math.cos(ref.a_s) + math.cos(ref.a_r)), *[-uc * math.cos(ref.a_r)] * 5, uc]
    )
    np.testing.assert_allclose(v, expected, atol=1e-12 * np.max(np.abs(v)))


def test_unequal_pressure_angles_keep_pairs_and_planet_modes() -> None:
    # The translational subspace has u_s = u_c = 0, so α_r does not enter its quadratic.
    gs = gearset(5, geometry__pressure_angle_ring=20.0)
    ref = Ref(gs)
    modes = natural_frequencies(gs)
    np.testing.assert_allclose(omega2(modes, "translational"), ref.translational(), rtol=RTOL)
    assert omega2(modes, "planet") == pytest.approx([ref.planet()], rel=RTOL)
    assert [m.multiplicity for m in modes if m.kind == "rotational"] == [1, 1, 1]


def test_independent_of_phasing_clearance_and_load() -> None:
    a = natural_frequencies(gearset(5))
    b = natural_frequencies(
        gearset(
            5,
            mesh_phasing__model="parker",
            backlash__sun_planet=0.0,
            clearance__sun_bearing=7.0,
            torque__input=10.0,
            stiffness__sun_planet_alternating=0.0,
            damping__sun_planet=0.2,
        )
    )
    assert [(m.kind, m.multiplicity) for m in a] == [(m.kind, m.multiplicity) for m in b]
    np.testing.assert_allclose([m.hz for m in a], [m.hz for m in b], rtol=1e-12)


def test_accidental_degeneracy_is_split_by_family() -> None:
    # Choose J_c so that a rotational root of Kahraman's quadratic equals the planet root
    # λ_p = (k_sp + k_rp)/m_p*: the quadratic is linear in m_c⁺, giving
    # m_c⁺ = [k_rp k_sp (N m_p* + 4 m_s*) − (k_sp + k_rp)² m_s*] / k_sp².
    gs0 = gearset(5, mass__planet=2.0)
    ref = Ref(gs0)
    ks, kr = ref.ksp, ref.krp
    mc_plus = (kr * ks * (5 * ref.mp_star + 4 * ref.ms_star) - (ks + kr) ** 2 * ref.ms_star) / ks**2
    r_c = gs0.geometry.module * (gs0.teeth.sun + gs0.teeth.planet) / 2
    jc = (mc_plus * math.cos(ref.a_s) ** 2 - 5 * 2.0) * r_c**2
    assert jc > 0
    gs = gs0.evolve({"inertia.carrier": jc})
    at = [m for m in natural_frequencies(gs) if m.omega_rad_s**2 == pytest.approx(ref.planet())]
    assert sorted((m.kind, m.multiplicity) for m in at) == [("planet", 2), ("rotational", 1)]
    assert at[0].omega_rad_s == at[1].omega_rad_s


# ---------------------------------------------------------------- JSON contract


def test_modes_table_contract() -> None:
    gs = gc.preset("hindawi2021")
    table = modes_table(gs)
    assert json.loads(json.dumps(table)) == table
    modes = natural_frequencies(gs)
    assert len(table) == len(modes)
    for row, m in zip(table, modes, strict=True):
        assert set(row) == {"hz", "ratio", "kind", "multiplicity"}
        assert type(row["hz"]) is float and type(row["ratio"]) is float
        assert type(row["multiplicity"]) is int and type(row["kind"]) is str
        assert row == {"hz": m.hz, "ratio": m.ratio, "kind": m.kind, "multiplicity": m.multiplicity}
    assert table[0]["ratio"] == 0.0 and table[0]["kind"] == "rotational"
    assert sum(r["multiplicity"] for r in table) == 4 + 5
