"""Valve null flow: the servo valve's lands leak near null, so pressure builds inside the nominal dead zone."""

from __future__ import annotations

from numba import njit

from compliance.effects.base import Effect
from compliance.effects.param import Param

# slots in the compiled core (tests/effects/test_effect_slots.py checks them against the layout)
P_NF_ON = 87
P_NF_A0 = 88
P_NF_W = 89

EFFECT = Effect(
    name="valve_null_flow",
    meaning="the servo valve passes flow near its null: its lands leak, so pressure builds inside the nominal dead zone",
    short="nf",
    slot=P_NF_ON,
    params=(
        Param("null_opening", "", "relative opening through which each land leaks at null (leakage / underlap)", 0.003,
              (0.0, 0.05), slot="a0"),
        Param("null_width", "V", "command over which a covered land stops leaking (sets the pressure gain at null)", 0.3,
              (0.05, 2.0), True, slot="w"),
    ),
    states=(),
    signature="steady errors well inside the dead-zone stall band; chamber pressures follow the command at null",
    signals=("position", "pressure_a", "pressure_b", "valve_command"),
    # linear treatment: no state; at the trim (valve at null) the leaks' flow-pressure slope enters the state
    # Jacobian through plant_rhs, and the input column is measured beyond the dead-zone edge (linear/trim.flow_columns)
    explanation="the servo valve leaks across its lands near null, so the loop keeps a pressure gain inside the "
                "nominal dead zone (leak opening {v} of full opening per land)",
    fit_grid={"null_opening": (0.001, 0.003, 0.01), "null_width": (0.1, 0.3, 0.65)},
    draw={"null_opening": (0.001, 0.01, True), "null_width": (0.1, 0.65, True)},
)


@njit(cache=True, error_model="numpy", inline="always")
def land_leak_openings(u, null_opening, null_width, dz_pos, dz_neg):
    """Relative openings through which the four lands leak near null (a_pa, a_at, a_pb, a_bt) [-].

    A real spool passes flow inside its nominal dead zone: air leaks through the radial
    clearance of every land, more the less of the land is covered (Merritt 1967, sec. 5.4: null
    leakage and the pressure sensitivity of a practical critical-centre valve; near null the
    clearance acts as a small underlap). Taken linear in the spool travel, as for an underlap of
    ``null_width``: each land leaks ``null_opening`` at null; a land the command covers leaks
    a0*(1 - |u|/w) and is shut from |u| = w; a land the command uncovers leaks a0*(1 + |u|/w)
    and keeps opening with the travel until its metering edge is reached at the nominal dead
    zone (beyond it the nominal opening adds and the leak stays at its edge value). With both
    lands of a port leaking the port pressure follows the command inside the dead zone (a finite
    pressure gain at null), and the flow keeps a finite gain across the whole dead zone.

    Parameters
    ----------
    u : float
        Command about the valve's null [V]; > 0 uncovers P->A and B->T.
    null_opening : float
        Relative opening of each land at null [-] (>= 0).
    null_width : float
        Command over which a covered land closes (the equivalent underlap) [V] (> 0).
    dz_pos, dz_neg : float
        Nominal dead zone for positive / negative commands [V] (where the uncovering land's edge opens).
    """
    s = u / null_width
    # an uncovering land opens until its edge (at least over the width, where a critically lapped valve opens anyway)
    edge = (dz_pos if u >= 0.0 else dz_neg) / null_width
    up = min(abs(s), max(edge, 1.0))
    down = max(1.0 - abs(s), 0.0)
    uncovering = null_opening * (1.0 + up)
    covering = null_opening * down
    if u >= 0.0:
        return uncovering, covering, covering, uncovering  # P->A and B->T uncovered
    return covering, uncovering, uncovering, covering


@njit(cache=True, error_model="numpy", inline="always")
def leaky_openings(null_opening, null_width, u, dz_pos, dz_neg, a_pa, a_at, a_pb, a_bt):
    """The four port openings [-] with the land leaks near null added (each at most fully open); ``u`` about null [V]."""
    l_pa, l_at, l_pb, l_bt = land_leak_openings(u, null_opening, null_width, dz_pos, dz_neg)  # Merritt 1967 sec. 5.4
    return min(a_pa + l_pa, 1.0), min(a_at + l_at, 1.0), min(a_pb + l_pb, 1.0), min(a_bt + l_bt, 1.0)
