"""External leakage: laminar leak from each chamber to atmosphere (fittings, rod seals)."""

from __future__ import annotations

from numba import njit

from compliance.effects.base import Effect
from compliance.effects.param import Param
from compliance.physics.leakage import laminar_leak

# slots in the compiled core (tests/effects/test_effect_slots.py checks them against the layout)
P_EL_ON = 58
P_EL_K = 59


@njit(cache=True, error_model="numpy", inline="always")
def chamber_leaks(P, pa, pb, ta, tb, ts, patm, qin_a, hin_a, qout_a, qin_b, hin_b, qout_b):
    """Hook ``chamber_leaks``: each chamber's leak to atmosphere (air drawn back in enters at the supply temperature).

    Pressures [Pa abs], temperatures [K], flows [kg/s].
    """
    if P[P_EL_ON] != 0.0:
        q_ea = laminar_leak(P[P_EL_K], pa, patm)  # to atmosphere (Hagen-Poiseuille, physics.leakage)
        q_eb = laminar_leak(P[P_EL_K], pb, patm)
        if q_ea >= 0.0:
            qout_a += q_ea
        else:
            qin_a -= q_ea
            hin_a -= q_ea * ts
        if q_eb >= 0.0:
            qout_b += q_eb
        else:
            qin_b -= q_eb
            hin_b -= q_eb * ts
    return qin_a, hin_a, qout_a, qin_b, hin_b, qout_b


EFFECT = Effect(
    name="external_leakage",
    meaning="laminar leak from each chamber to atmosphere (fittings, rod seals)",
    short="el",
    params=(Param("conductance", "kg/(s*Pa)", "leak mass flow per gauge pressure, each side", 1e-10, (1e-13, 1e-8), True,
                  slot="k", aliases=("k_ext",)),),
    states=(),
    signature="both chamber pressures sag towards atmosphere at rest; the valve keeps feeding both sides",
    signals=("pressure_a", "pressure_b", "valve_command"),
    explanation="both chambers leak to atmosphere through fittings or rod seals (laminar leak {v} per side)",
    fit_grid={"conductance": (3e-12, 1e-11, 3e-11, 1e-10, 3e-10, 1e-9)},
    draw={"conductance": (3e-11, 3e-10, True)},
    terms={"chamber_leaks": chamber_leaks},
)
