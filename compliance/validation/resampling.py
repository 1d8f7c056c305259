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
MAX_LOG_INTERVAL = 10.0  # controller periods (100 Hz for a 1 kHz controller): a coarser log cannot show the loop's transients
CLOCK_TOLERANCE = 1e-6  # share of a controller period within which two instants are the same (parsed time stamps)


def logged_indices(time: np.ndarray, ts: float) -> np.ndarray:
    """Controller periods (from the first sample) at which the logger wrote a sample.

    Parameters
    ----------
    time : ndarray
        Logged time stamps [s], strictly increasing.
    ts : float
        Controller sample time [s].

    Returns
    -------
    ndarray of int
        Index of the controller instant nearest each logged sample (unique, increasing).
    """
    t = np.asarray(time, dtype=float)
    return np.unique(np.rint((t - t[0]) / ts).astype(np.int64))


def _held_reference(t: np.ndarray, v: np.ndarray, grid: np.ndarray, held: np.ndarray) -> np.ndarray:
    """The controller's set-point between logged samples: a step holds, a ramp keeps ramping.

    A logged change that its neighbours do not continue is a step (the controller jumped once,
    somewhere in the interval: held at the last logged value); a change continued by the next or
    previous interval is a ramp or a sine the controller advanced every period (interpolated).
    """
    out = v[held]
    if v.size < 3:
        return out
    moved = np.abs(np.diff(v)) > 1e-12 * max(1.0, float(np.max(np.abs(v))))
    smooth = moved & (np.concatenate(([False], moved[:-1])) | np.concatenate((moved[1:], [False])))
    seg = np.clip(np.searchsorted(t, grid, side="right") - 1, 0, t.size - 2)
    ramp = smooth[seg]
    out[ramp] = np.interp(grid[ramp], t, v)
    return out


def _held_command(t: np.ndarray, v: np.ndarray, grid: np.ndarray, held: np.ndarray, ts: float) -> np.ndarray:
    """The command the controller held over each period from a log of its zero-order-hold staircase.

    Where no logged sample falls inside a period (a log on the controller's clock, or slower, or
    a missing sample), the last logged value at or before the period's start, exactly; where one
    does (a jittered clock, a faster log), the staircase's average over the period
    (``zoh_interval_average``), which conserves the command's time integral.
    """
    out = v[held]
    tol = CLOCK_TOLERANCE * ts
    edges = np.append(grid, grid[-1] + ts)
    inside = np.searchsorted(t, edges[1:] - tol, side="left") - np.searchsorted(t, edges[:-1] + tol, side="right")
    mixed = inside > 0
    if np.any(mixed):
        out[mixed] = zoh_interval_average(t, v, edges)[mixed]
    return out


def on_controller_clock(frame: pd.DataFrame, ts: float, where: str) -> tuple[pd.DataFrame, str | None]:
    """The recording on the controller's clock t_0 + k*ts (a replay needs one sample per period).

    Measured signals (position, pressures) are interpolated linearly at the controller's
    instants; the valve command, which the controller holds over its period, takes the last
    logged value at or before each instant, or its average over the period where a logged sample
    falls inside one (``_held_command``), and a set-point step holds (a ramp keeps ramping:
    ``_held_reference``). A recording already on the clock is returned unchanged.
    Which controller instants carry a logged sample: ``logged_indices``.

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
        The log is coarser than ``MAX_LOG_INTERVAL`` controller periods (to ``CLOCK_TOLERANCE``).
    """
    t = frame["time"].to_numpy(dtype=float)
    if is_uniform(t, ts):
        return frame, None
    dt = np.diff(t)
    med = float(np.median(dt))
    if med > MAX_LOG_INTERVAL * ts * (1.0 + CLOCK_TOLERANCE):
        raise InputError(
            f"{where}: time: logged every {med*1e3:.3g} ms (median), slower than {1.0/(MAX_LOG_INTERVAL*ts):.4g} Hz; "
            f"replaying the {ts*1e3:g} ms controller needs at least one sample per {MAX_LOG_INTERVAL:g} controller periods"
        )
    n = int(math.floor((t[-1] - t[0]) / ts + CLOCK_TOLERANCE)) + 1
    grid = t[0] + ts * np.arange(n)
    held = np.clip(np.searchsorted(t, grid + CLOCK_TOLERANCE * ts, side="right") - 1, 0, t.size - 1)
    out = {"time": grid}
    for col in frame.columns:
        if col == "time":
            continue
        v = frame[col].to_numpy(dtype=float)
        if col == "reference":
            out[col] = _held_reference(t, v, grid, held)
        elif col == "valve_command":
            out[col] = _held_command(t, v, grid, held, ts)
        else:
            out[col] = v[held] if col in HELD_COLUMNS else np.interp(grid, t, v)
    note = (f"resampled onto the {ts*1e3:g} ms controller clock: {t.size} samples at {dt.min()*1e3:.3g}..{dt.max()*1e3:.3g} ms "
            f"-> {n}; measured signals interpolated, command and set-point steps held, set-point ramps interpolated; "
            f"compared at the logged instants only")
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
