"""Valve flow-law coefficients consistent with a nominal flow rating, and the "detailed" valve.

A proportional valve is sold with one number, its nominal flow Q_N (700 NL/min for plant B):
the standard-air volume flow at p1 = 6 bar gauge inlet and a 1 bar pressure drop (VDI 3290 /
ISO 6358 "nominal flow"). Every flow law of seed 001 has one scale coefficient; this module
sets it so the law passes through that rating point. The power law (seed 001 eq. 7, lost in
the text) has two coefficients: its second one comes from a constrained least-squares fit to
the detailed valve model below over a charging run (docs/plant-b.md, "Flow laws").

The detailed valve ("the real valve" of the flow-law experiment) is ISO 6358 with a low
critical ratio b = 0.3 plus a laminar leakage-like term k_lam*(p1 - p2): real spool valves
show b well below the ideal-nozzle 0.528 and a laminar part at small pressure differences
(ISO 6358-2:2013 adds exactly such a subsonic index; Beater, "Pneumatic Drives", 2007, ch. 3).
"""

from __future__ import annotations

import numpy as np

from compliance.physics.valve_rating import (
    NORMAL_DENSITY,
    NORMAL_TEMPERATURE,
    rated_mass_flow,
    rating_point,
    sonic_conductance,
)
from compliance.physics.valve_flow import (
    bobrow_mass_flow,
    iso6358_mass_flow,
    power_law_mass_flow,
    sanville_mass_flow,
)

DETAILED_B = 0.3  # critical ratio of the "detailed" valve (assumed, typical of spool valves)
DETAILED_LAMINAR_SHARE = 0.05  # share of the laminar term in the rated flow (assumed)
POWER_EXPONENT = 0.25  # lambda, seed 001 (the only part of eq. 7 that survived)


def sanville_area(q_rated, p1, p2, t1=NORMAL_TEMPERATURE, gamma=1.4, r_gas=287.0):
    """Sanville effective area A_e passing through the rating point [m^2] (seed 001 eq. 5)."""
    return q_rated / sanville_mass_flow(1.0, p1, p2, t1, gamma, r_gas)


def bobrow_coefficient(q_rated, p1, p2):
    """Bobrow C_f*A at full opening passing through the rating point [kg/(s*Pa^0.5)] (seed 001 eq. 6)."""
    return q_rated / bobrow_mass_flow(1.0, 1.0, p1, p2)


def detailed_valve_flow(p_up, p_down, t_up, q_rated, p1, p2, b=DETAILED_B, laminar_share=DETAILED_LAMINAR_SHARE,
                        rho0=NORMAL_DENSITY, t0=NORMAL_TEMPERATURE):
    """Mass flow of the "detailed" valve at full opening [kg/s]: ISO 6358 (b) + laminar term.

    q = C_d p_up rho0 sqrt(T0/T) w(p_down/p_up; b) + k_lam (p_up - p_down), with C_d and k_lam set
    so the valve passes ``q_rated`` at (p1, p2) and the laminar term carries ``laminar_share`` of it.

    Parameters
    ----------
    p_up, p_down : float or array
        Absolute pressures [Pa].
    t_up : float
        Upstream temperature [K].
    q_rated : float
        Rated mass flow [kg/s] at (p1, p2) [Pa abs].
    """
    k_lam = laminar_share * q_rated / (p1 - p2)
    c_d = (1.0 - laminar_share) * q_rated / iso6358_mass_flow(1.0, 1.0, p1, p2, NORMAL_TEMPERATURE, b, rho0, t0)
    pu = np.asarray(p_up, float)
    pd = np.asarray(p_down, float)
    iso = np.vectorize(iso6358_mass_flow, otypes=[float])(1.0, c_d, pu, pd, t_up, b, rho0, t0)
    return iso + k_lam * (pu - pd)


def power_law_coefficients(q_rated, p1, p2, supply, atmosphere, t_up=NORMAL_TEMPERATURE, exponent=POWER_EXPONENT,
                           samples=400):
    """(C_f1, C_f2) of q = C_f1 dp^lambda + C_f2 dp through the rating point, fitted to the detailed valve.

    The rating fixes C_f2 = (q_r - C_f1 dp_r^lambda)/dp_r; C_f1 then minimises the squared
    difference to ``detailed_valve_flow`` charging a volume from ``atmosphere`` to ``supply``
    (pressures spaced evenly; a 1-D linear least-squares problem, closed form). C_f2 is kept
    >= 0 (a negative laminar term would make flow fall with the pressure difference).

    Returns
    -------
    tuple of float
        C_f1 [kg/(s*Pa^lambda)], C_f2 [kg/(s*Pa)].
    """
    dpr = p1 - p2
    p = np.linspace(atmosphere, supply, samples + 1)[:-1]
    dp = supply - p
    q = detailed_valve_flow(supply, p, t_up, q_rated, p1, p2)
    # q ~ c1*dp^l + (q_r - c1*dpr^l)/dpr*dp = c1*(dp^l - dpr^l*dp/dpr) + q_r*dp/dpr
    basis = dp**exponent - dpr**exponent * dp / dpr
    target = q - q_rated * dp / dpr
    c1 = float(basis @ target / (basis @ basis))
    c1 = min(c1, q_rated / dpr**exponent)  # keeps C_f2 >= 0
    c2 = (q_rated - c1 * dpr**exponent) / dpr
    return c1, max(c2, 0.0)


def rating_coefficients(nominal_flow_nl_min, atmosphere, supply, b=0.528, exponent=POWER_EXPONENT) -> dict:
    """Every flow-law coefficient of a valve of nominal flow ``nominal_flow_nl_min`` [NL/min].

    Parameters
    ----------
    atmosphere, supply : float
        Absolute pressures [Pa] (supply: the plant's, for the power-law fit range).
    b : float
        Critical ratio assumed for the ISO 6358 law of the plant.

    Returns
    -------
    dict
        ``sonic_conductance`` [m^3/(s*Pa)], ``effective_area`` [m^2],
        ``bobrow_coefficient`` [kg/(s*Pa^0.5)], ``power_law_c1`` [kg/(s*Pa^lambda)],
        ``power_law_c2`` [kg/(s*Pa)], ``rated_mass_flow`` [kg/s], ``p1``, ``p2`` [Pa].
    """
    q = rated_mass_flow(nominal_flow_nl_min)
    p1, p2 = rating_point(atmosphere)
    c1, c2 = power_law_coefficients(q, p1, p2, supply, atmosphere, exponent=exponent)
    return {
        "sonic_conductance": sonic_conductance(q, p1, p2, b=b),
        "effective_area": sanville_area(q, p1, p2),
        "bobrow_coefficient": bobrow_coefficient(q, p1, p2),
        "power_law_c1": c1,
        "power_law_c2": c2,
        "rated_mass_flow": q,
        "p1": p1,
        "p2": p2,
    }


def check_rating(c: dict, exponent=POWER_EXPONENT) -> dict:
    """Flow of each law at the rating point [kg/s] (all equal ``rated_mass_flow`` by construction)."""
    p1, p2 = c["p1"], c["p2"]
    t = NORMAL_TEMPERATURE
    return {
        "iso6358": iso6358_mass_flow(1.0, c["sonic_conductance"], p1, p2, t, 0.528, NORMAL_DENSITY, NORMAL_TEMPERATURE),
        "sanville": sanville_mass_flow(c["effective_area"], p1, p2, t, 1.4, 287.0),
        "bobrow": bobrow_mass_flow(c["bobrow_coefficient"], 1.0, p1, p2),
        "power_law": power_law_mass_flow(c["power_law_c1"], c["power_law_c2"], exponent, 1.0, p1, p2),
    }


if __name__ == "__main__":  # pragma: no cover - prints the values written in models/plant-b.toml
    _c = rating_coefficients(700.0, 101300.0, 6.0e5 + 101300.0)
    for _k, _v in _c.items():
        print(f"{_k:22s} {_v:.5g}")
