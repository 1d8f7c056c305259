"""Controller pieces for plant A: dead-zone compensation, PID step, position filter, saturation, and the
error band in which the PID with the smoothed dead-zone inverse leaves the valve shut (``stall_error``)."""

from __future__ import annotations

import math

from numba import njit

from compliance.model.config import PlantConfig

from compliance.model.vector_slots import (P_CDZN, P_CDZP, P_CSLN, P_CSLP, P_LC, P_RL_CLOSE, P_RL_END_RATE, P_RL_END_WIDTH,
                                           P_RL_LEAD, P_RL_OPEN, P_STROKE)


@njit(cache=True, error_model="numpy", inline="always")
def dead_zone_compensation(u_d, dz_pos, dz_neg, slope_pos, slope_neg, width):
    """Smoothed inverse of the valve dead zone, seed 000 eq. (3) as decoded in reference-plant.md [V].

    Parameters
    ----------
    u_d : float
        Demanded command without dead zone (PID output) [V].
    dz_pos, dz_neg : float
        Dead-zone edges zmd and |zme| assumed by the compensator [V].
    slope_pos, slope_neg : float
        md and me [-].
    width : float
        lc, the width of the linear smoothing about zero [V]; 0 gives the plain inverse.
    """
    if u_d >= width:
        return u_d / slope_pos + dz_pos
    if u_d <= -width:
        return u_d / slope_neg - abs(dz_neg)
    if u_d >= 0.0:
        return (dz_pos + width / slope_pos) / width * u_d
    return (abs(dz_neg) + width / slope_neg) / width * u_d


@njit(cache=True, error_model="numpy", inline="always")
def saturate(u, limit):
    """Clip a command to +/- limit [V]."""
    if u > limit:
        return limit
    if u < -limit:
        return -limit
    return u


@njit(cache=True, error_model="numpy", inline="always")
def first_order_filter_gain(cutoff_hz, sample_time):
    """Gain alpha of the discrete first-order low-pass y += alpha*(u - y) (exact ZOH discretisation)."""
    if cutoff_hz <= 0.0:
        return 1.0
    return 1.0 - math.exp(-2.0 * math.pi * cutoff_hz * sample_time)


@njit(cache=True, error_model="numpy", inline="always")
def pid_step(error, filtered_rate, integral, kp, ki, kd, sample_time):
    """One sample of the position PID with derivative on the filtered measurement [V].

    u_d = K_P*e + K_I*integral(e) - K_D*d(x_f)/dt (seed 000 section 3 eq. 8, lost in the text; the
    derivative acts on the filtered measured position so a set-point step does not kick).

    Returns
    -------
    tuple
        (u_d [V], updated integral [m*s]).
    """
    integral = integral + error * sample_time
    return kp * error + ki * integral - kd * filtered_rate, integral


@njit(cache=True, error_model="numpy", inline="always")
def pid_sample(P, xm, ref_k, x_filt, integral, alpha, kp, ki, kd, ts):
    """One controller sample of plant A's PID: filter, PID, dead-zone compensation (seed 000 eq. 3).

    Parameters
    ----------
    P : ndarray
        Plant parameter vector (the compensator's dead-zone slots).
    xm, ref_k : float
        Measured position and reference [m].
    x_filt, integral : float
        Filtered position [m] and error integral [m*s] from the previous sample.
    alpha : float
        Position filter gain (:func:`first_order_filter_gain`).
    kp, ki, kd, ts : float
        Gains and sample time [s].

    Returns
    -------
    tuple
        (u_d demanded [V], u_c compensated [V], new x_filt [m], new integral [m*s]).
    """
    x_new = x_filt + alpha * (xm - x_filt)
    rate = (x_new - x_filt) / ts
    u_d, integral = pid_step(ref_k - xm, rate, integral, kp, ki, kd, ts)
    if P[P_LC] > 0.0:
        u_c = dead_zone_compensation(u_d, P[P_CDZP], P[P_CDZN], P[P_CSLP], P[P_CSLN], P[P_LC])
    else:
        u_c = u_d
    return u_d, u_c, x_new, integral


@njit(cache=True, error_model="numpy", inline="always")
def rate_limited_setpoint(target, previous, opening_rate, closing_rate, end_rate, end_width, stroke, ts):
    """One sample of the governor's set-point rate limiter [m] (docs/physics.md, controller section).

    r[k] = r[k-1] + clip(r_in[k] - r[k-1], -R_c*T_s, +R_o*T_s): separate opening (x rising) and
    closing rates, as the gate-rate limits of the IEEE PES TR 2013 hydro governor models. Within
    ``end_width`` of the end stop being approached the rate is at most ``end_rate`` (a cushion
    zone: our own form; a sample that enters the zone is split at its edge). The state moves only toward
    ``target`` and never past it, so it cannot wind up.

    Parameters
    ----------
    target, previous : float
        Unlimited set-point now and the limited set-point of the previous sample [m].
    opening_rate, closing_rate : float
        Rate limits [m/s]; 0 = not limited in that direction.
    end_rate, end_width : float
        End-zone rate [m/s] (0 = no end zone) and zone width [m].
    stroke, ts : float
        Stroke [m] and controller sample time [s].
    """
    up = opening_rate * ts if opening_rate > 0.0 else math.inf
    down = closing_rate * ts if closing_rate > 0.0 else math.inf
    if end_rate > 0.0:
        up = _zone_travel(stroke - end_width - previous, up, end_rate * ts)
        down = _zone_travel(previous - end_width, down, end_rate * ts)
    step = target - previous
    if step > up:
        return previous + up
    if step < -down:
        return previous - down
    return target


@njit(cache=True, error_model="numpy", inline="always")
def _zone_travel(to_zone, travel, zone_travel):
    """Travel in one sample when the end zone starts ``to_zone`` ahead [m]: full rate to it, zone rate inside."""
    if to_zone <= 0.0:
        return min(travel, zone_travel)
    if travel <= to_zone:
        return travel
    if travel == math.inf:
        return math.inf
    return to_zone + zone_travel * (1.0 - to_zone / travel)  # the rest of the sample at the zone rate


@njit(cache=True, error_model="numpy", inline="always")
def limiter_sample(P, target, previous, gate, ts):
    """:func:`rate_limited_setpoint` with the rates, end zone and stroke of ``P``, held near the gate [m].

    With a lead limit D (``controller.setpoint_lead_limit`` > 0) the limited set-point stops moving
    while it leads the measured gate position ``gate`` by more than D in its direction of travel
    (ramp hold, our own form): a gate held back at an end stop does not leave the set-point far
    ahead to be caught up with a surge. It never moves away from the target.
    """
    r = rate_limited_setpoint(target, previous, P[P_RL_OPEN], P[P_RL_CLOSE], P[P_RL_END_RATE], P[P_RL_END_WIDTH],
                              P[P_STROKE], ts)
    lead = P[P_RL_LEAD]
    if lead > 0.0:
        if r > previous:
            r = max(previous, min(r, gate + lead))
        elif r < previous:
            r = min(previous, max(r, gate - lead))
    return r


def stall_error(cfg: PlantConfig, direction: str = "opening") -> float:
    """Error below which the compensated valve stays shut [m] (reference-plant.md, 'Known tension').

    The smoothed branch of seed 000 eq. (3) maps u_d in [0, lc) to u_c = (zmd' + lc/md')/lc * u_d
    (primes: the compensator's own estimates); the valve opens once u_c reaches its real dead zone
    zmd, i.e. at u_d = zmd*lc/(zmd' + lc/md'), so at |e| = that / K_P (derivative and integral
    terms are ~0 at rest). With zme, me for the closing direction; without smoothing (lc = 0) the
    mismatch of the valve and compensator dead zones divided by K_P. Paper values: 0.86 mm.
    The band of the configuration's PID; a plant kind without it says so (``PlantKind.stall_error``).
    """
    p = cfg.params
    if p["controller.kp"] <= 0.0:
        return 0.0
    side = "positive" if direction == "opening" else "negative"
    lc, kp = p["controller.compensation_width"], p["controller.kp"]
    dz_v, dz_c = p[f"valve.dead_zone_{side}"], p[f"controller.compensation_dead_zone_{side}"]
    md = p[f"controller.compensation_slope_{side}"]
    if lc <= 0.0:
        return max(dz_v - dz_c, 0.0) * md / kp
    return dz_v * lc / ((dz_c + lc / md) * kp)
