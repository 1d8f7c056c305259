"""Internal leakage: laminar leak across the piston seals from chamber A to chamber B."""

from __future__ import annotations

from numba import njit

from compliance.effects.base import Effect
from compliance.effects.param import Param
from compliance.physics.leakage import laminar_leak

# slots in the compiled core (tests/effects/test_effect_slots.py checks them against the layout)
P_IL_ON = 56
P_IL_K = 57


@njit(cache=True, error_model="numpy", inline="always")
def seal_leak(P, pa, pb, q):
    """Hook ``seal_leak``: ``q`` plus the laminar leak across the piston seals from A to B [kg/s] (pressures [Pa abs])."""
    return q + laminar_leak(P[P_IL_K], pa, pb)  # Hagen-Poiseuille through the seal gap (physics.leakage)


EFFECT = Effect(
    name="internal_leakage",
    meaning="laminar leak across the piston seals from side A to side B",
    short="il",
    slot=P_IL_ON,
    params=(Param("conductance", "kg/(s*Pa)", "leak mass flow per pressure difference", 1e-10, (1e-13, 1e-8), True,
                  slot="k", aliases=("k_int",)),),
    states=(),
    signature="command stays off null while holding a load; the pressure difference sags between corrections",
    signals=("valve_command", "pressure_a", "pressure_b"),
    explanation="air leaks across the piston seals from side A to side B (laminar leak {v})",
    fit_grid={"conductance": (3e-12, 1e-11, 3e-11, 1e-10, 3e-10, 1e-9)},
    draw={"conductance": (5e-11, 5e-10, True)},
    terms={"seal_leak": seal_leak},
)
