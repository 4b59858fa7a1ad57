"""Numbers and given values in figure text: one formatter (``plot._common.fmt``) writes a true
minus (U+2212), not a hyphen, and one helper (``given_values``) writes what a figure holds
fixed — a sweep's, a branch's and a stability chart's titles alike, a reference system's
parameters included."""

from __future__ import annotations

import numpy as np

import gearchaos as gc
from gearchaos.dynamics.attractors.basins import BasinAttractor
from gearchaos.plot._common import fmt, given, given_values, parameter_symbols
from gearchaos.plot.gallery import gallery_title

MINUS = "\N{MINUS SIGN}"


def test_values_are_written_with_a_true_minus() -> None:
    assert fmt(-1) == f"{MINUS}1"
    assert fmt(-0.25) == f"{MINUS}0.25"
    assert fmt(1e-8) == f"1e{MINUS}08"
    assert fmt(-0.0123, ".2g") == f"{MINUS}0.012"
    assert fmt(2.5) == "2.5" and fmt("up") == "up"
    assert given("alpha", -1) == rf"$\alpha$ = {MINUS}1"
    title = gallery_title("omega", 1.2, {"motion": "chaos", "lle": -0.012})
    assert title == rf"$\Omega$ = 1.2 · chaos · $\lambda_1$ = {MINUS}0.012"


def test_basin_legend_writes_the_figures_minus() -> None:
    a = BasinAttractor("1T", 1, float("nan"), 0.52, "multiplier", np.array([[-0.834, 0.1]]))
    assert a.legend("$x$", 0) == "1T ($x$ ≈ -0.834, |μ| 0.52)"  # plain text (the CLI's)
    assert a.legend("$x$", 0, fmt) == f"1T ($x$ ≈ {MINUS}0.834, |μ| 0.52)"


def test_given_values_of_a_reference_system_leave_out_the_swept() -> None:
    attrs = {"model_parameters": "Duffing(delta=0.25, alpha=-1.0, beta=1.0, gamma=0.1, n=3)"}
    got = given_values(attrs, fixed={"omega": 1.2, "label": "x"}, leave_out=("gamma",))
    assert got == [
        r"$\Omega$ = 1.2",
        r"$\delta$ = 0.25",
        rf"$\alpha$ = {MINUS}1",
        r"$\beta$ = 1",
    ]
    # a fixed value overrides the model's, once
    assert given_values(attrs, fixed={"alpha": 1.0})[:2] == [r"$\alpha$ = 1", r"$\delta$ = 0.25"]


def test_parameter_symbols_are_the_models_own_or_none() -> None:
    """The parameter symbols of what a store records: none for a gear set (the registry names
    its parameters), a reference system (no ``parameter_symbols``) or a model the user has not
    named; the model's own for a user model (the Kahraman–Singh example)."""
    from gearchaos.gearset.io import to_toml
    from gearchaos.model.loading import load_model_class, model_reference

    gs = gc.preset("sheng2016-v1")
    assert parameter_symbols({"model": "planetary", "gearset_toml": to_toml(gs)}) == {}
    oscillator = gc.backlash_oscillator(1.0).model
    assert parameter_symbols({"model": "backlash_oscillator", **model_reference(oscillator)}) == {}
    cls = load_model_class("examples/kahraman_singh_1991.py:KahramanSingh1991")
    attrs = {"model": "kahraman_singh_1991", **model_reference(cls())}
    assert parameter_symbols(attrs)["f_mean"] == r"\bar{F}_m"
    assert given("zeta_h", 0.05, parameter_symbols(attrs)) == r"$\zeta_h$ = 0.05"
    # the file moved: the class the user named (load_model_class) is the one it records
    attrs["model_class"] = "no/such/file.py:KahramanSingh1991"
    assert parameter_symbols(attrs)["f_mean"] == r"\bar{F}_m"
    # a model the user never named is never imported: no symbols
    attrs["model_class"] = "no/such/file.py:NeverNamed1991"
    assert parameter_symbols(attrs) == {}
