"""Another Runge–Kutta pair in the compiled integrator, for experiments: :func:`kernels_for`.

The integrator's kernels read the Butcher tableau from module constants
(:func:`~gearchaos.integrate._step.tableau_constants` of
:data:`~gearchaos.integrate.tableau.DOPRI5`), which numba folds into the machine code.
:func:`kernels_for` compiles the same code — the step, the error norm, the starting step, the
loop and the chains — with another explicit FSAL pair's constants instead (e.g.
:data:`~gearchaos.integrate.tableau.BS32` or :data:`~gearchaos.integrate.tableau.TSIT5`):
the functions of :mod:`._step` and :mod:`.dopri` are rebuilt from their code in a copy of their
module's namespace that holds the other constants. These kernels are compiled in each process
(not cached on disk: numba's cache is keyed on the source, which they share with the default
kernels). :func:`~gearchaos.integrate._chains.run_chains` takes ``tableau=``, and
:func:`use_tableau` makes every run inside a ``with`` block use another pair (a sweep, say).

Results of another pair are not those of the package: nothing records the pair, so this is for
benchmarks and tests (``benchmarks/bench_methods.py``).
"""

from __future__ import annotations

import functools
import types
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any, NamedTuple

import numba
from numba.core.registry import CPUDispatcher

from . import _step, dopri
from .tableau import DOPRI5, ButcherTableau

__all__ = ["TABLEAU_OVERRIDE", "Kernels", "kernels_for", "use_tableau"]

#: The pair every run of this process uses inside :func:`use_tableau` (empty: the package's).
TABLEAU_OVERRIDE: list[ButcherTableau] = []


class Kernels(NamedTuple):
    """The integrator's tableau-dependent kernels for one pair (signatures as in
    :mod:`._step` and :mod:`.dopri`)."""

    tableau: ButcherTableau
    rk_step: Any
    error_norm: Any
    stage_input: Any
    fsal_advance: Any
    initial_step: Any
    dense_state: Any
    dopri_run: Any
    dopri_chains: Any
    alpha: float


def _rebuild(module: types.ModuleType, overrides: dict[str, Any]) -> dict[str, Any]:
    """A copy of ``module``'s namespace with ``overrides``, in which every compiled function
    defined in the module is compiled afresh (same options, no disk cache) from its code, so
    that it reads the copy's constants and calls the copy's functions."""
    space = dict(vars(module))
    space.update(overrides)
    for name, obj in vars(module).items():
        if isinstance(obj, CPUDispatcher) and obj.py_func.__module__ == module.__name__:
            fn = obj.py_func
            clone = types.FunctionType(
                fn.__code__, space, fn.__name__, fn.__defaults__, fn.__closure__
            )
            clone.__doc__ = fn.__doc__
            options = {k: v for k, v in obj.targetoptions.items() if k != "nopython"}
            space[name] = numba.njit(**options)(clone)
    return space


@functools.cache
def kernels_for(tableau: ButcherTableau) -> Kernels:
    """The integrator compiled for the explicit FSAL pair ``tableau`` (the package's own
    kernels for :data:`~gearchaos.integrate.tableau.DOPRI5`)."""
    if tableau == DOPRI5:
        step: dict[str, Any] = vars(_step)
        loop: dict[str, Any] = vars(dopri)
    else:
        consts = _step.tableau_constants(tableau)
        step = _rebuild(_step, consts)
        names = ("rk_step", "error_norm", "fsal_advance", "initial_step", "dense_state")
        loop = _rebuild(dopri, {**consts, **{k: step[k] for k in names}})
    return Kernels(
        tableau=tableau,
        rk_step=step["rk_step"],
        error_norm=step["error_norm"],
        stage_input=step["stage_input"],
        fsal_advance=step["fsal_advance"],
        initial_step=step["initial_step"],
        dense_state=step["dense_state"],
        dopri_run=loop["dopri_run"],
        dopri_chains=loop["dopri_chains"],
        alpha=float(step["ALPHA"]),
    )


@contextmanager
def use_tableau(tableau: ButcherTableau) -> Iterator[None]:
    """Within the block, every :func:`~gearchaos.integrate._chains.run_chains` call of this
    process (simulations, batches, sweeps run in this process) integrates with ``tableau``."""
    old = TABLEAU_OVERRIDE[:]
    TABLEAU_OVERRIDE[:] = [tableau]
    try:
        yield
    finally:
        TABLEAU_OVERRIDE[:] = old
