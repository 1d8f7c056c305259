"""The set-point rate limiter as a remedy: its settings' box and a start derived from the requirements.

The limiter (docs/physics.md, controller section) is a governor setting, off in a configuration
that gives no rate. Its start in the search is what a commissioning engineer would set first:
each direction's rate so that a full stroke takes the middle of its required opening/closing
time window (the 25-75 % rule extrapolates the straight part to the whole stroke) when that is
at most 90 % of the tightest speed limit, else the slowest rate in the window's slower half
that stays under the limit; a ramp hold (lead limit) of 2 % of the stroke; and the meter-out
throttles opened to the top of their range, so that they back the limiter up instead of
competing with it. The box spans 0.8-1.2 times those rates and 0.5-10 % of the stroke for the hold.
"""

from __future__ import annotations

from compliance.sweep.candidates.parameter_paths import describe
from compliance.sweep.candidates.spec import Adjustable

__all__ = ["LIMITER_PATHS", "limiter_space", "limiter_stage_start", "limiter_start"]

THROTTLES = ("flow_control.opening_conductance", "flow_control.closing_conductance")


def limiter_stage_start(adjust, values: dict, lim_start: dict) -> dict:
    """Start of the limiter stage: ``values`` (the settings so far), the limiter's start, throttles at the top of their range."""
    out = {**values, **lim_start}
    out.update({a.param.path: a.high for a in adjust if a.param.path in THROTTLES})
    return out

LIMITER_PATHS = ("controller.setpoint_opening_rate", "controller.setpoint_closing_rate", "controller.setpoint_lead_limit")
SPEED_MARGIN = 0.9  # start below the speed limit: the gate overshoots the ramp a little when it breaks away (our choice)
DEFAULT_STROKE_TIME = 5.0  # s, when the requirement file states no stroke time (seed 000's setting)


def _window(reqset, metric: str, stroke: float) -> tuple[float, float] | None:
    for r in reqset.requirements:
        if r.metric == metric and r.enabled and r.limit is not None:
            lim = r.resolved_limit(stroke)
            return lim[0], lim[-1]
    return None


def _speed_limit(reqset, stroke: float) -> float | None:
    vals = [r.resolved_limit(stroke)[-1] for r in reqset.requirements
            if r.enabled and r.limit is not None and r.metric in ("max_speed", "max_opening_speed", "max_closing_speed")
            and r.comparator in ("<=", "<")]
    return min(vals) if vals else None


def limiter_start(cfg, reqset) -> dict:
    """Rates [m/s] and lead limit [m] a commissioning engineer would set first for ``reqset``."""
    L = cfg.params["cylinder.stroke"]
    v_max = _speed_limit(reqset, L)
    out = {}
    for path, metric in zip(LIMITER_PATHS[:2], ("opening_time", "closing_time")):
        lo, hi = _window(reqset, metric, L) or (DEFAULT_STROKE_TIME, DEFAULT_STROKE_TIME)
        mid = 0.5 * (lo + hi)
        rate = L / mid
        if v_max and rate > SPEED_MARGIN * v_max:
            rate = min(v_max, max(SPEED_MARGIN * v_max, L / (mid + 0.5 * (hi - mid))))
        out[path] = rate
    out[LIMITER_PATHS[2]] = 0.02 * L
    return out


def limiter_space(cfg, reqset) -> tuple[tuple[Adjustable, ...], dict]:
    """(the limiter's adjustable settings, their start) for the remedies search of a PID configuration."""
    start = limiter_start(cfg, reqset)
    L = cfg.params["cylinder.stroke"]
    adjust = []
    for path in LIMITER_PATHS:
        pp = describe(path, "remedies space")
        lo, hi = (0.005 * L, 0.10 * L) if path == LIMITER_PATHS[2] else (0.8 * start[path], 1.2 * start[path])
        adjust.append(Adjustable(pp, lo, hi, None, 3))
    return tuple(adjust), start
