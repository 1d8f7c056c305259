"""Performance metrics of position traces: ONE implementation for simulated and recorded runs.

Every function takes plain arrays (``time`` [s], ``position`` [m], ``reference`` [m],
``valve_command`` [V]) so the same code measures a simulation DataFrame and a bench recording
(use :func:`frame_columns` to pull the canonical columns out of a DataFrame). The definitions
are written out in ``docs/metrics.md``; python-control's ``step_info`` conventions are matched
for rise time (10-90 % of the actual change), settling time (last exit from a band about the
final value) and overshoot (per cent of the actual change).

This module is the public face of the metrics; each family lives in its own module:

- :mod:`compliance.metric_catalogue`: ``METRICS`` (what a requirement may name), options;
- :mod:`compliance.trace_windows`: columns, time windows, level crossings;
- :mod:`compliance.speed_metrics`: speeds and valve-command saturation;
- :mod:`compliance.step_metrics`: step detection and step responses;
- :mod:`compliance.stroke_metrics`: full-stroke times, independent adjustment;
- :mod:`compliance.position_error_metrics`: tracking errors and holding a position;
- :mod:`compliance.dead_band_metrics`: the hysteresis-loop dead band.
"""

from __future__ import annotations

from .dead_band_metrics import DeadBandMetrics, dead_band
from .metric_catalogue import METRICS, STEP_OPTION_DEFAULTS, MetricInfo
from .position_error_metrics import HoldMetrics, hold, tracking_errors
from .speed_metrics import saturation_fraction, speed, speed_extremes
from .step_metrics import DETECT_FRACTION, TAU_FRACTION, StepEvent, StepMetrics, find_steps, step_response
from .stroke_metrics import independent_adjustment, stroke_time
from .trace_windows import frame_columns

# unused here: importable from this module before it was split, so kept for callers
from .errors import InputError  # noqa: F401

__all__ = [
    "DETECT_FRACTION",
    "METRICS",
    "STEP_OPTION_DEFAULTS",
    "TAU_FRACTION",
    "DeadBandMetrics",
    "HoldMetrics",
    "MetricInfo",
    "StepEvent",
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
    "stroke_time",
    "tracking_errors",
]
