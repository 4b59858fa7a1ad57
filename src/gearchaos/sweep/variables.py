"""The per-point variables of a sweep store that several modules name: the step counts, the
transient a settling sweep skipped, and the orbit checks of ``bifurcation --orbits`` (names,
element types, fill values and flags). A leaf module: the store's checks read the layout from
here without importing the modules that run sweeps."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["ORBIT_STATUS", "ORBIT_VARIABLES", "SKIPPED", "STEP_COUNTS", "status_attrs"]

#: Per-point variable of a ``settle="auto"`` sweep: transient periods skipped (0: full transient).
SKIPPED = "transient_skipped"
#: the step counts stored per point, with their descriptions
STEP_COUNTS = {
    "steps_accepted": "steps accepted",
    "steps_rejected": "steps rejected",
    "steps_switch": "steps retried to end on a contact switch",
}

#: Flag values of ``orbit_status`` (−1: the point was not computed yet).
ORBIT_STATUS = {
    "not_computed": -1,
    "confirmed": 0,
    "unstable": 1,
    "shorter_period": 2,
    "not_converged": 3,
    "failed": 4,
    "not_periodic": 5,
    "period_too_long": 6,
}

#: Per-point variables (name → long name, dtype, fill value).
ORBIT_VARIABLES: dict[str, tuple[str, str, Any]] = {
    "orbit_residual": (
        "residual ‖Pⁿ(y*) − y*‖ / max(1, ‖y*‖) of the period-n orbit that confirms an nT label",
        "float64",
        np.nan,
    ),
    "orbit_max_multiplier": (
        "largest Floquet multiplier modulus max |μ| of that orbit",
        "float64",
        np.nan,
    ),
    "orbit_period": ("period n that was shot (0: none)", "int16", 0),
    "orbit_status": (
        "outcome of the shooting at the point (see flag_meanings)",
        "int8",
        ORBIT_STATUS["not_computed"],
    ),
}


def status_attrs() -> dict[str, Any]:
    """``flag_values`` / ``flag_meanings`` of ``orbit_status``."""
    return {
        "flag_values": list(ORBIT_STATUS.values()),
        "flag_meanings": " ".join(ORBIT_STATUS),
    }
