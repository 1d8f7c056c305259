"""Linkage compliance: the two cylinders are coupled through a flexible linkage; the sensor sits on 2A1."""

from __future__ import annotations

from numba import njit

from compliance.effects.base import Effect, State
from compliance.effects.param import Param

# slots in the compiled core (tests/effects/test_effect_slots.py checks them against the layout)
P_LK_ON = 79
P_LK_K = 80
P_LK_C = 81
S_X2 = 8
S_V2 = 9

EFFECT = Effect(
    name="linkage_compliance",
    meaning="the two cylinders are coupled through a flexible linkage; the sensor sits on 2A1",
    short="lk",
    params=(
        Param("stiffness", "N/m", "linkage stiffness between the cylinders", 2e6, (1e4, 5e7), True, slot="k",
              aliases=("k_link",)),
        Param("damping", "N*s/m", "linkage damping", 2000.0, (0.0, 1e4), slot="c", aliases=("c_link",)),
    ),
    # without the effect 2A2 follows 2A1 and plant_rhs keeps these equal to position and velocity
    states=(State("position_2", "X2", S_X2), State("velocity_2", "V2", S_V2)),
    signature="a resonance at the linkage frequency rings in command and pressures after steps",
    signals=("valve_command", "pressure_a", "pressure_b", "position"),
    explanation="the two cylinders are coupled through a flexible linkage (stiffness {v})",
    fit_grid={"stiffness": (3e4, 1e5, 4e5, 1.5e6, 6e6), "damping": (300.0, 3000.0)},
    # only a soft, lightly damped link shows in the pressures: with each cylinder carrying half the load a
    # 40 kN/m link moves them < 1 kPa and 0.07 V (the generated cases' visibility needs 3 kPa or 0.08 V)
    draw={"stiffness": (1e4, 3e4, True), "damping": (20.0, 300.0, True)},
)


@njit(cache=True, error_model="numpy", inline="always")
def link_force(stiffness, damping, x1, x2, v1, v2):
    """Force of the linkage on cylinder 2A1 [N] (spring-damper; positions [m], speeds [m/s])."""
    return stiffness * (x2 - x1) + damping * (v2 - v1)  # Kelvin-Voigt link between the two pistons
