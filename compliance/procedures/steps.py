"""The ``steps`` procedure: a set-point step sequence in closed loop, one step response per step.

Every step metric is measured on every step with the options each requirement asks for. A time
constant measured while a limiting device acts on the step (the set-point rate limiter ramping it,
the valve command saturated, peak or mean speed near the full-command figures of the same load and
circuit) or while the valve dead zone governs it is kept for the report but not eligible for a
verdict, with the rule that excluded it (``metrics.step_eligibility``).
"""

from __future__ import annotations

import numpy as np

from compliance import metrics as M
from compliance.metrics.catalogue import option_value
from compliance.metrics.step_eligibility import RATE_LIMIT_FRACTION, StepLimits, time_constant_eligibility
from compliance.plants import kind_of
from compliance.errors import InputError
from compliance.procedures.scenarios import add_drive_samples, closed_loop_trace, full_command_stroke, start_position, stroke
from compliance.procedures.outcomes import Sample, request_key

__all__ = ["RATE_LIMIT_FRACTION", "flow_saturation_voltage", "run_steps", "step_limits"]


def _step_profile(x0, size, pattern, lead, dwell, stroke_length, where):
    from compliance.simulation.profiles import Profile

    for flip in (1.0, -1.0):
        levels = [x0]
        for d in pattern:
            levels.append(levels[-1] + flip * (size if d == "up" else -size))
        if all(-1e-12 <= v <= stroke_length + 1e-12 for v in levels):
            times, values = [0.0], [x0]
            for k, lv in enumerate(levels[1:]):
                t = lead + k * dwell
                times += [t, t]
                values += [values[-1], lv]
            used = pattern if flip > 0 else ["down" if d == "up" else "up" for d in pattern]
            return Profile(np.array(times), np.array(values)), used, lead + len(pattern) * dwell
    raise InputError(f"{where}: steps of {size*1e3:.1f} mm in the pattern {pattern} leave the stroke 0..{stroke_length*1e3:.0f} mm either way")


def _full_command_speeds(cfg, op):
    """Speeds at full valve command (open loop) from each end under the operating point's load and circuit [m/s].

    Returns ``{direction: (peak, straight)}``: the peak speed, and the speed of the straight part
    of the stroke (25 % -> 75 %, or from 25 % to the end of the run if the stroke is slower), which
    is the rate limit the flow-control valves set once the start-up surge has passed.
    """
    L = stroke(cfg)
    res = {}
    for d in ("opening", "closing"):
        df = full_command_stroke(cfg, op, d, "full", 8.0, op.flow_control, drive="manual")
        tt, x = M.frame_columns(df, "time", "position")
        _, vo, vc = M.speed_extremes(tt, x)
        travelled = x - x[0] if d == "opening" else x[0] - x
        i25 = int(np.argmax(travelled >= 0.25 * L)) if np.any(travelled >= 0.25 * L) else None
        straight = 0.0
        if i25 is not None:
            i75 = int(np.argmax(travelled >= 0.75 * L)) if np.any(travelled >= 0.75 * L) else len(tt) - 1
            if i75 > i25:
                straight = (travelled[i75] - travelled[i25]) / (tt[i75] - tt[i25])
        res[d] = (vo if d == "opening" else vc, straight)
    return res


def flow_saturation_voltage(cfg, direction: int, flow_control: bool | None) -> float:
    """Command magnitude beyond which the flow through the valve stops growing [V].

    Without flow-control valves that is where the valve is fully open (``valve.saturation_voltage``).
    With a meter-out throttle of conductance C_thr in the exhaust path, the path's conductance
    1/sqrt(1/(A_re*C)^2 + 1/C_thr^2) (ISO 6358 series rule) is within 30 % of C_thr once
    A_re*C >= C_thr: beyond the opening A_re = C_thr/C the throttle, not the valve, sets the
    flow, so a step that drives the command past it is rate limited.
    """
    p = cfg.p
    installed = cfg.flow_control_installed if flow_control is None else bool(flow_control)
    dz = p("valve.dead_zone_positive") if direction > 0 else p("valve.dead_zone_negative")
    u_sat = p("valve.saturation_voltage")
    if not installed:
        return u_sat
    c_thr = p("flow_control.opening_conductance") if direction > 0 else p("flow_control.closing_conductance")
    c = p("valve.sonic_conductance")
    if c_thr <= 0.0 or c_thr >= c:
        return u_sat
    return dz + (u_sat - dz) * c_thr / c


def step_limits(cfg, op, with_speeds: bool) -> StepLimits:
    """What can limit a step of ``cfg`` at ``op`` (``metrics.step_eligibility.StepLimits``).

    The set-point rate limiter's rates when it acts at this point (``scenarios.at_operating_point`` has
    already bypassed it where the point injects the step downstream of it), the flow saturation voltage
    of each direction, the dead-zone stall band, and with ``with_speeds`` the full-command speeds.
    """
    p = cfg.params
    return StepLimits(
        stall={+1: kind_of(cfg).stall_error(cfg, "opening"), -1: kind_of(cfg).stall_error(cfg, "closing")},
        command_saturation={+1: flow_saturation_voltage(cfg, +1, op.flow_control),
                            -1: flow_saturation_voltage(cfg, -1, op.flow_control)},
        ramp_rate={+1: p.get("controller.setpoint_opening_rate", 0.0), -1: p.get("controller.setpoint_closing_rate", 0.0)},
        full_speed={(+1 if d == "opening" else -1): v for d, v in _full_command_speeds(cfg, op).items()} if with_speeds else None,
    )


def _opts(options: dict) -> dict:
    """Requirement options -> keyword arguments of metrics.step_response (SI)."""
    kw = {}
    for k in M.STEP_OPTION_DEFAULTS:
        if k in options:
            kw[k] = options[k].value
    return kw


def run_steps(cfg, proc, op, requests, out):
    """Run a ``steps`` procedure at ``op`` and add its samples to ``out`` (see ``procedures.run``)."""
    s = proc.settings
    L = stroke(cfg)
    x0 = start_position(cfg, op, proc)
    size = s["size"].resolve(L)
    ref, used, duration = _step_profile(x0, size, s["pattern"], s["lead"].value, s["dwell"].value, L,
                                        f"procedure '{proc.name}' at '{op.name}'")
    if used != s["pattern"]:
        out.notes.append(f"pattern reversed to {used} to stay inside the stroke from {x0*1e3:.1f} mm")
    label, tt, x, r, u = closed_loop_trace(cfg, proc, op, out, duration, x0, ref)
    installed = cfg.flow_control_installed if op.flow_control is None else bool(op.flow_control)
    circuit = "flow-control valves 2V2/2V3 " + ("in" if installed else "out (wide open)")
    if op.setpoint_limiter is False:
        circuit += "; step injected downstream of the set-point rate limiter"
    elif cfg.setpoint_rate_limited:
        circuit += "; through the set-point rate limiter"
    events = M.find_steps(tt, r, min_size=min(5e-5, 0.5 * size))
    wants_tau = any(m == "time_constant" for m, _ in requests)
    limits = step_limits(cfg, op, wants_tau)
    if limits.full_speed:
        vmax = limits.full_speed
        out.notes.append(
            "rate limit check at full command under this load and circuit: peak "
            f"{vmax[1][0]*1e3:.0f} / {vmax[-1][0]*1e3:.0f} mm/s, straight part "
            f"{vmax[1][1]*1e3:.0f} / {vmax[-1][1]*1e3:.0f} mm/s (opening / closing)"
        )
    if wants_tau and cfg.setpoint_rate_limited:
        out.notes.append("the governor's set-point rate limiter acts on these steps (opening "
                         f"{limits.ramp_rate[1]*1e3:.1f} mm/s, closing {limits.ramp_rate[-1]*1e3:.1f} mm/s): the steps are ramped")
    wanted = {m: (m, {}) for m, info in M.METRICS.items() if "steps" in info.kinds}
    wanted.update({request_key(m, o): (m, o) for m, o in requests if "steps" in M.METRICS[m].kinds})
    centre = cfg.p("valve.centre_voltage")
    per_opts: dict = {}
    for key, (metric, opts) in wanted.items():
        okey = request_key("", {k: v for k, v in opts.items() if k in M.STEP_OPTION_DEFAULTS})
        if okey not in per_opts:
            per_opts[okey] = [M.step_response(tt, x, ev, valve_command=u - centre,
                                              command_saturation=limits.command_saturation[1 if ev.size > 0 else -1],
                                              **_opts(opts))
                              for ev in events]
        for k, (ev, sm) in enumerate(zip(events, per_opts[okey])):
            direction = "up" if ev.size > 0 else "down"
            lab = f"step {k+1} of {len(events)} {direction} {abs(ev.size)*1e3:.2f} mm at {ev.t_step:.2f} s"
            detail = {"t_step": ev.t_step, "size": ev.size, "x_start": sm.x_start, "x_final": sm.x_final,
                      "step": k + 1, "steps": len(events), "circuit": circuit,
                      "start": "rest at the operating point" if k == 0 else f"rest after step {k} at {sm.x_start * 1e3:.1f} mm"}
            if metric in ("max_speed", "max_opening_speed", "max_closing_speed", "saturation_fraction"):
                continue
            val = getattr(sm, metric)
            reason = sm.reasons.get(metric)
            eligible = True
            if metric == "dead_time" and val is None:
                detail["non_responding"] = True  # the step never moved: its dead time is the worst case
            if metric == "time_constant":
                travel = option_value(opts, "travel")
                eligible, reason, more = time_constant_eligibility(k, len(events), ev, sm, limits,
                                                                   from_rest=s["tau_from_rest"], travel=travel)
                detail.update(more)
                val = more["tau_achieved"] if travel == "achieved" else more["tau_commanded"]
                if eligible and val is None:
                    detail["non_responding"] = True
            out.add(key, Sample(val, lab, reason, eligible, detail))
    # marks for plots (default options)
    for k, (ev, sm) in enumerate(zip(events, per_opts[request_key("", {})])):
        for name, v in sm.marks.items():
            out.marks.append({"trace": label, "step": k + 1, "type": name, "value": v})
    add_drive_samples(cfg, out, tt, x, u, label)
