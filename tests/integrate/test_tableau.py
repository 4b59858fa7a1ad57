"""Dormand–Prince 5(4) tableau: the identities it promises, checked in exact arithmetic.

Independent of :meth:`ButcherTableau.order_residuals`, the linear stability polynomial
R(z) = 1 + Σ_k (bᵀ A^(k−1) 1) z^k must match e^z through z^5 for the 5th-order weights (and only
through z^4 for the embedded 4th-order weights), and the bushy-tree conditions b·c^(k−1) = 1/k
are evaluated directly.
"""

from __future__ import annotations

import dataclasses
import math
from fractions import Fraction as Fr

import numpy as np
import pytest

from gearchaos.integrate import DOPRI5

S = DOPRI5.stages


def _matrix() -> list[list[Fr]]:
    A = [[Fr(0)] * S for _ in range(S)]
    for i, row in enumerate(DOPRI5.a):
        for j, v in enumerate(row):
            A[i][j] = Fr(v)
    return A


def _stability_coefficients(weights: tuple[Fr, ...], kmax: int) -> list[Fr]:
    """bᵀ A^(k−1) 1 for k = 1..kmax (coefficient of z^k in R(z))."""
    A = _matrix()
    v = [Fr(1)] * S
    out = []
    for _ in range(kmax):
        out.append(sum((w * x for w, x in zip(weights, v, strict=True)), Fr(0)))
        v = [sum((A[i][j] * v[j] for j in range(S)), Fr(0)) for i in range(S)]
    return out


def test_row_sums_equal_nodes() -> None:
    for i, row in enumerate(DOPRI5.a):
        assert len(row) == i
        assert sum(row, Fr(0)) == DOPRI5.c[i]


def test_weights_sum_to_one() -> None:
    assert sum(DOPRI5.b, Fr(0)) == 1
    assert sum(DOPRI5.b_hat, Fr(0)) == 1


def test_fsal() -> None:
    assert DOPRI5.fsal
    assert DOPRI5.c[-1] == 1
    assert tuple(DOPRI5.a[-1]) == tuple(DOPRI5.b[:-1])
    assert DOPRI5.b[-1] == 0


def test_order_conditions_of_both_weight_sets() -> None:
    r5 = DOPRI5.order_residuals(DOPRI5.b, 5)
    r4 = DOPRI5.order_residuals(DOPRI5.b_hat, 4)
    # 1 + 1 + 2 + 4 + 9 = 17 rooted trees up to order 5; 8 up to order 4
    assert len(r5) == 17
    assert len(r4) == 8
    assert all(v == 0 for v in r5.values())
    assert all(v == 0 for v in r4.values())


def test_embedded_weights_are_not_fifth_order() -> None:
    r = DOPRI5.order_residuals(DOPRI5.b_hat, 5)
    assert any(v != 0 for v in r.values())


def test_bushy_trees_directly() -> None:
    c = DOPRI5.c
    for k in range(1, 6):
        assert sum((b * ci ** (k - 1) for b, ci in zip(DOPRI5.b, c, strict=True)), Fr(0)) == Fr(
            1, k
        )
    for k in range(1, 5):
        got = sum((b * ci ** (k - 1) for b, ci in zip(DOPRI5.b_hat, c, strict=True)), Fr(0))
        assert got == Fr(1, k)


def test_linear_stability_polynomial_matches_exponential() -> None:
    coef = _stability_coefficients(DOPRI5.b, 6)
    for k in range(1, 6):
        assert coef[k - 1] == Fr(1, math.factorial(k))
    assert coef[5] != Fr(1, 720)  # the method is not 6th order
    coef_hat = _stability_coefficients(DOPRI5.b_hat, 5)
    for k in range(1, 5):
        assert coef_hat[k - 1] == Fr(1, math.factorial(k))
    assert coef_hat[4] != Fr(1, 120)


def test_error_weights() -> None:
    e = DOPRI5.error_weights
    assert all(ei == bi - bh for ei, bi, bh in zip(e, DOPRI5.b, DOPRI5.b_hat, strict=True))
    assert sum(e, Fr(0)) == 0
    assert any(x != 0 for x in e)


def test_check_passes_on_dopri5() -> None:
    DOPRI5.check()


def _with_entry(rows, i, j, value):
    rows = [list(r) for r in rows]
    rows[i][j] = value
    return tuple(tuple(r) for r in rows)


@pytest.mark.parametrize(
    "corrupt",
    [
        # a weight perturbed (Σb ≠ 1 and order conditions break)
        lambda t: dataclasses.replace(t, b=(t.b[0] + Fr(1, 1000), *t.b[1:])),
        # two stages of b swapped: Σb = 1 still, higher conditions fail
        lambda t: dataclasses.replace(t, b=(t.b[0], t.b[1], t.b[3], t.b[2], *t.b[4:])),
        # A entry changed: row sum ≠ c
        lambda t: dataclasses.replace(t, a=_with_entry(t.a, 3, 1, t.a[3][1] + Fr(1, 7))),
        # node changed
        lambda t: dataclasses.replace(t, c=(*t.c[:2], t.c[2] + Fr(1, 100), *t.c[3:])),
        # embedded weights equal to b: no error estimate
        lambda t: dataclasses.replace(t, b_hat=t.b),
        # embedded weights perturbed so that they are no longer 4th order
        lambda t: dataclasses.replace(
            t, b_hat=(t.b_hat[0] + Fr(1, 50), t.b_hat[1], t.b_hat[2] - Fr(1, 50), *t.b_hat[3:])
        ),
    ],
)
def test_check_fails_on_corrupted_tableau(corrupt) -> None:
    bad = corrupt(DOPRI5)
    with pytest.raises(AssertionError):
        bad.check()


# ------------------------------------------------------------------------------ dense output
def test_dense_output_is_hairers_as_scipy_tabulates_it() -> None:
    """The continuous extension built from the tableau's data (Hairer's d_i on the cubic
    Hermite form) is, coefficient by coefficient, scipy's ``RK45.P`` (order 4) and, for a pair
    without d_i, ``RK23.P`` (Bogacki–Shampine's cubic Hermite interpolant)."""
    from scipy.integrate._ivp.rk import RK23, RK45

    from gearchaos.integrate.tableau import BS32

    for tab, ref in ((DOPRI5, RK45.P), (BS32, RK23.P)):
        got = np.array([[float(x) for x in row] for row in tab.dense_matrix()])
        assert got.shape == ref.shape
        assert np.allclose(got, ref, rtol=1e-15, atol=0.0), tab.name


def test_dense_output_order_conditions() -> None:
    """Σ_i b_i(θ) Φ_i(t) = θ^ρ(t)/γ(t) for the 8 trees up to order 4, evaluated directly at a
    few θ; at θ = 1 the dense weights are b; the bushy tree of order 5 fails (order 4)."""
    D = DOPRI5.dense_matrix()
    c = DOPRI5.c

    def weights(th: Fr) -> list[Fr]:
        return [sum((x * th ** (m + 1) for m, x in enumerate(row)), Fr(0)) for row in D]

    assert weights(Fr(1)) == list(DOPRI5.b)
    for th in (Fr(1, 3), Fr(1, 2), Fr(5, 7)):
        w = weights(th)
        for k in range(1, 6):
            got = sum((wi * ci ** (k - 1) for wi, ci in zip(w, c, strict=True)), Fr(0))
            assert (got == th**k / k) == (k <= 4), (th, k)
    assert len([k for k in DOPRI5.dense_residuals() if "θ" in k]) == 8 * 4


def test_check_fails_on_corrupted_dense_output() -> None:
    d = DOPRI5.dense
    assert d is not None
    with pytest.raises(AssertionError, match="dense output"):
        dataclasses.replace(DOPRI5, dense=(d[0] + Fr(1, 10**6), *d[1:])).check()
    with pytest.raises(AssertionError, match="dense output"):
        dataclasses.replace(DOPRI5, dense_order=5).check()  # it is not of order 5
    with pytest.raises(AssertionError, match="dense output"):
        dataclasses.replace(DOPRI5, dense=None, dense_order=4).check()  # Hermite: order 3
    dataclasses.replace(DOPRI5, dense=None, dense_order=3).check()
