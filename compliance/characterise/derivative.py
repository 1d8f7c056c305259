"""Smoothed derivatives of sampled signals: a Savitzky-Golay filter on the actual sample times.

Savitzky & Golay (1964): at each sample a polynomial of low order is fitted by least squares
to the ``window`` samples around it and differentiated at that sample. On a uniform grid this
is exactly ``scipy.signal.savgol_filter(..., deriv=1, mode="interp")``; here the polynomial is
fitted in the real sample times, so loggers with jitter (the Zillen bench logs at 10-11 ms)
need no resampling. Near the ends the window is shifted inwards, as ``mode="interp"`` does.
"""

from __future__ import annotations

import numpy as np

from compliance.errors import InputError


def odd_window(samples: float, order: int) -> int:
    """Smallest odd window of at least ``samples`` and at least ``order + 2`` samples."""
    w = max(int(np.ceil(samples)), order + 2)
    return w if w % 2 == 1 else w + 1


def savgol_weights(time, window: int, order: int = 2):
    """Savitzky-Golay weights on the actual sample times.

    Parameters
    ----------
    time : array_like
        Strictly increasing sample times [s].
    window : int
        Odd number of samples in each local fit (> ``order``).
    order : int
        Polynomial order.

    Returns
    -------
    (idx, w_value, w_deriv)
        ``idx`` (n, window) sample indexes of each local fit; the smoothed value at sample i
        is ``sum(w_value[i] * y[idx[i]])`` and its derivative ``sum(w_deriv[i] * y[idx[i]])``
        [1/s].
    """
    t = np.asarray(time, dtype=float)
    n = t.size
    if window % 2 == 0 or window <= order:
        raise InputError(f"derivative window must be odd and larger than the order {order}, got {window}")
    if n < window:
        raise InputError(f"need at least {window} samples for the derivative window, have {n}")
    half = window // 2
    start = np.clip(np.arange(n) - half, 0, n - window)
    idx = start[:, None] + np.arange(window)[None, :]
    steps = np.diff(t)
    if n > window and np.ptp(steps) <= 1e-9 * np.median(steps):
        # uniform grid: interior rows share one set of weights; only the edges differ
        small_value, small_deriv = _weights(t[:window], np.arange(window)[None, :].repeat(window, 0), order, half)
        row = np.clip(np.arange(n), None, half) + np.clip(np.arange(n) - (n - 1 - half), 0, None)
        return idx, small_value[row], small_deriv[row]
    return (idx, *_weights(t, idx, order, half))


def _weights(t, idx, order, half):
    n = t.size
    scale = (t[-1] - t[0]) / (n - 1) * max(half, 1)  # conditions the Vandermonde matrix
    tau = (t[idx] - t[:, None]) / scale
    vander = np.empty(tau.shape + (order + 1,))
    vander[..., 0] = 1.0
    for k in range(1, order + 1):
        vander[..., k] = vander[..., k - 1] * tau
    normal = np.einsum("nwk,nwl->nkl", vander, vander)
    first_two = np.linalg.solve(normal, np.transpose(vander, (0, 2, 1)))[:, :2, :]  # (n, 2, window)
    return first_two[:, 0, :], first_two[:, 1, :] / scale


def smoothed_derivative(time, values, window: int, order: int = 2):
    """Local least-squares polynomial value and first derivative at every sample.

    Parameters
    ----------
    time : array_like
        Strictly increasing sample times [s].
    values : array_like
        Signal samples [any unit U].
    window : int
        Odd number of samples in each local fit (> ``order``).
    order : int
        Polynomial order (2 or 3 are usual).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Smoothed values [U] and derivative [U/s].
    """
    y = np.asarray(values, dtype=float)
    idx, w_value, w_deriv = savgol_weights(time, window, order)
    local = y[idx]
    return np.sum(w_value * local, axis=1), np.sum(w_deriv * local, axis=1)


def noise_std(time, values, window: int, order: int = 2, weights=None) -> float:
    """White-noise standard deviation of ``values`` estimated from the smoothing residual [U].

    For a least-squares smoother the residual of sample i has variance sigma^2 (1 - h_ii),
    h_ii the weight of the sample on itself, so sigma^2 = mean(r^2) / (1 - mean(h_ii)).
    Slow drifts the polynomial follows do not count as noise. ``weights``: the output of
    ``savgol_weights`` for the same times, window and order, if already computed.
    """
    y = np.asarray(values, dtype=float)
    idx, w_value, _ = weights if weights is not None else savgol_weights(time, window, order)
    resid = y - np.sum(w_value * y[idx], axis=1)
    own = w_value[np.arange(y.size), np.arange(y.size) - idx[:, 0]]
    return float(np.sqrt(np.mean(resid**2) / max(1.0 - np.mean(own), 1e-12)))
