"""Heat transfer: the chamber gas exchanges heat with the cylinder walls, so its temperature is a state."""

from __future__ import annotations

from numba import njit

from compliance.effects.base import Effect, ReplayPoint, Rest, State
from compliance.effects.param import Param

# slots in the compiled core (tests/effects/test_effect_slots.py checks them against the layout)
P_HT_ON = 54
P_HT_HA = 55
S_TA = 4
S_TB = 5


def rest(P, y, at: Rest) -> None:
    """Hook ``rest``: the gas at the supply temperature (the convention of a servo held at rest)."""
    y[S_TA] = at.supply_temperature
    y[S_TB] = at.supply_temperature


def replay_reset(P, y, point: ReplayPoint) -> None:
    """Hook ``replay_reset``: the gas temperatures are not measured; they carry over from the previous segment."""
    y[S_TA] = point.simulated["temperature_a"]
    y[S_TB] = point.simulated["temperature_b"]


EFFECT = Effect(
    name="heat_transfer",
    meaning="chambers exchange heat with the walls: gas temperature is a state, not the supply temperature",
    short="ht",
    slot=P_HT_ON,
    params=(Param("conductance", "W/K", "wall heat-transfer conductance hA per side", 10.0, (0.01, 500.0), True,
                  slot="ha", aliases=("hA",)),),
    states=(State("temperature_a", "TA", S_TA, "temperature"), State("temperature_b", "TB", S_TB, "temperature")),
    signature="pressures relax for a fraction of a second after every stop while the position holds",
    signals=("pressure_a", "pressure_b", "valve_command"),
    explanation="the chamber air exchanges heat with the cylinder walls instead of staying at supply temperature (wall conductance hA {v} per side)",
    fit_grid={"conductance": (0.3, 1.0, 3.0, 10.0, 30.0, 100.0)},
    draw={"conductance": (3.0, 60.0, True)},
    rest=rest,
    replay_reset=replay_reset,
)


@njit(cache=True, error_model="numpy", inline="always")
def wall_heat_flow(conductance, wall_temperature, gas_temperature):
    """Convective heat flow from wall to gas, Q = hA*(T_w - T) [W] (Newton's law of cooling)."""
    return conductance * (wall_temperature - gas_temperature)
