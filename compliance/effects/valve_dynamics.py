"""Valve dynamics: the valve opening follows the command through a pure delay and a second-order spool."""

from __future__ import annotations

from numba import njit

from compliance.effects.base import Effect, Lumped, State
from compliance.effects.param import Param

# slots in the compiled core (tests/effects/test_effect_slots.py checks them against the layout)
P_VD_ON = 60
P_VD_WN = 61
P_VD_Z = 62
P_VD_TD = 63
S_SP = 10
S_SV = 11


def trim(P, y, null) -> None:
    """Hook ``trim``: the spool at rest at the valve's null command ``null`` [V]."""
    if P[P_VD_ON]:
        y[S_SP] = null


def spool_rate_scale(P, scales) -> float:
    """Typical spool speed [V/s]: the command scale times the spool's natural frequency (at least 1 rad/s)."""
    return scales["command"] * max(P[P_VD_WN], 1.0)


EFFECT = Effect(
    name="valve_dynamics",
    meaning="the valve opening follows the command through a pure delay and a second-order spool response",
    short="vd",
    slot=P_VD_ON,
    params=(
        Param("natural_frequency", "rad/s", "spool natural frequency", 60.0, (5.0, 1000.0), True, slot="wn", aliases=("wv",)),
        Param("damping", "", "spool damping ratio", 0.7, (0.1, 3.0), slot="z", aliases=("zv",)),
        Param("delay", "s", "pure delay between command and spool", 0.005, (0.0, 0.05), slot="td", aliases=("td_valve",)),
    ),
    states=(State("spool_position", "SP", S_SP, "command"), State("spool_velocity", "SV", S_SV, spool_rate_scale)),
    command_state="spool_position",  # the spool carries the command to the ports (linear/trim.flow_columns)
    signature="pressures lag the command after every command change; the loop rings more at steps",
    signals=("pressure_a", "pressure_b", "valve_command", "position"),
    input_delay="delay",
    explanation="the servo valve does not open instantly: its spool follows the command with a delay and a second-order lag (natural frequency {v})",
    # a spool near the loop's bandwidth trades frequency, damping and delay: start in each basin
    fit_grid={"natural_frequency": (20.0, 30.0, 45.0, 70.0, 120.0, 250.0), "damping": (0.5, 1.0),
              "delay": (0.0, 0.006, 0.012, 0.02)},
    draw={"natural_frequency": (25.0, 80.0, True), "damping": (0.4, 1.0, False), "delay": (0.002, 0.015, False)},
    # phase lag of e^(-s t_d)/(s^2/w^2 + 2 zeta s/w + 1) at w << w_n: w (t_d + 2 zeta/w_n)
    lumped=Lumped("total_lag", "s", "delay + 2 zeta / w_n: the spool's total lag as the loop sees it",
                  lambda p: p["delay"] + 2.0 * p["damping"] / p["natural_frequency"]),
    trim=trim,
)


@njit(cache=True, error_model="numpy", inline="always")
def spool_acceleration(natural_frequency, damping, target, position, velocity):
    """Spool acceleration towards ``target`` [V/s^2 or 1/s^2, as the target]."""
    wn = natural_frequency
    return wn * wn * (target - position) - 2.0 * damping * wn * velocity  # second-order spool (Merritt 1967)
