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


@njit(cache=True, error_model="numpy", inline="always")
def land_leak_openings(u, null_opening, null_width, dz_pos, dz_neg):
    """Relative openings through which the four lands leak near null (a_pa, a_at, a_pb, a_bt) [-].

    A real spool passes flow inside its nominal dead zone: air leaks through the radial
    clearance of every land, more the less of the land is covered (Merritt 1967, sec. 5.4: null
    leakage and the pressure sensitivity of a practical critical-centre valve; near null the
    clearance acts as a small underlap). Taken linear in the spool travel, as for an underlap of
    ``null_width``: each land leaks ``null_opening`` at null; a land the command covers leaks
    a0*(1 - |u|/w) and is shut from |u| = w; a land the command uncovers leaks a0*(1 + |u|/w)
    and keeps opening with the travel until its metering edge is reached at the nominal dead
    zone (beyond it the nominal opening adds and the leak stays at its edge value). With both
    lands of a port leaking the port pressure follows the command inside the dead zone (a finite
    pressure gain at null), and the flow keeps a finite gain across the whole dead zone.

    Parameters
    ----------
    u : float
        Command about the valve's null [V]; > 0 uncovers P->A and B->T.
    null_opening : float
        Relative opening of each land at null [-] (>= 0).
    null_width : float
        Command over which a covered land closes (the equivalent underlap) [V] (> 0).
    dz_pos, dz_neg : float
        Nominal dead zone for positive / negative commands [V] (where the uncovering land's edge opens).
    """
    s = u / null_width
    # an uncovering land opens until its edge (at least over the width, where a critically lapped valve opens anyway)
    edge = (dz_pos if u >= 0.0 else dz_neg) / null_width
    up = min(abs(s), max(edge, 1.0))
    down = max(1.0 - abs(s), 0.0)
    uncovering = null_opening * (1.0 + up)
    covering = null_opening * down
    if u >= 0.0:
        return uncovering, covering, covering, uncovering  # P->A and B->T uncovered
    return covering, uncovering, uncovering, covering
