"""Picking samples out of a trace: named columns, time windows, level crossings, flagged runs.

The primitives every metric is built on, for simulated and recorded traces alike: plain
arrays in (``time`` [s] strictly increasing, a signal in SI), indices or interpolated times out.
"""

from __future__ import annotations

import numpy as np

from compliance.errors import InputError

__all__ = ["crossing", "frame_columns", "time_window", "true_runs"]


def frame_columns(frame, *names, where="trace"):
    """Return the named columns of a DataFrame as float arrays.

    Parameters
    ----------
    frame : pandas.DataFrame
        A trace with canonical columns (``time`` [s], ``position`` [m], ...).
    names : str
        Column names.
    where : str
        Name of the trace (file) for the error message.

    Raises
    ------
    InputError
        If a column is missing.
    """
    out = []
    for n in names:
        if n not in frame.columns:
            raise InputError(f"{where}: column '{n}' is needed for this metric but is missing")
        out.append(np.asarray(frame[n].to_numpy(), dtype=float))
    return out


def crossing(time, signal, level, start, direction):
    """First time at or after index ``start`` where ``signal`` crosses ``level`` going ``direction`` (+1/-1).

    Parameters
    ----------
    time : array [s]
    signal : array
        Any signal (its unit is that of ``level``).
    level : float
    start : int
        First sample index searched.
    direction : {+1, -1}
        +1: rising through ``level``; -1: falling through it.

    Returns
    -------
    float or None
        Linear interpolation between the two samples around the crossing [s]; None if never.
    """
    s = direction * (signal[start:] - level)
    idx = np.nonzero(s >= 0.0)[0]
    if idx.size == 0:
        return None
    i = start + int(idx[0])
    if i == start or i == 0:
        return float(time[i])
    s0 = direction * (signal[i - 1] - level)
    s1 = direction * (signal[i] - level)
    frac = 0.0 if s1 == s0 else -s0 / (s1 - s0)
    return float(time[i - 1] + frac * (time[i] - time[i - 1]))


def time_window(time, t_from, t_to):
    """Index slice of the samples with ``t_from <= t < t_to`` (``time`` [s] increasing)."""
    i0 = int(np.searchsorted(time, t_from, side="left"))
    i1 = int(np.searchsorted(time, t_to, side="left"))
    return slice(i0, max(i0, i1))


def true_runs(mask) -> list[tuple[int, int]]:
    """Contiguous runs of True samples as half-open index pairs ``[start, stop)``.

    ``[False, True, True, False, True]`` -> ``[(1, 3), (4, 5)]``.
    """
    flags = np.asarray(mask, dtype=bool).astype(int)
    edges = np.flatnonzero(np.diff(np.concatenate(([0], flags, [0]))))
    return list(zip(edges[0::2].tolist(), edges[1::2].tolist()))
