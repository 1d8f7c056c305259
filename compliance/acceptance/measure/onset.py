"""When a servo at rest starts to move after a set-point step: the end of the dead time on a noisy log.

The dead time ends when the position has moved ``DETECT_FRACTION`` (1 %) of the commanded step
(``metrics.step``), 32 um on a 2 % step of a 160 mm stroke: inside the noise of a field log
(about 20 um). A threshold at a noise-safe level would end the dead time late and shorten the
time constant by the same amount. Instead the start of the motion is fitted: at rest, then
accelerating from rest,

    x(t) = x0                                   for t < t0,
    x(t) = x0 + a (t - t0)^2 + b (t - t0)^3     for t >= t0

(a servo driven from rest starts with zero speed; the cubic term lets the acceleration change),
by least squares over the samples from the step until the conditioned travel reaches
``FIT_REACH`` of the step, and the 1 % level is read on the fitted curve. When the start is not
like that (a servo not at rest at the step, stick-slip), the caller says so or the residual is well above the noise and the
conditioned trace is read directly instead, with the time it spends near the level as its
uncertainty.
"""

from __future__ import annotations

import math

import numpy as np

from compliance.acceptance.measure.uncertainty import K, crossing_with_interval
from compliance.metrics.trace_windows import crossing

__all__ = ["FIT_REACH", "motion_onset"]

FIT_REACH = 0.15  # the fit runs until the conditioned travel reaches this share of the step (or 8 noise std)
NOISE_REACH = 8.0
GOOD_FIT = 1.5  # residual RMS within this multiple of the sensor noise: the onset model holds


def _fit(s_time: np.ndarray, y: np.ndarray, t0: float):
    s = np.clip(s_time - t0, 0.0, None)
    basis = np.column_stack((s * s, s * s * s))
    coef, *_ = np.linalg.lstsq(basis, y, rcond=None)
    r = y - basis @ coef
    return float(r @ r), coef


def _hinge(tt: np.ndarray, yy: np.ndarray):
    """Best (t0, coefficients, sse) of the rest-then-accelerate model on a coarse then a fine grid of t0."""
    grid = np.linspace(tt[0], tt[-1], 60)
    best = min(((*_fit(tt, yy, t0), t0) for t0 in grid), key=lambda r: r[0])
    step = grid[1] - grid[0]
    fine = np.linspace(best[2] - step, best[2] + step, 41)
    return min(((*_fit(tt, yy, t0), t0) for t0 in fine), key=lambda r: r[0])


def _model_crossing(t0: float, coef, level: float, horizon: float):
    s = np.linspace(0.0, horizon, 4001)
    y = coef[0] * s * s + coef[1] * s ** 3
    k = np.nonzero(y >= level)[0]
    return None if k.size == 0 else t0 + float(s[k[0]])


def motion_onset(time, raw, smooth, t_step: float, x0: float, size: float, sigma: float, u_smooth: float,
                 fraction: float = 0.01, fit: bool = True):
    """End of the dead time: the position has moved ``fraction`` of the commanded step ``size`` [s].

    Parameters
    ----------
    time, raw, smooth : array
        Even time base [s], logged and conditioned position [m].
    t_step : float
        Time of the set-point step [s].
    x0 : float
        Position at the step [m].
    size : float
        Commanded step, signed [m].
    sigma, u_smooth : float
        Sensor noise of a logged sample and standard uncertainty of a conditioned one [m].
    fraction : float
        Share of the step that ends the dead time (``metrics.DETECT_FRACTION``).
    fit : bool
        The servo was at rest at the step, so the onset model applies; False reads the conditioned trace.

    Returns
    -------
    (float or None, float, str)
        The time [s], its expanded uncertainty [s] and how it was read (``"onset fit"`` or
        ``"conditioned trace"``); None when the position never moved that far.
    """
    sgn = 1.0 if size >= 0 else -1.0
    level = fraction * abs(size)
    i0 = int(np.searchsorted(time, t_step, side="left"))
    travel = sgn * (np.asarray(smooth) - x0)
    reach = max(NOISE_REACH * sigma, FIT_REACH * abs(size))
    k = np.nonzero(travel[i0:] >= reach)[0]
    if sigma <= 0.0:  # a noise-free trace (a prediction): the level is read where the trace crosses it
        return crossing(time, travel, level, i0, +1), 0.0, "noise-free trace"
    if fit and k.size >= 6:
        i1 = i0 + int(k[0]) + 1
        tt = np.asarray(time[i0:i1], float)
        yy = sgn * (np.asarray(raw[i0:i1], float) - x0)
        sse, coef, t0 = _hinge(tt, yy)
        rms = math.sqrt(sse / tt.size)
        if rms <= GOOD_FIT * max(sigma, 1e-12) and coef[0] >= 0.0:
            t1 = _model_crossing(t0, coef, level, tt[-1] - t0)
            if t1 is not None:
                band = K * sigma * math.sqrt(3.0 / tt.size)  # the fitted curve's own scatter (3 parameters)
                lo = _model_crossing(t0, coef, max(level - band, 0.0), tt[-1] - t0) or t0
                hi = _model_crossing(t0, coef, level + band, tt[-1] - t0) or t1
                return t1, max(t1 - lo, hi - t1), "onset fit"
    u_level = math.hypot(u_smooth, sigma / math.sqrt(max(1, i0 - int(np.searchsorted(time, t_step - 0.05)))))
    t1, u = crossing_with_interval(time, sgn * (np.asarray(smooth) - x0), level, u_level, i0, +1)
    return t1, u, "conditioned trace"
