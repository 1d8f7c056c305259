"""A measured value with its measurement uncertainty, and the crossing time of a noisy trace.

Every figure the acceptance takes from a recording carries an expanded uncertainty ``U``
(coverage factor ``K = 2``, about 95 % for a normal error; JCGM 100:2008 (GUM) 6.2), built from
the contributions the instruments make: the sensor noise left after conditioning, the
transducer's resolution, the sample interval and the logger's anti-alias filter. Each
contribution is kept by name (the budget) so a report can say what limits a measurement.

A crossing time is read where the conditioned trace crosses its level; its uncertainty is the
time the trace spends within ``K`` standard uncertainties of that level, which a slow or stalled
crossing (a stick phase right at the 63.2 % point) makes long and a brisk one short.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from compliance.metrics.trace_windows import crossing

__all__ = ["K", "Measured", "combine", "crossing_with_interval", "missing", "peak_bias", "sample_uncertainty"]

K = 2.0  # coverage factor of the expanded uncertainty


@dataclass(frozen=True)
class Measured:
    """A measured value [SI] with its expanded uncertainty ``u`` [SI, k = 2].

    ``value`` is None when the log cannot support the figure (``reason`` says why); a value that
    exists but does not measure what the requirement asks (a rate-limited time constant) has
    ``eligible`` False and the reason. ``budget`` maps each contribution to its expanded part [SI].
    """

    value: float | None
    u: float = 0.0
    reason: str | None = None
    eligible: bool = True
    budget: dict = field(default_factory=dict)

    @property
    def low(self) -> float | None:
        """Lower end of the interval ``value - u``."""
        return None if self.value is None else self.value - self.u

    @property
    def high(self) -> float | None:
        """Upper end of the interval ``value + u``."""
        return None if self.value is None else self.value + self.u

    def ineligible(self, reason: str) -> "Measured":
        """The same value, not eligible for a verdict, for ``reason``."""
        return Measured(self.value, self.u, reason, False, self.budget)

    def as_dict(self) -> dict:
        """Plain-JSON form."""
        return {"value": self.value, "u": self.u, "reason": self.reason, "eligible": self.eligible,
                "budget": dict(self.budget)}


def missing(reason: str) -> Measured:
    """A figure the log cannot support, with the reason."""
    return Measured(None, 0.0, reason, False)


def combine(value: float | None, budget: dict, reason: str | None = None) -> Measured:
    """A measured value whose expanded uncertainty is the root sum of squares of ``budget`` (expanded parts)."""
    if value is None or not math.isfinite(value):
        return missing(reason or "no value")
    parts = {k: float(v) for k, v in budget.items() if v is not None and math.isfinite(v) and v > 0.0}
    return Measured(float(value), math.sqrt(sum(v * v for v in parts.values())), reason, True, parts)


def sample_uncertainty(dt: float) -> float:
    """Expanded uncertainty of an instant known to lie within one sample interval ``dt`` [s] (uniform, k = 2)."""
    return K * dt / math.sqrt(12.0)


def peak_bias(sigma: float, span: float, correlation: float) -> float:
    """How far noise lifts the largest of a trace's values above the noise-free largest [signal unit].

    The maximum of ``n`` independent normal samples of standard deviation ``sigma`` lies about
    sigma * sqrt(2 ln n) above their mean (extreme-value theory; Cramer 1946); a conditioned trace
    over ``span`` [s] holds n = span / ``correlation`` independent samples (its smoother's span).
    """
    n = max(span / correlation, 1.0) if correlation > 0 else 1.0
    return sigma * math.sqrt(2.0 * math.log(n)) if n > 1.0 else 0.0


def crossing_with_interval(time, signal, level: float, u_level: float, start: int, direction: int):
    """Crossing time of ``level`` and its expanded uncertainty from the time spent near it.

    Parameters
    ----------
    time, signal : array
        The conditioned trace (``time`` [s] increasing).
    level : float
        The level [signal unit].
    u_level : float
        Standard uncertainty of the trace and the level combined [signal unit].
    start : int
        First sample searched.
    direction : {+1, -1}
        Rising or falling through the level.

    Returns
    -------
    (float or None, float)
        The crossing time [s] (linear interpolation, ``metrics.trace_windows.crossing``), and the
        largest distance from it to the crossings of ``level -/+ K u_level`` [s] (0 when none).
    """
    t = crossing(time, signal, level, start, direction)
    if t is None:
        return None, 0.0
    band = K * u_level
    t_in = crossing(time, signal, level - direction * band, start, direction)
    t_out = crossing(time, signal, level + direction * band, int(np.searchsorted(time, t)), direction)
    t_in = t if t_in is None else t_in
    t_out = float(time[-1]) if t_out is None else t_out
    return t, max(t - t_in, t_out - t, 0.0)
