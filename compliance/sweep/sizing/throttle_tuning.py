"""Throttles refined by simulation: the manual full stroke's 25-75 % time on target at the set-up load.

The steady rule of ``sizing.size_servo`` ignores the pressure transients of a stroke; here each meter-out
conductance is corrected by a secant on log C until the simulated full stroke at the set-up
point (flow-control valves in) takes the target time (within ``TOLERANCE``). This is how plant
A's own throttles were derived (models/plant-a.toml, ``derived_for``: 5.0 s at 5.7 kN).

The set-up point is where the flow-control valves are adjusted on site, as a commissioning
engineer does it (plant paper section 5.2: at the governor set-up load): the requirement file's
operating point with the duty's set-up load when one is given, else the point at which the file
judges the independent adjustment of those valves, else the stroke-time requirement's first
point. One throttle cannot be tuned to several loads: a meter-out throttle's speed depends on the
load, which is why ``govcheck size`` sets the stroke times with the governor's set-point rate
limiter and keeps the throttles wide open as its backstop (``sizing.governor_design``); this module
reproduces how plant A's throttles were derived (models/plant-a.toml, ``derived_for``).
"""

from __future__ import annotations

import math

from compliance import metrics as M
from compliance.procedures.scenarios import full_command_stroke

__all__ = ["TOLERANCE", "setup_point", "stroke_target", "tune_throttles"]

TOLERANCE = 0.005  # relative stroke-time error accepted
KEYS = {"opening": "flow_control.opening_conductance", "closing": "flow_control.closing_conductance"}


def setup_point(reqset, candidates, setup_force: float | None = None) -> str:
    """Name of the operating point where the file adjusts the flow-control valves (module note)."""
    if setup_force is not None:
        for o, op in reqset.operating_points.items():
            if isinstance(op.load, float) and abs(op.load - setup_force) <= 0.01 * abs(setup_force) and op.flow_control is not False:
                return o
    for r in reqset.requirements:
        adjusts = any(reqset.procedures[p].kind == "independent_adjustment" for p in r.procedures if p in reqset.procedures)
        if r.enabled and adjusts:
            for o in r.operating_points:
                if o in candidates and reqset.operating_points[o].flow_control is not False:
                    return o
    return candidates[0]


def stroke_target(reqset, direction: str, stroke: float, given: float | None, setup_force: float | None = None):
    """(target time [s], set-up operating point) of a direction's full stroke: the duty's time, else the window's middle."""
    for r in reqset.requirements:
        if r.metric == f"{direction}_time" and r.enabled and r.operating_points:
            op = reqset.operating_points[setup_point(reqset, list(r.operating_points), setup_force)]
            if given is None and r.limit is not None:
                lim = r.resolved_limit(stroke)
                given = 0.5 * (lim[0] + lim[-1])
            return given, op
    return given, None


def _time(cfg, op, direction):
    df = full_command_stroke(cfg, op, direction, "full", 16.0, True, drive="manual")
    t, x = M.frame_columns(df, "time", "position")
    return M.stroke_time(t, x, cfg.params["cylinder.stroke"], direction)[0]


def tune_throttles(cfg, reqset, times: dict, iterations: int = 6, setup_force: float | None = None):
    """``cfg`` with each throttle refined to its target; returns (cfg, {direction: (target, achieved) or reason})."""
    report = {}
    for d, key in KEYS.items():
        target, op = stroke_target(reqset, d, cfg.params["cylinder.stroke"], times.get(d), setup_force)
        if target is None or op is None or cfg.params[key] <= 0.0:
            report[d] = "kept at the steady rule (no full-stroke requirement to set it against)"
            continue
        c0, t0 = cfg.params[key], _time(cfg, op, d)
        c1 = c0 * (t0 / target if t0 else 1.0)  # stroke time ~ 1/C once the throttle dominates
        for _ in range(iterations):
            cfg = cfg.replace(params={key: c1})
            t1 = _time(cfg, op, d)
            if t1 is None or t0 is None or abs(t1 / target - 1.0) < TOLERANCE:
                break
            slope = (math.log(t1) - math.log(t0)) / (math.log(c1) - math.log(c0)) if c1 != c0 else -1.0
            c0, t0 = c1, t1
            c1 = c1 * math.exp((math.log(target) - math.log(t1)) / (slope if slope < -0.05 else -1.0))
        report[d] = {"target": target, "achieved": t1, "conductance": cfg.params[key], "operating_point": op.name}
    return cfg, report
