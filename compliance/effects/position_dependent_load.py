"""Position-dependent load: the load changes along the stroke (gate hydraulic torque stiffness)."""

from __future__ import annotations

from numba import njit

from compliance.effects.base import Effect
from compliance.effects.param import Param

# slots in the compiled core (tests/effects/test_effect_slots.py checks them against the layout)
P_PL_ON = 71
P_PL_K = 72


@njit(cache=True, error_model="numpy", inline="always")
def load_force(P, position, stroke, force):
    """Hook ``load_force``: the closing force [N] plus the load stiffness about mid-stroke (positions [m])."""
    return force + P[P_PL_K] * (position - 0.5 * stroke)  # load stiffness about mid-stroke


EFFECT = Effect(
    name="position_dependent_load",
    meaning="the load changes along the stroke (gate hydraulic torque stiffness)",
    short="pl",
    slot=P_PL_ON,
    params=(Param("stiffness", "N/m", "added closing force per metre of opening (the core: about mid-stroke; the diagnosis: about the test's start)", 0.0, (-1.5e5, 1.5e5), slot="k",
                  aliases=("kL",)),),
    states=(),
    signature="holding pressure difference changes with position more than the nominal load says",
    signals=("pressure_a", "pressure_b", "valve_command"),
    explanation="the load changes along the stroke more than the nominal load says (stiffness {v})",
    fit_grid={"stiffness": (-1e5, -3e4, -1e4, 1e4, 3e4, 1e5)},
    draw={"stiffness": (2e4, 1e5, True)},
    draw_signed=True,
    terms={"load_force": load_force},
)
