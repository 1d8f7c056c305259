"""A recorded step series, one case per step: dead time, time constant, positioning error, with uncertainties.

The step figures are the simulation's (``metrics.step.step_response`` on the conditioned trace,
``TAU_FRACTION`` and ``DETECT_FRACTION`` of ``metrics.step``); what a log adds is measured here:
the end of the dead time is fitted through the noise (``measure.onset``), the 63.2 % point is read
on the conditioned trace with the time it spends near the level as its uncertainty, and the
positioning error carries the noise the conditioning leaves.

Each step says whether it can measure the time constant the standards mean: a step away from the
operating position (the steps back towards it start from the offset the previous step left and
are reported, not judged), with the servo valve not driven to its full opening (or, with the
flow-control valves in, to where their throttles take over the flow) before 63.2 %. Whether the
servo was at rest before the step is said beside it (``from_rest``): after a step back a servo
with a dead zone creeps towards its set-point, and the step series of IEC 60308 runs on from there.
"""

from __future__ import annotations

import math

import numpy as np

from compliance import metrics as M
from compliance.acceptance.measure.case import Case
from compliance.acceptance.measure.onset import motion_onset
from compliance.acceptance.measure.uncertainty import (K, Measured, combine, crossing_with_interval, missing, peak_bias,
                                                       sample_uncertainty)
from compliance.metrics.trace_windows import time_window
from compliance.procedures.steps import flow_saturation_voltage

__all__ = ["measure_steps", "step_events"]

PRE_WINDOW = 0.05  # s; the position and the set-point before a step: over this window (metrics.step_response's pre_window)
SUPPORT = 0.5  # a time figure whose expanded uncertainty exceeds this share of itself is not supported by the log
REST_WINDOW = 0.2  # s; the servo is at rest before a step when the line through its position over this window
# travels less than 1 % of the step (DETECT_FRACTION: motion the dead time would count) or K times its own scatter


def step_events(cond, settings: dict) -> list:
    """The set-point steps of a series: from the logged reference, dated by the sidecar's step times when it gives them."""
    ref = cond.column("reference")
    times = settings.get("step_times")
    if ref is None:
        after = settings.get("setpoints_after")
        if not times or not after or len(times) != len(after):
            return []
        before = [settings.get("operating_position", after[-1])] + list(after[:-1])
        ends = list(times[1:]) + [float(cond.time[-1]) + cond.dt]
        return [M.StepEvent(t, e, b, a) for t, e, b, a in zip(times, ends, before, after)]
    sizes = np.abs(np.diff(ref))
    smallest = min(5e-5, 0.5 * min((abs(c) for c in settings.get("step_changes") or [1.0]), default=1.0))
    events = M.find_steps(cond.time, ref, min_size=min(smallest, 5e-5 if sizes.size else smallest))
    out = []
    for ev in events:
        t_step = ev.t_step
        for t in times or ():  # the sidecar's instant when it lies within the logged jump (a filtered reference spreads it)
            if ev.t_step - 2.0 * cond.dt <= t <= ev.t_step + 2.0 * cond.dt:
                t_step = float(t)
        before = time_window(cond.time, t_step - PRE_WINDOW, t_step)
        settle = time_window(cond.time, max(t_step + 0.02, ev.t_end - 0.5), ev.t_end)
        r0 = float(np.median(ref[before])) if before.stop > before.start else ev.r_before
        r1 = float(np.median(ref[settle])) if settle.stop > settle.start else ev.r_after
        out.append(M.StepEvent(t_step, ev.t_end, r0, r1))
    return out


def _position_at_step(cond, t_step: float) -> tuple[float, float]:
    """The position at the step [m] as metrics.step takes it (the mean over ``PRE_WINDOW`` before it), and its
    standard uncertainty: the noise averaged over the window, never below the conditioned noise (a logger's filter
    correlates the samples, so they average less than independent ones)."""
    pre = time_window(cond.time, t_step - PRE_WINDOW, t_step)
    n = pre.stop - pre.start
    if n == 0:
        return float(np.interp(t_step, cond.time, cond.position)), cond.u_position
    return float(np.mean(cond.raw[pre])), max(cond.sigma / math.sqrt(n), cond.u_position)


def _role(ev, x_op: float | None) -> str:
    tol = max(0.01 * abs(ev.size), 2e-5)
    if x_op is None:
        return "step"
    if abs(ev.r_before - x_op) <= tol:
        return "outward"
    if abs(ev.r_after - x_op) <= tol:
        return "return"
    return "step"


def _at_rest(cond, t_step: float, size: float) -> bool:
    w = time_window(cond.time, t_step - REST_WINDOW, t_step)
    n = w.stop - w.start
    if n < 3:
        return False
    t = cond.time[w]
    slope = np.polyfit(t - t[0], cond.raw[w], 1)[0]
    travel = abs(slope) * (t[-1] - t[0])
    scatter = cond.sigma * math.sqrt(12.0 / n)  # standard deviation of a line fit's travel over n samples of white noise
    return travel <= max(K * scatter, M.DETECT_FRACTION * abs(size))


def _tau_reason(role: str, sm) -> str | None:
    """Why a step does not measure the time constant the standards mean, or None."""
    if role != "outward":
        return ("a step back towards the operating position starts from the offset the previous step left; the time "
                "constant is read on steps away from the operating position")
    if sm.rate_limited:
        return sm.reasons.get("time_constant")
    return None


def _time_figures(cond, ev, x0: float, u_x0: float, xf: float, u_xf: float, t1, u1: float):
    """(time constant to 63.2 % of the commanded step, to 63.2 % of the achieved travel) as Measured [s]."""
    i0 = int(np.searchsorted(cond.time, ev.t_step))
    sgn = 1 if ev.size >= 0 else -1
    out = []
    for target, u_level, what in ((x0 + M.TAU_FRACTION * ev.size, math.hypot(cond.u_position, u_x0), "commanded step"),
                                  (x0 + M.TAU_FRACTION * (xf - x0), math.hypot(cond.u_position, u_x0, M.TAU_FRACTION * u_xf),
                                   "achieved travel")):
        t63, u63 = crossing_with_interval(cond.time, cond.position, target, u_level, i0, sgn)
        if t1 is None:
            out.append(missing(f"no motion of 1 % of the step after {ev.t_step:.2f} s"))
        elif t63 is None or t63 > ev.t_end:
            seg = cond.position[time_window(cond.time, ev.t_step, ev.t_end)]
            reached = float(np.max(sgn * (seg - x0))) / abs(ev.size) if ev.size and seg.size else 0.0
            out.append(missing(f"not reached: the position reached {100 * reached:.0f} % of the {what}, never 63.2 % "
                               f"before the next set-point change"))
        else:
            out.append(combine(t63 - t1, {"63.2 % crossing": u63, "end of dead time": u1,
                                          "sample interval": sample_uncertainty(cond.dt), "logger filter": cond.filter_delay}))
    return out


def _step_case(name: str, cond, ev, k: int, n: int, run, valve, options: dict, stated: bool) -> Case:
    """Measure one step (see the module docstring)."""
    role = _role(ev, run.position)
    sgn = 1 if ev.size >= 0 else -1
    x0, u_x0 = _position_at_step(cond, ev.t_step)
    u = cond.column("valve_command")
    sat = valve["saturation"][sgn]
    sm = M.step_response(cond.time, cond.position, ev, valve_command=None if u is None else u - valve["centre"],
                         command_saturation=sat, detect=M.DETECT_FRACTION * abs(ev.size), **options)
    fw = time_window(cond.time, max(ev.t_step, ev.t_end - options.get("final_window", 0.5)), ev.t_end)
    n_fw = max(1, fw.stop - fw.start)
    xf, u_xf = sm.x_final, cond.sigma / math.sqrt(n_fw)
    rest = _at_rest(cond, ev.t_step, ev.size)
    t1, u1, how = motion_onset(cond.time, cond.raw, cond.position, ev.t_step, x0, ev.size, cond.sigma, cond.u_position,
                               fit=rest)
    lag = cond.filter_delay if stated else 0.0  # a stated instant is the controller's; the logged position lags by the filter
    dead = (missing(f"no motion of 1 % of the step after {ev.t_step:.2f} s") if t1 is None or t1 > ev.t_end
            else combine(t1 - lag - ev.t_step, {"end of dead time": u1, "step instant": sample_uncertainty(cond.dt),
                                                "logger filter": cond.filter_delay}))
    tau, tau_ach = _time_figures(cond, ev, x0, u_x0, xf, u_xf, None if dead.value is None else t1, u1)
    dead = _supported(dead, "dead time", cond)
    tau, tau_ach = _supported(tau, "time constant", cond), _supported(tau_ach, "time constant", cond)
    why = _tau_reason(role, sm)
    if why is not None:
        tau, tau_ach = tau.ineligible(why) if tau.value is not None else tau, tau_ach.ineligible(why) if tau_ach.value is not None else tau_ach
    elif tau.value is None and dead.value is not None:  # a step away from the point that never reached 63.2 %: the worst case
        tau = Measured(None, 0.0, tau.reason, True)
    peaks = K * cond.u_position
    final_span = float(cond.time[fw][-1] - cond.time[fw][0]) if fw.stop > fw.start else 0.0
    values = {
        "dead_time": dead,
        "time_constant": tau,
        "time_constant_achieved": tau_ach,
        "max_positioning_error": combine(sm.max_positioning_error, {
            "noise left after conditioning": peaks,
            "noise peak of a maximum": peak_bias(cond.u_position, final_span, max(cond.window, cond.dt))}),
        "steady_state_error": combine(sm.steady_state_error, {"noise": K * u_xf}),
        # mean |reference - position| over the final window: the steady error where the position crosses the set-point
        "mean_positioning_error": combine(float(np.mean(np.abs(ev.r_after - cond.position[fw]))) if fw.stop > fw.start else None,
                                          {"noise": K * cond.u_position}, "no sample in the final window"),
        "overshoot": _fraction(sm.overshoot, sm.reasons.get("overshoot"), peaks, abs(xf - x0)),
        "settling_time": _time(sm.settling_time, sm.reasons.get("settling_time"), cond),
        "rise_time": _time(sm.rise_time, sm.reasons.get("rise_time"), cond),
        "max_speed": combine(sm.max_speed, {"noise": K * math.sqrt(2.0) * cond.u_position / 0.02}),
    }
    direction = "up" if ev.size > 0 else "down"
    label = f"step {k + 1} of {n} {direction} {abs(ev.size) * 1e3:.2f} mm at {ev.t_step:.2f} s ({role})"
    cmd = None if u is None else float(np.max(np.abs(u[time_window(cond.time, ev.t_step, ev.t_end)] - valve["centre"])))
    conditions = {"position": run.position, "load": run.load, "flow_control": run.flow_control, "size": abs(ev.size),
                  "signed_size": ev.size, "direction": direction, "role": role, "from_rest": rest, "t_step": ev.t_step,
                  "x_start": x0, "x_final": xf, "max_command": cmd, "saturation_voltage": sat, "onset": how}
    marks = {"t_step": ev.t_step, "t_end": ev.t_end, **{k2: v for k2, v in sm.marks.items() if k2 in ("final_window", "tau_632")}}
    if t1 is not None:
        marks["motion_start"] = [t1, x0 + sgn * M.DETECT_FRACTION * abs(ev.size)]
    return Case(name, "steps", label, conditions, values, (), marks)


def _supported(m: Measured, what: str, cond) -> Measured:
    """``m``, or a missing figure when the log cannot support it (its uncertainty beyond ``SUPPORT`` of itself)."""
    if m.value is None or m.u <= SUPPORT * abs(m.value):
        return m
    return Measured(None, 0.0, f"the log cannot support this {what}: {1e3 * m.value:.1f} ms +/- {1e3 * m.u:.1f} ms "
                               f"(logged every {1e3 * cond.dt:.1f} ms with {1e6 * cond.sigma:.0f} um of noise)", m.eligible)


def _fraction(value, reason, u_pos: float, change: float) -> Measured:
    return combine(value, {"noise": u_pos / change if change > 0 else 0.0}, reason)


def _time(value, reason, cond) -> Measured:
    return combine(value, {"smoothing span": 0.5 * cond.window, "sample interval": sample_uncertainty(cond.dt)}, reason)


def measure_steps(name: str, cond, run, cfg, options: dict | None = None) -> list[Case]:
    """One case per set-point step of a recorded series (see the module docstring).

    Parameters
    ----------
    name : str
        The recording.
    cond : Conditioned
    run : SiteTest
    cfg : PlantConfig
        The plant model: the valve's centre and full-opening voltage, and where the flow-control
        valves take over (``procedures.steps.flow_saturation_voltage``).
    options : dict, optional
        Step-metric options (``metrics.STEP_OPTION_DEFAULTS``: ``final_window`` [s], ``settling_band``...).
    """
    events = step_events(cond, run.settings)
    valve = {"centre": cfg.p("valve.centre_voltage"),
             "saturation": {s: flow_saturation_voltage(cfg, s, run.flow_control) for s in (+1, -1)}}
    opts = {k: v for k, v in (options or {}).items() if k in ("final_window", "settling_band", "settling_band_abs")}
    stated = bool(run.settings.get("step_times"))
    if not events:
        why = ("no set-point step in the log: the reference column never jumps" if cond.column("reference") is not None
               else "no reference column and no step_times/setpoints_after in the sidecar: the steps are not known")
        return [Case(name, "steps", f"{name} (no step found)", {"position": run.position, "load": run.load,
                                                               "flow_control": run.flow_control}, {}, (), {}, why)]
    return [_step_case(name, cond, ev, k, len(events), run, valve, opts, stated) for k, ev in enumerate(events)]
