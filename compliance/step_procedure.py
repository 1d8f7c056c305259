"""The ``steps`` procedure: a set-point step sequence in closed loop, one step response per step.

Every step metric is measured on every step with the options each requirement asks for. A
time constant measured while the servo runs at its rate limit (valve command saturated, or
peak speed near the full-command speed under the same load and circuit) is kept for the
report but not eligible for a verdict: it then reflects flow saturation, not the linear
time constant (IEC 61362 asks for small steps).
"""

from __future__ import annotations

import numpy as np

from . import metrics as M
from .errors import InputError
from .procedure_scenarios import add_drive_samples, closed_loop_trace, full_command_stroke, start_position, stroke
from .run_outcomes import Sample, request_key

__all__ = ["RATE_LIMIT_FRACTION", "run_steps"]

# a step whose peak speed reaches this fraction of the full-command speed is rate limited
RATE_LIMIT_FRACTION = 0.9


def _step_profile(x0, size, pattern, lead, dwell, stroke_length, where):
    from .profiles import Profile

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
    """Peak speeds at full command from each end under the operating point's load and circuit [m/s]."""
    res = {}
    for d in ("opening", "closing"):
        df = full_command_stroke(cfg, op, d, "full", 3.0, op.flow_control)
        tt, x = M.frame_columns(df, "time", "position")
        _, vo, vc = M.speed_extremes(tt, x)
        res[d] = vo if d == "opening" else vc
    return res


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
    events = M.find_steps(tt, r, min_size=min(5e-5, 0.5 * size))
    wants_tau = any(m == "time_constant" for m, _ in requests)
    vmax = _full_command_speeds(cfg, op) if wants_tau else None
    if vmax:
        out.notes.append(
            "rate limit check: full-command peak speeds under this load and circuit "
            f"{vmax['opening']*1e3:.0f} mm/s opening, {vmax['closing']*1e3:.0f} mm/s closing"
        )
    wanted = {m: (m, {}) for m, info in M.METRICS.items() if "steps" in info.kinds}
    wanted.update({request_key(m, o): (m, o) for m, o in requests if "steps" in M.METRICS[m].kinds})
    sat_v = cfg.p("valve.saturation_voltage")
    centre = cfg.p("valve.centre_voltage")
    per_opts: dict = {}
    for key, (metric, opts) in wanted.items():
        okey = request_key("", opts)
        if okey not in per_opts:
            per_opts[okey] = [M.step_response(tt, x, ev, valve_command=u - centre, command_saturation=sat_v, **_opts(opts))
                              for ev in events]
        for k, (ev, sm) in enumerate(zip(events, per_opts[okey])):
            direction = "up" if ev.size > 0 else "down"
            lab = f"step {k+1} {direction} {abs(ev.size)*1e3:.2f} mm at {ev.t_step:.2f} s"
            detail = {"t_step": ev.t_step, "size": ev.size, "x_start": sm.x_start, "x_final": sm.x_final}
            if metric in ("max_speed", "max_opening_speed", "max_closing_speed", "saturation_fraction"):
                continue
            val = getattr(sm, metric)
            reason = sm.reasons.get(metric)
            eligible = True
            if metric == "time_constant" and val is not None:
                if sm.rate_limited:
                    eligible = False
                elif vmax is not None:
                    lim = vmax["opening" if ev.size > 0 else "closing"]
                    if lim > 0 and sm.max_speed >= RATE_LIMIT_FRACTION * lim:
                        eligible = False
                        reason = (f"rate limited: peak speed {sm.max_speed*1e3:.0f} mm/s >= "
                                  f"{RATE_LIMIT_FRACTION:.0%} of the full-command speed {lim*1e3:.0f} mm/s")
                detail["peak_speed"] = sm.max_speed
            out.add(key, Sample(val, lab, reason, eligible, detail))
    # marks for plots (default options)
    for k, (ev, sm) in enumerate(zip(events, per_opts[request_key("", {})])):
        for name, v in sm.marks.items():
            out.marks.append({"trace": label, "step": k + 1, "type": name, "value": v})
    add_drive_samples(cfg, out, tt, x, u, label)
