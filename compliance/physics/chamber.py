"""Chamber volumes and pressure dynamics of the cylinder sides."""

from __future__ import annotations

from numba import njit


@njit(cache=True, error_model="numpy", inline="always")
def chamber_pressure_rate(q_in, q_out, t_in, temperature, pressure, volume, dvolume_dt, heat_flow, gamma, r_gas):
    """Rate of change of chamber pressure from the energy equation [Pa/s].

    dp/dt = gamma/V * (R*T_in*q_in - R*T*q_out - p*dV/dt) + (gamma-1)/V * Q_dot.
    With T_in = T = T_s and Q_dot = 0 this is seed 000 eqs. (4)-(5) as decoded in
    reference-plant.md and seed 001 eqs. (3)-(4).

    Parameters
    ----------
    q_in, q_out : float
        Mass flows entering and leaving the chamber (both >= 0) [kg/s].
    t_in : float
        Temperature of the entering gas [K].
    temperature : float
        Chamber gas temperature [K] (leaving gas has it).
    pressure : float
        Chamber absolute pressure [Pa].
    volume, dvolume_dt : float
        Chamber volume [m^3] and its rate [m^3/s].
    heat_flow : float
        Heat flow from the walls into the gas [W].
    gamma, r_gas : float
        Heat capacity ratio [-] and gas constant [J/(kg*K)].
    """
    return gamma / volume * (r_gas * t_in * q_in - r_gas * temperature * q_out - pressure * dvolume_dt) + (
        gamma - 1.0
    ) / volume * heat_flow


@njit(cache=True, error_model="numpy", inline="always")
def chamber_temperature_rate(temperature, pressure, volume, dpressure_dt, dvolume_dt, q_net, r_gas):
    """Rate of change of chamber gas temperature from T = pV/(mR) [K/s].

    dT/dt = T * (dp/dt / p + dV/dt / V - q_net / m), with m = pV/(R T) (ideal gas).

    Parameters
    ----------
    temperature, pressure, volume : float
        Chamber state [K], [Pa], [m^3].
    dpressure_dt, dvolume_dt : float
        Rates [Pa/s], [m^3/s].
    q_net : float
        Net mass flow into the chamber [kg/s].
    r_gas : float
        Gas constant [J/(kg*K)].
    """
    mass = pressure * volume / (r_gas * temperature)
    return temperature * (dpressure_dt / pressure + dvolume_dt / volume - q_net / mass)
