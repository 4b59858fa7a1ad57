"""Butcher tableaux as data that check their own identities.

The Dormand–Prince 5(4) pair (Dormand & Prince 1980; Hairer, Nørsett & Wanner, *Solving ODEs I*,
§II.5, Table 5.2) with exact rational coefficients. :meth:`ButcherTableau.check` verifies the
row-sum condition Σ_j a_ij = c_i, the order conditions of the propagating 5th-order weights
(all 17 rooted trees up to order 5) and of the 4th-order embedded weights (8 trees up to order 4),
and the FSAL property (last row of A equals b). The compiled kernel reads its constants from
:data:`DOPRI5`, which is checked on import.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction as Fr

import numpy as np

__all__ = ["DOPRI5", "ButcherTableau"]


@dataclass(frozen=True)
class ButcherTableau:
    """An explicit embedded Runge–Kutta pair with exact rational coefficients."""

    name: str
    c: tuple[Fr, ...]
    a: tuple[tuple[Fr, ...], ...]  # strictly lower triangular rows, row i has i entries
    b: tuple[Fr, ...]  # propagating weights (order ``order``)
    b_hat: tuple[Fr, ...]  # embedded weights (order ``order_hat``)
    order: int
    order_hat: int

    @property
    def stages(self) -> int:
        return len(self.c)

    def a_matrix(self) -> np.ndarray:
        s = self.stages
        m = np.zeros((s, s))
        for i, row in enumerate(self.a):
            m[i, : len(row)] = [float(x) for x in row]
        return m

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
        """Raise ``AssertionError`` if any identity of the tableau fails (exact arithmetic)."""
        s = self.stages
        assert len(self.a) == s and len(self.b) == s and len(self.b_hat) == s, "shape"
        for i, row in enumerate(self.a):
            assert len(row) == i, f"row {i} of A must have {i} entries"
            assert sum(row, Fr(0)) == self.c[i], f"row sum of A[{i}] != c[{i}]"
        for label, w, p in (("b", self.b, self.order), ("b_hat", self.b_hat, self.order_hat)):
            bad = {k: r for k, r in self.order_residuals(w, p).items() if r != 0}
            assert not bad, f"{self.name}: order conditions of {label} fail: {bad}"
        # the embedded pair must differ, otherwise there is no error estimate
        assert any(e != 0 for e in self.error_weights), "b and b_hat coincide"
        assert sum(self.error_weights, Fr(0)) == 0, "Σ(b − b̂) must vanish"


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
