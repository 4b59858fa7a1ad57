"""Compiled right-hand sides of every built-in system, behind one dispatch function.

Signature of every kernel: ``rhs(t, y, p, dydt, obs, level)`` — time, state, packed parameters,
output derivative, output observables, and how many observables to write: ``OBS_NONE`` (none:
the inner stages of a step), ``OBS_TRACK`` (the first ``2 n_track``: the ``n_track`` observables
whose running extrema the integrator records and whose dead-zone switches it locates, followed
by their time derivatives) or ``OBS_ALL`` (all, including extras such as mesh forces: samples and
the variational equations). A kernel may write more than asked for, never less. The integrator
reads ``obs`` after the last stage of a step, which the Dormand–Prince FSAL property evaluates
exactly at the new point, so observables cost next to nothing.

One dispatch function (:func:`rhs`) keeps numba's on-disk cache effective: a cached kernel that
receives a jitted function as an argument cannot be cached, and closures over dispatchers are
re-compiled in every process.

The kernels are *called*, not inlined into the integrator at the numba-IR level (that cost
5–8 s of compile time per call site, issue 13), and compiled without numba's reference
counting (``_nrt=False``: they allocate nothing), so a call costs no atomic reference-count
updates of its array arguments; a step of the planetary model is then as fast as with the
kernel inlined. Terms that the default gear sets do not have (stiffness harmonics,
eccentricities) live in a called helper, off the common path.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import types
from numba.extending import overload

from .._numba import njit_noalloc, stack_array
from . import layout as L
from .layout import (
    B_C,
    B_C_EPR,
    B_C_EPS,
    B_C_ER,
    B_C_ES,
    B_CE_RP,
    B_CE_SP,
    B_CK_RP,
    B_CK_SP,
    B_S,
    B_S_EPR,
    B_S_EPS,
    B_S_ER,
    B_S_ES,
    B_SE_RP,
    B_SE_SP,
    B_SK_RP,
    B_SK_SP,
    FD_MAX_OBS,
    FD_MAX_STATE,
    KIND_BACKLASH_OSCILLATOR,
    KIND_DUFFING,
    KIND_LINEAR,
    KIND_LORENZ,
    KIND_PLANETARY,
    N_BLOCKS,
    P_ARP,
    P_ASP,
    P_BRP,
    P_BS,
    P_BSP,
    P_COS_AR,
    P_COS_AS,
    P_CRP,
    P_CS,
    P_CSP,
    P_ECC,
    P_EP,
    P_EPS_SP,
    P_ER,
    P_ES,
    P_HEADER,
    P_INV_MU_S,
    P_INV_MUC,
    P_INV_MUP,
    P_INV_MUS,
    P_KB,
    P_KRP_A,
    P_KRP_M,
    P_N,
    P_NH_RP,
    P_NH_SP,
    P_OMEGA,
    P_TD,
    P_TL,
    P_ZP,
    P_ZR,
    P_ZS,
    PLANETARY_FIXED_N,
    planetary_kind,
)
from .reference_kernels import (
    backlash_oscillator_rhs,
    backlash_oscillator_tangent,
    dead_zone,
    duffing_rhs,
    duffing_tangent,
    engaged,
    in_contact,
    linear_rhs,
    linear_tangent,
    lorenz_rhs,
    lorenz_tangent,
)

__all__ = [
    "OBS_ALL",
    "OBS_NONE",
    "OBS_TRACK",
    "dead_zone",
    "observe_many",
    "rhs",
    "tangent",
]

#: observables a right-hand side writes (see the module docstring)
OBS_NONE = 0
OBS_TRACK = 1
OBS_ALL = 2


@numba.njit(cache=True, inline="always")
def _sinusoid(a, w, s, c, ca, sa):  # pragma: no cover - compiled
    """e = a sin(wτ + θ) from s = sin wτ, c = cos wτ, ca = cos θ, sa = sin θ, with its first
    and second τ-derivatives (e'' = −w² e)."""
    e = a * (s * ca + c * sa)
    return e, a * w * (c * ca - s * sa), -w * w * e


@numba.njit(cache=True, inline="always")
def _at(group, N):  # pragma: no cover - compiled
    """Index of the first observable of a planetary group (``layout.PLANETARY_OBS``)."""
    return group[0] * N + group[1]


@numba.njit(cache=True, inline="always")
def _planet_direction(p, N, i):  # pragma: no cover - compiled
    """(s_i, c_i): the sine and cosine of planet i's sun–planet line of action (the sun's
    translation enters the mesh deflection as −x s_i + y c_i)."""
    return p[P_HEADER + B_S * N + i], p[P_HEADER + B_C * N + i]


@njit_noalloc
def _eccentric_phases(t, p):  # pragma: no cover - compiled
    """(Ω_s, Ω_p, Ω_r, cos Ω_s τ, sin Ω_s τ, cos Ω_p τ, sin Ω_p τ, cos Ω_r τ, sin Ω_r τ) with
    Ω_x = Ω/z_x, the rotation frequencies of the eccentricities, once per right-hand side for
    every planet (zeros without eccentricities)."""
    if p[P_ECC] == 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    om = p[P_OMEGA]
    om_s = om / p[P_ZS]
    om_p = om / p[P_ZP]
    om_r = om / p[P_ZR]
    return (
        om_s, om_p, om_r,
        math.cos(om_s * t), math.sin(om_s * t),
        math.cos(om_p * t), math.sin(om_p * t),
        math.cos(om_r * t), math.sin(om_r * t),
    )  # fmt: skip


@numba.njit(cache=True, inline="always")
def _chebyshev_harmonics(p, first, count, x, k, dk):  # pragma: no cover - compiled
    """k + Σ_h a_h T_h(x) and dk + Σ_h a_h T_h'(x), h = 2 … count + 1, with the amplitudes
    a_h = p[first …] (Chebyshev recurrences for T_h and T_h')."""
    tm2, tm1, dm2, dm1 = 1.0, x, 0.0, 1.0  # T_0, T_1 and their derivatives
    for h in range(count):
        tt = 2.0 * x * tm1 - tm2
        dt_ = 2.0 * tm1 + 2.0 * x * dm1 - dm2
        k += p[first + h] * tt
        dk += p[first + h] * dt_
        tm2, tm1, dm2, dm1 = tm1, tt, dm1, dt_
    return k, dk


@njit_noalloc
def _planetary_general(ph, p, i, N, ck, ckr, ksp, dksp, krp, dkrp, esp, esp_d, esp_dd, erp,
                       erp_d, erp_dd):  # pragma: no cover - compiled  # fmt: skip
    """The terms of planet i that the default gear sets do not have — stiffness harmonics
    h ≥ 2 and eccentricities (phases ``ph`` from :func:`_eccentric_phases`) — added to its
    stiffnesses, transmission errors and their derivatives (in the order of MODEL.md §5). A
    called function: it keeps the common path of the right-hand side short (compile time) and
    free of never-taken branches (run time)."""
    nh_sp = int(p[P_NH_SP])
    nh_rp = int(p[P_NH_RP])
    h0 = P_HEADER + N_BLOCKS * N  # first harmonic amplitude
    ksp, dksp = _chebyshev_harmonics(p, h0, nh_sp, ck, ksp, dksp)
    krp, dkrp = _chebyshev_harmonics(p, h0 + nh_sp, nh_rp, ckr, krp, dkrp)
    if p[P_ECC] != 0.0:
        om_s, om_p, om_r, cs_, ss_, cp_, sp_, cr_, sr_ = ph
        for a, w, s_, c_, bc, bs, to_sp in (
            (p[P_ES], om_s, ss_, cs_, B_C_ES, B_S_ES, True),
            (p[P_EP], om_p, sp_, cp_, B_C_EPS, B_S_EPS, True),
            (p[P_EP], om_p, sp_, cp_, B_C_EPR, B_S_EPR, False),
            # sin(−Ω_H τ + θ) = sin θ cos(Ω_H τ) + cos θ sin(−Ω_H τ): frequency −Ω_H
            (p[P_ER], -om_r, -sr_, cr_, B_C_ER, B_S_ER, False),
        ):
            e1, e1_d, e1_dd = _sinusoid(
                a, w, s_, c_, p[P_HEADER + bc * N + i], p[P_HEADER + bs * N + i]
            )
            if to_sp:
                esp += e1
                esp_d += e1_d
                esp_dd += e1_dd
            else:
                erp += e1
                erp_d += e1_d
                erp_dd += e1_dd
    return ksp, dksp, krp, dkrp, esp, esp_d, esp_dd, erp, erp_d, erp_dd


def _planetary_rhs(n_fixed):
    """The planetary right-hand side, for any planet count (``n_fixed`` = 0: read from ``p``)
    or compiled for ``n_fixed`` planets: the loops over the planets then have a fixed trip
    count and every parameter a fixed offset (no index arithmetic, no register spills; numba
    caches the variants apart, by the value of ``n_fixed``)."""

    @njit_noalloc
    def planetary_rhs(t, y, p, dydt, obs, level):  # pragma: no cover - compiled
        """Minimal relative-coordinate equations of MODEL.md §7.

        State y = (x̄_s, ȳ_s, p̄_1..p̄_N, σ̄, then their τ-derivatives).
        obs = (δ̄_sp1..N, δ̄_rp1..N, x̄_s, ȳ_s, F̄ᶜ_sp1..N, F̄ᶜ_rp1..N, then the τ-derivatives of
        these T = 4N + 2 tracked observables, then F̄_sp1..N, F̄_rp1..N, then the mesh stiffnesses
        κ_sp1..N, κ_rp1..N), at the offsets of ``layout.PLANETARY_OBS``, the table that also
        names them (:func:`~gearchaos.model.layout.planetary_obs_names`).
        The first 2N + 2 are the arguments of the dead zones (event-located);
        F̄ᶜ is the *contact* force of a mesh, κ f(δ̄; b̄) + c̄ δ̄' while the teeth touch
        (|δ̄| > b̄) and exactly 0 while they are apart; F̄ is the force of the equations of motion,
        κ f(δ̄; b̄) + c̄ δ̄' at all times (damping acts inside the clearance, MODEL.md §4). Their
        derivatives F̄ᶜ' = κ' f + κ δ̄' + c̄ δ̄'' (engaged) let the integrator refine the contact
        forces' extrema inside a step; the stiffnesses feed the tangent equations.
        """
        N = n_fixed if n_fixed > 0 else int(p[P_N])
        n = N + 3
        nt = _at(L.O_DOT, N)  # tracked observables (their derivatives follow them)
        o_dsp = _at(L.O_DELTA_SP, N)
        o_drp = _at(L.O_DELTA_RP, N)
        o_csp = _at(L.O_CONTACT_SP, N)
        o_crp = _at(L.O_CONTACT_RP, N)
        om = p[P_OMEGA]
        th = om * t
        c1 = math.cos(th)
        s1 = math.sin(th)
        x = y[0]
        yy = y[1]
        sig = y[N + 2]
        xd = y[n]
        yd = y[n + 1]
        sigd = y[n + N + 2]

        eps_sp = p[P_EPS_SP]
        krm = p[P_KRP_M]
        kra = p[P_KRP_A]
        csp = p[P_CSP]
        crp = p[P_CRP]
        bsp = p[P_BSP]
        brp = p[P_BRP]
        asp = p[P_ASP]
        arp = p[P_ARP]
        inv_mup = p[P_INV_MUP]
        general = p[P_ECC] != 0.0 or p[P_NH_SP] > 0.0 or p[P_NH_RP] > 0.0
        ph = _eccentric_phases(t, p) if general else (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)

        sum_fsp = 0.0
        sum_frp = 0.0
        sum_fx = 0.0
        sum_fy = 0.0
        for i in range(N):
            si, ci = _planet_direction(p, N, i)
            s_i = -x * si + yy * ci
            sd_i = -xd * si + yd * ci

            # --- time-varying stiffness, angle addition from one sin/cos pair of Ωτ
            ck = c1 * p[P_HEADER + B_CK_SP * N + i] - s1 * p[P_HEADER + B_SK_SP * N + i]
            ksp = 1.0 + eps_sp * ck
            dksp = eps_sp  # dκ/d(cos θ); times dcos θ/dτ below (tracked level only)
            ckr = c1 * p[P_HEADER + B_CK_RP * N + i] - s1 * p[P_HEADER + B_SK_RP * N + i]
            krp = krm + kra * ckr
            dkrp = kra

            # --- transmission errors and their τ-derivatives
            esp, esp_d, esp_dd = _sinusoid(
                asp, om, s1, c1, p[P_HEADER + B_CE_SP * N + i], p[P_HEADER + B_SE_SP * N + i]
            )
            erp, erp_d, erp_dd = _sinusoid(
                arp, om, s1, c1, p[P_HEADER + B_CE_RP * N + i], p[P_HEADER + B_SE_RP * N + i]
            )
            if general:
                g = _planetary_general(
                    ph, p, i, N, ck, ckr, ksp, dksp, krp, dkrp, esp, esp_d, esp_dd, erp, erp_d,
                    erp_dd
                )  # fmt: skip
                ksp, dksp, krp, dkrp, esp, esp_d, esp_dd, erp, erp_d, erp_dd = g

            pi_ = y[2 + i]
            pid = y[n + 2 + i]
            dsp = pi_ + s_i - esp
            dsp_d = pid + sd_i - esp_d
            drp = sig - pi_ - erp
            drp_d = sigd - pid - erp_d
            fzsp = dead_zone(dsp, bsp)
            fzrp = dead_zone(drp, brp)
            fsp = ksp * fzsp + csp * dsp_d
            frp = krp * fzrp + crp * drp_d
            dydt[n + 2 + i] = (frp - fsp) * inv_mup  # completed below

            if level >= OBS_TRACK:
                obs[o_dsp + i] = dsp
                obs[o_drp + i] = drp
                obs[nt + o_dsp + i] = dsp_d
                obs[nt + o_drp + i] = drp_d
                # contact forces: zero while the teeth are apart; their derivatives without the
                # c̄ δ̄'' term, which needs the accelerations (added after the loop)
                on = in_contact(dsp, bsp)
                sk = s1 * p[P_HEADER + B_CK_SP * N + i] + c1 * p[P_HEADER + B_SK_SP * N + i]
                obs[o_csp + i] = fsp if on else 0.0
                dfc = -om * sk * dksp * fzsp + ksp * dsp_d - csp * esp_dd
                obs[nt + o_csp + i] = dfc if on else 0.0
                on = in_contact(drp, brp)
                sk = s1 * p[P_HEADER + B_CK_RP * N + i] + c1 * p[P_HEADER + B_SK_RP * N + i]
                obs[o_crp + i] = frp if on else 0.0
                dfc = -om * sk * dkrp * fzrp + krp * drp_d - crp * erp_dd
                obs[nt + o_crp + i] = dfc if on else 0.0
                if level >= OBS_ALL:
                    obs[_at(L.O_FORCE_SP, N) + i] = fsp
                    obs[_at(L.O_FORCE_RP, N) + i] = frp
                    obs[_at(L.O_STIFFNESS_SP, N) + i] = ksp
                    obs[_at(L.O_STIFFNESS_RP, N) + i] = krp
            sum_fsp += fsp
            sum_frp += frp
            sum_fx += fsp * si
            sum_fy -= fsp * ci

        inv_mus = p[P_INV_MUS]
        inv_muc = p[P_INV_MUC]
        cas = p[P_COS_AS]
        car = p[P_COS_AR]
        qs = (p[P_TD] - sum_fsp) * inv_mus
        qc = (cas * sum_fsp + car * sum_frp - p[P_TL]) * inv_muc

        kb = p[P_KB]
        bs = p[P_BS]
        cb = p[P_CS]
        inv_ms = p[P_INV_MU_S]
        for j in range(n):
            dydt[j] = y[n + j]
        dydt[n] = (sum_fx - cb * xd - kb * dead_zone(x, bs)) * inv_ms
        dydt[n + 1] = (sum_fy - cb * yd - kb * dead_zone(yy, bs)) * inv_ms
        qcp = cas * qc
        for i in range(N):
            dydt[n + 2 + i] = qs + dydt[n + 2 + i] - qcp
        dydt[n + N + 2] = qs - (cas + car) * qc
        if level >= OBS_TRACK:
            obs[_at(L.O_X_S, N)] = x
            obs[_at(L.O_Y_S, N)] = yy
            obs[nt + _at(L.O_X_S, N)] = xd
            obs[nt + _at(L.O_Y_S, N)] = yd
            # the c̄ δ̄'' terms of the contact-force derivatives: δ̄_sp'' = p̄_i'' + s_i'' − e_sp'',
            # δ̄_rp'' = σ̄'' − p̄_i'' − e_rp'' (the e'' parts were added in the loop)
            for i in range(N):
                pdd = dydt[n + 2 + i]
                if in_contact(obs[o_dsp + i], bsp):
                    si, ci = _planet_direction(p, N, i)
                    obs[nt + o_csp + i] += csp * (pdd - dydt[n] * si + dydt[n + 1] * ci)
                if in_contact(obs[o_drp + i], brp):
                    obs[nt + o_crp + i] += crp * (dydt[n + N + 2] - pdd)

    return planetary_rhs


planetary_rhs = _planetary_rhs(0)


# ----------------------------------------------------------------------------- tangents
# Variational equations V' = J(τ, y) V for Lyapunov exponents. The vector fields are continuous
# (damping acts inside the clearances, MODEL.md §4), so J is the piecewise Jacobian: the dead
# zone contributes f'(x; b) = 1 outside the clearance and 0 inside. Each tangent kernel is called
# right after the right-hand side at the same (τ, y) and reads the deflections and stiffnesses it
# needs from ``obs``. V holds k tangent vectors in y[n:], row after row.


def _planetary_tangent(n_fixed):
    """The planetary tangent kernel for any planet count (``n_fixed`` = 0) or compiled for
    ``n_fixed`` planets, as :func:`_planetary_rhs`."""

    @njit_noalloc
    def planetary_tangent(t, y, p, obs, dydt, n, k):  # pragma: no cover - compiled
        N = n_fixed if n_fixed > 0 else int(p[P_N])
        nd = N + 3
        csp = p[P_CSP]
        crp = p[P_CRP]
        bsp = p[P_BSP]
        brp = p[P_BRP]
        inv_mus = p[P_INV_MUS]
        inv_mup = p[P_INV_MUP]
        inv_muc = p[P_INV_MUC]
        cas = p[P_COS_AS]
        car = p[P_COS_AR]
        o_dsp = _at(L.O_DELTA_SP, N)
        o_drp = _at(L.O_DELTA_RP, N)
        o_ksp = _at(L.O_STIFFNESS_SP, N)
        o_krp = _at(L.O_STIFFNESS_RP, N)
        kb = p[P_KB] * engaged(obs[_at(L.O_X_S, N)], p[P_BS])
        kby = p[P_KB] * engaged(obs[_at(L.O_Y_S, N)], p[P_BS])
        cb = p[P_CS]
        inv_ms = p[P_INV_MU_S]
        for r in range(k):
            o = n + r * n
            xv = y[o]
            yv = y[o + 1]
            sv = y[o + N + 2]
            xdv = y[o + nd]
            ydv = y[o + nd + 1]
            sdv = y[o + nd + N + 2]
            sum_fsp = 0.0
            sum_frp = 0.0
            sum_fx = 0.0
            sum_fy = 0.0
            for i in range(N):
                si, ci = _planet_direction(p, N, i)
                pv = y[o + 2 + i]
                pdv = y[o + nd + 2 + i]
                dsp = pv - xv * si + yv * ci
                dsp_d = pdv - xdv * si + ydv * ci
                drp = sv - pv
                drp_d = sdv - pdv
                fsp = obs[o_ksp + i] * engaged(obs[o_dsp + i], bsp) * dsp + csp * dsp_d
                frp = obs[o_krp + i] * engaged(obs[o_drp + i], brp) * drp + crp * drp_d
                dydt[o + nd + 2 + i] = (frp - fsp) * inv_mup  # completed below
                sum_fsp += fsp
                sum_frp += frp
                sum_fx += fsp * si
                sum_fy -= fsp * ci
            qs = -sum_fsp * inv_mus
            qc = (cas * sum_fsp + car * sum_frp) * inv_muc
            for j in range(nd):
                dydt[o + j] = y[o + nd + j]
            dydt[o + nd] = (sum_fx - cb * xdv - kb * xv) * inv_ms
            dydt[o + nd + 1] = (sum_fy - cb * ydv - kby * yv) * inv_ms
            for i in range(N):
                dydt[o + nd + 2 + i] += qs - cas * qc
            dydt[o + nd + N + 2] = qs - (cas + car) * qc

    return planetary_tangent


planetary_tangent = _planetary_tangent(0)


_TANGENTS = {
    **{planetary_kind(n): _planetary_tangent(n) for n in PLANETARY_FIXED_N},
    KIND_PLANETARY: planetary_tangent,
    KIND_BACKLASH_OSCILLATOR: backlash_oscillator_tangent,
    KIND_LINEAR: linear_tangent,
    KIND_DUFFING: duffing_tangent,
    KIND_LORENZ: lorenz_tangent,
}


def tangent(kind, t, y, p, obs, dydt, n, k):
    """dydt[n:] = J(τ, y[:n]) applied to the k tangent vectors stored in y[n:] (see above).

    Like :func:`rhs`, ``kind`` must be a compile-time literal inside compiled code."""
    _TANGENTS[int(kind)](t, y, p, obs, dydt, n, k)


@overload(tangent, inline="always")
def _tangent_overload(kind, t, y, p, obs, dydt, n, k):  # pragma: no cover - compiled
    if not isinstance(kind, types.IntegerLiteral):
        raise numba.errors.TypingError("tangent: 'kind' must be a compile-time literal")
    fn = _TANGENTS.get(kind.literal_value)
    if fn is None:  # a model without its own tangent: central finite differences of its rhs
        if kind.literal_value not in _KERNELS:
            raise numba.errors.TypingError(f"unknown system kind {kind.literal_value}")
        f = _KERNELS[kind.literal_value]

        def fd_impl(kind, t, y, p, obs, dydt, n, k):
            _finite_difference_tangent(f, t, y, p, dydt, n, k)

        return fd_impl

    def impl(kind, t, y, p, obs, dydt, n, k):
        fn(t, y, p, obs, dydt, n, k)

    return impl


#: Relative step of the finite-difference tangent: about the cube root of the float64
#: precision, which balances the truncation error (h²) of a central difference against
#: round-off (ε/h), a relative error of ~1e-10 in J·v for a smooth right-hand side.
FD_STEP = 6e-6


@numba.njit(cache=True, inline="always")
def _finite_difference_tangent(f, t, y, p, dydt, n, k):  # pragma: no cover - compiled
    """dydt[n:] = J(τ, y[:n]) v_j for the k vectors v_j stored after the state in y, J by
    central differences of the right-hand side f, one state component at a time (the
    component restored exactly after each evaluation): 2n evaluations, whatever k is."""
    fp = stack_array(FD_MAX_STATE)
    fm = stack_array(FD_MAX_STATE)
    ob = stack_array(FD_MAX_OBS)
    for j in range(n, n + n * k):
        dydt[j] = 0.0
    for i in range(n):
        s = y[i]
        h = FD_STEP * max(1.0, abs(s))
        y[i] = s + h
        hp = y[i] - s
        f(t, y, p, fp, ob, OBS_NONE)
        y[i] = s - h
        hm = s - y[i]
        f(t, y, p, fm, ob, OBS_NONE)
        y[i] = s
        for j in range(k):
            v = y[n + j * n + i]
            if v != 0.0:
                o = n + j * n
                for r in range(n):
                    dydt[o + r] += v * (fp[r] - fm[r]) / (hp + hm)


def register_kernel(kind: int, rhs_fn: object, tangent_fn: object = None) -> None:
    """Add the compiled right-hand side (and tangent; ``None``: finite differences) of a model
    defined outside the package under ``kind`` (:func:`gearchaos.model.contract.register_kernels`
    chooses it), before any kernel is compiled for that kind. A kind already taken by other
    functions is refused."""
    kind = int(kind)
    old = _KERNELS.get(kind)
    if old is not None and old is not rhs_fn:
        raise ValueError(f"kernel kind {kind} is already registered for another model")
    _KERNELS[kind] = rhs_fn
    if tangent_fn is not None:
        _TANGENTS[kind] = tangent_fn


_KERNELS = {
    **{planetary_kind(n): _planetary_rhs(n) for n in PLANETARY_FIXED_N},
    KIND_PLANETARY: planetary_rhs,
    KIND_BACKLASH_OSCILLATOR: backlash_oscillator_rhs,
    KIND_LINEAR: linear_rhs,
    KIND_DUFFING: duffing_rhs,
    KIND_LORENZ: lorenz_rhs,
}


def rhs(kind, t, y, p, dydt, obs, level):
    """Right-hand side of system ``kind`` (see :mod:`gearchaos.model.layout`); ``level`` says
    which observables to write (module docstring).

    Inside compiled code ``kind`` must be a compile-time literal (callers use
    ``numba.literally(kind)``): each kind then gets its own specialised, on-disk-cached machine
    code with a direct call and no run-time dispatch. From Python it simply dispatches.
    """
    _KERNELS[int(kind)](t, y, p, dydt, obs, level)


@overload(rhs, inline="always")
def _rhs_overload(kind, t, y, p, dydt, obs, level):  # pragma: no cover - compiled
    if not isinstance(kind, types.IntegerLiteral):
        raise numba.errors.TypingError(
            "gearchaos.model.kernels.rhs: 'kind' must be a compile-time literal; "
            "call numba.literally(kind) in the calling kernel"
        )
    k = kind.literal_value
    if k not in _KERNELS:
        raise numba.errors.TypingError(f"unknown system kind {k}")
    fn = _KERNELS[k]

    def impl(kind, t, y, p, dydt, obs, level):
        fn(t, y, p, dydt, obs, level)

    return impl


@numba.njit(cache=True)
def observe_many(kind, t, Y, p, n_obs):  # pragma: no cover - compiled
    """Observables (and derivatives) at many states: rows of ``Y`` at times ``t``."""
    numba.literally(kind)
    m = Y.shape[0]
    out = np.empty((m, n_obs))
    d = np.empty(Y.shape[1])
    ob = np.empty(n_obs)
    dd = np.empty((m, Y.shape[1]))
    for k in range(m):
        rhs(kind, t[k], Y[k], p, d, ob, OBS_ALL)
        out[k, :] = ob
        dd[k, :] = d
    return out, dd
