"""Position error over a window: tracking a moving set-point, and holding a fixed one under load.

Both compare ``reference`` [m] with ``position`` [m] over a time window: a sinusoid's tracking
errors (RMS, maximum) and a hold's mean and maximum error, drift and limit-cycle amplitude.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from compliance.errors import InputError
from compliance.metrics.trace_windows import time_window

__all__ = ["HoldMetrics", "hold", "tracking_errors"]


def tracking_errors(time, position, reference, t_from=-np.inf, t_to=np.inf):
    """RMS and maximum of reference - position over a window [m] (time-weighted RMS)."""
    time = np.asarray(time, float)
    sl = time_window(time, t_from, t_to)
    e = np.asarray(reference, float)[sl] - np.asarray(position, float)[sl]
    if e.size == 0:
        raise InputError("tracking window holds no samples")
    return float(np.sqrt(np.mean(e * e))), float(np.max(np.abs(e)))


@dataclass(frozen=True)
class HoldMetrics:
    """Holding a position under load, over a window [m]."""

    steady_state_error: float
    max_positioning_error: float
    drift: float
    limit_cycle_amplitude: float


def hold(time, position, reference, t_from, t_to):
    """Metrics of a hold window: mean and max error, drift (line fit), limit-cycle amplitude.

    drift = |slope of the least-squares line| x window length [m];
    limit-cycle amplitude = half the peak-to-peak of position minus that line [m].
    """
    time = np.asarray(time, float)
    sl = time_window(time, t_from, t_to)
    t = time[sl]
    x = np.asarray(position, float)[sl]
    r = np.asarray(reference, float)[sl]
    if t.size < 3:
        raise InputError("hold window holds fewer than 3 samples")
    e = r - x
    slope, icpt = np.polyfit(t - t[0], x, 1)
    resid = x - (icpt + slope * (t - t[0]))
    return HoldMetrics(
        float(abs(np.mean(e))),
        float(np.max(np.abs(e))),
        float(abs(slope) * (t[-1] - t[0])),
        float(0.5 * (np.max(resid) - np.min(resid))),
    )
