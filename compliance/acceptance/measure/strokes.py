"""A recorded full stroke: the 25-75 % stroke time, the stroke rate, the timing and the peak speed, with uncertainties.

The figures are the simulation's (``metrics.stroke.stroke_time``, ``stroke_timing``,
``metrics.speed.speed_extremes``) on the conditioned position from the command change on. A
crossing time carries the time the trace spends within two standard uncertainties of its level;
the peak speed carries the noise a centred 20 ms difference of the conditioned position keeps.

The standard test (IEC 60308:2024 servomotor timing, ASME PTC 29-2005 (R2020)) is a stroke at full
command from rest at one end to the other, through the speed-setting devices; a stroke that did
not start at an end, did not reach the other, or was not driven at full command is said.
"""

from __future__ import annotations

import math

import numpy as np

from compliance import metrics as M
from compliance.acceptance.measure.case import Case
from compliance.acceptance.measure.uncertainty import K, combine, crossing_with_interval, missing, peak_bias, sample_uncertainty
from compliance.validation.recorded_noise import robust_std

__all__ = ["command_change", "measure_stroke"]

END_TOLERANCE = 0.02  # share of the stroke within which a stroke starts "at the end stop"
SPEED_SPAN = 0.02  # s; metrics.speed's centred difference


def command_change(cond, centre: float) -> float | None:
    """Time of the largest jump of the valve command through its centre [s] (the start of a manual stroke)."""
    u = cond.column("valve_command")
    if u is None or u.size < 2:
        return None
    d = np.abs(np.diff(u))
    i = int(np.argmax(d))
    if np.sign(u[i] - centre) == np.sign(u[i + 1] - centre) or d[i] <= 0.0:
        return None
    return float(cond.time[i + 1])


def _direction(cond, settings: dict, t0: int) -> str:
    d = settings.get("direction")
    if d in ("opening", "closing"):
        return d
    return "opening" if cond.position[-1] >= cond.position[t0] else "closing"


def _departures(cond, run, direction: str, i0: int, stroke: float, limit: float, centre: float) -> list:
    out = []
    x = cond.position
    start_end = 0.0 if direction == "opening" else stroke
    if abs(x[i0] - start_end) > END_TOLERANCE * stroke:
        out.append(f"started at {x[i0] * 1e3:.1f} mm, not at the {'closed' if direction == 'opening' else 'open'} end stop")
    u = cond.column("valve_command")
    if u is not None and float(np.median(np.abs(u[i0:] - centre))) < 0.95 * limit:
        out.append(f"valve command {float(np.median(np.abs(u[i0:] - centre))):.2f} V about its centre, not full ({limit:g} V)")
    if run.flow_control is False:
        out.append("flow-control valves open: the stroke shows the servo valve, not the speed setting")
    if cond.column("reference") is not None and run.settings.get("command") != "full":
        out.append("a reference was logged: the stroke may have run in closed loop (the standard stroke is at full command)")
    return out


def _speed_budget(cond, i0: int) -> dict:
    """The peak speed's contributions: the speed noise the conditioning leaves, the noise peak a maximum picks, the filter.

    The speed noise is measured: the centred 20 ms difference of the conditioned position, less
    its own smooth course, has the spread of the noise alone. The filter contribution is the
    largest change of speed over the filter's lag (a first-order filter lags by 1 / (2 pi f_c)).
    """
    v = M.speed(cond.time[i0:], cond.position[i0:], SPEED_SPAN)
    n = int(round(4.0 * SPEED_SPAN / cond.dt)) | 1
    smooth = np.convolve(v, np.ones(n) / n, mode="same") if v.size > n else v
    sigma_v = robust_std((v - smooth)[n:-n]) if v.size > 3 * n else 0.0
    lag = int(round(cond.filter_delay / cond.dt))
    filt = float(np.max(np.abs(v[lag:] - v[:-lag]))) if 0 < lag < v.size else 0.0
    span = float(cond.time[-1] - cond.time[i0])
    return {"speed noise": K * sigma_v, "noise peak of a maximum": peak_bias(sigma_v, span, SPEED_SPAN), "logger filter": filt}


def measure_stroke(name: str, cond, run, cfg) -> list[Case]:
    """One case for a recorded full stroke (see the module docstring)."""
    stroke = cfg.p("cylinder.stroke")
    centre = cfg.p("valve.centre_voltage")
    t_cmd = run.settings.get("command_time")
    lag = cond.filter_delay if t_cmd is not None else 0.0  # a stated instant is the controller's; the logged position lags
    t_cmd = command_change(cond, centre) if t_cmd is None else t_cmd
    if t_cmd is None:
        reason = "no command change through the valve centre: the start of the stroke is not in the log"
        return [Case(name, "full_stroke", "full stroke", {"load": run.load, "flow_control": run.flow_control},
                     {m: missing(reason) for m in ("opening_time", "closing_time", "stroke_speed", "max_speed")})]
    i0 = int(np.searchsorted(cond.time, t_cmd))
    direction = _direction(cond, run.settings, i0)
    tt, x = cond.time[i0:], cond.position[i0:]
    T, t1, t2, why = M.stroke_time(tt, x, stroke, direction)
    sgn = 1 if direction == "opening" else -1
    metric = f"{direction}_time"
    values = {}
    if T is None:
        values[metric] = missing(why)
        values["stroke_speed"] = missing(why)
    else:
        lo, hi = (0.25, 0.75) if direction == "opening" else (0.75, 0.25)
        _, u1 = crossing_with_interval(tt, x, lo * stroke, cond.u_position, 0, sgn)
        _, u2 = crossing_with_interval(tt, x, hi * stroke, cond.u_position, 0, sgn)
        u_T = 2.0 * math.hypot(u1, u2, sample_uncertainty(cond.dt))
        values[metric] = combine(T, {"25 % and 75 % crossings": u_T})
        values["stroke_speed"] = combine(stroke / T, {"25 % and 75 % crossings": stroke * u_T / (T * T)})
    timing = {k: (None if v is None else v - lag if k in ("start_delay", "time_to_end") else v)
              for k, v in M.stroke_timing(tt, x, stroke, direction, T).items()}
    u_start = sample_uncertainty(cond.dt)
    values["start_delay"] = combine(timing["start_delay"], {"command instant": u_start, "1 % crossing": u_start,
                                                            "logger filter": cond.filter_delay}, "did not move 1 % of the stroke")
    values["time_to_end"] = combine(timing["time_to_end"], {"command instant": u_start, "end crossing": u_start},
                                    "did not reach 99 % of the stroke")
    v, vo, vc = M.speed_extremes(cond.time, cond.position, t_cmd)
    speed_budget = _speed_budget(cond, i0)
    values["max_speed"] = combine(v, speed_budget)
    values[f"max_{direction}_speed"] = combine(vo if direction == "opening" else vc, speed_budget)
    conditions = {"position": None, "load": run.load, "flow_control": run.flow_control, "direction": direction,
                  "t_command": t_cmd, "x_start": float(x[0]), "x_end": float(x[-1])}
    marks = {"t_command": t_cmd, "stroke_points": [t1, t2]}
    label = f"{direction} stroke at full command from {t_cmd:.2f} s"
    return [Case(name, "full_stroke", label, conditions, values,
                 tuple(_departures(cond, run, direction, i0, stroke, cfg.p("valve.command_limit"), centre)), marks)]
