"""Friction runs: a cylinder stroked at constant speeds, from a recording or synthesised (Zillen bench).

``prepare_run`` turns a recording (time, position, drive force, chamber pressure) into velocity,
friction (Zillen et al. eq. 3) and the constant-speed samples the map is fitted to
(:mod:`compliance.characterise.friction_map`); ``synthetic_friction_run`` makes such a recording
from a known map for the tests and the docs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from compliance.characterise.derivative import odd_window, smoothed_derivative
from compliance.errors import InputError
from compliance.physics.friction import stribeck_map_array
from compliance.units import ATMOSPHERE_PA


def piston_area(bore: float) -> float:
    """Piston area pi*d^2/4 [m^2] of a bore ``bore`` [m]."""
    return math.pi * bore**2 / 4.0


def friction_from_force(force, pressure_abs, area, atmosphere=ATMOSPHERE_PA):
    """Seal friction of a single-acting cylinder stroked by an external drive [N].

    Zillen et al. eq. (3): F_f = F - p_gauge * A, with F the force the drive applies [N],
    ``pressure_abs`` the chamber pressure [Pa abs] and ``area`` the piston area [m^2].
    """
    return np.asarray(force, dtype=float) - (np.asarray(pressure_abs, dtype=float) - atmosphere) * area


def stribeck_friction(velocity, coulomb, static, stribeck_velocity, viscous):
    """Friction-velocity map F(v) = sign(v)[F_C + (F_S - F_C) exp(-|v|/v_s)] + b v [N], vectorised.

    The plant's kernel ``compliance.physics.friction.stribeck_map`` over arrays.
    ``velocity`` [m/s], ``coulomb`` / ``static`` [N], ``stribeck_velocity`` [m/s], ``viscous`` [N*s/m].
    """
    return stribeck_map_array(velocity, static, coulomb, stribeck_velocity, viscous)


@dataclass(frozen=True)
class FrictionRun:
    """One recording prepared for the map: velocity, friction and pressure per sample."""

    name: str
    time: np.ndarray
    velocity: np.ndarray  # [m/s]
    friction: np.ndarray  # [N]
    pressure_gauge: np.ndarray  # [Pa]
    area: float  # piston area used for the pressure force [m^2]
    steady: np.ndarray  # speed constant within the tolerance over the derivative window

    @property
    def mean_pressure_gauge(self) -> float:
        """Mean gauge pressure of the run [Pa]."""
        return float(np.mean(self.pressure_gauge))


def prepare_run(name: str, frame: pd.DataFrame, area: float, *, window_s: float = 0.2,
                steady_tolerance: float = 0.1) -> FrictionRun:
    """Velocity (Savitzky-Golay, quadratic, ``window_s`` wide) and friction of one recording.

    ``frame`` needs ``time`` [s], ``position`` [m], ``force`` [N] and ``pressure_a`` [Pa abs].
    A sample is ``steady`` (a constant-speed point of the map) when the speed changes by less
    than ``steady_tolerance`` of itself over the derivative window: |a| * T_w <= tol * |v|.
    Reversals and ramps fail this; the map is a steady-state relation and they are not in it.
    """
    for col in ("time", "position", "force", "pressure_a"):
        if col not in frame.columns:
            raise InputError(f"{name}: friction needs a '{col}' column; has {', '.join(frame.columns)}")
    t = frame["time"].to_numpy(dtype=float)
    dt = float(np.median(np.diff(t)))
    window = odd_window(window_s / dt, 2)
    if t.size < 2 * window:
        raise InputError(f"{name}: {t.size} samples; the {window_s:g} s velocity window needs at least {2 * window}")
    _, v = smoothed_derivative(t, frame["position"].to_numpy(dtype=float), window, 2)
    _, a = smoothed_derivative(t, v, window, 2)
    steady = np.abs(a) * (window * dt) <= steady_tolerance * np.abs(v)
    p_abs = frame["pressure_a"].to_numpy(dtype=float)
    friction = friction_from_force(frame["force"].to_numpy(dtype=float), p_abs, area)
    return FrictionRun(name, t, v, friction, p_abs - ATMOSPHERE_PA, float(area), steady)


def synthetic_friction_run(speeds, map_params: dict, *, area: float, pressure_gauge: float, stroke=0.04,
                           sample_time=0.01, accel=0.5, force_noise=0.0, position_noise=0.0, seed=0,
                           pressure_coefficient=0.0) -> pd.DataFrame:
    """A single-acting cylinder stroked back and forth by a drive at the given speeds.

    Each speed s [m/s] gives one stroke out at +s and one back at -s over ``stroke`` [m], with
    ramps of ``accel`` [m/s^2]. The drive force is F = F_f(v) + p_gauge*A (inverse of Zillen
    eq. 3), F_f the map ``stribeck_friction(v, **map_params)`` plus ``pressure_coefficient`` *
    p_gauge on its Coulomb level. Seeded Gaussian noise on force [N] and position [m].

    Returns
    -------
    pandas.DataFrame
        ``time`` [s], ``position`` [m], ``pressure_a`` [Pa abs], ``force`` [N].
    """
    pieces = []
    for s in speeds:
        for sign in (1.0, -1.0):
            ramp = s / accel
            cruise = max(stroke / s - ramp, 0.0)
            t = np.arange(0.0, 2 * ramp + cruise, sample_time)
            v = np.minimum.reduce([np.full_like(t, s), accel * t, accel * (2 * ramp + cruise - t)])
            pieces.append(sign * np.clip(v, 0.0, None))
    v = np.concatenate(pieces)
    t = np.arange(v.size) * sample_time
    x = np.concatenate(([0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * sample_time)))
    c = dict(map_params)
    c["coulomb"] = c["coulomb"] + pressure_coefficient * pressure_gauge
    c["static"] = c["static"] + pressure_coefficient * pressure_gauge
    rng = np.random.default_rng(seed)
    force = stribeck_friction(v, **c) + pressure_gauge * area + rng.normal(0.0, force_noise, v.size) * (force_noise > 0)
    x = x + rng.normal(0.0, position_noise, v.size) * (position_noise > 0)
    return pd.DataFrame({"time": t, "position": x, "pressure_a": np.full(v.size, pressure_gauge + ATMOSPHERE_PA),
                         "force": force})
