"""Friction laws of a single-acting cylinder stroked by a drive, as functions of the measured motion.

The drive measures F = F_bias + F_f with F_bias = c0 + c1 * p_g (the pressure force p_g * A is
already removed by Zillen et al. eq. 3; c0 is a sensor zero, c1 a piston-area error) and
F_f the seal friction. Three friction laws, nested:

- static Stribeck map (reference-plant.md friction map, seed 000 eq. 7):
  F_f = sign(v) g(v, p) + b v,  g = F_C(p) + (F_S(p) - F_C(p)) exp(-|v| / v_s);
- pressure-dependent seal friction (Belforte et al. 2003; the core's
  ``pressure_dependent_friction``): F_C(p) = F_C0 + k_p p_g, F_S(p) = F_S0 + k_p p_g;
- pre-sliding hysteresis, LuGre bristles (Canudas de Wit et al. 1995):
  dz/dt = v - sigma0 |v| z / g(v, p),  F_f = sigma0 z + b v, whose steady state is the map
  and which makes the friction build up over a pre-sliding displacement g/sigma0 after each
  reversal instead of jumping;
- position-dependent seal friction (``friction_bench.position.POSITION_FRICTION``): both levels
  scale with 1 + a1 (x - x_r) + a2 (x - x_r)^2 along the stroke;
- a pressure rise along a power law, k_p p_r (p_g / p_r)^n, and a bias term c2 p_g^2
  (``friction_bench.pressure_shape``);
- friction drifting during each run: both levels scale with 1 + r (t - t_m)
  (``friction_bench.running_in``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from compliance.physics.friction import lugre_sampled_force, stribeck_magnitude
from compliance.diagnosis.friction_bench.position import MIN_FACTOR
from compliance.diagnosis.friction_bench.pressure_shape import pressure_rise
from compliance.diagnosis.friction_bench.running_in import drift_factor


@njit(cache=True)
def _stribeck_levels(speed, coulomb, static, stribeck_velocity):
    """The core's one Stribeck kernel over arrays of speed and (pressure-dependent) levels [N]."""
    out = np.empty(speed.size)
    for k in range(speed.size):
        out[k] = max(stribeck_magnitude(speed[k], static[k], coulomb[k], stribeck_velocity), 1e-6)
    return out


def stribeck_level(speed, pressure_gauge, coulomb0, static0, stribeck_velocity, pressure_coefficient=0.0,
                   pressure_exponent=1.0, reference_pressure=1.0):
    """g(v, p) = F_C(p) + (F_S(p) - F_C(p)) exp(-|v|/v_s) [N] (both levels rise by ``pressure_shape.pressure_rise``:
    k_p p_g, or k_p p_r (p_g / p_r)^n with an exponent).

    Evaluated by ``compliance.physics.friction.stribeck_magnitude``, the simulator's kernel.
    """
    v = np.ascontiguousarray(speed, dtype=float).ravel()
    p = np.broadcast_to(np.asarray(pressure_gauge, dtype=float), np.shape(speed)).ravel()
    rise = pressure_rise(p, pressure_coefficient, pressure_exponent, reference_pressure)
    fc = np.ascontiguousarray(coulomb0 + rise, dtype=float)
    fs = np.ascontiguousarray(static0 + rise, dtype=float)
    return _stribeck_levels(v, fc, fs, float(stribeck_velocity)).reshape(np.shape(speed))


def position_factor(position, params: dict) -> np.ndarray | float:
    """Relative friction level along the stroke, 1 + a1 (x - x_r) + a2 (x - x_r)^2 (``friction_along_stroke``).

    1.0 when the law has no ``position_gradient``; never below ``friction_bench.position.MIN_FACTOR``.
    """
    if "position_gradient" not in params or position is None:
        return 1.0
    d = np.asarray(position, dtype=float) - params["reference_position"]
    return np.maximum(1.0 + params["position_gradient"] * d + params.get("position_curvature", 0.0) * d * d, MIN_FACTOR)


def friction_force(velocity, pressure_gauge, time, params: dict, *, presliding: bool, n_sub: int = 2,
                   position=None) -> np.ndarray:
    """Seal friction of one run [N] under the law the parameters name.

    Parameters
    ----------
    velocity : ndarray
        Piston velocity [m/s].
    pressure_gauge : ndarray
        Chamber gauge pressure [Pa].
    time : ndarray
        [s] (the LuGre state integrates over it).
    params : dict
        ``coulomb`` [N], ``static`` [N], ``stribeck_velocity`` [m/s], ``viscous`` [N*s/m],
        ``pressure_coefficient`` [N/Pa] (0: pressure-independent; with ``nonlinear_pressure_friction``
        ``pressure_exponent`` [-] and ``reference_pressure`` [Pa]), ``bristle_stiffness``
        sigma0 [N/m] (with ``presliding``); with ``friction_along_stroke``: ``position_gradient``
        [1/m], ``position_curvature`` [1/m^2], ``reference_position`` [m].
    presliding : bool
        LuGre bristles (True) or the static map.
    position : ndarray, optional
        Piston position [m] (read only by a law with ``position_gradient``).
    """
    v = np.asarray(velocity, dtype=float)
    g = stribeck_level(v, pressure_gauge, params["coulomb"], params["static"], params["stribeck_velocity"],
                       params.get("pressure_coefficient", 0.0), params.get("pressure_exponent", 1.0),
                       params.get("reference_pressure", 1.0)) * position_factor(position, params) * drift_factor(time, params)
    if presliding:
        dt = np.concatenate(([0.0], np.diff(np.asarray(time, dtype=float))))
        return lugre_sampled_force(np.ascontiguousarray(v), np.ascontiguousarray(g), dt, float(params["bristle_stiffness"]), n_sub) \
            + params["viscous"] * v
    return np.sign(v) * g + params["viscous"] * v


def bias_force(pressure_gauge, params: dict) -> np.ndarray:
    """Direction-independent force of the bench [N]: sensor zero c0, area error c1 p_g and (with
    ``pressure_force_curvature``) c2 p_g^2."""
    p = np.asarray(pressure_gauge, dtype=float)
    return params.get("bias", 0.0) + (params.get("bias_per_pressure", 0.0) + params.get("bias_per_pressure_squared", 0.0) * p) * p


def core_equivalent(p: dict) -> str:
    """The bench's additive k_p (``pressure_coefficient`` [N/Pa]) in the core's multiplicative ``pressure_dependent_friction`` terms.

    The core scales both levels by 1 + k p_mean (p_mean the mean chamber gauge pressure; this
    single-acting cylinder has its rod side vented, so p_mean = p_g / 2): k = 2 k_p / F_0 per level.
    """
    from compliance.diagnosis.servo.explanation import effect_words
    from compliance.presentation.numbers import fmt_si

    rel = [f"{fmt_si(2.0 * p['pressure_coefficient'] / p[level], '1/Pa')} on {name}"
           for level, name in (("coulomb", "F_C"), ("static", "F_S")) if p[level] > 1e-3]
    if not rel:
        return ""
    return (f"; the plant model's declared effect \u201c{effect_words('pressure_dependent_friction')}\u201d, which scales both "
            f"levels by 1 + k \u00d7 the mean chamber gauge pressure, would need k = {' and '.join(rel)}")
