"""A valve's nominal flow rating (NL/min) and its ISO 6358 sonic conductance, both ways.

A proportional valve is sold with one number, its nominal flow Q_N: the standard-air volume
flow at p1 = 6 bar gauge inlet and a 1 bar pressure drop (VDI 3290 / ISO 6358 "nominal flow").
The sonic conductance C that passes through that rating point follows from seed 000 eq. (1);
the catalogue of hardware options and the sizing use these to speak in NL/min.
"""

from __future__ import annotations

from compliance.physics.valve_flow import iso6358_mass_flow

NORMAL_DENSITY = 1.204  # kg/m^3, ANR standard air 20 degC, 1 atm (seed 000 footnote; ISO 8778)
NORMAL_TEMPERATURE = 293.15  # K
RATING_INLET_GAUGE = 6.0e5  # Pa, nominal-flow inlet pressure (6 bar gauge, VDI 3290)
RATING_DROP = 1.0e5  # Pa, nominal-flow pressure drop (1 bar)
NL_MIN = 1e-3 / 60.0  # m^3/s of normal air per NL/min


def rated_mass_flow(nominal_flow_nl_min: float, rho0: float = NORMAL_DENSITY) -> float:
    """Mass flow of a nominal flow rating [kg/s] from normal litres per minute [NL/min]."""
    return nominal_flow_nl_min * NL_MIN * rho0


def rating_point(atmosphere: float) -> tuple[float, float]:
    """(p1, p2) absolute pressures of the nominal-flow test [Pa] for an atmosphere [Pa]."""
    p1 = RATING_INLET_GAUGE + atmosphere
    return p1, p1 - RATING_DROP


def sonic_conductance(q_rated, p1, p2, t1=NORMAL_TEMPERATURE, b=0.528, rho0=NORMAL_DENSITY, t0=NORMAL_TEMPERATURE):
    """ISO 6358 sonic conductance C passing through the rating point [m^3/(s*Pa)] (seed 000 eq. 1)."""
    return q_rated / iso6358_mass_flow(1.0, 1.0, p1, p2, t1, b, rho0, t0)


def conductance_of_rating(nominal_flow_nl_min: float, atmosphere: float, b: float = 0.528) -> float:
    """Sonic conductance [m^3/(s*Pa)] of a valve rated ``nominal_flow_nl_min`` [NL/min]."""
    p1, p2 = rating_point(atmosphere)
    return sonic_conductance(rated_mass_flow(nominal_flow_nl_min), p1, p2, b=b)


def rating_of_conductance(conductance: float, atmosphere: float, b: float = 0.528) -> float:
    """Nominal flow [NL/min] of a valve of sonic conductance ``conductance`` [m^3/(s*Pa)]."""
    return conductance / conductance_of_rating(1.0, atmosphere, b)
