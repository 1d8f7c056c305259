"""Physical plausibility of a whole recording: every sample in range, a time base that fits.

The reader checks what a format can get wrong (NaN, time going backwards); this module
checks what a logger or a person can get wrong with well-formed numbers: a 1e300 spike in
one sample, a pressure logged as gauge in an absolute column, time logged in milliseconds
(a 30 s test read as 30 000 s), a sample interval that disagrees with the sidecar's rate.
Every sample is checked, not only the first; the message names the row.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from compliance.errors import InputError

__all__ = ["RANGES", "check_no_gaps", "check_ranges", "check_time_base", "pressure_slip", "relative_time"]

# canonical column -> (low, high, unit, why); generous bounds of what any servo bench can log (SI)
RANGES = {
    "time": (-1e6, 1e6, "s", "a test lasts seconds to hours"),
    "position": (-10.0, 10.0, "m", "strokes are at most a few metres"),
    "reference": (-10.0, 10.0, "m", "strokes are at most a few metres"),
    "valve_command": (-100.0, 100.0, "V", "valve commands are volts (+/-10 V, 0-10 V, 24 V)"),
    "pressure_a": (0.0, 1e8, "Pa abs", "absolute pressure cannot be negative; a negative value is usually gauge logged as abs"),
    "pressure_b": (0.0, 1e8, "Pa abs", "absolute pressure cannot be negative; a negative value is usually gauge logged as abs"),
    "supply_pressure": (0.0, 1e8, "Pa abs", "absolute pressure cannot be negative; a negative value is usually gauge logged as abs"),
    "force": (-1e8, 1e8, "N", "bench forces are far below 100 MN"),
}
LOWEST_ABS_PRESSURE = 1e4  # [Pa abs] a servo chamber never sits near vacuum: below this the unit is wrong
# units a pressure is often logged in without saying so, tried in this order: value x factor lands in 0.9..12 bar abs
PRESSURE_UNITS = (("bar", 1e5), ("kPa", 1e3), ("MPa", 1e6), ("psi", 6894.757))
GAP_FACTOR = 10.0  # a time step this many median intervals long is missing samples, not jitter
RATE_MISMATCH = 100.0  # sample interval vs the sidecar's rate: beyond this factor the time unit is wrong
SLOW_SAMPLE = 0.5  # [s] a servo test sampled this slowly cannot resolve a 0.1 s time constant


UNIX_START = (1e8, 4.2e9)  # [s] Unix time of 1973 .. 2103: a time column that starts here is a clock, not a test time


def relative_time(path, time: np.ndarray) -> tuple[np.ndarray, dict | None]:
    """A clock time column (Unix seconds, or dates read as such) made relative to its first sample.

    Returns
    -------
    (numpy.ndarray, dict or None)
        Time [s] from the first sample, and ``{"unix": t0, "utc": "2024-03-05T14:22:01.125Z"}`` when the
        column was a clock (else the column unchanged and None).

    Raises
    ------
    InputError
        A start that looks like Unix time in milliseconds or microseconds read as seconds.
    """
    import datetime as dt

    t0 = float(time[0])
    if UNIX_START[0] <= t0 <= UNIX_START[1]:
        utc = dt.datetime.fromtimestamp(t0, dt.timezone.utc).isoformat(timespec="milliseconds").replace("+00:00", "Z")
        return time - t0, {"unix": t0, "utc": utc}
    for factor, unit in ((1e3, "milliseconds"), (1e6, "microseconds")):
        if UNIX_START[0] * factor <= t0 <= UNIX_START[1] * factor:
            raise InputError(
                f"{path}: column 'time' starts at {t0:.6g}, which is Unix time in {unit} read as seconds; give a "
                f"column map with the time unit (time = {{ column = ..., unit = \"{'ms' if factor == 1e3 else 'us'}\" }})")
    return time, None


def pressure_slip(value: float) -> str:
    """`` - looks like bar without a unit`` when an absolute pressure [Pa] is too low for any servo, else ``""``."""
    if not 0.0 < value < LOWEST_ABS_PRESSURE:
        return ""
    unit = next((u for u, f in PRESSURE_UNITS if 0.9e5 <= value * f <= 1.2e6), None)
    return (f" - looks like {unit} without a unit" if unit else "") + f" (below {LOWEST_ABS_PRESSURE / 1e5:g} bar abs)"


def check_ranges(path, frame: pd.DataFrame, row) -> None:
    """Every sample of every known column within its physical range; pressures not in another unit.

    Raises
    ------
    InputError
        Naming the column, the first row outside and how many samples are outside, or the
        pressure column whose median names a unit slip (bar, kPa, MPa, psi read as Pa).
    """
    for name in ("pressure_a", "pressure_b", "supply_pressure"):
        if name in frame.columns and len(frame):
            med = float(np.median(frame[name].to_numpy()))
            slip = pressure_slip(med)
            if slip:
                raise InputError(f"{path}: column '{name}' median {med:.6g} Pa abs{slip}; the canonical pressure is "
                                 "in Pa absolute: convert it, or give a column map with unit and kind")
    for name, (low, high, unit, why) in RANGES.items():
        if name not in frame.columns:
            continue
        v = frame[name].to_numpy()
        bad = np.flatnonzero((v < low) | (v > high))
        if bad.size:
            i = int(bad[0])
            med = float(np.median(v))
            slip = constant_hint(v, name) or (" - it looks like millimetres written without a unit"
                                              if unit == "m" and high < abs(med) <= 1e3 * high else "")
            raise InputError(
                f"{path}: {row(i)}: column '{name}' = {float(v[i]):.6g} {unit} is outside {low:g}..{high:g} {unit} "
                f"({bad.size} sample(s) outside; {why}){slip}; cut or repair the recording, or correct the column map's unit"
            )


def _sidecar_interval(meta: dict) -> tuple[float, str] | None:
    ctrl = meta.get("controller")
    for where, table, key in (("[controller] sample_time", ctrl, "sample_time"), ("sample_time", meta, "sample_time"),
                              ("sample_rate", meta, "sample_rate")):
        if isinstance(table, dict) and isinstance(table.get(key), (int, float)) and not isinstance(table.get(key), bool):
            value = float(table[key])
            if value > 0 and np.isfinite(value):
                return (1.0 / value if key == "sample_rate" else value), where
    return None


def check_no_gaps(path, time: np.ndarray) -> None:
    """A continuous test (a servo replay) has no missing samples: no time step over ``GAP_FACTOR`` median intervals.

    Bench runs that are logged in bursts (friction maps) are not held to this; the replay is.

    Raises
    ------
    InputError
        Naming the sample after the first gap, the times either side and the number of gaps.
    """
    steps = np.diff(time)
    dt = float(np.median(steps))
    gap = int(np.argmax(steps))
    if steps[gap] > GAP_FACTOR * dt:
        raise InputError(
            f"{path}: sample {gap + 2}: time jumps from {time[gap]:.9g} s to {time[gap + 1]:.9g} s, {steps[gap] / dt:.3g} x the "
            f"median interval {dt:.6g} s: samples are missing ({int(np.sum(steps > GAP_FACTOR * dt))} gap(s)); govcheck does "
            "not fill gaps: cut the recording at the gap or replay the parts separately")


def check_time_base(path, time: np.ndarray, meta: dict, unit_given: bool) -> None:
    """The sample interval agrees with the sidecar's rate (within 100x) and does not look like milliseconds.

    Parameters
    ----------
    path : path-like
        The recording, for messages.
    time : numpy.ndarray
        The time column [s] (strictly increasing, checked before).
    meta : dict
        The sidecar / column-map metadata (SI).
    unit_given : bool
        A column map stated the time unit; the milliseconds guess is then not made.

    Raises
    ------
    InputError
        A median sample interval 100x or more away from the sidecar's, or integer time stamps one
        second or more apart without a stated unit (time in ms, read as s).
    """
    dt = float(np.median(np.diff(time)))
    duration = float(time[-1] - time[0])
    side = _sidecar_interval(meta)
    if side is not None:
        ts, where = side
        if ts >= 1.0 and 0.5 < dt * ts < 2.0:
            raise InputError(
                f"{path}: the sidecar's {where} = {ts:g} looks like a rate in Hz (the recording is sampled every "
                f"{dt:.6g} s); sample_time is the interval in s: write {1.0 / ts:.6g} (or sample_rate = {ts:g})")
        ratio = dt / ts
        if not 1.0 / RATE_MISMATCH < ratio < RATE_MISMATCH:
            hint = " - the time column looks like milliseconds; the canonical time is in seconds" if 500 < ratio < 2000 else ""
            raise InputError(
                f"{path}: column 'time': median sample interval {dt:.6g} s is {ratio:.4g} x the sidecar's {where} = "
                f"{ts:.6g} s{hint}; convert the time to seconds (or give a column map with the time unit)"
            )
        return
    if not unit_given and time.size >= 10 and dt >= SLOW_SAMPLE and np.all(time == np.round(time)):
        raise InputError(
            f"{path}: column 'time': integer time stamps {dt:g} s apart ({duration:g} s in all) look like milliseconds; "
            "the canonical time is in seconds: convert it, or give a column map with unit = \"ms\" for time"
        )


def constant_hint(values: np.ndarray, name: str) -> str:
    """`` - the column never changes ...`` when a logged signal is one value from start to end (a transducer unplugged
    or a channel not wired reads a constant), else ``""``."""
    if values.size > 1 and float(np.ptp(values)) == 0.0:
        return (f" - column '{name}' holds the same value ({float(values[0]):.6g}) in all {values.size} samples: is its "
                "transducer unplugged or the channel not logged?")
    return ""
