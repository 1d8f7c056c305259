"""Which measured figure a requirement judges, as its file reads the requirement, and the test's own limits on it.

A requirement names a metric of the catalogue; the acceptance measures the same metric on the
site's recordings (``measure``), so the figure it judges is the one of that name. Two things the
test as run can still say: a hold whose window is shorter than the procedure's measurement window
cannot give that drift; a test that does not produce the metric at all (an opening stroke for a
closing time) is no case of the requirement.
"""

from __future__ import annotations

from compliance.acceptance.measure.uncertainty import Measured, missing

__all__ = ["measured_key", "row_value"]

HOLD_METRICS = ("drift", "max_positioning_error", "steady_state_error", "limit_cycle_amplitude")


def measured_key(req) -> str:
    """The name of the measured figure a requirement judges: its metric, read as its file says.

    A stroke time read end to end (``timing = "end_to_end"``, as an option or a field of the
    requirement) is the command-to-end-of-travel time of ``metrics.stroke.stroke_timing``
    (``time_to_end``); the 25-75 % reading (``full_rate``, the default) is the metric itself. Every
    other metric names its figure directly (a step's ``time_constant_achieved`` beside its
    ``time_constant``, a stroke's ``start_delay``).
    """
    timing = (req.options or {}).get("timing", getattr(req, "timing", None))
    timing = getattr(timing, "text", timing)
    if req.metric in ("opening_time", "closing_time") and timing == "end_to_end":
        return "time_to_end"
    return req.metric


def row_value(req, proc, case, key: str) -> Measured | None:
    """The figure of ``key`` a case gives for ``req`` at procedure ``proc``, or None when the case does not produce it."""
    if case.problem:
        return missing(case.problem)
    if key not in case.values:
        return None
    m = case.values[key]
    if proc.kind == "hold" and key in HOLD_METRICS and m.value is not None:
        asked = proc.settings["duration"].value - proc.settings["settle"].value
        ran = float(case.conditions.get("duration") or 0.0)
        if ran < asked * (1.0 - 1e-6):
            return missing(f"the hold window is {ran:.1f} s, shorter than the {asked:g} s window the procedure "
                           f"'{proc.name}' asks (duration {proc.settings['duration'].text} less settle "
                           f"{proc.settings['settle'].text}): the log cannot support this {key.replace('_', ' ')}")
    return m
