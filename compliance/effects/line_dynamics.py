"""Line dynamics: hoses between valve and cylinders add a volume and a flow restriction per side."""

from __future__ import annotations

from numba import njit

from compliance.effects.base import Effect, ReplayPoint, Rest, State
from compliance.effects.param import Param
from compliance.physics.valve_flow import iso6358_mass_flow

# slots in the compiled core (tests/effects/test_effect_slots.py checks them against the layout)
P_LD_ON = 76
P_LD_VOL = 77
P_LD_COND = 78
S_PLA = 13
S_PLB = 14


def rest(P, y, at: Rest) -> None:
    """Hook ``rest``: no flow at rest, so each hose at its chamber's pressure."""
    y[S_PLA] = at.pressure_a
    y[S_PLB] = at.pressure_b


def replay_reset(P, y, point: ReplayPoint) -> None:
    """Hook ``replay_reset``: each hose at its chamber's pressure where the replay restarts (recorded, else carried
    over; not the rest state's, which clamps to the supply a chamber a meter-out throttle holds above it)."""
    if P[P_LD_ON]:
        y[S_PLA] = point.measured.get("pressure_a", point.simulated["pressure_a"])
        y[S_PLB] = point.measured.get("pressure_b", point.simulated["pressure_b"])


EFFECT = Effect(
    name="line_dynamics",
    meaning="hoses between valve and cylinders add volume and a flow restriction",
    short="ld",
    slot=P_LD_ON,
    params=(
        Param("volume", "m^3", "hose volume per side", 2e-4, (1e-4, 5e-3), True, slot="vol", aliases=("V_line",)),
        Param("conductance", "m^3/(s*Pa)", "sonic conductance of each hose", 3e-8, (1e-9, 1e-7), True, slot="cond",
              aliases=("C_line",)),
    ),
    states=(State("line_pressure_a", "PLA", S_PLA, "pressure"), State("line_pressure_b", "PLB", S_PLB, "pressure")),
    signature="chamber pressures respond later and smoother than the valve command; the loop is less damped",
    signals=("pressure_a", "pressure_b", "valve_command"),
    explanation="the hoses between valve and cylinders add volume and a restriction (hose volume {v} per side)",
    fit_grid={"volume": (1e-4, 5e-4, 2e-3), "conductance": (1e-8, 3e-8, 1e-7)},
    draw={"volume": (1e-4, 6e-4, True), "conductance": (5e-9, 3e-8, True)},
    rest=rest,
    replay_reset=replay_reset,
)


@njit(cache=True, error_model="numpy", inline="always")
def hose_node(conductance, volume, port_pressure, chamber_pressure, t_supply, t_chamber, valve_flow,
              b_crit, rho0, t0, r_gas):
    """(mass flow hose -> chamber [kg/s], rate of the hose pressure [Pa/s]) of one side's hose.

    The hose is a lumped volume (isothermal node at the supply temperature [K]) fed by the valve
    flow [kg/s] and an ISO 6358 restriction to the chamber (seed 000 eq. (1)); pressures [Pa abs].
    """
    t_up = t_supply if port_pressure >= chamber_pressure else t_chamber
    q = iso6358_mass_flow(1.0, conductance, port_pressure, chamber_pressure, t_up, b_crit, rho0, t0)
    return q, r_gas * t_supply / volume * (valve_flow - q)  # mass balance of the hose volume
