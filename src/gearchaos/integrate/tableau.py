"""Butcher tableaux as data that check their own identities.

The Dormand–Prince 5(4) pair (Dormand & Prince 1980; Hairer, Nørsett & Wanner, *Solving ODEs I*,
§II.5, Table 5.2) with exact rational coefficients. :meth:`ButcherTableau.check` verifies the
row-sum condition Σ_j a_ij = c_i, the order conditions of the propagating 5th-order weights
(all 17 rooted trees up to order 5) and of the 4th-order embedded weights (8 trees up to order 4),
and the FSAL property (last row of A equals b). The compiled kernel reads its constants from
:data:`DOPRI5`, which is checked on import (:mod:`~gearchaos.integrate._step` turns a tableau
into the kernel's constant arrays, :meth:`ButcherTableau.arrays`).

Two more explicit FSAL pairs are data for experiments (:func:`~gearchaos.integrate.methods.\
kernels_for` compiles the integrator with another tableau): :data:`BS32`, the Bogacki–Shampine
3(2) pair (1989; exact), and :data:`TSIT5`, Tsitouras' 5(4) pair (2011; the published
floating-point coefficients, so its identities hold to round-off, ``tol``).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction as Fr
from typing import NamedTuple

import numpy as np

__all__ = ["BS32", "DOPRI5", "TSIT5", "ButcherTableau", "TableauArrays"]


class TableauArrays(NamedTuple):
    """A tableau's coefficients as float64 arrays, what the compiled kernels read: ``A``
    (s × s, zero on and above the diagonal), ``b``, ``b_hat``, ``c`` and the error weights
    ``e`` = b − b̂ (each rounded once from the exact difference)."""

    A: np.ndarray
    b: np.ndarray
    b_hat: np.ndarray
    c: np.ndarray
    e: np.ndarray


@dataclass(frozen=True)
class ButcherTableau:
    """An explicit embedded Runge–Kutta pair with exact rational coefficients (``tol`` > 0:
    coefficients given as floats, whose identities hold to ``tol``)."""

    name: str
    c: tuple[Fr, ...]
    a: tuple[tuple[Fr, ...], ...]  # strictly lower triangular rows, row i has i entries
    b: tuple[Fr, ...]  # propagating weights (order ``order``)
    b_hat: tuple[Fr, ...]  # embedded weights (order ``order_hat``)
    order: int
    order_hat: int
    tol: float = 0.0

    @property
    def stages(self) -> int:
        return len(self.c)

    def a_matrix(self) -> np.ndarray:
        s = self.stages
        m = np.zeros((s, s))
        for i, row in enumerate(self.a):
            m[i, : len(row)] = [float(x) for x in row]
        return m

    def arrays(self) -> TableauArrays:
        """The coefficients as float64 arrays (:class:`TableauArrays`)."""

        def vec(xs: tuple[Fr, ...]) -> np.ndarray:
            return np.array([float(x) for x in xs])

        return TableauArrays(
            self.a_matrix(), vec(self.b), vec(self.b_hat), vec(self.c), vec(self.error_weights)
        )

    @property
    def error_weights(self) -> tuple[Fr, ...]:
        """e = b − b̂: the local error estimate is h Σ e_i k_i."""
        return tuple(x - y for x, y in zip(self.b, self.b_hat, strict=True))

    @property
    def fsal(self) -> bool:
        """First same as last: the last stage is evaluated at (t + h, y_{n+1})."""
        return (
            self.c[-1] == 1
            and tuple(self.a[-1]) == tuple(self.b[: len(self.a[-1])])
            and (self.b[-1] == 0)
        )

    def order_residuals(self, weights: tuple[Fr, ...], order: int) -> dict[str, Fr]:
        """Residuals of the order conditions (exact, as fractions) for rooted trees ≤ ``order``."""
        s = self.stages
        A = [[Fr(0)] * s for _ in range(s)]
        for i, row in enumerate(self.a):
            for j, v in enumerate(row):
                A[i][j] = v
        c = list(self.c)
        b = list(weights)

        def dot(u: list[Fr], v: list[Fr]) -> Fr:
            return sum((x * y for x, y in zip(u, v, strict=True)), Fr(0))

        def av(v: list[Fr]) -> list[Fr]:
            return [dot(A[i], v) for i in range(s)]

        def mul(*vs: list[Fr]) -> list[Fr]:
            out = [Fr(1)] * s
            for v in vs:
                out = [x * y for x, y in zip(out, v, strict=True)]
            return out

        one = [Fr(1)] * s
        c2, c3 = mul(c, c), mul(c, c, c)
        ac, ac2, ac3 = av(c), av(c2), av(c3)
        aac, aac2 = av(ac), av(ac2)
        aaac = av(aac)
        conds: dict[str, tuple[list[Fr], Fr]] = {
            "b.1": (one, Fr(1)),
            "b.c": (c, Fr(1, 2)),
            "b.c2": (c2, Fr(1, 3)),
            "b.Ac": (ac, Fr(1, 6)),
            "b.c3": (c3, Fr(1, 4)),
            "b.cAc": (mul(c, ac), Fr(1, 8)),
            "b.Ac2": (ac2, Fr(1, 12)),
            "b.AAc": (aac, Fr(1, 24)),
            "b.c4": (mul(c3, c), Fr(1, 5)),
            "b.c2Ac": (mul(c2, ac), Fr(1, 10)),
            "b.cAc2": (mul(c, ac2), Fr(1, 15)),
            "b.cAAc": (mul(c, aac), Fr(1, 30)),
            "b.AcAc": (mul(ac, ac), Fr(1, 20)),
            "b.Ac3": (ac3, Fr(1, 20)),
            "b.A(cAc)": (av(mul(c, ac)), Fr(1, 40)),
            "b.AAc2": (aac2, Fr(1, 60)),
            "b.AAAc": (aaac, Fr(1, 120)),
        }
        orders = {"b.1": 1, "b.c": 2, "b.c2": 3, "b.Ac": 3}
        for k in ("b.c3", "b.cAc", "b.Ac2", "b.AAc"):
            orders[k] = 4
        out = {}
        for k, (vec, target) in conds.items():
            if orders.get(k, 5) <= order:
                out[k] = dot(b, vec) - target
        return out

    def check(self) -> None:
        """Raise ``AssertionError`` if any identity of the tableau fails (exact arithmetic;
        to within ``tol`` for a tableau given in floating point)."""
        s = self.stages
        tol = Fr(self.tol)
        assert len(self.a) == s and len(self.b) == s and len(self.b_hat) == s, "shape"
        for i, row in enumerate(self.a):
            assert len(row) == i, f"row {i} of A must have {i} entries"
            assert abs(sum(row, Fr(0)) - self.c[i]) <= tol, f"row sum of A[{i}] != c[{i}]"
        for label, w, p in (("b", self.b, self.order), ("b_hat", self.b_hat, self.order_hat)):
            bad = {k: r for k, r in self.order_residuals(w, p).items() if abs(r) > tol}
            assert not bad, f"{self.name}: order conditions of {label} fail: {bad}"
        # the embedded pair must differ, otherwise there is no error estimate
        assert any(e != 0 for e in self.error_weights), "b and b_hat coincide"
        assert abs(sum(self.error_weights, Fr(0))) <= tol, "Σ(b − b̂) must vanish"


#: The Dormand–Prince 5(4) pair (Dormand & Prince 1980), checked on import.
DOPRI5 = ButcherTableau(
    name="Dormand–Prince 5(4)",
    c=(Fr(0), Fr(1, 5), Fr(3, 10), Fr(4, 5), Fr(8, 9), Fr(1), Fr(1)),
    a=(
        (),
        (Fr(1, 5),),
        (Fr(3, 40), Fr(9, 40)),
        (Fr(44, 45), Fr(-56, 15), Fr(32, 9)),
        (Fr(19372, 6561), Fr(-25360, 2187), Fr(64448, 6561), Fr(-212, 729)),
        (Fr(9017, 3168), Fr(-355, 33), Fr(46732, 5247), Fr(49, 176), Fr(-5103, 18656)),
        (Fr(35, 384), Fr(0), Fr(500, 1113), Fr(125, 192), Fr(-2187, 6784), Fr(11, 84)),
    ),
    b=(Fr(35, 384), Fr(0), Fr(500, 1113), Fr(125, 192), Fr(-2187, 6784), Fr(11, 84), Fr(0)),
    b_hat=(
        Fr(5179, 57600),
        Fr(0),
        Fr(7571, 16695),
        Fr(393, 640),
        Fr(-92097, 339200),
        Fr(187, 2100),
        Fr(1, 40),
    ),
    order=5,
    order_hat=4,
)
DOPRI5.check()

#: The Bogacki–Shampine 3(2) pair (Bogacki & Shampine 1989; scipy's ``RK23``), FSAL, checked on
#: import.
BS32 = ButcherTableau(
    name="Bogacki–Shampine 3(2)",
    c=(Fr(0), Fr(1, 2), Fr(3, 4), Fr(1)),
    a=((), (Fr(1, 2),), (Fr(0), Fr(3, 4)), (Fr(2, 9), Fr(1, 3), Fr(4, 9))),
    b=(Fr(2, 9), Fr(1, 3), Fr(4, 9), Fr(0)),
    b_hat=(Fr(7, 24), Fr(1, 4), Fr(1, 3), Fr(1, 8)),
    order=3,
    order_hat=2,
)
BS32.check()

_TSIT5_C = (0.0, 0.161, 0.327, 0.9, 0.9800255409045097, 1.0, 1.0)
_TSIT5_A = (
    (),
    (0.161,),
    (-0.008480655492356989, 0.335480655492357),
    (2.897153057105493, -6.359448489975075, 4.3622954328695815),
    (5.325864828439257, -11.748883564062828, 7.4955393428898365, -0.09249506636175525),
    (5.86145544294642, -12.92096931784711, 8.159367898576159, -0.071584973281401,
     -0.028269050394068383),
    (0.09646076681806523, 0.01, 0.4798896504144996, 1.379008574103742, -3.290069515436081,
     2.324710524099774),
)  # fmt: skip
#: e = b − b̂ as published
_TSIT5_E = (-0.00178001105222577714, -0.0008164344596567469, 0.007880878010261995,
            -0.1447110071732629, 0.5823571654525552, -0.45808210592918697, 1.0 / 66.0)  # fmt: skip

#: Tsitouras' 5(4) pair (Tsitouras 2011, Table 1; Julia's ``Tsit5``), FSAL: the published
#: floating-point coefficients as exact binary fractions, identities checked to round-off.
TSIT5 = ButcherTableau(
    name="Tsitouras 5(4)",
    c=tuple(Fr(x) for x in _TSIT5_C),
    a=tuple(tuple(Fr(x) for x in row) for row in _TSIT5_A),
    b=tuple(Fr(x) for x in (*_TSIT5_A[-1], 0.0)),
    b_hat=tuple(Fr(x) - Fr(e) for x, e in zip((*_TSIT5_A[-1], 0.0), _TSIT5_E, strict=True)),
    order=5,
    order_hat=4,
    tol=1e-12,
)
TSIT5.check()
