"""The sensor noise a recording carries: its quantum and quantisation noise, its noise realisation, a robust spread.

A closed-loop replay feeds the recording's own position noise to the simulated sensor, so the
model's controller sees the same noise-driven crossings of the valve dead band as the real one.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import savgol_filter

NOISE_SMOOTHING = 0.031  # s; Savitzky-Golay window that separates sensor noise from motion
NOISE_FREE_STD = 1e-7  # m; below 0.1 um (finer than any position transducer) a recording counts as noise-free


def position_quantum(position: np.ndarray) -> float:
    """Quantisation step of a recorded position [m] (0 when the values are not on a grid).

    The step is the smallest positive difference between distinct values; it is accepted when
    every value lies on its grid to 1e-3 of a step.
    """
    u = np.unique(np.asarray(position, dtype=float))
    if u.size < 3:
        return 0.0
    q = float(np.min(np.diff(u)))
    if not q > 0:
        return 0.0
    k = u / q
    if np.max(np.abs(k - np.round(k))) > 1e-3 or np.any(np.abs(k) > 1e12):
        return 0.0
    return q


def quantisation_std(values: np.ndarray, resolution: float = 0.0) -> float:
    """Standard deviation of uniform quantisation, q / sqrt(12) [signal unit] (Widrow & Kollar 2008).

    ``q`` is the declared ``resolution`` when given (> 0), else the lattice the values sit on
    (``position_quantum``; 0 when they sit on none). A noise floor is never below it: with a
    coarse transducer (50 um against 20 um of noise) most sample-to-sample differences are zero
    and a difference- or median-based noise estimate collapses, while a model can match the
    reading no closer than the quantisation.
    """
    q = float(resolution) if resolution and resolution > 0 else position_quantum(values)
    return q / np.sqrt(12.0)


def estimate_position_noise(position: np.ndarray, sample_time: float) -> np.ndarray:
    """Sensor noise realisation of a position recorded at the controller rate [m].

    The recording minus its Savitzky-Golay smoothing (cubic, ``NOISE_SMOOTHING`` window): the
    servo's motion (time constants >= 0.1 s) passes the smoother, white sensor noise does not.
    """
    x = np.asarray(position, dtype=float)
    w = int(round(NOISE_SMOOTHING / sample_time)) | 1
    if x.size <= w or w < 5:
        return np.zeros_like(x)
    return x - savgol_filter(x, w, 3)


def robust_std(values: np.ndarray) -> float:
    """Standard deviation of Gaussian noise from the median absolute deviation (1.4826 * MAD)."""
    v = np.asarray(values, dtype=float)
    return float(1.4826 * np.median(np.abs(v - np.median(v)))) if v.size else 0.0
