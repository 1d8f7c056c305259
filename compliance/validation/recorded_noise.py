"""The noise a recording carries: the one noise-floor module (how close a correct model can come to a recording).

- the spread of Gaussian noise from the median absolute deviation (:func:`robust_std`,
  ``MAD_TO_STD``), on which every estimate below rests;
- the quantum of a transducer and its quantisation noise q / sqrt(12), below which no floor goes;
- the validation's floor from first differences over the samples at rest (:func:`noise_floor`):
  for white noise of standard deviation sigma, successive differences have sigma * sqrt(2);
- the diagnosis's floor from what a Savitzky-Golay smoother leaves (:func:`sensor_noise_std`),
  corrected for the share of white noise the smoother itself keeps (Savitzky & Golay 1964; the
  residual of white noise after a linear smoother h has variance sigma^2 * (1 - 2 h_0 + sum h^2));
- the recording's position noise realisation, fed to the simulated sensor of a closed-loop
  replay so the model's controller sees the same noise-driven crossings of the valve dead band
  (:func:`position_noise_estimate`, with its hold detection; :func:`replay_noise` on the
  controller's clock, readings drawn between a slower logger's samples).

Validation and diagnosis replay a recording with the same noise (``validation.replay``). What a
correct model's replay leaves on top of the sensor noise is the diagnosis's
(``diagnosis.evidence.residuals.null_replay_floors``).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.signal import savgol_coeffs, savgol_filter

# m; a recording whose position noise estimate spreads less than 1 um counts as noise-free: a gate servo's transducer
# over a 100-400 mm stroke scatters more (the practice recordings: 20 um), while what the 41 ms cubic smoother of
# ``position_noise_estimate`` leaves of a noise-free step response is 0.1-0.3 um (our choice)
NOISE_FREE_STD = 1e-6
NOISE_SMOOTHING = 0.031  # s; cubic Savitzky-Golay window a measured position is conditioned with (acceptance.measure)
MAD_TO_STD = 1.4826  # normal distribution: std = 1.4826 * MAD (1 / the 75 % quantile of the standard normal)
MIN_REST_SAMPLES = 200  # consecutive pairs at rest for the difference floor to use only those


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


def robust_std(values: np.ndarray) -> float:
    """Standard deviation of Gaussian noise from the median absolute deviation (``MAD_TO_STD`` * MAD)."""
    v = np.asarray(values, dtype=float)
    return float(MAD_TO_STD * np.median(np.abs(v - np.median(v)))) if v.size else 0.0


def noise_floor(values: np.ndarray, rest: np.ndarray | None = None, minimum: float = 0.0, resolution: float = 0.0) -> float:
    """Noise standard deviation of a recorded signal from its first differences (the validation's floor).

    Parameters
    ----------
    values : ndarray
        Recorded signal (SI).
    rest : ndarray of bool, optional
        Samples at rest; used when there are at least ``MIN_REST_SAMPLES`` consecutive pairs.
    minimum : float
        Lower bound of the result (SI).
    resolution : float
        Declared quantisation step (SI); 0: the lattice of the values, if any. The floor is never
        below its q / sqrt(12) (:func:`quantisation_std`).
    """
    y = np.asarray(values, dtype=float)
    d = np.diff(y)
    if rest is not None:
        pair = np.asarray(rest[1:], dtype=bool) & np.asarray(rest[:-1], dtype=bool)
        if np.count_nonzero(pair) >= MIN_REST_SAMPLES:
            d = d[pair]
    q_std = quantisation_std(y, resolution)
    if d.size == 0:
        return max(float(minimum), q_std)
    sigma = robust_std(d) / math.sqrt(2.0)
    return max(sigma, float(minimum), q_std)


# --------------------------------------------------------------------------- the diagnosis's floors
POSITION_WINDOW = 41  # samples: the smoother that separates position noise from motion (1 kHz: 41 ms)
POSITION_ORDER = 3
HOLD_WINDOW = 301  # samples: while the servo holds, a smoother this long still follows the motion (1 kHz: 0.3 s) ...
HOLD_TOLERANCE = 2.0  # ... where what it removes beyond the short one stays within this multiple of noise alone
SIGNAL_WINDOW = 21
SIGNAL_ORDER = 2
QUANTISED_SHARE = 0.5  # quantisation std above this share of the MAD estimate: use the trimmed RMS
TRIM = 0.01  # share of the largest residuals (transients) left out of the trimmed RMS
TRIMMED_RMS = 0.9617  # RMS of a normal variable within its central 99 %, in standard deviations


def _window(n: int, window: int, order: int) -> int:
    w = min(window, n if n % 2 == 1 else n - 1)
    return max(w, order + 2 if (order + 2) % 2 == 1 else order + 3)


def smoother_keep_factor(window: int, order: int) -> float:
    """Variance share of white noise left in x - S x by a Savitzky-Golay smoother S [-]."""
    h = savgol_coeffs(window, order)
    h0 = h[window // 2]
    return float(1.0 - 2.0 * h0 + np.sum(h * h))


def _odd_samples(window: int, dt: float) -> int:
    """A window given in samples at 1 kHz, in samples at the step ``dt`` [s] (odd)."""
    return int(round(window * 1e-3 / dt)) | 1


def position_noise_estimate(position: np.ndarray, dt: float = 1e-3) -> np.ndarray:
    """The recording's position noise as the part a smoother does not keep [m].

    ``dt`` is the sample step [s]; the windows below are stated at 1 kHz and keep their length
    in seconds at other rates.

    The 41 ms smoother that follows a step keeps the noise below ~25 Hz, the band a spool or a
    dead band passes: a replayed controller fed only the rest crosses the dead band less often
    than the real one did, and the stall creep of a hold comes out wrong (on an independent
    valve-lag recording this pulled the fitted spool from 150 to 223 rad/s). Where the servo holds,
    a ``HOLD_WINDOW`` smoother still follows the motion, so there the noise is taken against it;
    a sample counts as holding when, over a whole long window around it, the two smoothers differ
    by no more than ``HOLD_TOLERANCE`` times what white noise alone makes them differ.
    """
    x = np.asarray(position, dtype=float)
    if x.size < POSITION_ORDER + 3:
        return np.zeros_like(x)
    w = _window(x.size, _odd_samples(POSITION_WINDOW, dt), POSITION_ORDER)
    short = savgol_filter(x, w, POSITION_ORDER)
    wl = _odd_samples(HOLD_WINDOW, dt)
    if x.size < 3 * wl:
        return np.ascontiguousarray(x - short)
    long = savgol_filter(x, wl, POSITION_ORDER)
    sigma = sensor_noise_std(x, w, POSITION_ORDER)
    h_short = np.zeros(wl)
    h_short[(wl - w) // 2:(wl + w) // 2] = savgol_coeffs(w, POSITION_ORDER)
    white = sigma * np.sqrt(np.sum((h_short - savgol_coeffs(wl, POSITION_ORDER)) ** 2))  # std of short - long, noise alone
    box = np.ones(wl)
    spread = np.sqrt(np.convolve((short - long) ** 2, box / wl, mode="same"))
    moving = (spread > HOLD_TOLERANCE * white).astype(float)
    holding = np.convolve(moving, box, mode="same") == 0.0  # no motion anywhere in the long window around
    return np.ascontiguousarray(np.where(holding, x - long, x - short))


def sensor_noise_std(values: np.ndarray, window: int = SIGNAL_WINDOW, order: int = SIGNAL_ORDER, resolution: float = 0.0) -> float:
    """Robust estimate of the white sensor noise on a recorded signal [signal unit].

    Parameters
    ----------
    values : ndarray
        Recorded signal (uniform sampling).
    window, order : int
        Savitzky-Golay smoother separating noise from the signal.
    resolution : float
        Declared quantisation step [signal unit]; 0: the lattice the values sit on, if any.

    Returns
    -------
    float
        Standard deviation of the noise; transients barely move it (median absolute deviation);
        never below the quantisation's q / sqrt(12) (:func:`quantisation_std`).
    """
    x = np.asarray(values, dtype=float)
    if x.size < order + 3:
        return 0.0
    w = _window(x.size, window, order)
    r = x - savgol_filter(x, w, order)
    keep = np.sqrt(smoother_keep_factor(w, order))
    std = robust_std(r) / keep
    q_std = quantisation_std(x, resolution)
    if q_std > QUANTISED_SHARE * std:
        # a coarse lattice (50 um against 20 um of noise): the residual takes a few values and its median
        # absolute deviation says little; the RMS of all but its largest TRIM share does not collapse
        a = np.abs(r - np.median(r))
        kept = a[a <= np.quantile(a, 1.0 - TRIM)]
        std = max(std, float(np.sqrt(np.mean(kept * kept))) / keep / TRIMMED_RMS)
    std = max(std, q_std)
    if std == 0.0:  # heavily quantised, noise-free signal: quantisation noise q/sqrt(12)
        steps = np.abs(np.diff(x))
        steps = steps[steps > 0]
        if steps.size:
            std = float(np.min(steps)) / np.sqrt(12.0)
    return float(std)


FILL_SEED = 20240  # seed of the readings drawn between a slow logger's samples (``replay_noise``)


def replay_noise(position: np.ndarray, logged: np.ndarray | None, ts: float, quantum: float = 0.0,
                 share: float = 1.0) -> np.ndarray:
    """The position noise the controller saw, on its clock, estimated where the logger sampled it [m].

    Parameters
    ----------
    position : ndarray
        Recorded position on the controller's clock [m] (interpolated between logged samples).
    logged : ndarray or None
        Controller periods that carry a logged sample (None: every one).
    ts : float
        Controller sample time [s].
    quantum : float
        The transducer's quantisation step [m] (0: none).
    share : float
        Share of white noise the logger's anti-alias filter passes (``LoggerModel.noise_share``; 1: no filter).

    On a log slower than the controller the noise is known only at the logged instants: it is
    estimated on those samples (smoother windows in seconds, not samples). Between them the
    controller saw other, independent readings: they are drawn (seeded, ``FILL_SEED``) with the
    noise level the logged samples show and quantised like the transducer. Interpolating instead
    would hand the replayed controller a smoother signal than the real one read: on a 250 Hz
    trend log of a valve-offset servo (50 um transducer) its derivative term then dithered the
    valve with 0.29 V instead of the recorded 0.35 V, and a 30 ms sensor lag fitted as well as
    the true offset; with drawn readings the replay dithers 0.35 V and the offset's 1 s mean
    command misfit falls from 0.08 V to 0.04 V. Behind an anti-alias filter (``share`` < 1) no
    logged sample is a reading the controller saw: every reading is drawn, at the logged noise
    level divided by ``share``.
    """
    if logged is None and share == 1.0:
        return position_noise_estimate(position)
    logged = np.arange(position.size) if logged is None else logged
    x = position[logged]
    est = position_noise_estimate(x, dt=float(np.median(np.diff(logged))) * ts)
    out = np.interp(np.arange(position.size), logged, est)
    between = np.ones(position.size, dtype=bool)
    if share == 1.0:
        between[logged] = False
    sigma = sensor_noise_std(x, resolution=quantum) / share
    sigma = float(np.sqrt(max(sigma * sigma - quantum * quantum / 12.0, 0.0)))  # the noise beyond the quantisation
    base = position[between] - out[between]  # the interpolated reading without noise
    draw = base + np.random.default_rng(FILL_SEED).normal(0.0, sigma, int(between.sum()))
    out[between] = (np.round(draw / quantum) * quantum if quantum > 0 else draw) - base
    return out
