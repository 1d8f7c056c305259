"""Laminar leakage across piston seals and to atmosphere."""

from __future__ import annotations

from numba import njit


@njit(cache=True, error_model="numpy", inline="always")
def laminar_leak(conductance, p_from, p_to):
    """Laminar leak mass flow q = k*(p_from - p_to) [kg/s] (Hagen-Poiseuille through a seal gap, linear in dp).

    Parameters
    ----------
    conductance : float
        Leak conductance k [kg/(s*Pa)].
    p_from, p_to : float
        Absolute pressures on either side [Pa]; positive flow from ``p_from`` to ``p_to``.
    """
    return conductance * (p_from - p_to)


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
