"""Relative opening A_re(U) of a 5-port servo valve with a dead zone per port path."""

from __future__ import annotations

from numba import njit


@njit(cache=True, error_model="numpy", inline="always")
def path_opening(u: float, dead_zone: float, slope: float, saturation_voltage: float) -> float:
    """Relative opening of one port path for a command of the sign that opens it [-].

    A_re = 0 inside the dead zone, then linear to 1 at ``saturation_voltage``, saturated
    beyond (reference-plant.md, "relative opening": assumed shape fitted to seed 000 fig. 2;
    slope md/me of seed 000 eq. (3) scales the voltage axis).

    Parameters
    ----------
    u : float
        Magnitude of the command in the opening direction [V] (>= 0).
    dead_zone : float
        Dead-zone edge zmd or zme [V].
    slope : float
        Dead-zone slope md or me [-] (1 for the reference valve).
    saturation_voltage : float
        Command at which the path is fully open [V].
    """
    du = slope * (u - dead_zone)
    if du <= 0.0:
        return 0.0
    span = slope * (saturation_voltage - dead_zone)
    if du >= span:
        return 1.0
    return du / span


@njit(cache=True, error_model="numpy", inline="always")
def valve_openings(u, dz_pos, dz_neg, slope_pos, slope_neg, saturation_voltage):
    """Openings of the four port paths (P->A, A->T, P->B, B->T) for a command U [V].

    U > 0 opens P->A and B->T (gate opening direction); U < 0 opens P->B and A->T
    (seed 000 section 3; the dead zone zmd applies to U > 0, zme to U < 0).

    Returns
    -------
    tuple of float
        (a_pa, a_at, a_pb, a_bt), each in 0..1.
    """
    if u >= 0.0:
        a = path_opening(u, dz_pos, slope_pos, saturation_voltage)
        return a, 0.0, 0.0, a
    a = path_opening(-u, dz_neg, slope_neg, saturation_voltage)
    return 0.0, a, a, 0.0


@njit(cache=True, error_model="numpy", inline="always")
def signed_opening(u, dz_pos, dz_neg, slope_pos, slope_neg, saturation_voltage):
    """Relative opening for a command U [V] about the centre, signed: > 0 opens P->A and B->T [-].

    The quantity a lag acts on when the valve's dynamics sit after its dead zone (a flow
    response rather than a spool response; ``valve.dynamics_stage = "opening"``).
    """
    if u >= 0.0:
        return path_opening(u, dz_pos, slope_pos, saturation_voltage)
    return -path_opening(-u, dz_neg, slope_neg, saturation_voltage)


@njit(cache=True, error_model="numpy", inline="always")
def openings_from_signed(o):
    """Openings (a_pa, a_at, a_pb, a_bt) of a signed relative opening ``o``, clipped to +-1."""
    if o >= 0.0:
        a = o if o < 1.0 else 1.0
        return a, 0.0, 0.0, a
    a = -o if -o < 1.0 else 1.0
    return 0.0, a, a, 0.0
