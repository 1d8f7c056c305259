"""Seal friction: the Stribeck map, the variable-viscous model with a stick phase, LuGre."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy", inline="always")
def stribeck_magnitude(speed, static_force, coulomb_force, stribeck_velocity):
    """Velocity-weakening part of the friction map g(|v|) = F_C + (F_S - F_C)*exp(-|v|/v_s) [N].

    reference-plant.md, friction (assumed map for seed 000 fig. 3).
    """
    r = abs(speed) / stribeck_velocity
    if r > 40.0:  # exp(-40) < 5e-18: the Stribeck hump is gone, skip the exponential
        return coulomb_force
    return coulomb_force + (static_force - coulomb_force) * math.exp(-r)


@njit(cache=True, error_model="numpy", inline="always")
def stribeck_map(velocity, static_force, coulomb_force, stribeck_velocity, viscous):
    """Friction-velocity map F(v) = sign(v)*g(|v|) + b*v [N] (reference-plant.md, seed 000 eq. 7 map)."""
    if velocity == 0.0:
        return 0.0
    s = 1.0 if velocity > 0.0 else -1.0
    return s * stribeck_magnitude(velocity, static_force, coulomb_force, stribeck_velocity) + viscous * velocity


@njit(cache=True, error_model="numpy", inline="always")
def stick_force(applied_force, breakaway_force):
    """Friction of a stuck body [N]: it balances the applied force up to +/- the breakaway force."""
    return min(max(applied_force, -breakaway_force), breakaway_force)


@njit(cache=True, error_model="numpy", inline="always")
def variable_viscous_friction(velocity, applied_force, static_force, coulomb_force, stribeck_velocity, viscous, limit_velocity):
    """Variable viscous friction coefficient model with a stick phase [N] (seed 000 eq. 7).

    Above the limit speed F = f_V(v)*v with f_V(v) = F(v)/v from the friction map; below
    it the body sticks: friction balances the applied force up to the static force
    (Karnopp-type stick band, the form Gomes & Rosa 2003 use for the "stick" mode).

    Parameters
    ----------
    velocity : float
        Sliding velocity [m/s].
    applied_force : float
        Net non-friction force on the body [N] (used only in the stick band).
    static_force, coulomb_force : float
        F_S and F_C [N].
    stribeck_velocity : float
        v_s [m/s].
    viscous : float
        b [N*s/m].
    limit_velocity : float
        Limit speed below which the body is considered stuck [m/s].
    """
    if abs(velocity) < limit_velocity:
        return stick_force(applied_force, static_force)
    return stribeck_map(velocity, static_force, coulomb_force, stribeck_velocity, viscous)


@njit(cache=True, error_model="numpy", inline="always")
def lugre_bristle_rate(velocity, bristle, stiffness, static_force, coulomb_force, stribeck_velocity):
    """LuGre bristle deflection rate dz/dt = v - sigma0*|v|*z/g(v) [m/s] (Canudas de Wit et al. 1995)."""
    g = stribeck_magnitude(velocity, static_force, coulomb_force, stribeck_velocity)
    return velocity - stiffness * abs(velocity) * bristle / g


@njit(cache=True, error_model="numpy", inline="always")
def lugre_force(velocity, bristle, bristle_rate, stiffness, damping, viscous):
    """LuGre friction force F = sigma0*z + sigma1*dz/dt + sigma2*v [N] (Canudas de Wit et al. 1995).

    Its steady state is the Stribeck map of ``stribeck_map`` with sigma2 = b.
    """
    return stiffness * bristle + damping * bristle_rate + viscous * velocity


@njit(cache=True)
def lugre_sampled_force(v, g, dt, sigma0, n_sub):
    """LuGre bristle force sigma0*z [N] over a sampled velocity ``v`` [m/s] (Canudas de Wit et al. 1995).

    The same bristle law as :func:`lugre_bristle_rate`, integrated along a measured motion (the
    friction bench): for a velocity held over a substep h (``n_sub`` per sample step ``dt`` [s]),
    dz/dt = v - (sigma0 |v| / g) z relaxes z towards g sign(v)/sigma0 with rate sigma0 |v| / g;
    the update is exact for any h (no stiffness limit). ``g`` [N] is the Stribeck level per sample,
    ``sigma0`` [N/m] the bristle stiffness.
    """
    n = v.size
    out = np.empty(n)
    z = g[0] * np.sign(v[0]) / sigma0 if v[0] != 0.0 else 0.0
    out[0] = sigma0 * z
    for k in range(1, n):
        h = dt[k] / n_sub
        for j in range(n_sub):
            w = (j + 0.5) / n_sub
            vv = v[k - 1] * (1.0 - w) + v[k] * w
            gg = g[k - 1] * (1.0 - w) + g[k] * w
            if vv == 0.0 or gg <= 0.0:
                continue
            zs = gg / sigma0 * (1.0 if vv > 0.0 else -1.0)
            rate = sigma0 * abs(vv) / gg
            z = zs + (z - zs) * math.exp(-rate * h)
        out[k] = sigma0 * z
    return out


@njit(cache=True, error_model="numpy", inline="always")
def piecewise_stribeck_friction(velocity, applied_force, breakaway_force, low_speed_coefficient, critical_velocity,
                                high_speed_coefficient, limit_velocity):
    """Piecewise friction of seed 001 eq. (8) with a stick band [N].

    F_f = sign(v)*(F_j - k_v1*|v|) for |v| < v_d and
    F_f = sign(v)*(F_j - k_v1*v_d + k_v2*(|v| - v_d)) for |v| >= v_d; below the limit speed the
    body sticks while |applied| <= F_j (friction balances the applied force).

    Parameters
    ----------
    velocity, applied_force : float
        [m/s], net non-friction force [N].
    breakaway_force : float
        F_j [N].
    low_speed_coefficient, high_speed_coefficient : float
        k_v1, k_v2 [N*s/m].
    critical_velocity : float
        v_d [m/s].
    limit_velocity : float
        Stick band [m/s].
    """
    if abs(velocity) < limit_velocity:
        return stick_force(applied_force, breakaway_force)
    s = 1.0 if velocity > 0.0 else -1.0
    speed = abs(velocity)
    if speed < critical_velocity:
        return s * (breakaway_force - low_speed_coefficient * speed)
    return s * (breakaway_force - low_speed_coefficient * critical_velocity + high_speed_coefficient * (speed - critical_velocity))


# ---- the same kernels over numpy arrays (bench characterisation, plots): one loop, one formula
@njit(cache=True, error_model="numpy")
def _stribeck_loop(velocity, static_force, coulomb_force, stribeck_velocity, viscous, signed, out):
    for i in range(out.size):
        if signed:
            out[i] = stribeck_map(velocity[i], static_force[i], coulomb_force[i], stribeck_velocity[i], viscous[i])
        else:
            out[i] = stribeck_magnitude(velocity[i], static_force[i], coulomb_force[i], stribeck_velocity[i])
    return out


def _over_arrays(signed: bool, velocity, static_force, coulomb_force, stribeck_velocity, viscous):
    arrays = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (velocity, static_force, coulomb_force,
                                                                          stribeck_velocity, viscous)))
    flat = [np.ascontiguousarray(a).ravel() for a in arrays]
    out = np.empty(flat[0].size)
    return _stribeck_loop(*flat, signed, out).reshape(arrays[0].shape)[()]  # a scalar for scalar inputs


def stribeck_magnitude_array(speed, static_force, coulomb_force, stribeck_velocity):
    """:func:`stribeck_magnitude` element-wise over numpy arrays (broadcast) [N]."""
    return _over_arrays(False, speed, static_force, coulomb_force, stribeck_velocity, 0.0)


def stribeck_map_array(velocity, static_force, coulomb_force, stribeck_velocity, viscous):
    """:func:`stribeck_map` element-wise over numpy arrays (broadcast) [N]."""
    return _over_arrays(True, velocity, static_force, coulomb_force, stribeck_velocity, viscous)
