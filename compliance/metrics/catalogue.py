"""The metric catalogue: every metric a requirement may name, its units and its options.

One declaration per metric (SI unit, display unit, the procedure kinds that produce it,
what it means, the options a requirement may give it). Requirement files are validated
against it, the harness formats values with it and the report explains metrics from it.
Plant B's path-tracking metrics (seed 001) are declared here too.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["CHOICE_OPTIONS", "METRICS", "STEP_OPTION_DEFAULTS", "MetricInfo", "option_value"]


@dataclass(frozen=True)
class MetricInfo:
    """Declaration of one metric: SI unit, display unit, which procedure kinds produce it."""

    name: str
    si_unit: str  # "" = dimensionless fraction
    display_unit: str
    display_scale: float  # display value = SI value * display_scale
    kinds: tuple[str, ...]
    meaning: str
    options: tuple[str, ...] = ()


_SETTLE_OPTS = ("settling_band", "settling_band_abs", "final_window")

METRICS: dict[str, MetricInfo] = {
    m.name: m
    for m in (
        MetricInfo("dead_time", "s", "s", 1.0, ("steps",), "command step to first detectable motion", ("detect",)),
        MetricInfo(
            "time_constant", "s", "s", 1.0, ("steps",),
            "end of dead time to 63.2 % of the travel (achieved, or the commanded step), first step from rest, "
            "steps no limiting device acts on",
            ("detect", "travel"),
        ),
        MetricInfo("rise_time", "s", "s", 1.0, ("steps",), "10 % to 90 % of the actual change", ("final_window",)),
        MetricInfo("settling_time", "s", "s", 1.0, ("steps",), "step to last exit from the settling band", _SETTLE_OPTS),
        MetricInfo("overshoot", "", "%", 100.0, ("steps",), "peak beyond the final value, per cent of the change", ("final_window",)),
        MetricInfo(
            "steady_state_error", "m", "mm", 1e3, ("steps", "hold"),
            "|reference - mean position| over the final window", ("final_window",),
        ),
        MetricInfo(
            "max_positioning_error", "m", "mm", 1e3, ("steps", "hold"),
            "max |reference - position| over the final (settled) windows", ("final_window",),
        ),
        MetricInfo("tracking_rms_error", "m", "mm", 1e3, ("sine",), "RMS of reference - position after the skip"),
        MetricInfo("tracking_max_error", "m", "mm", 1e3, ("sine",), "max |reference - position| after the skip"),
        MetricInfo("dead_band", "m", "mm", 1e3, ("dead_band",), "width of the position/reference hysteresis loop"),
        MetricInfo("opening_time", "s", "s", 1.0, ("full_stroke",),
                   "full-stroke opening time, timed as the requirement's timing names", ("timing",)),
        MetricInfo("closing_time", "s", "s", 1.0, ("full_stroke",),
                   "full-stroke closing time, timed as the requirement's timing names", ("timing",)),
        MetricInfo("start_delay", "s", "s", 1.0, ("full_stroke",),
                   "full stroke: command to 1 % of the stroke travelled"),
        MetricInfo("time_to_end", "s", "s", 1.0, ("full_stroke",),
                   "full stroke: command to 99 % of the stroke travelled (the end stop)"),
        MetricInfo("cushion_time", "s", "s", 1.0, ("full_stroke",),
                   "full stroke: 90 % to 99 % of the stroke travelled (the approach to the end stop)"),
        MetricInfo(
            "stroke_speed", "m/s", "mm/s", 1e3, ("full_stroke",),
            "mean speed from 25 % to 75 % of a full stroke (the rate the speed setting sets; stroke / full-stroke time)",
        ),
        MetricInfo(
            "max_speed", "m/s", "mm/s", 1e3, ("steps", "sine", "full_stroke", "hold", "dead_band"),
            "max |dx/dt| over a centred 20 ms difference",
        ),
        MetricInfo(
            "max_opening_speed", "m/s", "mm/s", 1e3, ("steps", "sine", "full_stroke", "hold", "dead_band"),
            "max dx/dt (opening direction)",
        ),
        MetricInfo(
            "max_closing_speed", "m/s", "mm/s", 1e3, ("steps", "sine", "full_stroke", "hold", "dead_band"),
            "max -dx/dt (closing direction)",
        ),
        MetricInfo("limit_cycle_amplitude", "m", "mm", 1e3, ("hold",), "half peak-to-peak of the detrended position"),
        MetricInfo("drift", "m", "mm", 1e3, ("hold",), "|slope of a line fit| x window length"),
        MetricInfo(
            "saturation_fraction", "", "%", 100.0, ("steps", "sine", "hold", "dead_band"),
            "fraction of time |valve command| >= the valve's full-opening voltage",
        ),
        MetricInfo(
            "cross_adjustment_change", "", "%", 100.0, ("independent_adjustment",),
            "relative change of the other direction's full-stroke time when one flow-control valve is changed",
        ),
        MetricInfo(
            "adjusted_time_change", "", "%", 100.0, ("independent_adjustment",),
            "relative change of the adjusted direction's full-stroke time (shows the adjustment acts)",
        ),
    )
}

# options of the step metrics with defaults: name -> (SI unit, default text, meaning)
STEP_OPTION_DEFAULTS = {
    "settling_band": ("", "2 %", "half-width of the settling band, fraction of the actual change (step_info)"),
    "settling_band_abs": ("m", "0 mm", "lower bound on the band half-width (sensor resolution)"),
    "detect": ("m", "0 mm", "motion threshold for the dead time; 0 = max(1 % of the step, 5 x pre-step noise)"),
    "final_window": ("s", "0.5 s", "window before the next step over which the settled position is taken"),
}

# options that name a reading (a word from a fixed list, not a quantity): name -> (choices, default, meaning)
CHOICE_OPTIONS = {
    "timing": (("full_rate", "end_to_end", "extrapolated"), "full_rate",
               "how a full-stroke time is timed: full_rate = the stroke at the rate of its straight part (25-75 % "
               "extrapolated; a stroke with no straight part gets its end-to-end time, flagged); end_to_end = command to "
               "the end of travel, start delay included; extrapolated = 25-75 % extrapolated whatever the shape"),
    "travel": (("achieved", "commanded"), "achieved",
               "what 63.2 % of the time constant refers to: the travel the servo achieved (x_final - x0) or the "
               "commanded step"),
}


def option_value(options: dict, name: str) -> str:
    """The value of choice option ``name`` in a requirement's ``options`` (its default when not given)."""
    v = (options or {}).get(name)
    return CHOICE_OPTIONS[name][1] if v is None else str(getattr(v, "text", v))


# plant B (seed 001): path and axis tracking; kinds as in procedures.kinds.TRACKING / ROBOT_TRACKING
_ROBOT_TRACKING = ("circle_tracking", "helix_tracking", "stroke_tracking")
_TRACKING = ("axis_tracking",) + _ROBOT_TRACKING
_TRACKING_METRICS = {
    m.name: m
    for m in (
        MetricInfo("path_rms_error", "m", "mm", 1e3, _ROBOT_TRACKING,
                   "RMS distance of the tool point from the reference path (3-D contour error) over the motion"),
        MetricInfo("path_max_error", "m", "mm", 1e3, _ROBOT_TRACKING,
                   "max distance of the tool point from the reference path over the motion"),
        MetricInfo("axis_rms_error", "m", "mm", 1e3, _TRACKING, "RMS of reference - position of each axis over the motion"),
        MetricInfo("axis_max_error", "m", "mm", 1e3, _TRACKING, "max |reference - position| of each axis over the motion"),
        MetricInfo("stick_slip_episodes", "", "", 1.0, _TRACKING,
                   "stretches >= 10 ms where an axis's reference moves > 5 mm/s but the axis is stopped or reversed"),
        MetricInfo("stick_slip_fraction", "", "%", 100.0, _TRACKING,
                   "time an axis spends in stick-slip episodes / time its reference moves > 5 mm/s (each moving axis)"),
    )
}
METRICS.update(_TRACKING_METRICS)
