"""Noise floors of recorded signals: how close a correct model can come to a recording.

Each residual the diagnosis fits is divided by its signal's noise floor, so a correct model
leaves normalised residuals of about one on every signal and the signals weigh equally.

- Measured signals (pressures, position): the sensor noise, estimated robustly (median
  absolute deviation) from what a Savitzky-Golay smoother leaves, corrected for the share of
  white noise the smoother itself keeps (Savitzky & Golay 1964; the residual of white noise
  after a linear smoother h has variance sigma^2 * (1 - 2 h_0 + sum h^2)).
- What a correct model's replay leaves on top (the error of the injected noise estimate, the
  states read at re-synchronisations, stall points): ``residuals.null_replay_floors``.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import savgol_coeffs, savgol_filter

POSITION_WINDOW = 41  # samples: the smoother that separates position noise from motion (1 kHz: 41 ms)
POSITION_ORDER = 3
SIGNAL_WINDOW = 21
SIGNAL_ORDER = 2
MAD_TO_STD = 1.4826  # normal distribution: std = 1.4826 * MAD


def _window(n: int, window: int, order: int) -> int:
    w = min(window, n if n % 2 == 1 else n - 1)
    return max(w, order + 2 if (order + 2) % 2 == 1 else order + 3)


def smoother_keep_factor(window: int, order: int) -> float:
    """Variance share of white noise left in x - S x by a Savitzky-Golay smoother S [-]."""
    h = savgol_coeffs(window, order)
    h0 = h[window // 2]
    return float(1.0 - 2.0 * h0 + np.sum(h * h))


def position_noise_estimate(position: np.ndarray) -> np.ndarray:
    """The recording's position noise as the part the smoother does not keep [m]."""
    x = np.asarray(position, dtype=float)
    if x.size < POSITION_ORDER + 3:
        return np.zeros_like(x)
    w = _window(x.size, POSITION_WINDOW, POSITION_ORDER)
    return np.ascontiguousarray(x - savgol_filter(x, w, POSITION_ORDER))


def sensor_noise_std(values: np.ndarray, window: int = SIGNAL_WINDOW, order: int = SIGNAL_ORDER) -> float:
    """Robust estimate of the white sensor noise on a recorded signal [signal unit].

    Parameters
    ----------
    values : ndarray
        Recorded signal (uniform sampling).
    window, order : int
        Savitzky-Golay smoother separating noise from the signal.

    Returns
    -------
    float
        Standard deviation of the noise; transients barely move it (median absolute deviation).
    """
    x = np.asarray(values, dtype=float)
    if x.size < order + 3:
        return 0.0
    w = _window(x.size, window, order)
    r = x - savgol_filter(x, w, order)
    mad = float(np.median(np.abs(r - np.median(r))))
    std = MAD_TO_STD * mad / np.sqrt(smoother_keep_factor(w, order))
    if std == 0.0:  # heavily quantised, noise-free signal: quantisation noise q/sqrt(12)
        steps = np.abs(np.diff(x))
        steps = steps[steps > 0]
        if steps.size:
            std = float(np.min(steps)) / np.sqrt(12.0)
    return float(std)
