"""Model-validation measures: fit per signal and windowed error statistics with limits.

Two families:

- **Fit** (system identification convention, as MATLAB ``compare`` / ``goodnessOfFit``):
  ``NRMSE = ||y - yhat|| / ||y - mean(y)||`` and ``fit % = 100 * (1 - NRMSE)``. 100 % is a
  perfect match, 0 % is no better than the recording's mean, negative is worse.
- **Windowed errors** in the style of IEC 61400-27-2 (model validation of wind turbines):
  the test is cut into windows (steady / transient); in each, on per-unit signals, the
  maximum error MXE = max|e|, the mean error ME = mean(e) and the mean absolute error
  MAE = mean|e|, with e = (recorded - simulated) / base after a zero-phase low-pass that
  removes sensor noise (``error_filter_cutoff``). Each measure is compared with a
  user-set limit per signal and window kind; a window passes when every assessed measure
  is within its limit (|ME| for the mean error).

Per-unit bases (``per_unit_bases``): position / stroke, valve command / command limit,
pressures / supply pressure (absolute).

The default limits (``DEFAULT_LIMITS``) are govcheck's starting point, not numbers from a
standard: the position's steady MXE of 0.01 pu is the IEC 61362 maximum positioning error
(1 % of stroke) as seed 000 applies it - a model that cannot reproduce the position better
than the acceptance limit cannot decide acceptance. Put a grid code's own numbers in a
settings TOML (``docs/validation.md``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

import numpy as np
from scipy.signal import butter, filtfilt

from compliance.model.config import PlantConfig
from compliance.errors import InputError
from compliance.validation.resampling import is_uniform

SIGNAL_UNITS = {"position": "m", "valve_command": "V", "pressure_a": "Pa", "pressure_b": "Pa", "supply_pressure": "Pa"}
WINDOW_KINDS = ("steady", "transient")
MEASURES = ("max_error", "mean_error", "mean_absolute_error")


@dataclass(frozen=True)
class ErrorLimits:
    """Limits of the windowed error measures [pu]; None means "not assessed".

    Attributes
    ----------
    max_error : float or None
        Limit of MXE = max|e|.
    mean_error : float or None
        Limit of |ME| = |mean(e)|.
    mean_absolute_error : float or None
        Limit of MAE = mean|e|.
    """

    max_error: float | None = None
    mean_error: float | None = None
    mean_absolute_error: float | None = None

    def as_dict(self) -> dict:
        """Mapping measure -> limit."""
        return {m: getattr(self, m) for m in MEASURES}


DEFAULT_LIMITS: Mapping[tuple[str, str], ErrorLimits] = {
    ("position", "steady"): ErrorLimits(0.01, 0.005, 0.005),
    ("position", "transient"): ErrorLimits(0.05, 0.02, 0.02),
    ("valve_command", "steady"): ErrorLimits(0.10, 0.03, 0.05),
    ("valve_command", "transient"): ErrorLimits(0.20, 0.05, 0.08),
    ("pressure_a", "steady"): ErrorLimits(0.02, 0.01, 0.01),
    ("pressure_a", "transient"): ErrorLimits(0.05, 0.02, 0.03),
    ("pressure_b", "steady"): ErrorLimits(0.02, 0.01, 0.01),
    ("pressure_b", "transient"): ErrorLimits(0.05, 0.02, 0.03),
    ("supply_pressure", "steady"): ErrorLimits(0.02, 0.01, 0.01),
    ("supply_pressure", "transient"): ErrorLimits(0.05, 0.02, 0.02),
}


@dataclass(frozen=True)
class ErrorWindow:
    """A stretch of the test assessed as a whole.

    Attributes
    ----------
    name : str
    start, end : float
        [s] (recording time; ``start`` included, ``end`` excluded except at the recording's end).
    kind : {"steady", "transient"}
    """

    name: str
    start: float
    end: float
    kind: str

    def __post_init__(self):
        if self.kind not in WINDOW_KINDS:
            raise InputError(f"window '{self.name}': kind '{self.kind}' is not one of {', '.join(WINDOW_KINDS)}")
        if not (math.isfinite(self.start) and math.isfinite(self.end) and self.end > self.start):
            raise InputError(f"window '{self.name}': needs start < end (got {self.start!r} .. {self.end!r} s)")


@dataclass(frozen=True)
class MetricSettings:
    """Settings of the windowed error statistics.

    Attributes
    ----------
    limits : Mapping
        (signal, kind) -> ErrorLimits.
    error_filter_cutoff : float
        Cut-off of the zero-phase 2nd-order Butterworth low-pass applied to the error [Hz]; 0: none.
    transient_duration : float
        How long after a set-point change a window counts as transient [s].
    windows : tuple of ErrorWindow
        Explicit windows; empty: derived from the recorded reference (``derive_windows``).
    """

    limits: Mapping[tuple[str, str], ErrorLimits] = None  # type: ignore[assignment]
    error_filter_cutoff: float = 20.0
    transient_duration: float = 1.0
    windows: tuple[ErrorWindow, ...] = ()

    def __post_init__(self):
        if self.limits is None:
            object.__setattr__(self, "limits", dict(DEFAULT_LIMITS))
        if not (math.isfinite(self.error_filter_cutoff) and self.error_filter_cutoff >= 0):
            raise InputError(f"metrics.error_filter_cutoff = {self.error_filter_cutoff!r}; expected a frequency >= 0 Hz")
        if not (math.isfinite(self.transient_duration) and self.transient_duration > 0):
            raise InputError(f"metrics.transient_duration = {self.transient_duration!r}; expected a duration > 0 s")


# ----------------------------------------------------------------------------------- fit
def nrmse(y, yhat) -> float | None:
    """Normalised RMS error ||y - yhat|| / ||y - mean(y)|| [-]; None when y is constant."""
    y = np.asarray(y, dtype=float)
    yhat = np.asarray(yhat, dtype=float)
    if not y.size:
        return None
    d = y - y.mean()
    den = math.sqrt(float(np.sum(d * d)))
    if not den > 0:
        return None
    e = y - yhat
    return math.sqrt(float(np.sum(e * e))) / den


def fit_percent(y, yhat) -> float | None:
    """Fit 100 * (1 - ||y - yhat|| / ||y - mean(y)||) [%]; None when y is constant."""
    e = nrmse(y, yhat)
    return None if e is None else 100.0 * (1.0 - e)


def signal_fit(y, yhat) -> dict:
    """Fit, NRMSE, RMS error and largest |error| of one signal (SI units for the errors)."""
    y = np.asarray(y, dtype=float)
    yhat = np.asarray(yhat, dtype=float)
    e = y - yhat
    return {
        "fit_percent": fit_percent(y, yhat),
        "nrmse": nrmse(y, yhat),
        "rms_error": float(np.sqrt(np.mean(e**2))) if e.size else None,
        "max_abs_error": float(np.max(np.abs(e))) if e.size else None,
    }


# ----------------------------------------------------------------------------------- per unit
def per_unit_bases(cfg: PlantConfig, supply_pressure: float | None = None) -> dict[str, dict]:
    """Per-unit base of each signal.

    Returns
    -------
    dict
        signal -> {"value": base (SI), "unit", "meaning"}: position / ``cylinder.stroke``,
        valve command / ``valve.command_limit``, pressures / the supply pressure [Pa abs]
        (the test's, else the configured one).
    """
    ps = float(supply_pressure) if supply_pressure else cfg.p("air.supply_pressure")
    return {
        "position": {"value": cfg.p("cylinder.stroke"), "unit": "m", "meaning": "stroke"},
        "valve_command": {"value": cfg.p("valve.command_limit"), "unit": "V", "meaning": "command limit"},
        "pressure_a": {"value": ps, "unit": "Pa", "meaning": "supply pressure (abs)"},
        "pressure_b": {"value": ps, "unit": "Pa", "meaning": "supply pressure (abs)"},
        "supply_pressure": {"value": ps, "unit": "Pa", "meaning": "supply pressure (abs)"},
    }


# ----------------------------------------------------------------------------------- windows
def derive_windows(time, reference, transient_duration: float, stroke: float) -> list[ErrorWindow]:
    """Steady and transient windows of a test, from its recorded set-point.

    A set-point change (a step, a ramp, a sinusoid) opens a transient window that lasts until
    ``transient_duration`` after the change ends; the rest until the next change is steady.
    Changes closer than ``transient_duration`` form one episode. Without a reference (or a
    constant one) the whole recording is one steady window.

    Parameters
    ----------
    time, reference : ndarray
        [s], [m].
    transient_duration : float
        [s].
    stroke : float
        [m]; set-point changes smaller than 1e-6 of it per sample are ignored (rounding).
    """
    t = np.asarray(time, dtype=float)
    t0, t1 = float(t[0]), float(t[-1])
    if reference is None:
        return [ErrorWindow("whole recording", t0, t1, "steady")]
    r = np.asarray(reference, dtype=float)
    change = np.flatnonzero(np.abs(np.diff(r)) > 1e-6 * stroke) + 1  # the new value holds from t[i]
    if change.size == 0:
        return [ErrorWindow("whole recording", t0, t1, "steady")]
    episodes: list[list[int]] = []
    for i in change:
        if episodes and t[i] - t[episodes[-1][1]] < transient_duration:
            episodes[-1][1] = int(i)
        else:
            episodes.append([int(i), int(i)])
    out: list[ErrorWindow] = []
    cursor = t0
    for k, (a, b) in enumerate(episodes):
        ta, tb = float(t[a]), float(t[b])
        nxt = float(t[episodes[k + 1][0]]) if k + 1 < len(episodes) else t1
        if ta > cursor:
            out.append(ErrorWindow("initial hold" if not out else f"settled {cursor:.2f}-{ta:.2f} s", cursor, ta, "steady"))
        tr_end = min(tb + transient_duration, nxt, t1)
        if a == b:
            name = f"step {(r[a] - r[a - 1]) * 1e3:+.1f} mm at {ta:.2f} s"
        else:
            name = f"tracking {ta:.2f}-{tb:.2f} s"
        if tr_end > ta:
            out.append(ErrorWindow(name, ta, tr_end, "transient"))
        cursor = tr_end
    if t1 > cursor:
        out.append(ErrorWindow(f"settled {cursor:.2f}-{t1:.2f} s", cursor, t1, "steady"))
    return out


def window_mask(time: np.ndarray, window: ErrorWindow) -> np.ndarray:
    """Samples of ``window``: start <= t < end (t <= end for a window ending at the last sample)."""
    t = np.asarray(time, dtype=float)
    last = window.end >= t[-1]
    return (t >= window.start) & ((t <= window.end) if last else (t < window.end))


def filtered_error(time, error, cutoff: float) -> np.ndarray:
    """Zero-phase 2nd-order Butterworth low-pass of an error signal (``cutoff`` [Hz]; 0: unchanged).

    Non-uniform recordings are filtered on their median step and interpolated back.
    """
    t = np.asarray(time, dtype=float)
    e = np.asarray(error, dtype=float)
    if cutoff <= 0 or e.size < 16:
        return e
    uniform = is_uniform(t)
    dt = float(np.median(np.diff(t)))
    nyq = 0.5 / dt
    if cutoff >= nyq:
        return e
    b, a = butter(2, cutoff / nyq)
    if uniform:
        return filtfilt(b, a, e)
    grid = t[0] + dt * np.arange(int((t[-1] - t[0]) / dt) + 1)
    return np.interp(t, grid, filtfilt(b, a, np.interp(grid, t, e)))


def error_measures(error_pu: np.ndarray) -> dict:
    """MXE, ME and MAE of a per-unit error [pu] (None for an empty window)."""
    e = np.asarray(error_pu, dtype=float)
    if e.size == 0:
        return {"max_error": None, "mean_error": None, "mean_absolute_error": None}
    return {"max_error": float(np.max(np.abs(e))), "mean_error": float(np.mean(e)), "mean_absolute_error": float(np.mean(np.abs(e)))}


def assess(measures: dict, limits: ErrorLimits | None) -> tuple[bool, list[str]]:
    """Compare error measures with their limits.

    Returns
    -------
    (bool, list of str)
        True when every assessed measure is within its limit (|ME| for the mean error), and
        the names of the measures that are not.
    """
    if limits is None:
        return True, []
    failed = []
    for m in MEASURES:
        lim = getattr(limits, m)
        val = measures.get(m)
        if lim is None or val is None:
            continue
        if abs(val) > lim:
            failed.append(m)
    return not failed, failed


def window_metrics(time, recorded: dict, simulated: dict, bases: dict, windows: list[ErrorWindow], settings: MetricSettings) -> list[dict]:
    """Fit and windowed error measures for every window and signal.

    Parameters
    ----------
    time : ndarray
        [s].
    recorded, simulated : dict
        signal -> ndarray (SI); the signals compared.
    bases : dict
        signal -> per-unit base (SI float).
    windows : list of ErrorWindow
    settings : MetricSettings

    Returns
    -------
    list of dict
        One row per (window, signal): ``window``, ``kind``, ``start``, ``end``, ``signal``,
        ``fit_percent``, ``max_error``, ``mean_error``, ``mean_absolute_error`` [pu],
        ``limits``, ``pass``, ``failed``.
    """
    t = np.asarray(time, dtype=float)
    rows = []
    filt = {}
    for sig in recorded:
        e_pu = (np.asarray(recorded[sig], dtype=float) - np.asarray(simulated[sig], dtype=float)) / bases[sig]
        filt[sig] = filtered_error(t, e_pu, settings.error_filter_cutoff)
    for w in windows:
        m = window_mask(t, w)
        for sig in recorded:
            meas = error_measures(filt[sig][m])
            lim = settings.limits.get((sig, w.kind))
            ok, failed = assess(meas, lim)
            y = np.asarray(recorded[sig], dtype=float)[m]
            yh = np.asarray(simulated[sig], dtype=float)[m]
            rows.append({
                "window": w.name, "kind": w.kind, "start": w.start, "end": w.end, "signal": sig,
                "samples": int(np.count_nonzero(m)),
                "fit_percent": fit_percent(y, yh) if y.size else None,
                **meas,
                "limits": lim.as_dict() if lim else None,
                "pass": ok, "failed": failed,
            })
    return rows
