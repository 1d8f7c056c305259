"""Full-command stroke procedures: ``full_stroke`` times and ``independent_adjustment`` of the speed settings.

Open loop at full valve command from one end of the stroke to the other, through the
meter-out flow-control valves 2V2/2V3 (seed 000); the stroke time comes from the straight
part of the stroke (``metrics.stroke_time``). Independent adjustment changes one valve's
conductance and measures both directions again.
"""

from __future__ import annotations

import numpy as np

from compliance import metrics as M
from compliance.errors import InputError
from compliance.procedures.scenarios import full_command_stroke, stroke
from compliance.procedures.outcomes import Sample, downsample

__all__ = ["run_full_stroke", "run_independent_adjustment", "stroke_runs"]

# the flow-control valve that sets each direction's speed (parameter key of its conductance)
_VALVE_KEY = {"opening": "flow_control.opening_conductance", "closing": "flow_control.closing_conductance"}


def stroke_runs(cfg, op, command, flow_control, timeout, label, out, directions=("opening", "closing"), start="end_stop"):
    """Full-command strokes from each end, simulated long enough to pass 25-75 % and reach the end.

    Parameters
    ----------
    cfg : PlantConfig
    op : requirements.OperatingPoint
        Its load is held during the strokes.
    command : "full" or Amount
        Valve command magnitude about the centre [V].
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

    Returns
    -------
    dict
        direction -> (stroke time [s] or None, reason or None, DataFrame, t at 25 %, t at 75 %).
    """
    L = stroke(cfg)
    times = {}
    for d in directions:
        x_end = L if d == "opening" else 0.0
        # simulate 8 s, then double up to the timeout until the stroke passes 75 % (25 %) and ends
        dur = min(8.0, timeout)
        while True:
            df = full_command_stroke(cfg, op, d, command, dur, flow_control, start)
            tt, x = M.frame_columns(df, "time", "position")
            T, t1, t2, why = M.stroke_time(tt, x, L, d)
            done = abs(x[-1] - x_end) <= 0.01 * L
            if (T is not None and done) or dur >= timeout:
                break
            dur = min(2.0 * dur, timeout)
        times[d] = (T, why, df, t1, t2)
        if label:
            tl = f"{label} {d}"
            out.traces.append(downsample(df, tl))
            if t1 is not None and t2 is not None:
                out.marks.append({"trace": tl, "type": "stroke_points", "value": [[t1, x[np.searchsorted(tt, t1)]], [t2, x[np.searchsorted(tt, t2)]]]})
    return times


def run_full_stroke(cfg, proc, op, requests, out):
    """Run a ``full_stroke`` procedure at ``op`` and add its samples to ``out`` (see ``procedures.run``)."""
    s = proc.settings
    label = f"{proc.name}@{op.name}"
    times = stroke_runs(cfg, op, s["command"], s["flow_control"], s["timeout"].value, label, out, s["directions"], s["start"])
    circuit = "flow-control valves 2V2/2V3 in" if s["flow_control"] else "flow-control valves 2V2/2V3 out"
    L = stroke(cfg)
    for d, (T, why, df, t1, t2) in times.items():
        tt, x = M.frame_columns(df, "time", "position")
        # ASME PTC 29-2005 (R2020) servomotor timing: start delay, 25-75 % time, time to the end stop, cushioning
        detail = {"t25_75": [t1, t2], **M.stroke_timing(tt, x, L, d, T), "circuit": circuit, "load": op.load_text}
        out.add(f"{d}_time", Sample(T, f"{d} at full command", why, detail=detail))
        out.add("stroke_speed", Sample(None if T is None else L / T, d, why, detail=detail))
        v, vo, vc = M.speed_extremes(tt, x)
        out.add("max_speed", Sample(v, d))
        out.add("max_opening_speed" if d == "opening" else "max_closing_speed", Sample(vo if d == "opening" else vc, d))
    out.notes.append("flow-control valves " + ("installed" if s["flow_control"] else "removed") + f"; load {op.load_text}")


def run_independent_adjustment(cfg, proc, op, requests, out):
    """Run an ``independent_adjustment`` procedure at ``op`` and add its samples to ``out``."""
    s = proc.settings
    timeout = s["timeout"].value
    base = stroke_runs(cfg, op, s["command"], True, timeout, f"{proc.name}@{op.name} base", out, start=s["start"])
    base_t = {d: v[0] for d, v in base.items()}
    for d, v in base.items():
        if v[0] is None:
            raise InputError(f"procedure '{proc.name}' at '{op.name}': base {v[1]}")
    for adj in s["adjust"]:
        key = _VALVE_KEY[adj]
        c0 = cfg.p(key)
        other = "closing" if adj == "opening" else "opening"
        if c0 <= 0.0:
            _not_measured(out, adj, f"{key} = 0 (no throttle in the circuit): there is nothing to adjust")
            continue
        mod_cfg = cfg.replace(params={key: c0 * s["factor"]})
        mod = stroke_runs(mod_cfg, op, s["command"], True, timeout, f"{proc.name}@{op.name} {adj} x{s['factor']:g}", out,
                          start=s["start"])
        mod_t = {d: v[0] for d, v in mod.items()}
        if any(v is None for v in mod_t.values()):
            _not_measured(out, adj, "; ".join(v[1] for v in mod.values() if v[0] is None))
            continue
        cross, own = M.independent_adjustment(base_t, mod_t, adj)
        detail = {"base": base_t, "modified": mod_t, "factor": s["factor"], "parameter": key}
        out.add("cross_adjustment_change", Sample(cross, f"{other} time when {adj} valve x{s['factor']:g}", detail=detail))
        out.add("adjusted_time_change", Sample(own, f"{adj} time when {adj} valve x{s['factor']:g}", detail=detail))
        out.notes.append(
            f"{key} x{s['factor']:g}: opening {base_t['opening']:.2f} -> {mod_t['opening']:.2f} s, "
            f"closing {base_t['closing']:.2f} -> {mod_t['closing']:.2f} s"
        )


def _not_measured(out, adjusted, reason):
    """Both adjustment metrics without a value, for the same reason."""
    out.add("cross_adjustment_change", Sample(None, f"adjust {adjusted}", reason))
    out.add("adjusted_time_change", Sample(None, f"adjust {adjusted}", reason))
