"""Linkage compliance: the two cylinders are coupled through a flexible linkage; the sensor sits on 2A1."""

from __future__ import annotations

from numba import njit

from compliance.effects.base import Balance, Effect, ReplayPoint, Rest, State
from compliance.effects.param import Param

# slots in the compiled core (tests/effects/test_effect_slots.py checks them against the layout)
P_LK_ON = 79
P_LK_K = 80
P_LK_C = 81
S_X2 = 8
S_V2 = 9
REST_ITERATIONS = 50  # fixed-point steps for 2A2's rest position (contracts while the link is stiffer than the load curve)


def rest(P, y, at: Rest) -> None:
    """Hook ``rest``: 2A2 where 2A1 is (the link relaxed; ``hold`` loads it)."""
    y[S_X2] = at.position


def hold(P, y, at: Rest) -> None:
    """Hook ``hold``: 2A2's position where both cylinders rest with equal friction shares (in place).

    Each cylinder carries half the gate-ring load at its own position (``plant_rhs``); with
    f_link = K (x2 - x) the balance f1 + f_link - F(x)/2 = f2 - f_link - F(x2)/2 is solved for x2 by
    fixed-point iteration; a link too soft to carry it leaves 2A2 on its end stop.
    """
    if not (P[P_LK_ON] != 0.0 and at.tandem):
        return
    x = at.position
    f1, f2 = at.piston_forces
    load1 = 0.5 * at.load(x)
    x2 = x
    for _ in range(REST_ITERATIONS):
        x2_new = x + 0.5 * (f2 - f1 + load1 - 0.5 * at.load(x2)) / P[P_LK_K]
        x2_new = min(max(x2_new, 0.0), at.stroke)
        if abs(x2_new - x2) < 1e-12:
            x2 = x2_new
            break
        x2 = x2_new
    y[S_X2] = x2


def trim_balance(P, at: Balance):
    """Hook ``trim_balance``: each cylinder carries half the gate-ring load at its own position.

    2A1 at rest without friction, f1 + K (x2 - x) = F(x)/2, solved for x2 by a fixed number of
    fixed-point steps together with the pressures holding the mean load. Returns (closing force
    on the actuator [N], its ``at.pressures``, {S_X2: x2}), or None without the effect.
    """
    if not (P[P_LK_ON] and at.tandem):
        return None
    x = at.position
    x2 = x
    f_here = at.load(x)
    for _ in range(REST_ITERATIONS):
        f = 0.5 * (f_here + at.load(x2))
        balanced = at.pressures(f)
        x2 = x + (0.5 * f_here - at.piston_force(balanced[0], balanced[1])) / P[P_LK_K]
    return f, balanced, {S_X2: x2}


def replay_reset(P, y, point: ReplayPoint) -> None:
    """Hook ``replay_reset``: 2A2 moves with 2A1 (its position follows from ``hold``)."""
    y[S_V2] = point.velocity


EFFECT = Effect(
    name="linkage_compliance",
    meaning="the two cylinders are coupled through a flexible linkage; the sensor sits on 2A1",
    short="lk",
    slot=P_LK_ON,
    params=(
        Param("stiffness", "N/m", "linkage stiffness between the cylinders", 2e6, (1e4, 5e7), True, slot="k",
              aliases=("k_link",)),
        Param("damping", "N*s/m", "linkage damping", 2000.0, (0.0, 1e4), slot="c", aliases=("c_link",)),
    ),
    # without the effect 2A2 follows 2A1 and plant_rhs keeps these equal to position and velocity
    states=(State("position_2", "X2", S_X2, "stroke", shadows="position"),
            State("velocity_2", "V2", S_V2, "speed", shadows="velocity")),
    signature="a resonance at the linkage frequency rings in command and pressures after steps",
    signals=("valve_command", "pressure_a", "pressure_b", "position"),
    explanation="the two cylinders are coupled through a flexible linkage (stiffness {v})",
    fit_grid={"stiffness": (3e4, 1e5, 4e5, 1.5e6, 6e6), "damping": (300.0, 3000.0)},
    # only a soft, lightly damped link shows in the pressures: with each cylinder carrying half the load a
    # 40 kN/m link moves them < 1 kPa and 0.07 V (the generated cases' visibility needs 3 kPa or 0.08 V)
    draw={"stiffness": (1e4, 3e4, True), "damping": (20.0, 300.0, True)},
    requires={"cylinder.arrangement": "tandem"},
    frees=("bristle_2",),  # 2A2's own LuGre bristle
    rest=rest,
    hold=hold,
    trim_balance=trim_balance,
    replay_reset=replay_reset,
)


@njit(cache=True, error_model="numpy", inline="always")
def link_force(stiffness, damping, x1, x2, v1, v2):
    """Force of the linkage on cylinder 2A1 [N] (spring-damper; positions [m], speeds [m/s])."""
    return stiffness * (x2 - x1) + damping * (v2 - v1)  # Kelvin-Voigt link between the two pistons
