"""Reference (set-point) and command profiles: step sequences, ramps, sinusoids, recorded samples."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
from numba import njit

from compliance.errors import InputError
from compliance.units import parse_quantity
from compliance.units.amounts import parse_position


@dataclass(frozen=True)
class Profile:
    """A piecewise-linear signal of time, held at its end values outside its samples.

    Steps are two samples at the same instant (value before, value after).

    Attributes
    ----------
    times : numpy.ndarray
        Non-decreasing sample times [s].
    values : numpy.ndarray
        Values at those times (SI: m for a reference, V for a command).
    """

    times: np.ndarray
    values: np.ndarray

    def __post_init__(self):
        t = np.asarray(self.times, dtype=float)
        v = np.asarray(self.values, dtype=float)
        if t.ndim != 1 or t.shape != v.shape or t.size == 0:
            raise InputError("profile: times and values must be 1-D arrays of the same, non-zero length")
        if np.any(np.diff(t) < 0) or not np.all(np.isfinite(t)) or not np.all(np.isfinite(v)):
            raise InputError("profile: times must be finite and non-decreasing, values finite")
        object.__setattr__(self, "times", t)
        object.__setattr__(self, "values", v)

    def at(self, t) -> np.ndarray:
        """Sample the profile at times ``t``; a step at t_s takes its new value from t_s on."""
        t = np.asarray(t, dtype=float)
        out = np.empty(t.shape)
        piecewise_linear(self.times, self.values, t.ravel(), out.reshape(-1))
        return out

    @staticmethod
    def constant(value: float) -> "Profile":
        """A constant profile."""
        return Profile(np.array([0.0]), np.array([float(value)]))


@njit(cache=True, error_model="numpy")
def piecewise_linear(times, values, t, out):
    """Fill ``out[j]`` with the piecewise-linear signal (``times``, ``values``) at ``t[j]`` [s].

    Held at the end values outside the samples; at a double sample (a step) the later value holds
    from its instant on (the last sample at or before t starts the segment). ``t`` may come in any
    order; a non-decreasing ``t`` (a sample grid) walks the segments once.
    """
    m = times.shape[0]
    i = -1  # the last sample at or before t (-1: none), as numpy.searchsorted(times, t, "right") - 1
    for j in range(t.shape[0]):
        tj = t[j]
        if tj != tj:
            i = m - 1  # NaN sorts after every sample
        else:
            while i + 1 < m and times[i + 1] <= tj:
                i += 1
            while i >= 0 and times[i] > tj:
                i -= 1
        a = max(i, 0)
        b = min(a + 1, m - 1)
        t0 = times[a]
        t1 = times[b]
        w = 0.0
        if t1 > t0:
            w = min(max((tj - t0) / (t1 - t0), 0.0), 1.0)
        out[j] = values[0] if tj < times[0] else values[a] + w * (values[b] - values[a])


def steps(spec: str, x0: float, stroke: float, where: str = "--steps") -> Profile:
    """Step sequence from a spec such as ``"2%@1s,-2%@4s"`` or ``"5 mm@1 s"``.

    Each item is an increment (percent of stroke or a length) applied at a time; increments
    accumulate from the initial position ``x0`` [m].
    """
    times = [0.0]
    values = [x0]
    level = x0
    for item in [s for s in spec.split(",") if s.strip()]:
        if "@" not in item:
            raise InputError(f"{where}: item '{item.strip()}' must look like '2%@1s' (increment@time)")
        amount, when = item.split("@", 1)
        t = parse_quantity(when.strip(), "s", where)
        if t < times[-1]:
            raise InputError(f"{where}: step times must not go backwards ('{item.strip()}')")
        level += parse_position(amount, stroke, where, require_unit=False)
        if not 0.0 <= level <= stroke:
            raise InputError(f"{where}: step '{item.strip()}' takes the set-point to {level*1e3:.1f} mm, outside the stroke 0..{stroke*1e3:.0f} mm")
        times += [t, t]
        values += [values[-1], level]
    return Profile(np.array(times), np.array(values))


def sine(amplitude: float, frequency: float, x0: float, start: float = 0.0, duration: float = 60.0, points_per_period: int = 200) -> Profile:
    """Sinusoid x0 + A*sin(2*pi*f*(t - start)) from ``start`` for ``duration`` [m], seed 000 section 5."""
    if frequency <= 0 or amplitude < 0:
        raise InputError("sine: frequency must be > 0 and amplitude >= 0")
    n = max(int(duration * frequency * points_per_period), 2)
    t = start + np.linspace(0.0, duration, n + 1)
    v = x0 + amplitude * np.sin(2.0 * math.pi * frequency * (t - start))
    if start > 0:
        t = np.concatenate([[0.0], t])
        v = np.concatenate([[x0], v])
    return Profile(t, v)


def ramp(x0: float, x1: float, start: float, rate: float) -> Profile:
    """Ramp from ``x0`` to ``x1`` starting at ``start`` with speed ``rate`` [m/s]."""
    if rate <= 0:
        raise InputError("ramp: rate must be > 0")
    t1 = start + abs(x1 - x0) / rate
    return Profile(np.array([0.0, start, t1]), np.array([x0, x0, x1]))


def triangle(center: float, amplitude: float, period: float, cycles: int, start: float = 0.0) -> Profile:
    """Slow triangular wave about ``center`` (dead-band tests, IEC 60308)."""
    t = [0.0, start]
    v = [center, center]
    for k in range(cycles):
        t0 = start + k * period
        t += [t0 + period / 4, t0 + 3 * period / 4, t0 + period]
        v += [center + amplitude, center - amplitude, center]
    return Profile(np.array(t), np.array(v))


_SINE_RE = re.compile(r"^\s*([^,]+),\s*([^,]+?)\s*(?:,\s*([^,]+))?$")


def parse_sine(spec: str, x0: float, duration: float, where: str = "--sine") -> Profile:
    """Parse ``"8mm,0.05Hz"`` or ``"8mm,0.05Hz,2s"`` (amplitude, frequency, start)."""
    m = _SINE_RE.match(spec)
    if not m:
        raise InputError(f"{where}: expected 'AMPLITUDE,FREQUENCY[,START]', e.g. '8mm,0.05Hz'")
    amp = parse_quantity(m.group(1), "m", where)
    freq = parse_quantity(m.group(2), "Hz", where)
    start = parse_quantity(m.group(3), "s", where) if m.group(3) else 0.0
    return sine(amp, freq, x0, start=start, duration=max(duration - start, 1e-3))
