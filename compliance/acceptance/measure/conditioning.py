"""A recorded trace made ready for the metrics: its noise floor, resolution, rate, filter, and a smoothed position.

The metrics (``compliance.metrics``) are the simulation's; a recording differs from a simulated
trace by what its instruments add. This module measures that from the recording itself, with the
one noise-floor module (``validation.recorded_noise``):

- the position's sensor noise (robust, never below the quantisation q / sqrt(12)) and its
  resolution (declared in ``[channels.position]`` or the lattice the values sit on);
- the logger's sample interval and its first-order anti-alias filter, whose lag at low
  frequency is a delay of 1 / (2 pi f_c) (``validation.logger_model``);
- a conditioned position: a cubic Savitzky-Golay smoother over ``NOISE_SMOOTHING`` (31 ms), the
  window the noise floor uses to separate sensor noise from motion. It keeps a cubic motion over
  the window exactly and leaves white noise of standard deviation sigma * sqrt(sum h^2) (h its
  coefficients; Savitzky & Golay 1964), which is the standard uncertainty of one conditioned sample.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.signal import savgol_coeffs, savgol_filter

from compliance.errors import InputError
from compliance.validation.recorded_noise import (NOISE_SMOOTHING, position_noise_estimate, position_quantum, robust_std,
                                                 sensor_noise_std)
from compliance.validation.resampling import is_uniform, resample_uniform

__all__ = ["Conditioned", "condition", "MIN_SMOOTHING_SAMPLES"]

SMOOTHING_ORDER = 3
MIN_SMOOTHING_SAMPLES = 7  # a cubic smoother over fewer samples barely averages: the trace is used as logged
NOISE_WINDOW = 0.021  # s; the noise estimate's smoother (recorded_noise.SIGNAL_WINDOW samples at 1 kHz)


@dataclass(frozen=True)
class Conditioned:
    """A recording on an even time base with its position conditioned and its instruments measured (SI)."""

    time: np.ndarray  # [s], even
    position: np.ndarray  # conditioned (smoothed) position [m]
    raw: np.ndarray  # position as logged [m]
    columns: dict  # every other canonical column on the same time base
    dt: float  # sample interval [s]
    sigma: float  # sensor noise of the logged position (standard deviation) [m]
    resolution: float  # position quantum [m] (0: none found)
    u_position: float  # standard uncertainty of one conditioned sample [m]
    window: float  # smoother span [s] (0: none)
    filter_delay: float  # lag of the logger's anti-alias filter at low frequency [s] (0: none)
    resampled: bool  # the logged time base was uneven and was interpolated onto an even one

    def column(self, name: str) -> np.ndarray | None:
        """Another canonical column on the conditioned time base, or None when not logged."""
        return self.columns.get(name)

    @property
    def rate(self) -> float:
        """Sample rate [Hz]."""
        return 1.0 / self.dt

    def instruments(self) -> dict:
        """What the instruments are, as a report lists them (SI)."""
        return {"rate": self.rate, "sample_interval": self.dt, "position_noise": self.sigma,
                "position_resolution": self.resolution, "conditioned_uncertainty": self.u_position,
                "smoothing_window": self.window, "filter_delay": self.filter_delay, "resampled": self.resampled}


def _cutoff(metadata: dict) -> float | None:
    channel = ((metadata.get("channels") or {}).get("position") or {})
    value = channel.get("anti_alias_cutoff") or (metadata.get("logger") or {}).get("anti_alias_cutoff")
    return float(value) if isinstance(value, (int, float)) and value > 0 else None


def _resolution(metadata: dict, position: np.ndarray) -> float:
    declared = ((metadata.get("channels") or {}).get("position") or {}).get("resolution")
    if isinstance(declared, (int, float)) and declared > 0:
        return float(declared)
    return position_quantum(position)


def condition(frame, metadata: dict | None, where: str, *, noise_free: bool = False) -> Conditioned:
    """Measure the instruments of a recording and condition its position.

    Parameters
    ----------
    frame : pandas.DataFrame
        ``read_recording`` output (``time`` [s], ``position`` [m], other canonical columns).
    metadata : dict or None
        Its metadata (``logger``, ``channels``).
    where : str
        The recording, for messages.
    noise_free : bool
        A simulated trace (a prediction): no noise to measure, nothing to smooth.

    Raises
    ------
    InputError
        Fewer than ``MIN_SMOOTHING_SAMPLES`` samples.
    """
    metadata = metadata or {}
    t = frame["time"].to_numpy(dtype=float)
    if t.size < MIN_SMOOTHING_SAMPLES:
        raise InputError(f"{where}: {t.size} samples; a test needs at least {MIN_SMOOTHING_SAMPLES}")
    uneven = not is_uniform(t)
    cols = {}
    for name in frame.columns:
        if name == "time":
            continue
        v = frame[name].to_numpy(dtype=float)
        cols[name] = resample_uniform(t, v)[1] if uneven else v
    grid = resample_uniform(t, t)[0] if uneven else t
    dt = float(np.median(np.diff(grid)))
    raw = cols.pop("position")
    if noise_free:
        return Conditioned(grid, raw, raw, cols, dt, 0.0, 0.0, 0.0, 0.0, 0.0, uneven)
    resolution = _resolution(metadata, raw)
    noise_samples = int(round(NOISE_WINDOW / dt)) | 1
    sigma = sensor_noise_std(raw, max(noise_samples, 5), resolution=resolution)
    n = int(round(NOISE_SMOOTHING / dt)) | 1
    if n >= MIN_SMOOTHING_SAMPLES and raw.size > n:
        smooth = savgol_filter(raw, n, SMOOTHING_ORDER)
        keep = math.sqrt(float(np.sum(savgol_coeffs(n, SMOOTHING_ORDER) ** 2)))
        window = n * dt
        # the noise the smoother leaves, measured: a logger's anti-alias filter correlates the noise, which a
        # smoother then averages less than white noise (the noise realisation of recorded_noise, smoothed alike)
        left = robust_std(savgol_filter(position_noise_estimate(raw, dt), n, SMOOTHING_ORDER))
    else:
        smooth, keep, window, left = raw.copy(), 1.0, 0.0, 0.0
    fc = _cutoff(metadata)
    delay = 1.0 / (2.0 * math.pi * fc) if fc else 0.0
    return Conditioned(grid, smooth, raw, cols, dt, sigma, resolution, max(sigma * keep, left), window, delay, uneven)
