"""Performance metrics of position traces: ONE implementation for simulated and recorded runs.

Every function takes plain arrays (``time`` [s], ``position`` [m], ``reference`` [m],
``valve_command`` [V]) so the same code measures a simulation DataFrame and a bench recording
(use :func:`frame_columns` to pull the canonical columns out of a DataFrame). The definitions
are written out in ``docs/metrics.md``; python-control's ``step_info`` conventions are matched
for rise time (10-90 % of the actual change), settling time (last exit from a band about the
final value) and overshoot (per cent of the actual change).

This module is the public face of the metrics; each family lives in its own module:

- :mod:`compliance.metrics.catalogue`: ``METRICS`` (what a requirement may name), options;
- :mod:`compliance.metrics.trace_windows`: columns, time windows, level crossings;
- :mod:`compliance.metrics.speed`: speeds and valve-command saturation;
- :mod:`compliance.metrics.step`: step detection and step responses;
- :mod:`compliance.metrics.step_eligibility`: which steps measure the time constant, and why not;
- :mod:`compliance.metrics.stroke`: full-stroke figures, stroke time by a named timing, independent adjustment;
- :mod:`compliance.metrics.position_error`: tracking errors and holding a position;
- :mod:`compliance.metrics.dead_band`: the hysteresis-loop dead band.
"""

from __future__ import annotations

from compliance.metrics.dead_band import DeadBandMetrics, dead_band
from compliance.metrics.catalogue import METRICS, STEP_OPTION_DEFAULTS, MetricInfo
from compliance.metrics.position_error import HoldMetrics, hold, tracking_errors
from compliance.metrics.speed import saturation_fraction, speed, speed_extremes
from compliance.metrics.step import DETECT_FRACTION, TAU_FRACTION, StepEvent, StepMetrics, find_steps, step_response
from compliance.metrics.step_eligibility import StepLimits, time_constant_eligibility, time_constant_value
from compliance.metrics.stroke import independent_adjustment, stroke_figures, stroke_time, stroke_timing, timed
from compliance.metrics.trace_windows import frame_columns

__all__ = [
    "DETECT_FRACTION",
    "METRICS",
    "STEP_OPTION_DEFAULTS",
    "TAU_FRACTION",
    "DeadBandMetrics",
    "HoldMetrics",
    "MetricInfo",
    "StepEvent",
    "StepLimits",
    "StepMetrics",
    "dead_band",
    "find_steps",
    "frame_columns",
    "hold",
    "independent_adjustment",
    "saturation_fraction",
    "speed",
    "speed_extremes",
    "step_response",
    "stroke_figures",
    "stroke_time",
    "stroke_timing",
    "time_constant_eligibility",
    "time_constant_value",
    "timed",
    "tracking_errors",
]
