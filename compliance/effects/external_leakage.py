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
def vent_leak(P, p, patm, q):
    """Hook ``vent_leak``: ``q`` plus the laminar leak from a chamber at ``p`` to atmosphere [kg/s] (pressures [Pa abs])."""
    return q + laminar_leak(P[P_EL_K], p, patm)  # Hagen-Poiseuille through fittings and rod seals (physics.leakage)


EFFECT = Effect(
    name="external_leakage",
    meaning="laminar leak from each chamber to atmosphere (fittings, rod seals)",
    short="el",
    slot=P_EL_ON,
    params=(Param("conductance", "kg/(s*Pa)", "leak mass flow per gauge pressure, each side", 1e-10, (1e-13, 1e-8), True,
                  slot="k", aliases=("k_ext",)),),
    states=(),
    signature="both chamber pressures sag towards atmosphere at rest; the valve keeps feeding both sides",
    signals=("pressure_a", "pressure_b", "valve_command"),
    explanation="both chambers leak to atmosphere through fittings or rod seals (laminar leak {v} per side)",
    fit_grid={"conductance": (3e-12, 1e-11, 3e-11, 1e-10, 3e-10, 1e-9)},
    draw={"conductance": (3e-11, 3e-10, True)},
    terms={"vent_leak": vent_leak},
)
