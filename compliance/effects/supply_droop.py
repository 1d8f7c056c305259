"""Supply droop: the supply pressure sags under flow (a finite reservoir refilled through a regulator)."""

from __future__ import annotations

from numba import njit

from compliance.effects.base import Effect, ReplayPoint, Rest, State
from compliance.effects.param import Param

# slots in the compiled core (tests/effects/test_effect_slots.py checks them against the layout)
P_SD_ON = 64
P_SD_VOL = 65
P_SD_COND = 66
S_PSUP = 12


def rest(P, y, at: Rest) -> None:
    """Hook ``rest``: the reservoir at the regulated supply pressure."""
    y[S_PSUP] = at.supply_pressure


def replay_reset(P, y, point: ReplayPoint) -> None:
    """Hook ``replay_reset``: the reservoir at the recorded supply pressure, else carried over from the previous segment."""
    if P[P_SD_ON]:
        y[S_PSUP] = point.measured["supply_pressure"] if "supply_pressure" in point.measured else point.simulated["supply_pressure"]


EFFECT = Effect(
    name="supply_droop",
    meaning="supply pressure sags under flow: finite reservoir refilled through a regulator",
    short="sd",
    slot=P_SD_ON,
    params=(
        Param("reservoir_volume", "m^3", "reservoir plus supply line volume", 0.02, (1e-3, 0.5), True, slot="vol",
              aliases=("Vr",)),
        Param("regulator_conductance", "kg/(s*Pa)", "regulator refill flow per pressure deficit", 1e-7, (1e-10, 1e-5), True,
              slot="cond"),
    ),
    states=(State("supply_pressure", "PSUP", S_PSUP, "pressure"),),
    signature="supply pressure dips during fast moves; the filling side's pressure rises more slowly than modelled",
    signals=("supply_pressure", "pressure_a", "pressure_b"),
    explanation="the supply pressure sags while the valve draws air: the reservoir is finite and the regulator refills it slowly (reservoir {v})",
    fit_grid={"reservoir_volume": (0.003, 0.02, 0.1), "regulator_conductance": (1e-8, 1e-7, 1e-6)},
    draw={"reservoir_volume": (0.003, 0.03, True), "regulator_conductance": (1e-8, 1e-7, True)},
    rest=rest,
    replay_reset=replay_reset,
)


@njit(cache=True, error_model="numpy", inline="always")
def reservoir_pressure_rate(regulator_conductance, set_pressure, pressure, drawn_flow, volume, r_gas, temperature):
    """Supply reservoir pressure rate behind a regulator [Pa/s] (isothermal vessel, mass balance).

    dp_s/dt = R*T/V_r * (k_reg*(p_set - p_s) - q_drawn): the regulator refills the reservoir
    (seed 000 fig. 6, 3V1 + 3Z2) with a flow proportional to the pressure deficit.
    """
    refill = regulator_conductance * (set_pressure - pressure)
    if refill < 0.0:
        refill = 0.0  # a regulator does not vent the reservoir
    return r_gas * temperature / volume * (refill - drawn_flow)
