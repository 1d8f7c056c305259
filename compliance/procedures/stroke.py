"""Full-stroke procedures: ``full_stroke`` times and ``independent_adjustment`` of the speed settings.

A full stroke runs from one end of the stroke to the other under the operating point's load
(the plant's load curve in service, or a stated constant load), driven as the procedure says:
by the governor (a full set-point change through the closed loop, its set-point rate limiter
acting) or in manual (full valve command, open loop). Every timing figure of the stroke is
measured (``metrics.stroke_figures``); each requirement's stroke time is timed by the reading it
names (option ``timing``: full rate, end to end or extrapolated). Independent adjustment changes
one direction's speed setting (the limiter's rate, or that direction's flow-control valve) and
measures both directions again.
"""

from __future__ import annotations

import numpy as np

from compliance import metrics as M
from compliance.errors import InputError
from compliance.metrics.catalogue import option_value
from compliance.metrics.stroke import stroke_figures, timed
from compliance.procedures.scenarios import full_command_stroke, stroke
from compliance.procedures.outcomes import Sample, downsample, request_key

__all__ = ["ADJUSTERS", "adjusting_device", "run_full_stroke", "run_independent_adjustment", "stroke_runs"]

# the setting that sets each direction's speed, per device (parameter keys)
ADJUSTERS = {
    "limiter": {"opening": "controller.setpoint_opening_rate", "closing": "controller.setpoint_closing_rate"},
    "throttle": {"opening": "flow_control.opening_conductance", "closing": "flow_control.closing_conductance"},
}
_TIME_METRIC = {"opening": "opening_time", "closing": "closing_time"}


def stroke_runs(cfg, op, command, flow_control, timeout, label, out, directions=("opening", "closing"), start="end_stop",
                drive="governor"):
    """Full strokes from each end, simulated long enough to pass 25-75 % and reach the end.

    Parameters
    ----------
    cfg : PlantConfig
    op : requirements.OperatingPoint
        Its load is held during the strokes.
    command : "full" or Amount
        Valve command magnitude about the centre of a manual stroke [V].
    flow_control : bool
        Flow-control valves in the circuit.
    timeout : float
        Longest simulated time per stroke [s] (runs start at 8 s and double up to it).
    label : str
        Trace label prefix; empty = keep no traces or marks in ``out``.
    out : RunOutcome
    directions : iterable of {"opening", "closing"}
    start : {"end_stop", "rest"}
        Initial chamber pressures (``simulation.scenario.stroke_start_pressures``).
    drive : {"governor", "manual"}
        ``scenarios.full_command_stroke``.

    Returns
    -------
    dict
        direction -> (figures of ``metrics.stroke_figures``, DataFrame).
    """
    L = stroke(cfg)
    runs = {}
    for d in directions:
        x_end = L if d == "opening" else 0.0
        # simulate 8 s, then double up to the timeout until the stroke passes 75 % (25 %) and ends
        dur = min(8.0, timeout)
        while True:
            df = full_command_stroke(cfg, op, d, command, dur, flow_control, start, drive)
            tt, x = M.frame_columns(df, "time", "position")
            fig = stroke_figures(tt, x, L, d)
            done = abs(x[-1] - x_end) <= 0.01 * L
            if (fig["extrapolated"] is not None and done) or dur >= timeout:
                break
            dur = min(2.0 * dur, timeout)
        runs[d] = (fig, df)
        if label:
            tl = f"{label} {d}"
            out.traces.append(downsample(df, tl))
            t1, t2 = fig["t25_75"]
            if t1 is not None and t2 is not None:
                out.marks.append({"trace": tl, "type": "stroke_points", "value": [[t1, x[np.searchsorted(tt, t1)]], [t2, x[np.searchsorted(tt, t2)]]]})
    return runs


def _timing_requests(requests, direction) -> dict:
    """Request key -> timing of every stroke-time request for ``direction`` (the default reading included)."""
    metric = _TIME_METRIC[direction]
    out = {metric: option_value({}, "timing")}
    for m, opts in requests:
        if m == metric:
            out[request_key(m, opts)] = option_value(opts, "timing")
    return out


def _drive_text(s: dict, installed: bool) -> str:
    circuit = "flow-control valves 2V2/2V3 " + ("in" if installed else "out")
    if s["drive"] == "governor":
        return f"driven by the governor (full set-point change, closed loop, set-point rate limiter as configured); {circuit}"
    return f"driven in manual (full valve command, open loop); {circuit}"


def run_full_stroke(cfg, proc, op, requests, out):
    """Run a ``full_stroke`` procedure at ``op`` and add its samples to ``out`` (see ``procedures.run``)."""
    s = proc.settings
    label = f"{proc.name}@{op.name}"
    runs = stroke_runs(cfg, op, s["command"], s["flow_control"], s["timeout"].value, label, out, s["directions"], s["start"],
                       s["drive"])
    how = _drive_text(s, s["flow_control"])
    L = stroke(cfg)
    for d, (fig, df) in runs.items():
        tt, x = M.frame_columns(df, "time", "position")
        base = {"t25_75": fig["t25_75"], "extrapolated": fig["extrapolated"], "straight": fig["straight"],
                "quarter_speeds": fig["quarter_speeds"], "start_delay": fig["start_delay"], "time_to_end": fig["time_to_end"],
                "cushion_time": fig["cushion_time"], "cushion_at_rate": fig["cushion_at_rate"], "drive": s["drive"],
                "circuit": how, "load": op.load_text}
        for key, timing in _timing_requests(requests, d).items():
            val, note, used = timed(fig, timing)
            detail = {**base, "timing": timing, "timed_as": used}
            if val is not None and note:
                detail["flag"] = note
            out.add(key, Sample(val, d, None if val is not None else note, detail=detail))
        T = fig["extrapolated"]
        out.add("stroke_speed", Sample(None if T is None else L / T, d, fig["reason"], detail=base))
        for m in ("start_delay", "time_to_end", "cushion_time"):
            why = None if fig[m] is not None else f"{d}: the stroke did not reach {'1' if m == 'start_delay' else '99'} % of its travel"
            out.add(m, Sample(fig[m], d, why, detail=base))
        v, vo, vc = M.speed_extremes(tt, x)
        out.add("max_speed", Sample(v, d))
        out.add("max_opening_speed" if d == "opening" else "max_closing_speed", Sample(vo if d == "opening" else vc, d))
    out.notes.append(f"{how}; load {op.load_text}")


def adjusting_device(cfg, setting: str) -> str:
    """The device an ``independent_adjustment`` changes: the limiter when configured (``auto``), else the throttles."""
    if setting == "auto":
        return "limiter" if cfg.setpoint_rate_limited else "throttle"
    return setting


def run_independent_adjustment(cfg, proc, op, requests, out):
    """Run an ``independent_adjustment`` procedure at ``op`` and add its samples to ``out``."""
    s = proc.settings
    timeout = s["timeout"].value
    device = adjusting_device(cfg, s["device"])
    fc = True if device == "throttle" else None  # the throttles are adjusted in the circuit; else as configured

    def times(c, label):
        runs = stroke_runs(c, op, s["command"], fc, timeout, label, out, start=s["start"], drive=s["drive"])
        return {d: timed(fig, s["timing"]) for d, (fig, _) in runs.items()}

    base = times(cfg, f"{proc.name}@{op.name} base")
    base_t = {d: v[0] for d, v in base.items()}
    for d, v in base.items():
        if v[0] is None:
            raise InputError(f"procedure '{proc.name}' at '{op.name}': base {d}: {v[1]}")
    for adj in s["adjust"]:
        key = ADJUSTERS[device][adj]
        c0 = cfg.p(key)
        other = "closing" if adj == "opening" else "opening"
        if c0 <= 0.0:
            what = "no throttle in the circuit" if device == "throttle" else "the limiter does not limit this direction"
            _not_measured(out, adj, f"{key} = 0 ({what}): there is nothing to adjust")
            continue
        mod_cfg = cfg.replace(params={key: c0 * s["factor"]}, sources={key: cfg.sources.get(key, "user")})
        mod = times(mod_cfg, f"{proc.name}@{op.name} {adj} x{s['factor']:g}")
        mod_t = {d: v[0] for d, v in mod.items()}
        if any(v is None for v in mod_t.values()):
            _not_measured(out, adj, "; ".join(v[1] for v in mod.values() if v[0] is None))
            continue
        cross, own = M.independent_adjustment(base_t, mod_t, adj)
        detail = {"base": base_t, "modified": mod_t, "factor": s["factor"], "parameter": key, "device": device,
                  "timing": s["timing"], "drive": s["drive"]}
        what = "limiter rate" if device == "limiter" else "valve"
        out.add("cross_adjustment_change", Sample(cross, f"{other} time when {adj} {what} x{s['factor']:g}", detail=detail))
        out.add("adjusted_time_change", Sample(own, f"{adj} time when {adj} {what} x{s['factor']:g}", detail=detail))
        out.notes.append(
            f"{key} x{s['factor']:g}: opening {base_t['opening']:.2f} -> {mod_t['opening']:.2f} s, "
            f"closing {base_t['closing']:.2f} -> {mod_t['closing']:.2f} s ({s['timing'].replace('_', ' ')} timing)"
        )


def _not_measured(out, adjusted, reason):
    """Both adjustment metrics without a value, for the same reason."""
    out.add("cross_adjustment_change", Sample(None, f"adjust {adjusted}", reason))
    out.add("adjusted_time_change", Sample(None, f"adjust {adjusted}", reason))
