"""Valve offset: a null shift of the servo valve (the valve sees the command plus an offset)."""

from __future__ import annotations

from numba import njit

from compliance.effects.base import Effect
from compliance.effects.param import Param

# slots in the compiled core (tests/effects/test_effect_slots.py checks them against the layout)
P_VO_ON = 69
P_VO_OFF = 70


@njit(cache=True, error_model="numpy", inline="always")
def valve_command(P, u):
    """Hook ``valve_command``: the command the valve acts on [V], shifted by the null offset."""
    return u + P[P_VO_OFF]  # valve null shift


def trim_null(P, null):
    """Hook ``trim_null``: the command that puts the shifted valve at its null [V]."""
    return null - (P[P_VO_OFF] if P[P_VO_ON] else 0.0)


EFFECT = Effect(
    name="valve_offset",
    meaning="null shift of the servo valve: the valve sees the command plus an offset",
    short="vo",
    slot=P_VO_ON,
    params=(Param("offset", "V", "voltage added to the command at the valve", 0.0, (-1.5, 1.5), slot="off", aliases=("u0",)),),
    states=(),
    signature="asymmetric response up vs down; the holding command sits off the compensated null",
    signals=("valve_command", "position"),
    explanation="the servo valve's null is shifted: the valve sees the command plus an offset of {v}",
    fit_grid={"offset": (-0.4, -0.2, -0.1, 0.1, 0.2, 0.4)},
    draw={"offset": (0.05, 0.4, True)},
    draw_signed=True,
    terms={"valve_command": valve_command},
    trim_null=trim_null,
)
