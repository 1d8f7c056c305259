"""A recorded hold: the drift over the window and, when the loop held, the positioning error and limit cycle.

The servomotor drift test runs with the positioner in manual and the valve at null (IEC 60308:2024
servomotor tests; ASME PTC 29-2005 (R2020)): nothing then corrects a leak, so the position shows it.
A closed-loop hold hides the same leak behind the controller. The drift is the simulation's
(``metrics.position_error.hold`` on the conditioned position: |slope of the line fit| x window length), beside the largest
excursion from the start of the window; the positioning error and the limit cycle are properties
of the closed loop and are not read on an open-loop window.
"""

from __future__ import annotations

import math

import numpy as np

from compliance import metrics as M
from compliance.acceptance.measure.case import Case
from compliance.acceptance.measure.uncertainty import K, combine, missing, peak_bias
from compliance.metrics.trace_windows import time_window

__all__ = ["measure_hold"]

START_WINDOW = 0.05  # s; the position at the start of the window is the mean over this span (steps' pre_window)


def _window(cond, run) -> tuple[float, float, list]:
    notes = []
    w = run.settings.get("window")
    if w:
        t0, t1 = float(w[0]), float(w[1])
    else:
        t0 = run.settings.get("valve_null_from") or float(cond.time[0])
        t1 = float(cond.time[-1])
        notes.append(f"hold window not stated: {t0:.2f} s to the end of the recording")
    end = float(cond.time[-1]) + 0.5 * cond.dt
    if t1 > end:
        notes.append(f"the window ends at {t1:.2f} s but the recording at {cond.time[-1]:.2f} s")
        t1 = end
    return t0, t1, notes


def measure_hold(name: str, cond, run, cfg) -> list[Case]:
    """One case for a recorded hold (see the module docstring)."""
    t0, t1, notes = _window(cond, run)
    w = time_window(cond.time, t0, t1 + 0.5 * cond.dt)
    open_loop = run.settings.get("valve_null_from") is not None and run.settings["valve_null_from"] <= t0 + cond.dt
    base = {"position": run.position, "load": run.load, "flow_control": run.flow_control, "loop": "open" if open_loop else "closed",
            "window": [t0, t1]}
    label = f"hold at {run.position * 1e3:.1f} mm over {t0:.1f}-{t1:.1f} s" if run.position is not None else "hold"
    if w.stop - w.start < 3:
        reason = f"the hold window {t0:.2f}-{t1:.2f} s holds fewer than 3 samples"
        return [Case(name, "hold", label, base, {m: missing(reason) for m in ("drift", "max_positioning_error")}, tuple(notes))]
    ref = cond.column("reference")
    ref = np.full(cond.time.shape, np.nan) if ref is None else ref
    h = M.hold(cond.time, cond.position, ref, t0, t1 + 0.5 * cond.dt)
    n = w.stop - w.start
    span = cond.time[w][-1] - cond.time[w][0]
    u_fit = K * cond.sigma * math.sqrt(12.0 / n)  # a line fit's travel over n samples of white noise
    start = time_window(cond.time, t0, t0 + START_WINDOW)
    x_start = float(np.mean(cond.raw[start]))
    excursion = float(np.max(np.abs(cond.position[w] - x_start)))
    u_start = cond.sigma / math.sqrt(max(1, start.stop - start.start))
    values = {
        "drift": combine(h.drift, {"noise": u_fit, "resolution": K * cond.resolution / math.sqrt(12.0)}),
        "drift_excursion": combine(excursion, {
            "noise left after conditioning": K * cond.u_position, "start position": K * u_start,
            "noise peak of a maximum": peak_bias(cond.u_position, span, max(cond.window, cond.dt))}),
        "drift_end": combine(float(cond.position[w][-1] - x_start), {"noise": K * math.hypot(cond.u_position, u_start)}),
    }
    if open_loop:
        why = "the loop was open during the window (valve at null): a closed-loop property is not measured by this test"
        for m in ("max_positioning_error", "steady_state_error", "limit_cycle_amplitude"):
            values[m] = missing(why)
    elif not np.all(np.isfinite(ref[w])):
        for m in ("max_positioning_error", "steady_state_error"):
            values[m] = missing("no reference logged")
        values["limit_cycle_amplitude"] = combine(h.limit_cycle_amplitude, {
            "noise left after conditioning": K * cond.u_position,
            "noise peak of a maximum": peak_bias(cond.u_position, span, max(cond.window, cond.dt))})
    else:
        peak = peak_bias(cond.u_position, span, max(cond.window, cond.dt))
        values["max_positioning_error"] = combine(h.max_positioning_error, {"noise left after conditioning": K * cond.u_position,
                                                                           "noise peak of a maximum": peak})
        values["steady_state_error"] = combine(h.steady_state_error, {"noise": K * cond.sigma / math.sqrt(n)})
        values["limit_cycle_amplitude"] = combine(h.limit_cycle_amplitude, {"noise left after conditioning": K * cond.u_position,
                                                                           "noise peak of a maximum": peak})
    base.update(x_start=x_start, duration=span, direction="closing" if values["drift_end"].value < 0 else "opening")
    return [Case(name, "hold", label, base, values, tuple(notes), {"window": [t0, t1]})]
