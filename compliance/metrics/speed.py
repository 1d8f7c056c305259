"""How hard the servo is driven: piston speeds and valve-command saturation.

Both say how close a run comes to the servomotor's rate limit (the valve fully open).
"""

from __future__ import annotations

import numpy as np

from compliance.metrics.trace_windows import time_window

__all__ = ["saturation_fraction", "speed", "speed_extremes"]


def speed(time, position, window=0.02):
    """Velocity from a centred difference over ``window`` [m/s].

    Parameters
    ----------
    time : array [s]
    position : array [m]
    window : float
        Span of the centred difference [s]; 20 ms suppresses sample-level noise while keeping
        the ~0.1 s dynamics of a gate servo.
    """
    time = np.asarray(time, float)
    position = np.asarray(position, float)
    n = time.size
    if n < 3:
        return np.zeros(n)
    dt = float(np.median(np.diff(time)))
    k = max(1, int(round(window / 2.0 / dt))) if dt > 0 else 1
    lo = np.clip(np.arange(n) - k, 0, n - 1)
    hi = np.clip(np.arange(n) + k, 0, n - 1)
    span = time[hi] - time[lo]
    span[span <= 0] = np.inf
    return (position[hi] - position[lo]) / span


def speed_extremes(time, position, t_from=-np.inf, t_to=np.inf, window=0.02):
    """Maximum speeds in a window: (max |v|, max opening v, max closing -v) [m/s]."""
    v = speed(time, position, window)
    sl = time_window(np.asarray(time, float), t_from, t_to)
    seg = v[sl]
    if seg.size == 0:
        return 0.0, 0.0, 0.0
    return float(np.max(np.abs(seg))), float(max(0.0, np.max(seg))), float(max(0.0, -np.min(seg)))


def saturation_fraction(time, valve_command, threshold, t_from=-np.inf, t_to=np.inf):
    """Fraction of time the valve command is at or beyond ``threshold`` in magnitude [-].

    Parameters
    ----------
    time : array [s]
    valve_command : array [V]
    threshold : float
        Command magnitude at which the valve is fully open [V].
    """
    time = np.asarray(time, float)
    u = np.asarray(valve_command, float)
    sl = time_window(time, t_from, t_to)
    t = time[sl]
    if t.size < 2:
        return 0.0
    dt = np.diff(t)
    sat = (np.abs(u[sl][:-1]) >= threshold * (1.0 - 1e-9)).astype(float)
    return float(np.sum(sat * dt) / np.sum(dt))
