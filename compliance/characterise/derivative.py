"""Smoothed derivatives of sampled signals: a Savitzky-Golay filter on the actual sample times.

Savitzky & Golay (1964): at each sample a polynomial of low order is fitted by least squares
to the ``window`` samples around it and differentiated at that sample. On a uniform grid this
is exactly ``scipy.signal.savgol_filter(..., deriv=1, mode="interp")``; here the polynomial is
fitted in the real sample times, so loggers with jitter (the Zillen bench logs at 10-11 ms)
need no resampling. Near the ends the window is shifted inwards, as ``mode="interp"`` does.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError


def odd_window(samples: float, order: int) -> int:
    """Smallest odd window of at least ``samples`` and at least ``order + 2`` samples."""
    w = max(int(np.ceil(samples)), order + 2)
    return w if w % 2 == 1 else w + 1


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
    t = np.asarray(time, dtype=float)
    y = np.asarray(values, dtype=float)
    n = t.size
    if window % 2 == 0 or window <= order:
        raise InputError(f"derivative window must be odd and larger than the order {order}, got {window}")
    if n < window:
        raise InputError(f"need at least {window} samples for the derivative window, have {n}")
    half = window // 2
    start = np.clip(np.arange(n) - half, 0, n - window)
    idx = start[:, None] + np.arange(window)[None, :]
    scale = (t[-1] - t[0]) / (n - 1) * max(half, 1)  # conditions the Vandermonde matrix
    tau = (t[idx] - t[:, None]) / scale
    vander = tau[:, :, None] ** np.arange(order + 1)[None, None, :]
    normal = np.einsum("nwk,nwl->nkl", vander, vander)
    rhs = np.einsum("nwk,nw->nk", vander, y[idx])
    coef = np.linalg.solve(normal, rhs[..., None])[..., 0]
    return coef[:, 0], coef[:, 1] / scale
