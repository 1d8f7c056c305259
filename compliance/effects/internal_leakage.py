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
def chamber_leaks(P, pa, pb, ta, tb, ts, patm, qin_a, hin_a, qout_a, qin_b, hin_b, qout_b):
    """Hook ``chamber_leaks``: the seal leak A -> B added to each chamber's inflow, inflow*temperature, outflow.

    Pressures [Pa abs], temperatures [K], flows [kg/s]; gas leaves a chamber at its own temperature.
    """
    if P[P_IL_ON] != 0.0:
        q_il = laminar_leak(P[P_IL_K], pa, pb)  # A -> B across the piston seals (Hagen-Poiseuille, physics.leakage)
        if q_il >= 0.0:
            qout_a += q_il
            qin_b += q_il
            hin_b += q_il * ta
        else:
            qin_a -= q_il
            hin_a -= q_il * tb
            qout_b -= q_il
    return qin_a, hin_a, qout_a, qin_b, hin_b, qout_b


EFFECT = Effect(
    name="internal_leakage",
    meaning="laminar leak across the piston seals from side A to side B",
    short="il",
    params=(Param("conductance", "kg/(s*Pa)", "leak mass flow per pressure difference", 1e-10, (1e-13, 1e-8), True,
                  slot="k", aliases=("k_int",)),),
    states=(),
    signature="command stays off null while holding a load; the pressure difference sags between corrections",
    signals=("valve_command", "pressure_a", "pressure_b"),
    explanation="air leaks across the piston seals from side A to side B (laminar leak {v})",
    fit_grid={"conductance": (3e-12, 1e-11, 3e-11, 1e-10, 3e-10, 1e-9)},
    draw={"conductance": (5e-11, 5e-10, True)},
    terms={"chamber_leaks": chamber_leaks},
)
