"""Laminar leakage through a seal gap (read by the internal and external leakage effects)."""

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
