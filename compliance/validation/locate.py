"""Where in a recording does the model go wrong? Residuals, noise floors, located windows.

For each recorded signal the residual r = recorded - replayed is compared with that signal's
own noise floor, estimated from the recording (not from the model):

    floor = 1.4826 * MAD(diff(y)) / sqrt(2)

over the samples at rest (``recorded_noise.noise_floor``, the one noise-floor module). For
white sensor noise of standard deviation sigma, successive differences have standard deviation
sigma*sqrt(2), and the MAD ignores the few large differences of fast transients. A minimum floor (a fraction of the signal's per-unit base)
keeps noise-free recordings from flagging round-off.

The smoothed |r| (centred moving average over ``smoothing`` seconds) must rise above
``k_on * floor`` to open a window and falls below ``k_off * floor`` to close it (hysteresis);
windows shorter than ``min_duration`` are dropped and windows closer than ``merge_gap`` are
merged. Each window is attributed to the operating regimes of ``compliance.validation.regimes``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, asdict

import numpy as np
import pandas as pd

from compliance.errors import InputError
from compliance.validation.recorded_noise import noise_floor
from compliance.validation.regimes import Regimes, attribute

SIGNALS = ("position", "valve_command", "pressure_a", "pressure_b", "supply_pressure")
MIN_FLOOR_PU = 1e-5  # minimum noise floor, per unit of the signal's base (1.6 um, 0.1 mV, 8 Pa on plant A)
ONSET_SPAN = 0.2  # s; the regimes at a window's onset say more than its whole length when a misfit then persists


@dataclass(frozen=True)
class LocateSettings:
    """How residual windows are found.

    Attributes
    ----------
    k_on, k_off : float
        Open / close a window when the smoothed |residual| crosses k * noise floor (k_off <= k_on).
    smoothing : float
        Centred moving-average window of |residual| [s].
    min_duration : float
        Shorter windows are dropped [s].
    merge_gap : float
        Windows separated by less are merged [s].
    min_floor_pu : float
        Minimum noise floor as a fraction of the signal's per-unit base.
    """

    k_on: float = 3.0
    k_off: float = 2.0
    smoothing: float = 0.05
    min_duration: float = 0.05
    merge_gap: float = 0.1
    min_floor_pu: float = MIN_FLOOR_PU

    def __post_init__(self):
        for name in ("k_on", "k_off", "smoothing", "min_floor_pu"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise InputError(f"locate.{name} = {v!r}; expected a positive number")
        for name in ("min_duration", "merge_gap"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
                raise InputError(f"locate.{name} = {v!r}; expected a number >= 0 (seconds)")
        if self.k_off > self.k_on:
            raise InputError(f"locate.k_off ({self.k_off:g}) must not exceed locate.k_on ({self.k_on:g})")


@dataclass
class Window:
    """A time window where one signal's residual stands above its noise floor.

    Attributes
    ----------
    signal : str
    start, end : float
        [s] (recording time).
    i_start, i_end : int
        Sample indexes (inclusive).
    peak_time : float
        Time of the largest smoothed |residual| [s].
    peak_abs : float
        Largest smoothed |residual| (SI unit of the signal).
    peak_ratio : float
        peak_abs / noise floor.
    mean_residual : float
        Mean of recorded - simulated over the window (sign: the recording is above when > 0).
    rms_residual : float
    regimes : dict
        Regime -> fraction of the window's samples.
    dominant : list
        Regimes the window spends at least half its time in.
    onset : list
        Regimes dominant over the window's first ``ONSET_SPAN`` seconds (where the misfit began).
    """

    signal: str
    start: float
    end: float
    i_start: int
    i_end: int
    peak_time: float
    peak_abs: float
    peak_ratio: float
    mean_residual: float
    rms_residual: float
    regimes: dict = field(default_factory=dict)
    dominant: list = field(default_factory=list)
    onset: list = field(default_factory=list)

    @property
    def duration(self) -> float:
        """[s]."""
        return self.end - self.start

    def to_dict(self) -> dict:
        """JSON-ready mapping (adds ``duration``)."""
        d = asdict(self)
        d["duration"] = self.duration
        return d


def residuals(recording: pd.DataFrame, simulated: pd.DataFrame, signals=SIGNALS, exclude=()) -> dict[str, np.ndarray]:
    """Residuals recorded - simulated for every signal present in both frames.

    Parameters
    ----------
    recording, simulated : pandas.DataFrame
        Same length, same time stamps (``replay`` output).
    signals : iterable of str
    exclude : iterable of str
        Signals not to compare (e.g. the valve command in a plant-only replay: it is the input).
    """
    if len(recording) != len(simulated):
        raise InputError(f"residuals: the recording has {len(recording)} samples, the simulation {len(simulated)}")
    out = {}
    for s in signals:
        if s in exclude or s not in recording or s not in simulated:
            continue
        out[s] = recording[s].to_numpy(dtype=float) - simulated[s].to_numpy(dtype=float)
    return out


def smoothed_abs(time: np.ndarray, values: np.ndarray, window: float) -> np.ndarray:
    """Centred moving average of |values| over ``window`` seconds (any sampling).

    Computed from the running trapezoidal integral, so a non-uniform recording is averaged
    over time, not over samples. The window is truncated at the recording's ends.
    """
    t = np.asarray(time, dtype=float)
    a = np.abs(np.asarray(values, dtype=float))
    cum = np.concatenate(([0.0], np.cumsum(0.5 * (a[1:] + a[:-1]) * np.diff(t))))
    lo = np.maximum(t - 0.5 * window, t[0])
    hi = np.minimum(t + 0.5 * window, t[-1])
    span = hi - lo
    avg = (np.interp(hi, t, cum) - np.interp(lo, t, cum)) / np.where(span > 0, span, 1.0)
    return np.where(span > 0, avg, a)


def hysteresis_windows(time: np.ndarray, level: np.ndarray, on: float, off: float, min_duration: float, merge_gap: float) -> list[tuple[int, int]]:
    """Index windows where ``level`` goes above ``on`` until it falls below ``off``.

    Returns
    -------
    list of (int, int)
        Inclusive index ranges, merged when closer than ``merge_gap`` [s], at least
        ``min_duration`` [s] long.
    """
    t = np.asarray(time, dtype=float)
    lv = np.asarray(level, dtype=float)
    above_on = lv > on
    if not above_on.any():
        return []
    above_off = lv > off
    # grow each "above on" run to the surrounding "above off" run
    wins = []
    idx = np.flatnonzero(above_off)
    breaks = np.flatnonzero(np.diff(idx) > 1)
    starts = np.concatenate(([idx[0]], idx[breaks + 1]))
    ends = np.concatenate((idx[breaks], [idx[-1]]))
    for a, b in zip(starts, ends):
        if above_on[a:b + 1].any():
            wins.append([int(a), int(b)])
    merged: list[list[int]] = []
    for w in wins:
        if merged and t[w[0]] - t[merged[-1][1]] < merge_gap:
            merged[-1][1] = w[1]
        else:
            merged.append(w)
    return [(a, b) for a, b in merged if t[b] - t[a] >= min_duration]


def locate(
    recording: pd.DataFrame,
    simulated: pd.DataFrame,
    regimes: Regimes,
    bases: dict[str, float],
    settings: LocateSettings = LocateSettings(),
    exclude=(),
    resolutions: dict | None = None,
    command_input_from: float | None = None,
) -> tuple[list[Window], dict[str, float], dict[str, np.ndarray]]:
    """Located windows of every compared signal, sorted by start time.

    Parameters
    ----------
    recording, simulated : pandas.DataFrame
        Recording and its replay (same time stamps).
    regimes : Regimes
        ``compliance.validation.regimes.compute_regimes`` of the recording.
    bases : dict
        Per-unit base of each signal (SI) for the minimum floor.
    settings : LocateSettings
    exclude : iterable of str
        Signals not compared.
    resolutions : dict, optional
        Signal -> quantisation step (SI) of its channel, a lower bound of its floor.
    command_input_from : float, optional
        Time [s] from which the recorded valve command was the replay's input (a hold test's positioner
        in manual): the command's floor is estimated on the samples before it, where the controller wrote it.

    Returns
    -------
    (list of Window, dict, dict)
        Windows; noise floor per signal (SI); smoothed |residual| per signal.
    """
    t = recording["time"].to_numpy(dtype=float)
    res = residuals(recording, simulated, exclude=exclude)
    rest = regimes.masks.get("at_rest")
    windows: list[Window] = []
    floors: dict[str, float] = {}
    levels: dict[str, np.ndarray] = {}
    for sig, r in res.items():
        base = bases.get(sig, 0.0)
        values, at_rest = recording[sig].to_numpy(dtype=float), rest
        if sig == "valve_command" and command_input_from is not None and np.count_nonzero(t < command_input_from) > 1:
            values, at_rest = values[t < command_input_from], None if rest is None else rest[t < command_input_from]
        floor = noise_floor(values, at_rest, settings.min_floor_pu * base, (resolutions or {}).get(sig, 0.0))
        if not floor > 0:
            floor = max(float(np.max(np.abs(r))) * 1e-9, 1e-300)
        floors[sig] = floor
        lv = smoothed_abs(t, r, settings.smoothing)
        levels[sig] = lv
        for a, b in hysteresis_windows(t, lv, settings.k_on * floor, settings.k_off * floor, settings.min_duration, settings.merge_gap):
            k = a + int(np.argmax(lv[a:b + 1]))
            seg = r[a:b + 1]
            frac, dom = attribute(regimes, a, b)
            b_on = max(a, int(np.searchsorted(t, t[a] + ONSET_SPAN, side="right")) - 1)
            _, onset = attribute(regimes, a, min(b, b_on))
            windows.append(Window(
                signal=sig, start=float(t[a]), end=float(t[b]), i_start=a, i_end=b,
                peak_time=float(t[k]), peak_abs=float(lv[k]), peak_ratio=float(lv[k] / floor),
                mean_residual=float(np.mean(seg)), rms_residual=float(np.sqrt(np.mean(seg**2))),
                regimes=frac, dominant=dom, onset=onset,
            ))
    windows.sort(key=lambda w: (w.start, SIGNALS.index(w.signal) if w.signal in SIGNALS else 99))
    return windows, floors, levels


def merge_across_signals(windows: list[Window], regimes: Regimes, gap: float = 0.0) -> list[dict]:
    """Union of overlapping windows of different signals: one "event" per stretch of misfit.

    Returns
    -------
    list of dict
        ``start``, ``end``, ``duration`` [s], ``signals`` (those involved, with their peak
        ratio), ``regimes`` (fractions over the event) and ``dominant``.
    """
    events: list[dict] = []
    for w in sorted(windows, key=lambda w: w.start):
        if events and w.start - events[-1]["end"] <= gap:
            e = events[-1]
            if w.end > e["end"]:
                e["end"], e["i_end"] = w.end, w.i_end
            e["signals"][w.signal] = max(e["signals"].get(w.signal, 0.0), w.peak_ratio)
        else:
            events.append({"start": w.start, "end": w.end, "i_start": w.i_start, "i_end": w.i_end, "signals": {w.signal: w.peak_ratio}})
    for e in events:
        e["duration"] = e["end"] - e["start"]
        e["regimes"], e["dominant"] = attribute(regimes, e["i_start"], e["i_end"])
    return events
