"""A recording on the controller's clock: uniform-grid checks, resampling, zero-order-hold averages.

A replay simulates on the controller grid ``t0 + k*T_s``; these functions move a recording (logged
at any rate, evenly or not) onto that grid and say when it already is on it.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from compliance.errors import InputError


def is_uniform(time: np.ndarray, step: float | None = None, rtol: float = 1e-3) -> bool:
    """True when the samples are evenly spaced (at ``step`` [s] if given) to ``rtol`` of a step."""
    dt = np.diff(np.asarray(time, dtype=float))
    ref = float(np.median(dt)) if step is None else step
    return bool(dt.size) and bool(np.all(np.abs(dt - ref) <= rtol * ref))


def resample_uniform(time: np.ndarray, values: np.ndarray, step: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Linear interpolation of a (possibly non-uniform) signal onto an even grid from ``time[0]``.

    Parameters
    ----------
    time : ndarray
        Strictly increasing sample times [s].
    values : ndarray
        Samples.
    step : float, optional
        Grid step [s]; default the median sample spacing.

    Returns
    -------
    (ndarray, ndarray)
        Grid times [s] and the interpolated values.
    """
    time = np.asarray(time, dtype=float)
    step = float(np.median(np.diff(time))) if step is None else float(step)
    n = int(math.floor((time[-1] - time[0]) / step + 1e-9)) + 1
    grid = time[0] + step * np.arange(n)
    return grid, np.interp(grid, time, np.asarray(values, dtype=float))


HELD_COLUMNS = ("reference", "valve_command")  # written by the controller: constant between its samples
MAX_LOG_INTERVAL = 4.0  # controller periods; a coarser log cannot show the loop's transients


def on_controller_clock(frame: pd.DataFrame, ts: float, where: str) -> tuple[pd.DataFrame, str | None]:
    """The recording on the controller's clock t_0 + k*ts (a replay needs one sample per period).

    Measured signals (position, pressures) are interpolated linearly at the controller's
    instants; the set-point and the valve command, which the controller holds over its period,
    take the last logged value at or before each instant. A recording already on the clock
    is returned unchanged.

    Parameters
    ----------
    frame : pandas.DataFrame
        Canonical recording (strictly increasing ``time`` [s]).
    ts : float
        Controller sample time [s].
    where : str
        File name for messages.

    Returns
    -------
    (pandas.DataFrame, str or None)
        The recording on the clock, and a note saying what was resampled (None if nothing).

    Raises
    ------
    InputError
        The log is coarser than ``MAX_LOG_INTERVAL`` controller periods.
    """
    t = frame["time"].to_numpy(dtype=float)
    if is_uniform(t, ts):
        return frame, None
    dt = np.diff(t)
    med = float(np.median(dt))
    if med > MAX_LOG_INTERVAL * ts:
        raise InputError(
            f"{where}: time: logged every {med*1e3:.3g} ms (median); replaying the {ts*1e3:g} ms controller needs at "
            f"least one sample per {MAX_LOG_INTERVAL:g} controller periods"
        )
    n = int(math.floor((t[-1] - t[0]) / ts + 1e-9)) + 1
    grid = t[0] + ts * np.arange(n)
    held = np.clip(np.searchsorted(t, grid + 1e-6 * ts, side="right") - 1, 0, t.size - 1)
    out = {"time": grid}
    for col in frame.columns:
        if col == "time":
            continue
        v = frame[col].to_numpy(dtype=float)
        out[col] = v[held] if col in HELD_COLUMNS else np.interp(grid, t, v)
    note = (f"resampled onto the {ts*1e3:g} ms controller clock: {t.size} samples at {dt.min()*1e3:.3g}..{dt.max()*1e3:.3g} ms "
            f"-> {n}; measured signals interpolated, set-point and command held")
    return pd.DataFrame(out), note


def zoh_interval_average(time: np.ndarray, values: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Average of a zero-order-hold signal over each interval [edges[k], edges[k+1]).

    The recorded valve command is what a ZOH controller output looked like to the logger:
    each sample holds until the next. Averaging that staircase over each controller period
    returns the recorded values exactly when the logger ran at the controller's rate and clock,
    and conserves the time integral of the command (hence the valve's mass flow to first order)
    for any other sampling.

    Parameters
    ----------
    time : ndarray
        Sample times [s] (strictly increasing).
    values : ndarray
        Samples (held until the next sample; the last one held for ever, the first one before).
    edges : ndarray
        Interval edges [s], increasing, length n + 1.

    Returns
    -------
    ndarray
        n interval averages.
    """
    time = np.asarray(time, dtype=float)
    values = np.asarray(values, dtype=float)
    # integral of the staircase from time[0]: piecewise linear with knots at the sample times
    cum = np.concatenate(([0.0], np.cumsum(values[:-1] * np.diff(time))))

    def integral(t):
        t = np.asarray(t, dtype=float)
        inside = np.interp(np.clip(t, time[0], time[-1]), time, cum)
        before = np.minimum(t - time[0], 0.0) * values[0]
        after = np.maximum(t - time[-1], 0.0) * values[-1]
        return inside + before + after

    f = integral(edges)
    width = np.diff(edges)
    return np.diff(f) / width


def controller_grid(time: np.ndarray, sample_time: float) -> np.ndarray:
    """Controller sample instants relative to the first recorded sample, covering the recording [s]."""
    span = float(time[-1] - time[0])
    n = int(math.ceil(span / sample_time - 1e-9))
    return sample_time * np.arange(n + 1)
