"""Step responses: find the set-point steps of a trace and measure each response.

Dead time and time constant follow IEC 61362 (first detectable motion; 63.2 % of the achieved
travel, the first-order definition, with 63.2 % of the commanded step beside it); rise time (10-90 % of the actual change), settling time (last exit from a
band about the final value) and overshoot (per cent of the actual change) match python-control's
``step_info`` conventions. Definitions are written out in ``docs/metrics.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from compliance.metrics.speed import speed_extremes
from compliance.metrics.trace_windows import crossing, time_window

__all__ = ["DETECT_FRACTION", "TAU_FRACTION", "StepEvent", "StepMetrics", "find_steps", "step_response"]

# fraction of the commanded step that defines the time constant (1 - 1/e, first-order response)
TAU_FRACTION = 1.0 - math.exp(-1.0)
# default motion threshold for the dead time, fraction of the commanded step
DETECT_FRACTION = 0.01


@dataclass(frozen=True)
class StepEvent:
    """A set-point step found in a reference trace."""

    t_step: float  # [s]
    t_end: float  # next step or end of trace [s]
    r_before: float  # [m]
    r_after: float  # [m]

    @property
    def size(self) -> float:
        """Signed step size [m]."""
        return self.r_after - self.r_before


def find_steps(time, reference, min_size=5e-5, merge=0.005):
    """Find the steps of a piecewise-constant reference.

    Parameters
    ----------
    time : array [s]
    reference : array [m]
    min_size : float
        Smallest jump between consecutive samples counted as a step [m]; 50 um is far above
        the per-sample change of any sinusoid or ramp the procedures use (8 mm at 0.05 Hz moves
        2.5 um per 1 ms sample).
    merge : float
        Jumps closer than this are one step spread over a few samples [s].
    """
    time = np.asarray(time, float)
    reference = np.asarray(reference, float)
    d = np.diff(reference)
    idx = np.nonzero(np.abs(d) > min_size)[0]
    groups = []
    for i in idx:
        if groups and time[i] - time[groups[-1][1]] <= merge:
            groups[-1][1] = i + 1
        else:
            groups.append([i, i + 1])
    # a step is dated by the first sample holding the new value (or the start of a spread step)
    starts = [float(time[i0 + 1]) if i1 == i0 + 1 else float(time[i0]) for i0, i1 in groups]
    events = []
    for g, (i0, i1) in enumerate(groups):
        t_end = starts[g + 1] if g + 1 < len(groups) else float(time[-1]) + (float(time[-1] - time[-2]) if time.size > 1 else 0.0)
        events.append(StepEvent(starts[g], t_end, float(reference[i0]), float(reference[i1])))
    return events


@dataclass(frozen=True)
class StepMetrics:
    """Metrics of one step response; ``None`` values come with a reason in ``reasons``."""

    event: StepEvent
    x_start: float  # position before the step [m]
    x_final: float  # settled position (mean over the final window) [m]
    dead_time: float | None  # [s]
    time_constant: float | None  # [s]
    rise_time: float | None  # [s]
    settling_time: float | None  # [s]
    overshoot: float | None  # fraction of the actual change [-]
    steady_state_error: float  # [m]
    max_positioning_error: float  # [m]
    max_speed: float  # [m/s]
    rate_limited: bool
    reasons: dict = field(default_factory=dict)
    marks: dict = field(default_factory=dict)
    time_constant_achieved: float | None = None  # end of dead time to 63.2 % of the ACHIEVED travel x_final - x_start [s]
    command_peak: float | None = None  # max |valve command| from the step to the later 63.2 % point [V]; None = no command


def step_response(
    time,
    position,
    event: StepEvent,
    *,
    valve_command=None,
    command_saturation=None,
    settling_band=0.02,
    settling_band_abs=0.0,
    detect=0.0,
    final_window=0.5,
    pre_window=0.05,
):
    """Measure one step response.

    Parameters
    ----------
    time, position : array [s], [m]
    event : StepEvent
        The step (from :func:`find_steps`); the response is analysed on [t_step, t_end).
    valve_command : array [V], optional
        About the valve centre. Its peak up to the later 63.2 % point is kept (``command_peak``);
        with ``command_saturation`` [V] a step whose command reaches the flow saturation before the
        commanded 63.2 % point is flagged *saturated* (``rate_limited``): its time constant then
        reflects flow saturation, not the linear time constant (``metrics.step_eligibility``).
    settling_band : float
        Half-width of the settling band as a fraction of the actual change (step_info: 0.02).
    settling_band_abs : float
        Lower bound on the band half-width [m].
    detect : float
        Motion threshold for the dead time [m]; 0 = max(1 % of |step|, 5 x the standard
        deviation of the position over ``pre_window`` before the step). For a first-order
        lag the time constant then reads low by tau*ln(1/0.99) = 1 % (docs/metrics.md).
    final_window : float
        Settled position = mean over the last ``final_window`` before ``t_end`` [s].
    pre_window : float
        Window before the step over which the starting position is averaged [s].
    """
    time = np.asarray(time, float)
    position = np.asarray(position, float)
    reasons: dict = {}
    marks: dict = {}
    i_step = int(np.searchsorted(time, event.t_step, side="left"))
    i_end = int(np.searchsorted(time, event.t_end, side="left"))
    x0, noise = _start_position(time, position, event, i_step, pre_window)
    xf, sse, mpe = _final_position(time, position, event, i_step, i_end, final_window, marks)
    tt = time[i_step:i_end]
    xx = position[i_step:i_end]
    vmax = speed_extremes(time, position, event.t_step, event.t_end)[0]
    thr = detect if detect > 0 else max(DETECT_FRACTION * abs(event.size), 5.0 * noise)
    t_move = _motion_start(tt, xx, event, x0, thr, reasons, marks)
    dead_time = None if t_move is None else t_move - event.t_step
    tau, rate_limited = _time_constant(time, tt, xx, event, x0, t_move, i_step, valve_command, command_saturation,
                                       reasons, marks)
    rise, settle, over = _step_info(tt, xx, event, x0, xf, thr, settling_band, settling_band_abs, reasons, marks)
    tau_a = t63a = None
    if t_move is not None and abs(xf - x0) > thr:  # the same definition on the travel the servo actually made
        t63a = crossing(tt, xx, x0 + TAU_FRACTION * (xf - x0), 0, 1 if xf > x0 else -1)
        tau_a = None if t63a is None else t63a - t_move
        if t63a is not None:
            marks["tau_632_achieved"] = [t63a, x0 + TAU_FRACTION * (xf - x0)]
    u_peak = None
    if valve_command is not None:
        t63 = marks.get("tau_632", [None])[0]
        t_to = max((v for v in (t63, t63a) if v is not None), default=event.t_end)
        u = np.asarray(valve_command, float)[i_step: max(i_step + 1, int(np.searchsorted(time, t_to, side="right")))]
        u_peak = float(np.max(np.abs(u))) if u.size else None
    return StepMetrics(
        event, x0, xf, dead_time, tau, rise, settle, over, sse, mpe, vmax, rate_limited, reasons, marks, tau_a, u_peak
    )


def _start_position(time, position, event: StepEvent, i_step: int, pre_window: float) -> tuple[float, float]:
    """Position before the step [m] (mean over ``pre_window``) and its standard deviation [m]."""
    pre = time_window(time, event.t_step - pre_window, event.t_step)
    if pre.stop > pre.start:
        return float(np.mean(position[pre])), float(np.std(position[pre]))
    return float(position[max(0, i_step - 1)]), 0.0


def _final_position(time, position, event: StepEvent, i_step: int, i_end: int, final_window: float, marks: dict):
    """(settled position, steady-state error, max positioning error) [m] over the final window."""
    fw = time_window(time, max(event.t_step, event.t_end - final_window), event.t_end)
    if fw.stop <= fw.start:
        fw = slice(max(i_step, i_end - 1), max(i_step + 1, i_end))
    xf = float(np.mean(position[fw]))
    sse = abs(event.r_after - xf)
    mpe = float(np.max(np.abs(event.r_after - position[fw])))
    marks["final_window"] = [float(time[fw.start]), float(time[fw.stop - 1])]
    marks["x_final"] = xf
    return xf, sse, mpe


def _motion_start(tt, xx, event: StepEvent, x0: float, thr: float, reasons: dict, marks: dict) -> float | None:
    """Time of the first detectable motion in the commanded direction (ends the dead time) [s]."""
    sgn = 1.0 if event.size >= 0 else -1.0
    t_move = crossing(tt, sgn * (xx - x0), thr, 0, +1) if tt.size else None
    if t_move is None:
        reasons["dead_time"] = f"no motion beyond {thr * 1e3:.3g} mm after the step"
    else:
        marks["motion_start"] = [t_move, x0 + sgn * thr]
    return t_move


def _time_constant(time, tt, xx, event: StepEvent, x0: float, t_move, i_step: int, valve_command, command_saturation,
                   reasons: dict, marks: dict) -> tuple[float | None, bool]:
    """End of dead time to 63.2 % of the COMMANDED step [s], and whether the valve saturated first."""
    dr = event.size
    sgn = 1.0 if dr >= 0 else -1.0
    target = x0 + TAU_FRACTION * dr
    t63 = crossing(tt, xx, target, 0, int(sgn)) if tt.size else None
    if t63 is None:
        reached = (np.max(sgn * (xx - x0)) / abs(dr)) if tt.size and dr != 0 else 0.0
        reasons["time_constant"] = (
            f"stalled: reached {100 * reached:.0f} % of the commanded step, never 63.2 % "
            f"(steady error inside the valve dead zone)"
        )
        return None, False
    if t_move is None:
        reasons["time_constant"] = reasons["dead_time"]
        return None, False
    marks["tau_632"] = [t63, target]
    if valve_command is not None and command_saturation is not None:
        u = np.asarray(valve_command, float)[i_step : int(np.searchsorted(time, t63, side="right"))]
        if u.size and np.max(np.abs(u)) >= command_saturation * (1.0 - 1e-9):
            reasons["time_constant"] = (
                f"saturated: valve command reached {np.max(np.abs(u)):.2f} V >= flow saturation "
                f"{command_saturation:.2f} V (valve fully open, or flow-control valve limiting) before 63.2 %"
            )
            return t63 - t_move, True
    return t63 - t_move, False


def _step_info(tt, xx, event: StepEvent, x0: float, xf: float, thr: float, settling_band: float,
               settling_band_abs: float, reasons: dict, marks: dict):
    """step_info-style (rise time [s], settling time [s], overshoot [-]) on the actual change."""
    change = xf - x0
    if abs(change) <= max(thr, 1e-12):
        for k in ("rise_time", "settling_time", "overshoot"):
            reasons[k] = "no net motion"
        return None, None, None
    rise = settle = None
    s = 1.0 if change > 0 else -1.0
    t10 = crossing(tt, xx, x0 + 0.1 * change, 0, int(s))
    t90 = crossing(tt, xx, x0 + 0.9 * change, 0, int(s))
    if t10 is not None and t90 is not None:
        rise = t90 - t10
    else:
        reasons["rise_time"] = "did not pass 10 % and 90 % of the change"
    band = max(settling_band * abs(change), settling_band_abs)
    outside = np.nonzero(np.abs(xx - xf) >= band)[0]
    if outside.size == 0:
        settle = 0.0
    elif outside[-1] + 1 < tt.size:
        settle = float(tt[outside[-1] + 1] - event.t_step)
    else:
        reasons["settling_time"] = "not settled before the next step"
    if settle is not None:
        marks["settled"] = [event.t_step + settle, xf]
    marks["band"] = [xf - band, xf + band]
    peak = float(np.max(s * (xx - x0)))
    over = max(0.0, (peak - abs(change)) / abs(change))
    return rise, settle, over
