"""The planetary observables are laid out once (``layout.PLANETARY_GROUPS``): the names Python
gives them and the offsets the compiled kernel writes them at come from the same table. At a
random time and state every named observable must equal its definition (MODEL.md §3, §4, §7),
computed in numpy by the independent right-hand side of ``tests/integrate/test_vs_scipy.py``."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest
from planetary_variants import variant_gearset

from gearchaos.model import layout as L
from gearchaos.model.planetary import planetary_system

_spec = importlib.util.spec_from_file_location(
    "_vs_scipy", Path(__file__).resolve().parents[1] / "integrate" / "test_vs_scipy.py"
)
assert _spec is not None and _spec.loader is not None
_vs_scipy = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_vs_scipy)
model_md_rhs = _vs_scipy.model_md_rhs


def test_names_follow_the_table() -> None:
    names = L.planetary_obs_names(2)
    assert names[:6] == ("delta_sp_1", "delta_sp_2", "delta_rp_1", "delta_rp_2", "x_s", "y_s")
    assert names[L.planetary_n_track(2)] == "delta_sp_dot_1"
    assert names[-1] == "stiffness_rp_2"
    for n in (1, 3, 5, 7):
        names = L.planetary_obs_names(n)
        assert len(names) == len(set(names)) == L.planetary_offset(L.PLANETARY_OBS["size"], n)
        for group, per_planet in L.PLANETARY_GROUPS:
            first = L.planetary_offset(L.PLANETARY_OBS[group], n)
            assert names[first] == (f"{group}_1" if per_planet else group)
        nt = L.planetary_n_track(n)
        assert [names[nt + k] for k in range(nt)] == [_dot(names[k]) for k in range(nt)]


def _dot(name: str) -> str:
    """The name of an observable's τ-derivative: x_s → x_s_dot, delta_sp_2 → delta_sp_dot_2."""
    base, _, i = name.rpartition("_")
    return f"{base}_dot_{i}" if i.isdigit() else f"{name}_dot"


@pytest.mark.parametrize(("n", "rare"), [(3, False), (5, True), (6, False), (7, True), (2, False)])
def test_every_named_observable_is_its_model_md_definition(n: int, rare: bool) -> None:
    omega = 1.3
    system = planetary_system(variant_gearset(n, rare), omega)
    par = system.model.parameters
    rhs = model_md_rhs(par, omega)
    names = system.obs_names
    assert system.n_obs == len(names)
    rng = np.random.default_rng(n)
    b = max(par.b_sp, par.b_rp, par.b_s)
    for _ in range(4):
        t = float(rng.uniform(0, 50))
        y = rng.normal(scale=2.0 * b, size=system.n_state)
        obs = dict(zip(names, system.observe(np.array([t]), y[None, :])[0], strict=True))
        d_sp, d_rp, d_sp_d, d_rp_d, f_sp, f_rp = rhs.meshes(t, y)
        h = 1e-6  # the contact forces' τ-derivatives: central difference along the flow
        fdot = [
            (np.array(rhs.meshes(t + h, y + h * rhs(t, y))[4 + m])
             - np.array(rhs.meshes(t - h, y - h * rhs(t, y))[4 + m])) / (2 * h)
            for m in (0, 1)
        ]  # fmt: skip
        th = omega * t
        k_sp = 1.0 + par.eps_sp * np.cos(th + np.asarray(par.phi_sp))
        k_rp = par.kappa_rp_mean + par.kappa_rp_alt * np.cos(th + np.asarray(par.phi_rp))
        for h_, a in enumerate(par.harmonics_sp, start=2):
            k_sp = k_sp + a * np.cos(h_ * (th + np.asarray(par.phi_sp)))
        for h_, a in enumerate(par.harmonics_rp, start=2):
            k_rp = k_rp + a * np.cos(h_ * (th + np.asarray(par.phi_rp)))
        n_dof = n + 3
        expected: dict[str, float] = {
            "x_s": y[0], "y_s": y[1], "x_s_dot": y[n_dof], "y_s_dot": y[n_dof + 1],
        }  # fmt: skip
        for i in range(n):
            touch_sp, touch_rp = abs(d_sp[i]) > par.b_sp, abs(d_rp[i]) > par.b_rp
            expected |= {
                f"delta_sp_{i + 1}": d_sp[i],
                f"delta_rp_{i + 1}": d_rp[i],
                f"delta_sp_dot_{i + 1}": d_sp_d[i],
                f"delta_rp_dot_{i + 1}": d_rp_d[i],
                f"force_sp_{i + 1}": f_sp[i],
                f"force_rp_{i + 1}": f_rp[i],
                f"contact_force_sp_{i + 1}": f_sp[i] if touch_sp else 0.0,
                f"contact_force_rp_{i + 1}": f_rp[i] if touch_rp else 0.0,
                f"contact_force_sp_dot_{i + 1}": fdot[0][i] if touch_sp else 0.0,
                f"contact_force_rp_dot_{i + 1}": fdot[1][i] if touch_rp else 0.0,
                f"stiffness_sp_{i + 1}": k_sp[i],
                f"stiffness_rp_{i + 1}": k_rp[i],
            }
        assert set(expected) == set(names)
        for name, value in expected.items():
            tol = 1e-5 if name.startswith("contact_force") and "_dot" in name else 1e-11
            assert obs[name] == pytest.approx(value, rel=tol, abs=tol), name
