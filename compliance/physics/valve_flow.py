"""Mass flow through a pneumatic restriction: ISO 6358, Sanville, Bobrow and a power law."""

from __future__ import annotations

import math

from numba import njit

# Above this pressure ratio the ISO 6358 ellipse is replaced by its chord to a = 1: the
# ellipse has an infinite slope at a = 1, which would make the chamber equations stiff
# without changing any flow by more than 0.2 % of the choked value.
ISO_LINEAR_RATIO = 0.999


@njit(cache=True, error_model="numpy", inline="always")
def iso6358_flow_function(a: float, b: float) -> float:
    """ISO 6358 flow function w(a), seed 000 eq. (2) (dimensionless).

    Parameters
    ----------
    a : float
        Downstream/upstream absolute pressure ratio p2/p1 (0..1).
    b : float
        Critical pressure ratio (0..1).
    """
    if a <= b:
        return 1.0  # seed 000 eq. (2): choked (sonic) flow
    if a >= 1.0:
        return 0.0
    if a > ISO_LINEAR_RATIO:
        r = (ISO_LINEAR_RATIO - b) / (1.0 - b)
        w_lin = math.sqrt(1.0 - r * r)
        return w_lin * (1.0 - a) / (1.0 - ISO_LINEAR_RATIO)  # regularised near a = 1 (see module note)
    r = (a - b) / (1.0 - b)
    return math.sqrt(1.0 - r * r)  # seed 000 eq. (2): subsonic ellipse


@njit(cache=True, error_model="numpy", inline="always")
def iso6358_mass_flow(opening, conductance, p_up, p_down, t_up, b, rho0, t0):
    """Signed mass flow through an ISO 6358 restriction, seed 000 eq. (1) [kg/s].

    Positive from ``p_up`` to ``p_down``; reverse flow (p_down > p_up) is negative with the
    roles of the two sides swapped.

    Parameters
    ----------
    opening : float
        Relative opening A_re (0..1) [-].
    conductance : float
        Sonic conductance C [m^3/(s*Pa)].
    p_up, p_down : float
        Absolute pressures of the nominal upstream and downstream sides [Pa].
    t_up : float
        Temperature of the gas on the side it flows from [K].
    b : float
        Critical pressure ratio [-].
    rho0, t0 : float
        Reference density [kg/m^3] and temperature [K] of the conductance rating (NTP).
    """
    if opening <= 0.0 or conductance <= 0.0:
        return 0.0
    temp = 1.0 if t_up == t0 else math.sqrt(t0 / t_up)  # sqrt(T0/T1); 1 in the isothermal base model
    if p_up >= p_down:
        return opening * conductance * p_up * rho0 * temp * iso6358_flow_function(p_down / p_up, b)
    return -opening * conductance * p_down * rho0 * temp * iso6358_flow_function(p_up / p_down, b)


@njit(cache=True, error_model="numpy", inline="always")
def series_conductance(c1: float, c2: float) -> float:
    """Sonic conductance of two restrictions in series [m^3/(s*Pa)].

    ISO 6358-1 (1989) annex combination rule 1/C^2 = 1/C1^2 + 1/C2^2 (exact for two choked
    nozzles of equal b, within a few % in the subsonic range). A conductance <= 0 means
    'no restriction' for ``c2``.
    """
    if c1 <= 0.0:
        return 0.0
    if c2 <= 0.0:
        return c1
    return 1.0 / math.sqrt(1.0 / (c1 * c1) + 1.0 / (c2 * c2))


@njit(cache=True, error_model="numpy", inline="always")
def sanville_mass_flow(area, p_up, p_down, t_up, gamma, r_gas):
    """Signed mass flow of an ideal compressible orifice, Sanville (1971), seed 001 eq. (5) [kg/s].

    Parameters
    ----------
    area : float
        Effective flow area A(u) [m^2].
    p_up, p_down : float
        Absolute pressures [Pa]; flow is positive from up to down.
    t_up : float
        Upstream temperature [K].
    gamma, r_gas : float
        Heat capacity ratio [-] and gas constant [J/(kg*K)].
    """
    if area <= 0.0:
        return 0.0
    sign = 1.0
    pu, pd = p_up, p_down
    if pd > pu:
        sign = -1.0
        pu, pd = p_down, p_up
    ratio = pd / pu
    ct = (2.0 / (gamma + 1.0)) ** (gamma / (gamma - 1.0))  # seed 001: C_t, critical ratio
    if ratio <= ct:
        flow = area / math.sqrt(t_up) * pu * math.sqrt(gamma / r_gas * (2.0 / (gamma + 1.0)) ** ((gamma + 1.0) / (gamma - 1.0)))
    else:
        term = ratio ** (2.0 / gamma) - ratio ** ((gamma + 1.0) / gamma)
        flow = area / math.sqrt(t_up) * math.sqrt(2.0 * gamma / (r_gas * (gamma - 1.0))) * pu * math.sqrt(max(term, 0.0))
    return sign * flow


@njit(cache=True, error_model="numpy", inline="always")
def bobrow_mass_flow(coefficient, area, p_up, p_down):
    """Signed mass flow by Bobrow & McDonell (1998), seed 001 eq. (6): q = C_f*A*sqrt(p_up - p_down) [kg/s].

    Parameters
    ----------
    coefficient : float
        C_f [kg/(s*m^2*Pa^0.5)].
    area : float
        Opening area A(u) [m^2] (or a relative opening with C_f scaled accordingly).
    p_up, p_down : float
        Absolute pressures [Pa].
    """
    dp = p_up - p_down
    if dp >= 0.0:
        return coefficient * area * math.sqrt(dp)
    return -coefficient * area * math.sqrt(-dp)


@njit(cache=True, error_model="numpy", inline="always")
def power_law_mass_flow(c1, c2, exponent, opening, p_up, p_down):
    """Signed empirical power-law flow q = A*(C_f1*dp^lambda + C_f2*dp) [kg/s].

    Seed 001 eq. (7) is lost in the text; this is a fitted power law in the pressure
    difference with lambda = 0.25 in the paper (documented in docs/physics.md).

    Parameters
    ----------
    c1 : float
        C_f1 [kg/(s*Pa^lambda)].
    c2 : float
        C_f2, a linear (laminar) term [kg/(s*Pa)].
    exponent : float
        lambda [-].
    opening : float
        Relative opening (0..1) [-].
    p_up, p_down : float
        Absolute pressures [Pa].
    """
    dp = p_up - p_down
    s = 1.0 if dp >= 0.0 else -1.0
    adp = abs(dp)
    return s * opening * (c1 * adp**exponent + c2 * adp)
